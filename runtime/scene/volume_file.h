/* volume_file.h — loaders for tetrahedral meshes (VTK XML .vtu, TetGen .node/.ele) and the validation
 * both share. All return a vfx_result and write a message naming what and where into err. */
#ifndef RT_VOLUME_FILE_H
#define RT_VOLUME_FILE_H

#include <stddef.h>
#include "tet_mesh.h" /* tetra/: the mesh type and tet_validate */

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
