/* file.c — see file.h. */
#include "core/file.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

vfx_result rt_read_file(const char *path, size_t max_bytes, const char *cap_text, char **out,
                         size_t *size, char *err, size_t errlen)
{
    *out = NULL;
    *size = 0;
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
        return VFX_ERR_IO;
    }
    long end = -1;
    if (fseek(f, 0, SEEK_END) == 0)
        end = ftell(f);
    if (end < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        snprintf(err, errlen, "%s: cannot determine the size (not a regular file?)", path);
        return VFX_ERR_IO;
    }
    size_t n = (size_t)end;
    if (n > max_bytes) { /* refuse a huge file before allocating anything for it */
        fclose(f);
        snprintf(err, errlen, "%s: %llu bytes, above the cap of %s", path, (unsigned long long)n, cap_text);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    char *buf = malloc(n + 1);
    if (!buf) {
        fclose(f);
        snprintf(err, errlen, "%s: out of memory for %llu bytes", path, (unsigned long long)n);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    size_t got = fread(buf, 1, n, f);
    fclose(f);
    if (got != n) {
        free(buf);
        snprintf(err, errlen, "%s: short read (%llu bytes expected)", path, (unsigned long long)n);
        return VFX_ERR_IO;
    }
    buf[n] = 0;
    *out = buf;
    *size = n;
    return VFX_OK;
}
