/* log.h — the runtime's logger: a callback, never printf from library code. */
#ifndef RT_LOG_H
#define RT_LOG_H

#include <volfx/volfx.h>

typedef struct rt_logger {
    void (*fn)(void *user, vfx_log_level level, const char *message); /* NULL -> stderr */
    void *user;
} rt_logger;

/* Formats and sends one message through `logger` (stderr when logger or its fn is NULL). */
void rt_logf(const rt_logger *logger, vfx_log_level level, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* A logger callback that writes "[volfx level] message" to stderr; usable as rt_logger.fn. */
void rt_log_stderr(void *user, vfx_log_level level, const char *message);

#endif
