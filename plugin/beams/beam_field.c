/* beam_field.c — float and double instances of the closed form, validation, density. */
#include "beams/beam_field.h"

#include <math.h>
#include <stdio.h>

/* log1p(z)/z for z >= 0. The float version mirrors the GLSL, where log() near 1 is only good
 * to an absolute 2^-21: a series below 0.1 (terms to z^9, under float epsilon), log above. */
static float log1p_over_f(float z)
{
    if (z < 0.1f) {
        float s = 1.f / 10.f;
        for (int n = 9; n >= 1; --n)
            s = 1.f / (float)n - z * s;
        return s;
    }
    return logf(1.f + z) / z;
}

static double log1p_over_d(double z) { return z > 0 ? log1p(z) / z : 1.0; }

#define REAL float
#define SFX(n) n##_f
#define R_SQRT sqrtf
#define R_FMA fmaf
#define R_FABS fabsf
#define R_LOG1P_OVER log1p_over_f
#define R_EDGE_TERMS 12   /* (1/4)^12 = 6e-8 */
#define R_GRAZING_M 0.25f /* the closed form loses at most ~60 ulps above it (3.7e-6 seen) */
#define R_SERIES_TERMS 12 /* (1/4)^12 = 6e-8: under float epsilon */
#include "beam_field_impl.inc"
#undef REAL
#undef SFX
#undef R_SQRT
#undef R_FMA
#undef R_FABS
#undef R_LOG1P_OVER
#undef R_SERIES_TERMS
#undef R_EDGE_TERMS
#undef R_GRAZING_M

#define REAL double
#define SFX(n) n##_d
#define R_SQRT sqrt
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
    out->smooth = 0;      /* a v1 beam has the hard support; the effect sets the falloff */
    out->joint_count = 0; /* straight; volfx_beam_set_joints makes it a polyline */
    return VFX_OK;
}

float volfx_beam_integral_f(const volfx_beam_d *bm, const float O[3], const float V[3], float t0, float t1)
{
    if (bm->joint_count >= 2) {
        float J[VOLFX_BEAM_MAX_JOINTS][3];
        for (int k = 0; k < bm->joint_count; ++k)
            for (int i = 0; i < 3; ++i)
                J[k][i] = (float)bm->joints[k][i];
        return polyline_integral_f((const float(*)[3])J, bm->joint_count, (float)bm->radius, (float)bm->a,
                                   (float)bm->b, (float)bm->eps, bm->smooth, O, V, t0, t1);
    }
    float M[3] = {(float)bm->head[0], (float)bm->head[1], (float)bm->head[2]};
    float D[3] = {(float)bm->dir[0], (float)bm->dir[1], (float)bm->dir[2]};
    return beam_integral_f(M, D, (float)bm->length, (float)bm->radius, (float)bm->a, (float)bm->b,
                           (float)bm->eps, bm->smooth, O, V, t0, t1);
}

double volfx_beam_integral_d(const volfx_beam_d *bm, const double O[3], const double V[3], double t0, double t1)
{
    if (bm->joint_count >= 2)
        return polyline_integral_d((const double(*)[3])bm->joints, bm->joint_count, bm->radius, bm->a, bm->b,
                                   bm->eps, bm->smooth, O, V, t0, t1);
    return beam_integral_d(bm->head, bm->dir, bm->length, bm->radius, bm->a, bm->b, bm->eps, bm->smooth, O, V, t0, t1);
}

/* w(r) = (1 - r^2/R^2)^2 for the smooth support, 1 for the hard one (r^2 <= R^2 here). */
static double falloff_d(const volfx_beam_d *bm, double r2)
{
    if (!bm->smooth)
        return 1.0;
    double q = 1.0 - r2 / (bm->radius * bm->radius);
    return q * q;
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

double volfx_beam_density_d(const volfx_beam_d *bm, const double p[3])
{
    if (bm->joint_count >= 2) { /* straight from the definition: r = distance to the polyline */
        double e = bm->eps > VOLFX_BEAM_EPS_FLOOR * bm->radius ? bm->eps : VOLFX_BEAM_EPS_FLOOR * bm->radius;
        double R2 = bm->radius * bm->radius, rho = 0, d2 = 0, r2 = INFINITY;
        for (int k = 0; k < 3; ++k)
            d2 += (p[k] - bm->joints[0][k]) * (p[k] - bm->joints[0][k]);
        for (int k = 0; k + 1 < bm->joint_count; ++k)
            r2 = fmin(r2, seg_dist2(bm->joints[k], bm->joints[k + 1], p));
        if (d2 <= R2)
            rho += bm->a * falloff_d(bm, d2) / sqrt(d2 + e * e);
        if (r2 <= R2)
            rho += bm->b * falloff_d(bm, r2) / sqrt(r2 + e * e);
        return rho;
    }
    double e = bm->eps > VOLFX_BEAM_EPS_FLOOR * bm->radius ? bm->eps : VOLFX_BEAM_EPS_FLOOR * bm->radius;
    double d[3], d2 = 0, u = 0;
    for (int k = 0; k < 3; ++k) {
        d[k] = p[k] - bm->head[k];
        d2 += d[k] * d[k];
        u += d[k] * bm->dir[k];
    }
    double R2 = bm->radius * bm->radius, rho = 0;
    if (d2 <= R2)
        rho += bm->a * falloff_d(bm, d2) / sqrt(d2 + e * e);
    double r2;
    if (u < 0) {
        r2 = d2;
    } else if (u > bm->length) {
        r2 = 0;
        for (int k = 0; k < 3; ++k) {
            double q = d[k] - bm->length * bm->dir[k];
            r2 += q * q;
        }
    } else {
        r2 = 0;
        for (int k = 0; k < 3; ++k) {
            double q = d[k] - u * bm->dir[k];
            r2 += q * q;
        }
    }
    if (r2 <= R2)
        rho += bm->b * falloff_d(bm, r2) / sqrt(r2 + e * e);
    return rho;
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
