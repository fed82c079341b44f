/* log.c — formatting front of the logger callback. */
#include "core/log.h"

#include <stdarg.h>
#include <stdio.h>

void rt_log_stderr(void *user, vfx_log_level level, const char *message)
{
    static const char *names[] = {"debug", "info", "warn", "error"};
    (void)user;
    fprintf(stderr, "[volfx %s] %s\n", names[level <= VFX_LOG_ERROR ? level : VFX_LOG_ERROR], message);
}

void rt_logf(const rt_logger *logger, vfx_log_level level, const char *fmt, ...)
{
    char buf[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    if (logger && logger->fn)
        logger->fn(logger->user, level, buf);
    else
        rt_log_stderr(NULL, level, buf);
}
