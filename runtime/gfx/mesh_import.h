/* mesh_import.h — static meshes from files (Assimp C API) or made in code, and their upload. */
#ifndef RT_MESH_IMPORT_H
#define RT_MESH_IMPORT_H

#include <stddef.h>
#include <stdint.h>
#include <volfx/volfx.h>

#include "core/sandbox.h"

/* CPU mesh: every mesh of a file flattened into one with node transforms applied. */
typedef struct rt_mesh_data {
    float *positions;    /* 3 per vertex */
    float *normals;      /* 3 per vertex */
    uint32_t *indices;   /* 3 per triangle */
    uint32_t vertex_count, index_count;
    float bounds_min[3], bounds_max[3];
} rt_mesh_data;

/* GPU mesh ready to draw. */
typedef struct rt_mesh_gpu {
    unsigned vao, vbo, ibo;
    uint32_t index_count;
} rt_mesh_gpu;

/* Imports a file with Assimp (triangulated, normals generated when absent), in a child process
 * with the limits of rt_sandbox_default_limits (core/sandbox.h): a crash, hang or blow-up of
 * the reader is VFX_ERR_FORMAT saying which. Errors name the file and carry Assimp's message;
 * a file with no triangles is VFX_ERR_FORMAT. */
vfx_result rt_mesh_import(const char *path, rt_mesh_data *out, char *err, size_t errlen);
/* Same from memory (`hint` is the format extension, e.g. "obj"); for fuzzing and tests. */
vfx_result rt_mesh_import_memory(const void *data, size_t size, const char *hint,
                                  rt_mesh_data *out, char *err, size_t errlen);
/* Tests only: Assimp gets the bytes without mesh_check.c's checks (to show its own crash is
 * contained). */
#define RT_MESH_IMPORT_UNCHECKED 1u
/* rt_mesh_import_memory with the child's limits (NULL: the defaults) and RT_MESH_IMPORT_* flags. */
vfx_result rt_mesh_import_memory_ex(const void *data, size_t size, const char *hint, const rt_sandbox_limits *lim,
                                     unsigned flags, rt_mesh_data *out, char *err, size_t errlen);
/* An axis-aligned box from min to max (outward normals). */
vfx_result rt_mesh_make_box(const float min[3], const float max[3], rt_mesh_data *out);
/* Frees the arrays; NULL allowed. */
void rt_mesh_data_free(rt_mesh_data *m);
/* Uploads to GL (needs a current context). */
vfx_result rt_mesh_upload(const rt_mesh_data *m, rt_mesh_gpu *out);
/* Deletes the GL objects. */
void rt_mesh_gpu_destroy(rt_mesh_gpu *g);

#endif
