/* beam_field_f.c — the lab's float32 instance of the C closed form (beam_field_impl.inc; its
 * float path is the one the shader beams/beam_field.glsl mirrors), for the CPU benches
 * (bench_beams). The product runs the shader, which the tests check themselves
 * (tests/beams/beam_probe.h). */
#include "beam_field_f.h"

#include <math.h>
#include <stdbool.h>

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

#define REAL float
#define SFX(n) n##_f
#define R_SQRT sqrtf
#define R_COS cosf
#define R_FLOOR floorf
#define R_FMA fmaf
#define R_FABS fabsf
#define R_LOG1P_OVER log1p_over_f
#define R_EDGE_TERMS 12   /* (1/4)^12 = 6e-8 */
#define R_GRAZING_M 0.25f /* the closed form loses at most ~60 ulps above it (3.7e-6 seen) */
#define R_SERIES_TERMS 12 /* (1/4)^12 = 6e-8: under float epsilon */
#include "beam_field_impl.inc"

#include "beam_field_anat.h"

#define SFXF(n) n##_f

float volfx_beam_integral_f(const volfx_beam_d *bm, const float O[3], const float V[3], float t0, float t1)
{
    double and[8];
    bool anat = anatomy_d(bm, and);
    float an[8];
    for (int k = 0; k < 8; ++k)
        an[k] = (float)and[k];
    if (bm->joint_count >= 2 && anat) {
        float J[VOLFX_BEAM_MAX_JOINTS][3];
        for (int k = 0; k < bm->joint_count; ++k)
            for (int i = 0; i < 3; ++i)
                J[k][i] = (float)bm->joints[k][i];
        float H = polyline_integral_f((const float(*)[3])J, bm->joint_count, (float)bm->radius,
                                      an[0] > 0 ? 0.f : (float)bm->a, (float)bm->b, (float)bm->eps, bm->smooth, O,
                                      V, t0, t1);
        if (t1 > t0)
            POLY_ANATOMY(float, SFXF, J, bm->joint_count);
        return H;
    }
    if (anat) {
        float M[3] = {(float)bm->head[0], (float)bm->head[1], (float)bm->head[2]};
        float D[3] = {(float)bm->dir[0], (float)bm->dir[1], (float)bm->dir[2]};
        return beam_integral_anat_f(M, D, (float)bm->length, (float)bm->radius, (float)bm->a, (float)bm->b,
                                    (float)bm->eps, bm->smooth, an, O, V, t0, t1);
    }
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

