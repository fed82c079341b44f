/* fuzz_assimp.c — libFuzzer target: Assimp import from memory as we call it (OBJ hint), then our
 * flattening of the scene. Assimp is the system library and is not instrumented: coverage
 * guidance sees only our mesh_import.c; Assimp's own code is exercised blind. */
#include <stdint.h>
#include <stdlib.h>

#include "gfx/mesh_import.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rt_mesh_data mesh;
    char err[256];
    if (rt_mesh_import_memory(data, size, "obj", &mesh, err, sizeof err) == VFX_OK)
        rt_mesh_data_free(&mesh);
    return 0;
}
