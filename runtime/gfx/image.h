/* image.h — PNG screenshots (zlib, no libpng) and PFM raw-quantity dumps. */
#ifndef RT_IMAGE_H
#define RT_IMAGE_H

#include <stddef.h>
#include <stdint.h>
#include <volfx/volfx.h>

/* Writes an RGBA8 image (top row first) as an 8-bit RGBA PNG. */
vfx_result rt_write_png(const char *path, uint32_t width, uint32_t height, const uint8_t *rgba,
                         char *err, size_t errlen);
/* Writes a one-channel float32 image (top row first) as a standard little-endian PFM ("Pf",
 * scale -1, rows stored bottom first as the format requires). */
vfx_result rt_write_pfm(const char *path, uint32_t width, uint32_t height, const float *data,
                         char *err, size_t errlen);
/* Reads a one-channel PFM into malloc'd floats (top row first). Either endianness. */
vfx_result rt_read_pfm(const char *path, uint32_t *width, uint32_t *height, float **data,
                        char *err, size_t errlen);

#endif
