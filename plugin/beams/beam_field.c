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
#define R_LOG1P_OVER log1p_over_f
#define R_EDGE_TERMS 12   /* (1/4)^12 = 6e-8 */
#define R_SERIES_TERMS 24 /* (1/2)^24 = 6e-8: under float epsilon */
#include "beam_field_impl.inc"
#undef REAL
#undef SFX
#undef R_SQRT
#undef R_FMA
#undef R_LOG1P_OVER
#undef R_SERIES_TERMS
#undef R_EDGE_TERMS

#define REAL double
#define SFX(n) n##_d
#define R_SQRT sqrt
#define R_FMA fma
#define R_LOG1P_OVER log1p_over_d
#define R_EDGE_TERMS 27   /* (1/4)^27 = 6e-17 */
#define R_SERIES_TERMS 54 /* (1/2)^54 = 6e-17: under double epsilon */
#include "beam_field_impl.inc"
#undef REAL
#undef SFX
#undef R_SQRT
#undef R_FMA
#undef R_LOG1P_OVER
#undef R_SERIES_TERMS
#undef R_EDGE_TERMS

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
    out->smooth = 0; /* a v1 beam has the hard support; volfx_beam_validate2 sets the falloff */
    return VFX_OK;
}

float volfx_beam_integral_f(const volfx_beam_d *bm, const float O[3], const float V[3], float t0, float t1)
{
    float M[3] = {(float)bm->head[0], (float)bm->head[1], (float)bm->head[2]};
    float D[3] = {(float)bm->dir[0], (float)bm->dir[1], (float)bm->dir[2]};
    return beam_integral_f(M, D, (float)bm->length, (float)bm->radius, (float)bm->a, (float)bm->b,
                           (float)bm->eps, bm->smooth, O, V, t0, t1);
}

double volfx_beam_integral_d(const volfx_beam_d *bm, const double O[3], const double V[3], double t0, double t1)
{
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

double volfx_beam_density_d(const volfx_beam_d *bm, const double p[3])
{
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
