/* water_test_host.h — the water tests' particle chunks: n particles as x, y, z columns handed
 * over in chunks of `chunk` (several chunks exercise the plugin's concatenation). */
#ifndef WATER_TEST_HOST_H
#define WATER_TEST_HOST_H

#include <stdint.h>

#include "volfx/volfx.h"

/* Chunks of n particles in chunks of `chunk`. */
static inline uint32_t water_test_chunk_count(uint32_t n, uint32_t chunk)
{
    return n ? (n + chunk - 1) / chunk : 0;
}

/* Fills out's count and position columns with chunk `index`; returns its first particle. */
static inline uint32_t water_test_chunk(const float *x, const float *y, const float *z, uint32_t n, uint32_t chunk,
                                        uint32_t index, vfx_particle_view *out)
{
    uint32_t first = index * chunk;
    out->count = n - first < chunk ? n - first : chunk;
    out->pos[0] = x + first;
    out->pos[1] = y + first;
    out->pos[2] = z + first;
    return first;
}

#endif
