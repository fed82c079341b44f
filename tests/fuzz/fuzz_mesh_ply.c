/* fuzz_mesh_ply.c — libFuzzer target: mesh import from memory of PLY, binary and ASCII (the header checks of mesh_check.c, then Assimp's PLY reader), and the flattening of
 * what it returns. Assimp is the system library and is not instrumented: guidance sees only
 * mesh_check.c and mesh_import.c. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "gfx/mesh_import.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rt_mesh_data mesh;
    char err[256];
    const char *hint = "ply";
    if (rt_mesh_import_memory(data, size, hint, &mesh, err, sizeof err) == VFX_OK)
        rt_mesh_data_free(&mesh);
    return 0;
}
