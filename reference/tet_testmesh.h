/* tet_testmesh.h — the generated tetrahedral grid and orbit camera that volfx-bench tetvol,
 * volfx-tetvol-mpi and the MPI tests render, in one place so that all of them render the same
 * mesh. Host-side helpers (not part of the plugin). */
#ifndef REF_TET_TESTMESH_H
#define REF_TET_TESTMESH_H

#include "tet_render.h"

/* Fills m with n^3 cubes x 5 tets over [-1,1]^3 (alternate cubes mirrored so faces match),
 * scalar 0.5 + 0.5 sin(3x) cos(2y) cos(1.5z) at the points, range [0, 1], named "grid"; the
 * arrays are malloc'd (free each). Returns 0, or -1 when out of memory (m partly filled). */
int ref_testmesh_grid(int n, tet_mesh *m);

/* Clears c and sets a w x h view rotated Rx(pitch) Ry(yaw), no translation (the caller places
 * the eye), and the perspective projection of focal factor f = 1 / tan(fovy / 2) between the
 * near and far planes. f is the caller's so its rounding stays the caller's (a constant fov
 * folds at compile time). */
void ref_testmesh_orbit(tet_camera *c, int w, int h, float yaw, float pitch, float f,
                            float nearp, float farp);

/* Extinction and colour of tf at scalar s in float64 (an independent reading of tet_tf:
 * piecewise linear between its points or between its two ends, clamped outside). */
void ref_tf_eval(const tet_tf *tf, double s, double *tau, double rgb[3]);

/* The scalar of tet tt (4 point indices of m) at p by barycentric interpolation, in double;
 * NaN when p is outside it. */
double ref_testmesh_tet_scalar(const tet_mesh *m, const uint32_t tt[4], const double p[3]);
/* Float64 emission-absorption ray march through a mesh made by ref_testmesh_grid(n): per pixel
 * (centre rays of the renderer's camera model) the ray's span inside [-1,1]^3 is cut into
 * `steps` equal pieces, the scalar at each midpoint interpolated linearly in the containing tet
 * (found from the cube it lies in), colour and extinction from ref_tf_eval, composited front to
 * back. out: width*height*4 premultiplied RGBA, row 0 = bottom. */
void ref_testmesh_raymarch(int n, const tet_mesh *m, const tet_camera *c, const tet_tf *tf,
                           int steps, double *out);

#endif
