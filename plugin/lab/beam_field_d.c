/* beam_field_d.c — the lab's float64 closed form of the beam integral (beam_field_impl.inc, the
 * C source the shader shaders/beams/beam_field.glsl is checked against, never compiled from it)
 * and the density straight from its definition: the tests' references, never in libvolfx. */
#include "beam_field_d.h"

#include <math.h>
#include <stdbool.h>

static double log1p_over_d(double z) { return z > 0 ? log1p(z) / z : 1.0; }

#define REAL double
#define SFX(n) n##_d
#define R_SQRT sqrt
#define R_COS cos
#define R_FLOOR floor
#define R_FMA fma
#define R_FABS fabs
#define R_LOG1P_OVER log1p_over_d
#define R_EDGE_TERMS 27   /* (1/4)^27 = 6e-17 */
#define R_GRAZING_M 0.5
#define R_SERIES_TERMS 54 /* (1/2)^54 = 6e-17: under double epsilon */
#include "beam_field_impl.inc"

#include "beam_field_anat.h"

#define SFXD(n) n##_d

double volfx_beam_integral_d(const volfx_beam_d *bm, const double O[3], const double V[3], double t0, double t1)
{
    double an[8];
    bool anat = anatomy_d(bm, an);
    if (bm->joint_count >= 2 && anat) {
        const double(*J)[3] = (const double(*)[3])bm->joints;
        double H = polyline_integral_d(J, bm->joint_count, bm->radius, an[0] > 0 ? 0.0 : bm->a, bm->b, bm->eps,
                                       bm->smooth, O, V, t0, t1);
        if (t1 > t0)
            POLY_ANATOMY(double, SFXD, J, bm->joint_count);
        return H;
    }
    if (anat)
        return beam_integral_anat_d(bm->head, bm->dir, bm->length, bm->radius, bm->a, bm->b, bm->eps, bm->smooth,
                                    an, O, V, t0, t1);
    if (bm->joint_count >= 2)
        return polyline_integral_d((const double(*)[3])bm->joints, bm->joint_count, bm->radius, bm->a, bm->b,
                                   bm->eps, bm->smooth, O, V, t0, t1);
    return beam_integral_d(bm->head, bm->dir, bm->length, bm->radius, bm->a, bm->b, bm->eps, bm->smooth, O, V, t0, t1);
}

/* One piece's density k w(r) / sqrt(r^2 + e^2) inside radius R, w = (1 - r^2/R^2)^2 for the
 * smooth support, 1 for the hard one. */
static double piece_density(const volfx_beam_d *bm, double k, double r2, double R, double e)
{
    if (!(k > 0) || !(r2 <= R * R))
        return 0;
    double w = 1.0;
    if (bm->smooth) {
        double q = 1.0 - r2 / (R * R);
        w = q * q;
    }
    return k * w / sqrt(r2 + e * e);
}

static double dist2_d(const double a[3], const double p[3])
{
    return (p[0] - a[0]) * (p[0] - a[0]) + (p[1] - a[1]) * (p[1] - a[1]) + (p[2] - a[2]) * (p[2] - a[2]);
}

/* Squared distance from p to the segment a..b (its end points included). */
static double seg_dist2(const double a[3], const double b[3], const double p[3])
{
    double d[3], w[3], dd = 0, wd = 0;
    for (int k = 0; k < 3; ++k) {
        d[k] = b[k] - a[k], w[k] = p[k] - a[k];
        dd += d[k] * d[k], wd += w[k] * d[k];
    }
    double u = dd > 0 ? fmin(fmax(wd / dd, 0.0), 1.0) : 0.0, r2 = 0;
    for (int k = 0; k < 3; ++k)
        r2 += (w[k] - u * d[k]) * (w[k] - u * d[k]);
    return r2;
}

double volfx_beam_profile_d(const volfx_beam_d *bm, double u)
{
    double an[8] = {0, 0, 0, 0, bm->taper, bm->surge, bm->surge_inv_wl, bm->surge_phase};
    return bm->joint_count >= 2 ? 1.0 : profile_d(an, bm->length, u);
}

/* Straight from the definition (beam_field.h): nothing of the closed form's pieces. */
double volfx_beam_density_d(const volfx_beam_d *bm, const double p[3])
{
    double e = bm->eps > VOLFX_BEAM_EPS_FLOOR * bm->radius ? bm->eps : VOLFX_BEAM_EPS_FLOOR * bm->radius;
    double Rh = bm->head_radius > 0 ? bm->head_radius : bm->radius, rho = 0;
    const double *head = bm->joint_count >= 2 ? bm->joints[0] : bm->head;
    double src[3];
    for (int k = 0; k < 3; ++k)
        src[k] = bm->joint_count >= 2 ? bm->joints[bm->joint_count - 1][k] : bm->head[k] + bm->length * bm->dir[k];
    rho += piece_density(bm, bm->a, dist2_d(head, p), Rh, e);
    if (bm->orb_radius > 0)
        rho += piece_density(bm, bm->orb_a, dist2_d(src, p), bm->orb_radius, e);
    if (bm->joint_count >= 2) { /* r = distance to the polyline */
        double r2 = INFINITY;
        for (int k = 0; k + 1 < bm->joint_count; ++k)
            r2 = fmin(r2, seg_dist2(bm->joints[k], bm->joints[k + 1], p));
        return rho + piece_density(bm, bm->b, r2, bm->radius, e);
    }
    double u = 0;
    for (int k = 0; k < 3; ++k)
        u += (p[k] - bm->head[k]) * bm->dir[k];
    double uc = fmin(fmax(u, 0.0), bm->length), foot[3];
    for (int k = 0; k < 3; ++k)
        foot[k] = bm->head[k] + uc * bm->dir[k];
    double R = bm->radius * volfx_beam_profile_d(bm, uc);
    return rho + piece_density(bm, bm->b, dist2_d(foot, p), R, e);
}
