/* fuzz_particle_file.c — libFuzzer target: the particle file decoder. */
#include <stdint.h>
#include <stdlib.h>

#include "scene/particle_file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    float *xyz = NULL;
    uint32_t n = 0;
    char err[256];
    if (rt_particle_file_parse(data, size, &xyz, &n, err, sizeof err) == VFX_OK)
        free(xyz);
    return 0;
}
