/* error.c — rt_errf, the runtime's (err, errlen) message writer. */
#include "core/error.h"

#include <stdarg.h>
#include <stdio.h>

vfx_result rt_errf(char *err, size_t errlen, vfx_result r, const char *fmt, ...)
{
    if (!err || errlen == 0)
        return r;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
    return r;
}
