/* particle_file.c — see particle_file.h. Bytes are assembled explicitly so the format stays
 * little-endian on any host. */
#include "scene/particle_file.h"
#include "core/file.h"
#include "scene/scene.h"

_Static_assert(RT_PARTICLE_FILE_MAX_COUNT == RT_SCENE_MAX_PARTICLES, "one particle cap");

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void set_err(char *err, size_t errlen, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void set_err(char *err, size_t errlen, const char *fmt, ...)
{
    if (!err || !errlen)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
}

static float decode_f32(const unsigned char *p)
{
    uint32_t u = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

static void encode_f32(float f, unsigned char *p)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    p[0] = (unsigned char)u, p[1] = (unsigned char)(u >> 8), p[2] = (unsigned char)(u >> 16),
    p[3] = (unsigned char)(u >> 24);
}

static vfx_result parse_named(const char *name, const void *data, size_t size, float **xyz,
                              uint32_t *count, char *err, size_t errlen)
{
    *xyz = NULL;
    *count = 0;
    if (size % 12 != 0) {
        set_err(err, errlen, "%s: size %llu bytes is not a multiple of 12 (x,y,z float32 per particle)",
                name, (unsigned long long)size);
        return VFX_ERR_FORMAT;
    }
    size_t n = size / 12;
    if (n > RT_PARTICLE_FILE_MAX_COUNT) {
        set_err(err, errlen, "%s: %llu particles, above the cap of %u (RT_PARTICLE_FILE_MAX_COUNT)", name, (unsigned long long)n,
                RT_PARTICLE_FILE_MAX_COUNT);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    if (n == 0)
        return VFX_OK;
    float *out = malloc(n * 3 * sizeof(float));
    if (!out) {
        set_err(err, errlen, "%s: out of memory for %llu particles", name, (unsigned long long)n);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    const unsigned char *p = data;
    for (size_t i = 0; i < 3 * n; ++i) {
        out[i] = decode_f32(p + 4 * i);
        if (!isfinite(out[i])) {
            if (err && errlen)
                snprintf(err, errlen, "%s: particle %llu has a non-finite %c (%s)", name,
                         (unsigned long long)(i / 3), "xyz"[i % 3], isnan(out[i]) ? "NaN" : "Inf");
            free(out);
            return VFX_ERR_FORMAT;
        }
    }
    *xyz = out;
    *count = (uint32_t)n;
    return VFX_OK;
}

vfx_result rt_particle_file_parse(const void *data, size_t size, float **xyz, uint32_t *count,
                                   char *err, size_t errlen)
{
    if (!xyz || !count || (!data && size)) {
        set_err(err, errlen, "particle data: NULL argument");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    return parse_named("particle data", data, size, xyz, count, err, errlen);
}

vfx_result rt_particle_file_load(const char *path, float **xyz, uint32_t *count, char *err,
                                  size_t errlen)
{
    if (!path || !xyz || !count) {
        set_err(err, errlen, "particle file: NULL argument");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    *xyz = NULL;
    *count = 0;
    char *buf;
    size_t size;
    char tmp[512];
    vfx_result rr = rt_read_file(path, (size_t)RT_PARTICLE_FILE_MAX_COUNT * 12, "4194304 particles (RT_PARTICLE_FILE_MAX_COUNT)", &buf,
                                  &size, tmp, sizeof tmp);
    if (rr) {
        set_err(err, errlen, "%s", tmp);
        return rr;
    }
    vfx_result r = parse_named(path, buf, size, xyz, count, err, errlen);
    free(buf);
    return r;
}

vfx_result rt_particle_file_save(const char *path, const float *xyz, uint32_t count, char *err,
                                  size_t errlen)
{
    if (!path || (!xyz && count)) {
        set_err(err, errlen, "particle file: NULL argument");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    for (size_t i = 0; i < 3 * (size_t)count; ++i)
        if (!isfinite(xyz[i])) {
            if (err && errlen)
                snprintf(err, errlen, "%s: particle %llu has a non-finite %c; nothing written", path,
                         (unsigned long long)(i / 3), "xyz"[i % 3]);
            return VFX_ERR_INVALID_ARGUMENT;
        }
    FILE *f = fopen(path, "wb");
    if (!f) {
        if (err && errlen)
            snprintf(err, errlen, "%s: cannot create: %s", path, strerror(errno));
        return VFX_ERR_IO;
    }
    unsigned char chunk[12 * 256];
    size_t k = 0;
    int ok = 1;
    for (size_t i = 0; i < 3 * (size_t)count && ok; ++i) {
        encode_f32(xyz[i], chunk + 4 * k++);
        if (k == sizeof chunk / 4) {
            ok = fwrite(chunk, 1, sizeof chunk, f) == sizeof chunk;
            k = 0;
        }
    }
    if (ok && k)
        ok = fwrite(chunk, 1, 4 * k, f) == 4 * k;
    if (fclose(f) != 0)
        ok = 0;
    if (!ok) {
        set_err(err, errlen, "%s: write failed (disk full?)", path);
        return VFX_ERR_IO;
    }
    return VFX_OK;
}
