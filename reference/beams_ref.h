/* beams_ref.h — float64 reference for the beam integral: adaptive Gauss-Kronrod quadrature of
 * the raw density (volfx_beam_density_d), independent of the closed form. */
#ifndef REF_BEAMS_REF_H
#define REF_BEAMS_REF_H

#include <stdint.h>
#include "lab/beam_field_d.h"

/* H along origin + t*dir (|dir| = 1) over [t0, t1], summed over n beams, relative accuracy
 * about `rel_tol`. Breakpoints at support and slab boundaries and closest approaches, so the
 * quadrature never straddles a kink or a peak. *evals (optional) counts density evaluations. */
double ref_beams_integral(const volfx_beam_d *beams, uint32_t n, const double origin[3],
                              const double dir[3], double t0, double t1, double rel_tol,
                              uint64_t *evals);

/* The conditioning of H for a float32 pipeline: the largest change of the exact H (float64
 * closed form, summed over beams, each beam bounded separately) when one float32 input moves by
 * `ulps` float32 ulps: a component of dir (by ulps * FLT_EPSILON), or a component of a beam's
 * head relative to the eye (by ulps * FLT_EPSILON * max(|eye|, |head - eye|)). Absolute, same
 * units as H. No float32 algorithm fed such inputs can be more accurate than this. */
double ref_beams_cond_abs(const volfx_beam_d *beams, uint32_t n, const double eye[3],
                              const double dir[3], double t0, double t1, double ulps);

#endif
