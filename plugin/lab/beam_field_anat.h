/* beam_field_anat.h — the anatomy as the C closed form reads it, shared by the lab's float64
 * instance (beam_field_d.c) and its float32 one (beam_field_f.c). Include after an instance of
 * beam_field_impl.inc (POLY_ANATOMY calls its prim_piece). */
#ifndef VOLFX_BEAM_FIELD_ANAT_H
#define VOLFX_BEAM_FIELD_ANAT_H

#include <stdbool.h>

#include "beams/beam_field.h"

/* The anatomy as beam_integral_anat reads it; false when there is none (version 2's field). */
static inline bool anatomy_d(const volfx_beam_d *bm, double an[8])
{
    double v[8] = {bm->head_radius, bm->orb_radius, bm->orb_a, 0, bm->taper, bm->surge, bm->surge_inv_wl,
                   bm->surge_phase};
    if (bm->joint_count >= 2)
        v[4] = v[5] = 0; /* a polyline has no body profile */
    bool any = false;
    for (int k = 0; k < 8; ++k)
        an[k] = v[k], any |= v[k] != 0;
    return any;
}

/* A polyline's head at its own radius and its orb at the last joint (sphere pieces); the head
 * is left out of the polyline's own integral when it has its own radius. */
#define POLY_ANATOMY(REAL, SFX, J, nj)                                                                   \
    do {                                                                                                 \
        REAL zero[3] = {0, 0, 0}, eps = (REAL)bm->eps, Rr = (REAL)bm->radius;                           \
        eps = eps > (REAL)VOLFX_BEAM_EPS_FLOOR * Rr ? eps : (REAL)VOLFX_BEAM_EPS_FLOOR * Rr;             \
        if (an[0] > 0 && bm->a > 0)                                                                      \
            H += (REAL)bm->a * SFX(prim_piece)(O, V, J[0], zero, 0, 0, (REAL)an[0], eps, t0, t1, bm->smooth); \
        if (an[1] > 0 && an[2] > 0)                                                                      \
            H += (REAL)an[2] * SFX(prim_piece)(O, V, J[nj - 1], zero, 0, 0, (REAL)an[1], eps, t0, t1, bm->smooth); \
    } while (0)

#endif
