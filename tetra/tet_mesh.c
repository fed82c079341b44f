/* tet_mesh.c — ownership of tet_mesh arrays. */
#include "tet_mesh.h"

#include <stdlib.h>
#include <string.h>

void tet_mesh_free(tet_mesh *mesh)
{
    if (!mesh)
        return;
    free(mesh->points);
    free(mesh->tets);
    free(mesh->scalar);
    memset(mesh, 0, sizeof *mesh);
}
