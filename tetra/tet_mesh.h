/* tet_mesh.h — an unstructured tetrahedral grid in memory, as the loaders produce it and the
 * cell-projection renderer consumes it. Owned by whoever loaded it; tet_mesh_free frees. */
#ifndef TET_MESH_H
#define TET_MESH_H

#include <stddef.h>
#include <stdint.h>
#include "tet_result.h"

typedef struct tet_mesh {
    uint32_t point_count;
    uint32_t tet_count;
    float *points;     /* 3 * point_count: x, y, z */
    uint32_t *tets;    /* 4 * tet_count point indices, positively oriented after loading */
    float *scalar;     /* point_count values of the chosen field (NULL when none was asked) */
    char scalar_name[64];
    float scalar_min, scalar_max;
    uint32_t inverted_fixed;   /* tets whose orientation the loader flipped */
    uint32_t degenerate_count; /* zero-volume tets found (kept, reported) */
} tet_mesh;

/* Frees the arrays of a mesh and zeroes it; NULL allowed. */
void tet_mesh_free(tet_mesh *mesh);

/* Checks a filled mesh: indices in range, finite points (TET_ERR_NUMERIC naming the point),
 * NaN scalars (TET_ERR_NUMERIC naming the point), flips inverted tets, counts degenerate ones,
 * sets scalar_min/max. */
tet_result tet_validate(tet_mesh *mesh, char *err, size_t errlen);

#endif
