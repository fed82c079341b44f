/* args.c — see args.h. */
#define _POSIX_C_SOURCE 200809L
#include "core/args.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

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
    struct stat st;
    if (!path || !*path) {
        snprintf(err, errlen, "%s wants a file name", opt);
        return false;
    }
    if (stat(path, &st) == 0) {
        if (S_ISDIR(st.st_mode) || access(path, W_OK) != 0) {
            snprintf(err, errlen, "%s: %s %s", opt, path, S_ISDIR(st.st_mode) ? "is a directory" : "is not writable");
            return false;
        }
        return true;
    }
    char dir[1024];
    const char *slash = strrchr(path, '/');
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) + (slash == path) : 1, slash ? path : ".");
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode) || access(dir, W_OK | X_OK) != 0) {
        snprintf(err, errlen, "%s: cannot create %s (directory '%s' %s)", opt, path, dir,
                 stat(dir, &st) != 0 ? "does not exist" : "is not writable");
        return false;
    }
    return true;
}
