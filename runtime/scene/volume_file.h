/* volume_file.h — loaders for tetrahedral meshes (VTK XML .vtu, TetGen .node/.ele) and the validation
 * both share. All return a vfx_result and write a message naming what and where into err. */
#ifndef RT_VOLUME_FILE_H
#define RT_VOLUME_FILE_H

#include <stddef.h>
#include <volfx/volfx.h>
#include "tet_mesh.h" /* tetra/: the mesh type and tet_validate */

/* Documented caps (docs/tetvol-input.md); each refusal names the cap it hit. Claimed counts are
 * also bounded by what the file can hold before anything is allocated for them. */
#define RT_VOLUME_MAX_FILE_BYTES (1u << 30) /* a .vtu, .node or .ele file is read whole: 1 GiB */
#define RT_VOLUME_MAX_POINTS (1u << 24)     /* 16,777,216 points */
#define RT_VOLUME_MAX_TETS (1u << 24)       /* 16,777,216 tetrahedra */
/* |coordinate| of a mesh point at most (the scene's coordinate range): one node at 1e30
 * stretched the bounds the degenerate-cell test is relative to, and every cell was dropped */
#define RT_VOLUME_MAX_COORD 1e6
#define RT_VTU_MAX_DECODED_BYTES (1u << 30) /* base64-decoded plus inflated array bytes, per file */
#define RT_ZLIB_MAX_RATIO 1032u             /* deflate cannot expand a byte beyond this */

/* The tet library's result as the runtime's: tet_result's values are vfx_result's
 * (tetra/tet_result.h), checked in volume_file_vtu.c where both are seen. */
static inline vfx_result rt_result_from_tet(tet_result r) { return (vfx_result)r; }

/* Loads a VTK XML UnstructuredGrid file (tetrahedra only); scalar_name NULL -> no scalar.
 * A vector point field gives its magnitude. On error *out is left zeroed. */
vfx_result rt_volume_load_vtu(const char *path, const char *scalar_name, tet_mesh *out,
                            char *err, size_t errlen);
/* Same from a buffer in memory (size bytes; need not be NUL-terminated). */
vfx_result rt_volume_load_vtu_mem(const void *data, size_t size, const char *scalar_name,
                                tet_mesh *out, char *err, size_t errlen);
/* Loads TetGen base.node + base.ele (path_base without extension); scalar_name NULL -> none,
 * "attr0".."attrN" or "" -> node attribute k ("" = attribute 0). */
vfx_result rt_volume_load_tetgen(const char *path_base, const char *scalar_name,
                               tet_mesh *out, char *err, size_t errlen);

#endif
