/* image.c — PNG via zlib's compress2 and crc32; PFM by hand. */
#include "gfx/image.h"
#include "core/file.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

static void be32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v >> 24), p[1] = (uint8_t)(v >> 16), p[2] = (uint8_t)(v >> 8), p[3] = (uint8_t)v;
}

static bool chunk(FILE *f, const char *type, const uint8_t *data, uint32_t len)
{
    uint8_t hdr[8];
    be32(hdr, len);
    memcpy(hdr + 4, type, 4);
    uLong crc = crc32(0, hdr + 4, 4);
    if (len)
        crc = crc32(crc, data, len);
    uint8_t c[4];
    be32(c, (uint32_t)crc);
    return fwrite(hdr, 1, 8, f) == 8 && (len == 0 || fwrite(data, 1, len, f) == len)
           && fwrite(c, 1, 4, f) == 4;
}

vfx_result rt_write_png(const char *path, uint32_t w, uint32_t h, const uint8_t *rgba, char *err,
                         size_t errlen)
{
    if (!path || !rgba || w == 0 || h == 0 || w > 65535 || h > 65535) {
        snprintf(err, errlen, "png: bad arguments (%ux%u)", w, h);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    size_t row = (size_t)w * 4 + 1;
    size_t raw_len = row * h;
    uint8_t *raw = malloc(raw_len);
    uLongf zlen = compressBound((uLong)raw_len);
    uint8_t *z = malloc(zlen);
    if (!raw || !z) {
        free(raw), free(z);
        snprintf(err, errlen, "png: out of memory for %ux%u", w, h);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t y = 0; y < h; ++y) {
        raw[y * row] = 0; /* filter: none */
        memcpy(raw + y * row + 1, rgba + (size_t)y * w * 4, (size_t)w * 4);
    }
    int zr = compress2(z, &zlen, raw, (uLong)raw_len, 6);
    free(raw);
    if (zr != Z_OK) {
        free(z);
        snprintf(err, errlen, "png: zlib error %d", zr);
        return VFX_ERR_IO;
    }
    char why[1200];
    FILE *f = rt_open_output(path, "wb", why, sizeof why);
    if (!f) {
        free(z);
        snprintf(err, errlen, "png: %s", why);
        return VFX_ERR_IO;
    }
    static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    uint8_t ihdr[13];
    be32(ihdr, w);
    be32(ihdr + 4, h);
    ihdr[8] = 8, ihdr[9] = 6, ihdr[10] = 0, ihdr[11] = 0, ihdr[12] = 0; /* 8-bit RGBA */
    bool ok = fwrite(sig, 1, 8, f) == 8 && chunk(f, "IHDR", ihdr, 13)
              && chunk(f, "IDAT", z, (uint32_t)zlen) && chunk(f, "IEND", NULL, 0);
    ok = (fclose(f) == 0) && ok;
    free(z);
    if (!ok) {
        snprintf(err, errlen, "png: write to '%s' failed", path);
        return VFX_ERR_IO;
    }
    return VFX_OK;
}

vfx_result rt_write_pfm(const char *path, uint32_t w, uint32_t h, const float *data, char *err,
                         size_t errlen)
{
    if (!path || !data || w == 0 || h == 0) {
        snprintf(err, errlen, "pfm: bad arguments");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    char why[1200];
    FILE *f = rt_open_output(path, "wb", why, sizeof why);
    if (!f) {
        snprintf(err, errlen, "pfm: %s", why);
        return VFX_ERR_IO;
    }
    bool ok = fprintf(f, "Pf\n%u %u\n-1.0\n", w, h) > 0;
    for (uint32_t y = 0; y < h && ok; ++y) /* PFM stores the bottom row first */
        ok = fwrite(data + (size_t)(h - 1 - y) * w, sizeof(float), w, f) == w;
    ok = (fclose(f) == 0) && ok;
    if (!ok) {
        snprintf(err, errlen, "pfm: write to '%s' failed", path);
        return VFX_ERR_IO;
    }
    return VFX_OK;
}

vfx_result rt_read_pfm(const char *path, uint32_t *w, uint32_t *h, float **data, char *err,
                        size_t errlen)
{
    *data = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, errlen, "pfm: cannot open '%s'", path);
        return VFX_ERR_IO;
    }
    char magic[3] = {0};
    double scale = 0;
    if (fscanf(f, "%2s %u %u %lf", magic, w, h, &scale) != 4 || strcmp(magic, "Pf") != 0 || *w == 0
        || *h == 0 || *w > 65535 || *h > 65535 || scale == 0 || fgetc(f) == EOF) {
        fclose(f);
        snprintf(err, errlen, "pfm: '%s' is not a one-channel PFM", path);
        return VFX_ERR_FORMAT;
    }
    size_t n = (size_t)*w * *h;
    float *d = malloc(n * sizeof(float));
    if (!d || fread(d, sizeof(float), n, f) != n) {
        free(d);
        fclose(f);
        snprintf(err, errlen, "pfm: '%s' is truncated", path);
        return VFX_ERR_FORMAT;
    }
    fclose(f);
    const uint16_t probe = 1;
    bool host_le = *(const uint8_t *)&probe == 1;
    if ((scale < 0) != host_le) /* swap bytes when the file's endianness differs */
        for (size_t i = 0; i < n; ++i) {
            uint8_t *b = (uint8_t *)&d[i], t;
            t = b[0], b[0] = b[3], b[3] = t, t = b[1], b[1] = b[2], b[2] = t;
        }
    float *top = malloc(n * sizeof(float));
    if (!top) {
        free(d);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t y = 0; y < *h; ++y)
        memcpy(top + (size_t)y * *w, d + (size_t)(*h - 1 - y) * *w, *w * sizeof(float));
    free(d);
    *data = top;
    return VFX_OK;
}
