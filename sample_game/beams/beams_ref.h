/* beams_ref.h — float64 reference for the beam integral: adaptive Gauss-Kronrod quadrature of
 * the raw density (vfx_beam_density_d), independent of the closed form. */
#ifndef VFX_BEAMS_REF_H
#define VFX_BEAMS_REF_H

#include <stdint.h>
#include "beams/beam_field.h"

/* H along origin + t*dir (|dir| = 1) over [t0, t1], summed over n beams, relative accuracy
 * about `rel_tol`. Breakpoints at support and slab boundaries and closest approaches, so the
 * quadrature never straddles a kink or a peak. *evals (optional) counts density evaluations. */
double vfx_beams_ref_integral(const vfx_beam_d *beams, uint32_t n, const double origin[3],
                              const double dir[3], double t0, double t1, double rel_tol,
                              uint64_t *evals);

#endif
