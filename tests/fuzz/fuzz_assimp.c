/* fuzz_assimp.c — libFuzzer target: mesh import from memory of OBJ, through the path the game
 * takes: the checks, Assimp and the flattening run in a child process (core/sandbox.h), whose
 * answer the host reads back and checks. The child's coverage does not reach the fuzzer, so the
 * checks of mesh_check.c (Assimp-free) also run here, in the fuzzer's process, for guidance.
 * Assimp is the system library and is not instrumented. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "gfx/mesh_check.h"
#include "gfx/mesh_import.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rt_mesh_data mesh;
    char err[256];
    char name[16];
    snprintf(name, sizeof name, "fuzz.%s", "obj");
    rt_mesh_check_bytes(rt_mesh_format_of_name(name), data, size, name, err, sizeof err);
    if (rt_mesh_import_memory(data, size, "obj", &mesh, err, sizeof err) == VFX_OK)
        rt_mesh_data_free(&mesh);
    return 0;
}
