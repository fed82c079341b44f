/* tet_result.c — tet_errf, the tet library's (err, errlen) message writer. */
#include "tet_result.h"

#include <stdarg.h>
#include <stdio.h>

void tet_errf(char *err, size_t errlen, const char *fmt, ...)
{
    if (!err || errlen == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
}
