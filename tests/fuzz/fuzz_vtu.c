/* fuzz_vtu.c — libFuzzer target: VTK XML .vtu parsing from memory (ascii, base64, appended, zlib)
 * with and without a named scalar field, then validation as the loader does it. */
#include <stdint.h>
#include <stdlib.h>

#include "scene/volume_file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char err[256];
    /* Both the "no scalar" path and the named vector-magnitude path are reachable from one input. */
    const char *names[2] = {NULL, "Velocity"};
    for (int i = 0; i < 2; i++) {
        tet_mesh mesh;
        if (rt_volume_load_vtu_mem(data, size, names[i], &mesh, err, sizeof err) == VFX_OK)
            tet_mesh_free(&mesh);
    }
    return 0;
}
