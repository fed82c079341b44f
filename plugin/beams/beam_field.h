/* beam_field.h — the beam density field and its closed-form line integral.
 *
 * One beam: head M, unit direction D, length L, strengths a (head) and b (trail), softening
 * eps, support radius R:
 *   head   rho_h(P) = a / sqrt(|P-M|^2 + eps^2)              where |P-M| <= R
 *   trail  rho_t(P) = b / sqrt(r^2 + eps^2)                  where r <= R
 *          r = distance to the axis for 0 <= u <= L, |P-M| for u < 0, |P-(M+L D)| for u > L,
 *          u = (P-M).D
 * H = integral of sum(rho) along a ray. The closed form splits each beam into four pieces
 * (head sphere, cap behind M, cylinder slab, cap beyond M+L D), each clipped to its support;
 * each piece is an integral of 1/sqrt((s x + beta)^2 + Q^2), done by volfx_beam_segment_integral.
 * The softening is floored at VOLFX_BEAM_EPS_FLOOR * R so that eps = 0 with a ray exactly
 * through M or the axis gives a large finite H, not Inf/NaN (the reference uses the same floor).
 * docs/beams-method.md has the derivation; shaders/beams/beam_field.glsl is the float32 closed form
 * the effect runs, checked by the tests (tests/beams/beam_probe.h) against the lab's float64
 * references (plugin/lab/beam_field_d.h: the C closed form and the density). This header holds
 * what the effect needs at run time: the float64 beam, its validation, joints and bounds. */
#ifndef VOLFX_BEAM_FIELD_H
#define VOLFX_BEAM_FIELD_H

#include <volfx/volfx.h>

#define VOLFX_BEAM_EPS_FLOOR 1e-6
#define VOLFX_BEAM_MAX_JOINTS 6 /* polyline joints J0..J5 (docs/beams.md "Bending beams") */

/* Beam in float64, normalised (unit D), as the integrals use it. */
typedef struct volfx_beam_d {
    double head[3], dir[3];
    double length, radius, a, b, eps;
    int smooth; /* 1: densities times w(r) = (1 - (r/R)^2)^2 (the smooth support), 0: hard */
    int joint_count;                           /* 0: straight; 2..MAX: a polyline, head at J0 */
    double joints[VOLFX_BEAM_MAX_JOINTS][3];
    /* the attack's anatomy (vfx_beam; all 0: none, the field above exactly): the head sphere's
     * radius (0 -> radius), the orb at the source (the end M + L D, or the last joint) with its
     * radius (0: none) and strength, the body's radius profile (straight beams only):
     * R(u) = radius (1 - taper clamp(u / L, 0, 1)) (1 + surge bump(u surge_inv_wl + surge_phase)),
     * bump(x) = ((1 + cos 2 pi x) / 2)^3; the caps use R(0) and R(L). Each piece's softening
     * floor is VOLFX_BEAM_EPS_FLOOR times its own radius. */
    double head_radius, orb_radius, orb_a, taper, surge, surge_inv_wl, surge_phase;
} volfx_beam_d;

/* Checks a beam (finite, L >= 0, R > 0, a, b, eps >= 0, D not zero) and normalises D into out;
 * VFX_ERR_INVALID_ARGUMENT with a message naming the field otherwise. */
vfx_result volfx_beam_validate(const vfx_beam *in, volfx_beam_d *out, char *err, size_t errlen);

/* Makes a validated beam the polyline xyz[0..3 count) (count 0: straight again; else 2 to
 * VOLFX_BEAM_MAX_JOINTS finite joints): head = J0, dir and length those of the first segment.
 * VFX_ERR_INVALID_ARGUMENT with a message otherwise. */
vfx_result volfx_beam_set_joints(volfx_beam_d *bm, const float *xyz, uint32_t count, char *err, size_t errlen);

/* The largest support radius of any piece (head, orb, body at its widest): bounds for culling. */
double volfx_beam_max_radius(const volfx_beam_d *beam);

#endif
