/* beam_field.c — the float64 instance of the closed form (beam_field_impl.inc), validation,
 * density. The float32 closed form the effect runs is the shader, beams/beam_field.glsl (the tests
 * check it through a compute probe); a C float32 instance for the CPU benches is the lab's
 * (plugin/lab/beam_field_f.c). */
#include "beams/beam_field.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>

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
#undef REAL
#undef SFX
#undef R_SQRT
#undef R_COS
#undef R_FLOOR
#undef R_FMA
#undef R_FABS
#undef R_LOG1P_OVER
#undef R_SERIES_TERMS
#undef R_EDGE_TERMS
#undef R_GRAZING_M

vfx_result volfx_beam_validate(const vfx_beam *in, volfx_beam_d *out, char *err, size_t errlen)
{
    const float *f = &in->head[0];
    static const char *names[] = {"head.x", "head.y", "head.z", "length", "dir.x", "dir.y",
                                  "dir.z", "radius", "a", "b", "eps"};
    for (int i = 0; i < 11; ++i)
        if (!isfinite(f[i])) {
            snprintf(err, errlen, "beam %s is not finite", names[i]);
            return VFX_ERR_INVALID_ARGUMENT;
        }
    double d2 = (double)in->dir[0] * in->dir[0] + (double)in->dir[1] * in->dir[1] + (double)in->dir[2] * in->dir[2];
    if (!(d2 > 0)) {
        snprintf(err, errlen, "beam dir is the zero vector");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    if (in->length < 0 || !(in->radius > 0) || in->a < 0 || in->b < 0 || in->eps < 0) {
        snprintf(err, errlen, "beam needs length >= 0, radius > 0, a, b, eps >= 0 (got L %g, R %g, a %g, b %g, eps %g)",
                 (double)in->length, (double)in->radius, (double)in->a, (double)in->b, (double)in->eps);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    double n = sqrt(d2);
    for (int k = 0; k < 3; ++k) {
        out->head[k] = in->head[k];
        out->dir[k] = in->dir[k] / n;
    }
    out->length = in->length;
    out->radius = in->radius;
    out->a = in->a;
    out->b = in->b;
    out->eps = in->eps;
    out->smooth = 0;      /* hard support here; the effect sets the falloff */
    out->joint_count = 0; /* straight; volfx_beam_set_joints makes it a polyline */
    out->head_radius = out->orb_radius = out->orb_a = 0; /* no anatomy: the effect sets it */
    out->taper = out->surge = out->surge_inv_wl = out->surge_phase = 0;
    return VFX_OK;
}

#include "beams/beam_field_anat.h"

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

double volfx_beam_max_radius(const volfx_beam_d *bm)
{
    double r = bm->radius * (bm->joint_count >= 2 ? 1.0 : 1.0 + bm->surge);
    r = fmax(r, bm->head_radius);
    return bm->orb_a > 0 ? fmax(r, bm->orb_radius) : r;
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

vfx_result volfx_beam_set_joints(volfx_beam_d *bm, const float *xyz, uint32_t count, char *err, size_t errlen)
{
    if (count == 0) {
        bm->joint_count = 0;
        return VFX_OK;
    }
    if (count < 2 || count > VOLFX_BEAM_MAX_JOINTS || !xyz) {
        snprintf(err, errlen, "beam joint_count %u (0, or 2 to %d, with joints)", count, VOLFX_BEAM_MAX_JOINTS);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    for (uint32_t k = 0; k < count; ++k)
        for (int i = 0; i < 3; ++i) {
            if (!isfinite(xyz[3 * k + i])) {
                snprintf(err, errlen, "beam joint %u is not finite", k);
                return VFX_ERR_INVALID_ARGUMENT;
            }
            bm->joints[k][i] = xyz[3 * k + i];
        }
    bm->joint_count = (int)count;
    /* the head is J0; dir and length describe the first segment (tile bounds use the joints) */
    double d[3], n = 0;
    for (int i = 0; i < 3; ++i) {
        bm->head[i] = bm->joints[0][i];
        d[i] = bm->joints[1][i] - bm->joints[0][i];
        n += d[i] * d[i];
    }
    n = sqrt(n);
    if (n > 0)
        for (int i = 0; i < 3; ++i)
            bm->dir[i] = d[i] / n;
    bm->length = n;
    return VFX_OK;
}
