/* The water lit by the plugin's own lights (shaders/water/effect_lights.glsl, docs/water-look.md
 * "Beams in the water, and the water lit by them"): the GLSL terms themselves, evaluated on the
 * GPU by shaders/water/lights_probe.comp (the lab's shader table), against a float64 quadrature
 * of the same light over its segment (Gauss-Legendre over pieces of the segment's length,
 * straight from the definition: no angle substitution, no erf). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <epoxy/gl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gpu/gpu.h"
#include "test_plugin.h"
#include "volfx_lab.h"
#include "water/water_lights.h"

typedef struct probe_case {
    float x_s[4], r_kind[4], p0_hmin[4], p1[4], n[4];
} probe_case;

/* The lobe of effect_lights.glsl, in double: exp((r.l - 1) / s^2) / (2 pi s^2 (1 - exp(-2 / s^2))). */
static double lobe(const double r[3], const double l[3], double s)
{
    double rl = r[0] * l[0] + r[1] * l[1] + r[2] * l[2];
    return exp((rl - 1.0) / (s * s)) / (2.0 * M_PI * s * s * (1.0 - exp(-2.0 / (s * s))));
}

/* Adds the three integrands over t in [ta, tb] of the segment: 5-point Gauss-Legendre on pieces
 * of 1/4000 of the segment. */
static void integrate(const double x[3], const double r[3], const double n[3], const double p0[3],
                      const double p1[3], double s, double ta, double tb, double out[3])
{
    static const double gx[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                                 0.9061798459386640};
    static const double gw[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
                                 0.2369268850561891};
    int pieces = (int)ceil(4000 * (tb - ta));
    double len2 = 0;
    for (int k = 0; k < 3; ++k)
        len2 += (p1[k] - p0[k]) * (p1[k] - p0[k]);
    for (int i = 0; i < pieces; ++i)
        for (int g = 0; g < 5; ++g) {
            double t = ta + (tb - ta) * (i + 0.5 + 0.5 * gx[g]) / pieces, w = gw[g] * 0.5 * (tb - ta) / pieces;
            double d[3], d2 = 0;
            for (int k = 0; k < 3; ++k) {
                d[k] = p0[k] + t * (p1[k] - p0[k]) - x[k];
                d2 += d[k] * d[k];
            }
            double dl = sqrt(d2), l[3] = {d[0] / dl, d[1] / dl, d[2] / dl}, du = w * sqrt(len2);
            double nl = n[0] * l[0] + n[1] * l[1] + n[2] * l[2];
            out[0] += lobe(r, l, s) * du / d2;
            out[1] += du / d2;
            out[2] += fmax(nl, 0.0) * du / d2;
        }
}

/* Float64 reference of one case: (integral D(l(u)) du / d^2, integral du / d^2, integral
 * max(n.l, 0) du / d^2) over the segment (a point: D(l) / d^2, 1 / d^2, max(n.l, 0) / d^2).
 * 5-point Gauss-Legendre on 4,000 equal pieces: the narrowest feature, the lobe's footprint on the
 * segment, is at least s h wide (>= 0.012 here, h >= 0.1), and the longest segment 8, so a piece is
 * <= 1/6 of it; GL5 is then exact to ~(1/6)^10. The irradiance's kink, where n.(p(t) - x) = 0
 * (linear in t), is a piece boundary: the segment is integrated in two parts split there. */
static void reference(const probe_case *c, double out[3])
{
    double x[3], r[3], p0[3], p1[3], n[3], s = c->x_s[3];
    for (int k = 0; k < 3; ++k)
        x[k] = c->x_s[k], r[k] = c->r_kind[k], p0[k] = c->p0_hmin[k], p1[k] = c->p1[k], n[k] = c->n[k];
    double rn = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (int k = 0; k < 3; ++k)
        r[k] /= rn;
    out[0] = out[1] = out[2] = 0;
    if (c->r_kind[3] < 0.5) {
        double d[3], d2 = 0;
        for (int k = 0; k < 3; ++k)
            d[k] = p0[k] - x[k], d2 += d[k] * d[k];
        double l[3] = {d[0] / sqrt(d2), d[1] / sqrt(d2), d[2] / sqrt(d2)};
        out[0] = lobe(r, l, s) / d2;
        out[1] = 1.0 / d2;
        out[2] = fmax(n[0] * l[0] + n[1] * l[1] + n[2] * l[2], 0.0) / d2;
        return;
    }
    double f0 = 0, f1 = 0;   /* n.(p(t) - x) at t = 0 and 1 */
    for (int k = 0; k < 3; ++k)
        f0 += n[k] * (p0[k] - x[k]), f1 += n[k] * (p1[k] - x[k]);
    double tk = (f0 > 0) != (f1 > 0) ? f0 / (f0 - f1) : 1.0;
    integrate(x, r, n, p0, p1, s, 0.0, tk, out);
    if (tk < 1.0)
        integrate(x, r, n, p0, p1, s, tk, 1.0, out);
}
static double urand(unsigned *st)
{
    *st = *st * 1664525u + 1013904223u;
    return (*st >> 8) / 16777216.0;
}

/* Distance from x to the segment's line (the cases keep it >= h_min: the clamp is a definition). */
static double line_dist(const probe_case *c)
{
    double e[3], a[3], ee = 0, ae = 0, aa = 0;
    for (int k = 0; k < 3; ++k)
        e[k] = c->p1[k] - c->p0_hmin[k], a[k] = c->x_s[k] - c->p0_hmin[k], ee += e[k] * e[k], ae += a[k] * e[k],
        aa += a[k] * a[k];
    return sqrt(fmax(aa - ae * ae / ee, 0));
}

/* Cases: a beam segment 1..8 long over a point of the water, the reflected ray aimed at a random
 * point of the segment (the streak) or near it, lobe widths 0.05..0.2 and the plugin's. */
static uint32_t make_cases(probe_case *out, uint32_t n)
{
    unsigned st = 12345u;
    uint32_t k = 0;
    while (k < n) {
        probe_case c;
        memset(&c, 0, sizeof c);
        double len = 1 + 7 * urand(&st), h0 = 0.3 + 3 * urand(&st);
        double th = 2 * M_PI * urand(&st), ph = 0.3 * (urand(&st) - 0.5);
        double e[3] = {cos(th) * cos(ph), sin(ph), sin(th) * cos(ph)};
        double x[3] = {4 * (urand(&st) - 0.5), 0, 4 * (urand(&st) - 0.5)};
        double p0[3] = {x[0] - 0.5 * len * e[0] + 2 * (urand(&st) - 0.5), x[1] + h0, x[2] - 0.5 * len * e[2]};
        bool point = k % 8 == 7;
        double tgt = urand(&st) * len, aim[3], an = 0;
        for (int i = 0; i < 3; ++i) {
            c.p0_hmin[i] = (float)p0[i];
            c.p1[i] = (float)(point ? p0[i] : p0[i] + len * e[i]);
            c.x_s[i] = (float)x[i];
            aim[i] = p0[i] + (point ? 0 : tgt * e[i]) - x[i];
        }
        /* near the segment: a deviation of up to 2.5 lobe widths off it, half of the cases */
        double s = k % 5 == 0 ? VOLFX_WATER_LIGHT_LOBE : 0.05 + 0.15 * urand(&st);
        for (int i = 0; i < 3; ++i)
            an += aim[i] * aim[i];
        an = sqrt(an);
        for (int i = 0; i < 3; ++i)
            aim[i] = aim[i] / an + (k % 2 ? 2.5 * s * (urand(&st) - 0.5) : 0);
        an = sqrt(aim[0] * aim[0] + aim[1] * aim[1] + aim[2] * aim[2]);
        for (int i = 0; i < 3; ++i)
            c.r_kind[i] = (float)(aim[i] / an);
        c.x_s[3] = (float)s;
        c.r_kind[3] = point ? 0.f : 1.f;
        /* the surface's normal: tilted up to 85 degrees from up, so that the light dips below the
         * surface's plane in part of the cases (the irradiance's clip) */
        double tilt = 1.48 * urand(&st), az = 2 * M_PI * urand(&st);
        c.n[0] = (float)(sin(tilt) * cos(az));
        c.n[1] = (float)cos(tilt);
        c.n[2] = (float)(sin(tilt) * sin(az));
        c.p0_hmin[3] = VOLFX_WATER_LIGHT_HMIN;
        if (!point && line_dist(&c) < 2 * VOLFX_WATER_LIGHT_HMIN)
            continue;
        out[k++] = c;
    }
    return k;
}

static vfx_context *g_ctx;
static const vfx_plugin_api *g_api;

/* Runs the probe over the cases; results (spec, fluence, irradiance, 0) per case. */
static void run_probe(const probe_case *cases, uint32_t n, float (*res)[4])
{
    /* the probe is in the lab's shader table (never libvolfx's): attach the lab first */
    assert_int_equal(volfx_lab_attach(g_ctx), VFX_OK);
    GLuint prog = volfx_gpu_compute(g_ctx, "water/lights_probe.comp", NULL);
    assert_int_not_equal(prog, 0);
    GLuint buf[2];
    glCreateBuffers(2, buf);
    glNamedBufferStorage(buf[0], n * sizeof *cases, cases, 0);
    glNamedBufferStorage(buf[1], n * 16, NULL, GL_MAP_READ_BIT);
    glUseProgram(prog);
    glUniform1ui(glGetUniformLocation(prog, "u_count"), n);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buf[0]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, buf[1]);
    glDispatchCompute((n + 63) / 64, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(buf[1], 0, n * 16, res);
    glDeleteBuffers(2, buf);
    assert_int_equal(glGetError(), GL_NO_ERROR);
}

/* Both terms against the quadrature. Tolerances (relative to the case's value, plus a floor
 * relative to the streak's peak, what a pixel shows against the brightest of the streak):
 * - specular: the closed form drops the 3 y^4 / 128 term of dphi / dy, 9 / (128 c^2) relative
 *   (c = cos(delta) / s^2 >= 0.5 / 0.2^2 = 12.5: 4.5e-4 at the widest lobe tested); float32
 *   costs exp((cos(delta) - 1) / s^2) about 2 ulps of cos(delta) over s^2 (<= 5e-5 at s = 0.05)
 *   and the erf difference 2 x 1.5e-7 (A&S 7.1.26) plus the float32 arguments' rounding, absolute
 *   against a peak of order 1: so 1e-3 relative + 2e-5 of the peak.
 * - fluence: exact in closed form; float32 atan (a few ulps of pi / 2) and the foot's rounding
 *   (the distance h from a float32 projection: ~1e-7 |x - p0| / h relative): 1e-5 relative plus
 *   1e-6 of pi / h. */
static void test_terms_match_quadrature(void **state)
{
    (void)state;
    enum { N = 400 };
    probe_case *cases = calloc(N, sizeof *cases);
    float(*res)[4] = calloc(N, sizeof *res);
    uint32_t n = make_cases(cases, N);
    run_probe(cases, n, res);
    double worst_s = 0, worst_f = 0, worst_e = 0, max_rel_s = 0;
    uint32_t lit = 0, clipped = 0;
    for (uint32_t i = 0; i < n; ++i) {
        double ref[3];
        reference(&cases[i], ref);
        double s = cases[i].x_s[3];
        double h = cases[i].r_kind[3] > 0.5 ? line_dist(&cases[i]) : 1.0;
        double norm = 1.0 / (2.0 * M_PI * s * s);
        double peak = cases[i].r_kind[3] > 0.5 ? norm * sqrt(2.0 * M_PI) * s / h : ref[0]; /* streak peak ~ 1 / (sqrt(2 pi) s h) */
        double tol_s = 1e-3 * ref[0] + 2e-5 * peak;
        double tol_f = 1e-5 * ref[1] + 1e-6 * M_PI / h;
        double es = fabs(res[i][0] - ref[0]), ef = fabs(res[i][1] - ref[1]), ee = fabs(res[i][2] - ref[2]);
        /* the irradiance: exact in closed form like the fluence (its clip angle's rounding costs
         * nothing to first order: the integrand is 0 there); sin of float32 angles and the
         * difference of two sines, a few ulps of R / h: the fluence's tolerance */
        double tol_e = 1e-5 * ref[2] + 1e-6 * M_PI / h;
        if (ee / tol_e > worst_e)
            worst_e = ee / tol_e;
        /* a line partly below the surface's plane: the clip at work */
        if (cases[i].r_kind[3] > 0.5) {
            double f0 = 0, f1 = 0;
            for (int k = 0; k < 3; ++k)
                f0 += cases[i].n[k] * (cases[i].p0_hmin[k] - cases[i].x_s[k]),
                f1 += cases[i].n[k] * (cases[i].p1[k] - cases[i].x_s[k]);
            clipped += (f0 > 0) != (f1 > 0);
        }
        if (es / tol_s > worst_s)
            worst_s = es / tol_s;
        if (ef / tol_f > worst_f)
            worst_f = ef / tol_f;
        if (ref[0] > 1e-3 * peak) {
            lit++;
            if (es / ref[0] > max_rel_s)
                max_rel_s = es / ref[0];
        }
        if (es > tol_s || ef > tol_f || ee > tol_e)
            printf("case %u (%s, s %.3f, h %.3f): spec %.9g ref %.9g (err/tol %.2f), fluence %.9g ref %.9g (err/tol "
                   "%.2f), irradiance %.9g ref %.9g (err/tol %.2f)\n",
                   i, cases[i].r_kind[3] > 0.5 ? "line" : "point", s, h, res[i][0], ref[0], es / tol_s, res[i][1],
                   ref[1], ef / tol_f, res[i][2], ref[2], ee / tol_e);
    }
    printf("%u cases (%u with a specular above 1e-3 of the streak's peak, %u lines half below the surface's "
           "plane): specular max err/tol %.3f (max rel %.2e where lit), fluence max err/tol %.3f, irradiance max "
           "err/tol %.3f\n", n, lit, clipped, worst_s, max_rel_s, worst_f, worst_e);
    assert_true(lit > n / 4);       /* the cases do exercise the streak */
    assert_true(clipped > n / 20);  /* and the irradiance's clip */
    assert_true(worst_s <= 1.0);
    assert_true(worst_f <= 1.0);
    assert_true(worst_e <= 1.0);
    free(cases);
    free(res);
}

/* A point of the water right on the line (a beam entering the water) stays finite: h is clamped
 * at h_min, so the terms are those at h_min from the line. */
static void test_on_the_line_is_finite(void **state)
{
    (void)state;
    probe_case c[2];
    memset(c, 0, sizeof c);
    c[0].n[1] = c[1].n[1] = 1;
    for (int k = 0; k < 2; ++k) {
        float p0[4] = {-1, 0, 0, VOLFX_WATER_LIGHT_HMIN}, p1[4] = {1, 0, 0, 0}, r[4] = {0, 1, 0, 1};
        memcpy(c[k].p0_hmin, p0, sizeof p0);
        memcpy(c[k].p1, p1, sizeof p1);
        memcpy(c[k].r_kind, r, sizeof r);
        c[k].x_s[3] = VOLFX_WATER_LIGHT_LOBE;
    }
    c[1].x_s[1] = -VOLFX_WATER_LIGHT_HMIN; /* h_min below the line, the same geometry */
    float res[2][4];
    run_probe(c, 2, res);
    printf("on the line: spec %g fluence %g; at h_min: spec %g fluence %g\n", res[0][0], res[0][1], res[1][0],
           res[1][1]);
    assert_true(isfinite(res[0][0]) && isfinite(res[0][1]));
    assert_float_equal(res[0][1], res[1][1], 1e-5 * res[1][1]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_terms_match_quadrature),
        cmocka_unit_test(test_on_the_line_is_finite),
    };
    return test_plugin_run_group(tests, &g_ctx, &g_api);
}
