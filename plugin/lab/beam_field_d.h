/* beam_field_d.h — the lab's float64 C closed form of the beam integral (beam_field_d.c, from
 * beam_field_impl.inc) and the density from its definition (beams/beam_field.h has the field and
 * the float64 beam): the references the tests check the shader against, and the benches' error
 * measure. Lab library only: libvolfx holds none of it. */
#ifndef VOLFX_LAB_BEAM_FIELD_D_H
#define VOLFX_LAB_BEAM_FIELD_D_H

#include "beams/beam_field.h"

/* Integral over x in [x0, x1] of 1/sqrt((s x + beta)^2 + Q^2), s >= 0, Q > 0, without
 * cancellation (float64; beam_field_f.h has the float32 instance). */
double volfx_beam_segment_integral_d(double x0, double x1, double s, double beta, double Q);
/* The smooth support's piece: integral over x in [x0, x1] of (h^2 - y^2)^2 / sqrt(y^2 + Q^2),
 * y = s x + beta, for |y| <= h (values in units of R, h and Q of order 1 or less). */
double volfx_beam_segment_integral_smooth_d(double x0, double x1, double s, double beta, double Q,
                                            double h);

/* H of one beam along the ray origin + t*dir (|dir| = 1), t in [t0, t1], float64 (the shader is
 * the float32 closed form; beam_field_f.h a C float32 instance for the benches). */
double volfx_beam_integral_d(const volfx_beam_d *beam, const double origin[3], const double dir[3],
                           double t0, double t1);

/* The body's radius multiplier R(u) / radius at u (1 without a profile), float64. */
double volfx_beam_profile_d(const volfx_beam_d *beam, double u);

/* The density at a point (float64), for references and tests. */
double volfx_beam_density_d(const volfx_beam_d *beam, const double p[3]);

#endif
