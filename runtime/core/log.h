/* log.h — the runtime's logger: a callback, never printf from library code. */
#ifndef VFX_LOG_H
#define VFX_LOG_H

#include <volfx/volfx.h>

typedef struct vfx_logger {
    void (*fn)(void *user, vfx_log_level level, const char *message); /* NULL -> stderr */
    void *user;
} vfx_logger;

/* Formats and sends one message through `logger` (stderr when logger or its fn is NULL). */
void vfx_logf(const vfx_logger *logger, vfx_log_level level, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* A logger callback that writes "[volfx level] message" to stderr; usable as vfx_logger.fn. */
void vfx_log_stderr(void *user, vfx_log_level level, const char *message);

#endif
