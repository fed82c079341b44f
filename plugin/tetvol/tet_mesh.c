/* tet_mesh.c — ownership of vfx_tet_mesh arrays. */
#include "tet_mesh.h"

#include <stdlib.h>
#include <string.h>

void vfx_tet_mesh_free(vfx_tet_mesh *mesh)
{
    if (!mesh)
        return;
    free(mesh->points);
    free(mesh->tets);
    free(mesh->scalar);
    memset(mesh, 0, sizeof *mesh);
}
