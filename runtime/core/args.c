/* args.c — see args.h. */
#define _POSIX_C_SOURCE 200809L
#include "core/args.h"
#include "core/file.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool rt_arg_u32(const char *opt, const char *v, uint32_t lo, uint32_t hi, uint32_t *out, char *err,
                size_t errlen)
{
    char *end = NULL;
    errno = 0;
    unsigned long long x = v && *v >= '0' && *v <= '9' ? strtoull(v, &end, 10) : 0;
    if (!v || !end || *end || errno || x < lo || x > hi) {
        snprintf(err, errlen, "%s wants a whole number in %u..%u, got '%s'", opt, lo, hi, v ? v : "");
        return false;
    }
    *out = (uint32_t)x;
    return true;
}

bool rt_arg_double(const char *opt, const char *v, double lo, double hi, double *out, char *err,
                   size_t errlen)
{
    char *end = NULL;
    double x = v ? strtod(v, &end) : NAN;
    if (!v || end == v || *end || !isfinite(x) || x < lo || x > hi) {
        snprintf(err, errlen, "%s wants a number in %g..%g, got '%s'", opt, lo, hi, v ? v : "");
        return false;
    }
    *out = x;
    return true;
}

bool rt_arg_size(const char *opt, const char *v, uint32_t max, uint32_t *w, uint32_t *h, char *err,
                 size_t errlen)
{
    const char *x = v ? strchr(v, 'x') : NULL;
    char a[32];
    if (!x || (size_t)(x - v) >= sizeof a) {
        snprintf(err, errlen, "%s wants WxH (each 1..%u), got '%s'", opt, max, v ? v : "");
        return false;
    }
    memcpy(a, v, (size_t)(x - v));
    a[x - v] = 0;
    if (!rt_arg_u32(opt, a, 1, max, w, err, errlen) || !rt_arg_u32(opt, x + 1, 1, max, h, err, errlen)) {
        snprintf(err, errlen, "%s wants WxH (each 1..%u), got '%s'", opt, max, v);
        return false;
    }
    return true;
}

bool rt_arg_writable(const char *opt, const char *path, char *err, size_t errlen)
{
    if (!path || !*path) {
        snprintf(err, errlen, "%s wants a file name", opt);
        return false;
    }
    char msg[1200];
    if (rt_check_output_path(path, msg, sizeof msg) != VFX_OK) {
        snprintf(err, errlen, "%s: %s", opt, msg);
        return false;
    }
    return true;
}
