/* file.c — see file.h. */
#define _POSIX_C_SOURCE 200809L
#include "core/file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *kind_of(mode_t m)
{
    if (S_ISDIR(m)) return "is a directory";
    if (S_ISFIFO(m)) return "is a FIFO (named pipe)";
    if (S_ISCHR(m)) return "is a character device";
    if (S_ISBLK(m)) return "is a block device";
    if (S_ISSOCK(m)) return "is a socket";
    return "is not a regular file";
}

vfx_result rt_check_regular_file(const char *path, char *err, size_t errlen)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
        return VFX_ERR_IO;
    }
    if (!S_ISREG(st.st_mode)) {
        snprintf(err, errlen, "%s: %s, not a regular file", path, kind_of(st.st_mode));
        return VFX_ERR_IO;
    }
    return VFX_OK;
}

/* /dev/null (by device number, so a link to it counts): the one device an output may be */
static int is_dev_null(const struct stat *st)
{
    struct stat n;
    return S_ISCHR(st->st_mode) && stat("/dev/null", &n) == 0 && S_ISCHR(n.st_mode) && n.st_rdev == st->st_rdev;
}

vfx_result rt_check_output_path(const char *path, char *err, size_t errlen)
{
    struct stat st;
    if (!path || !*path) {
        snprintf(err, errlen, "an empty output path");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    if (stat(path, &st) == 0) {
        if (!S_ISREG(st.st_mode) && !is_dev_null(&st)) {
            snprintf(err, errlen, "%s %s; an output must be a regular file or /dev/null", path, kind_of(st.st_mode));
            return VFX_ERR_IO;
        }
        if (access(path, W_OK) != 0) {
            snprintf(err, errlen, "%s is not writable", path);
            return VFX_ERR_IO;
        }
        return VFX_OK;
    }
    char dir[1024];
    const char *slash = strrchr(path, '/');
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) + (slash == path) : 1, slash ? path : ".");
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode) || access(dir, W_OK | X_OK) != 0) {
        snprintf(err, errlen, "cannot create %s (directory '%s' %s)", path, dir,
                 stat(dir, &st) != 0 ? "does not exist" : !S_ISDIR(st.st_mode) ? "is not a directory" : "is not writable");
        return VFX_ERR_IO;
    }
    return VFX_OK;
}

FILE *rt_open_output(const char *path, const char *mode, char *err, size_t errlen)
{
    /* O_NONBLOCK: a FIFO without a reader fails at once (ENXIO) instead of blocking the open
     * forever; it is cleared again for the writes to a regular file */
    int fd = path && *path ? open(path, O_WRONLY | O_CREAT | O_TRUNC | O_NONBLOCK | O_NOCTTY | O_CLOEXEC, 0666) : -1;
    if (fd < 0) {
        int e = path && *path ? errno : EINVAL;
        struct stat st;
        if (e == ENXIO && stat(path, &st) == 0 && S_ISFIFO(st.st_mode))
            snprintf(err, errlen, "%s is a FIFO (named pipe) with no reader; an output must be a regular file or /dev/null",
                     path ? path : "");
        else
            snprintf(err, errlen, "cannot write %s: %s", path ? path : "(null)", strerror(e));
        return NULL;
    }
    struct stat st;
    if (fstat(fd, &st) != 0 || (!S_ISREG(st.st_mode) && !is_dev_null(&st))) {
        close(fd);
        snprintf(err, errlen, "%s %s; an output must be a regular file or /dev/null", path, kind_of(st.st_mode));
        return NULL;
    }
    int fl = fcntl(fd, F_GETFL);
    FILE *f = fl < 0 || fcntl(fd, F_SETFL, fl & ~O_NONBLOCK) < 0 ? NULL : fdopen(fd, mode);
    if (!f) {
        snprintf(err, errlen, "cannot write %s: %s", path, strerror(errno));
        close(fd);
    }
    return f;
}

static vfx_result over_cap(const char *path, unsigned long long n, int at_least, const char *cap_text,
                           char *err, size_t errlen)
{
    snprintf(err, errlen, "%s: %s%llu bytes, above the cap of %s", path, at_least ? "at least " : "",
             n, cap_text);
    return VFX_ERR_INVALID_ARGUMENT;
}

vfx_result rt_read_file(const char *path, size_t max_bytes, const char *cap_text, char **out,
                         size_t *size, char *err, size_t errlen)
{
    *out = NULL;
    *size = 0;
    vfx_result r = rt_check_regular_file(path, err, errlen);
    if (r)
        return r;
    /* O_NONBLOCK: if the path became a FIFO after the check, open returns at once and the
     * fstat below refuses it; on a regular file the flag changes nothing. */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd < 0) {
        snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
        return VFX_ERR_IO;
    }
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        snprintf(err, errlen, "%s: %s, not a regular file", path, kind_of(st.st_mode));
        return VFX_ERR_IO;
    }
    if (st.st_size < 0 || (unsigned long long)st.st_size > max_bytes) { /* before allocating */
        close(fd);
        return over_cap(path, (unsigned long long)st.st_size, 0, cap_text, err, errlen);
    }
    /* Read to EOF rather than trusting st_size: /proc files say 0, a growing file says more
     * later. The buffer grows only when a read past the expected end returns data. */
    size_t cap = st.st_size > 0 ? (size_t)st.st_size : 4096, n = 0;
    char *buf = malloc(cap + 1);
    for (;;) {
        if (!buf) {
            close(fd);
            snprintf(err, errlen, "%s: out of memory for %zu bytes", path, cap);
            return VFX_ERR_OUT_OF_MEMORY;
        }
        char probe[4096];
        int full = n == cap; /* then read into probe: EOF here costs no reallocation */
        ssize_t got = read(fd, full ? probe : buf + n, full ? sizeof probe : cap - n);
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            int e = errno;
            free(buf);
            close(fd);
            snprintf(err, errlen, "%s: read failed after %zu bytes: %s", path, n, strerror(e));
            return VFX_ERR_IO;
        }
        if (got == 0)
            break;
        if (full) {
            if (n + (size_t)got > max_bytes) {
                free(buf);
                close(fd);
                return over_cap(path, (unsigned long long)(n + (size_t)got), 1, cap_text, err, errlen);
            }
            size_t ncap = cap > max_bytes / 2 ? max_bytes : 2 * cap;
            if (ncap < n + (size_t)got)
                ncap = n + (size_t)got;
            char *nb = realloc(buf, ncap + 1);
            if (!nb)
                free(buf);
            buf = nb;
            cap = ncap;
            if (buf)
                memcpy(buf + n, probe, (size_t)got);
        }
        n += (size_t)got;
    }
    close(fd);
    if (n > max_bytes) {
        free(buf);
        return over_cap(path, (unsigned long long)n, 1, cap_text, err, errlen);
    }
    buf[n] = 0;
    *out = buf;
    *size = n;
    return VFX_OK;
}
