/* tet_tf.c — the transfer function along one ray segment. Inside a tet the scalar is linear
 * along the ray, so between two breakpoints of a piecewise-linear table extinction and colour
 * are linear along the ray too: splitting the segment at the breakpoints it crosses leaves
 * pieces whose emission-absorption integral has a closed form but for one Gaussian-type
 * integral, evaluated to ~1e-6 (see piece_exact); pieces are composited front to back. The
 * alternative is a pre-integrated
 * lookup (Röttger et al. 2000; Engel et al. 2001, "1D integral tables"): cumulative integrals of
 * tau and tau*colour over a grid of the scalar give any segment in four lookups, at the price of
 * the grid's resolution and of ignoring attenuation inside the segment. Both are measured in
 * docs/tetvol.md. */
#include "tet_engine.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The piece holding s: the largest k < n - 1 with s >= s[k] (0 below the table). */
static int piece_of(const tf_prep *tf, double s)
{
    int lo = 0, hi = tf->n - 2;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (s >= tf->s[mid])
            lo = mid;
        else
            hi = mid - 1;
    }
    return lo;
}

/* Extinction and colour at scalar s: linear in the piece, clamped to the table's ends. The
 * arithmetic (float differences, double parameter) is that of the two-point function. */
static void tf_eval(const tf_prep *tf, double s, double *tau, double rgb[3])
{
    const int k = tf->n > 2 ? piece_of(tf, s) : 0;
    double range = (double)tf->s[k + 1] - tf->s[k];
    double u = range > 0 ? (s - tf->s[k]) / range : 0.0;
    if (u < 0) u = 0;
    if (u > 1) u = 1;
    *tau = tf->tau[k] + (tf->tau[k + 1] - tf->tau[k]) * u;
    for (int c = 0; c < 3; c++)
        rgb[c] = tf->rgb[k][c] + (tf->rgb[k + 1][c] - tf->rgb[k][c]) * u;
}

/* One piece [ta, tb] of depth by the midpoint rule: colour at the midpoint scalar times the
 * opacity, alpha = 1 - exp(-tau * length) (opacity exact for linear tau, colour not). */
static void piece_midpoint(const tf_prep *tf, double S0, double Sb, double ta, double tb, double L,
                           double *alpha, double rgb[3])
{
    double tau;
    tf_eval(tf, S0 + Sb * 0.5 * (ta + tb), &tau, rgb);
    /* float32 exp: alpha is stored as a float anyway */
    *alpha = 1.0 - (double)expf((float)(-tau * (tb - ta) * L));
    for (int c = 0; c < 3; c++)
        rgb[c] *= *alpha;
}

/* One piece of length l over which tau runs linearly from ta to tb and the colour from ca to
 * cb: with phi(t) = ta t + (tb - ta) t^2 / (2 l) and T = exp(-phi), the emitted colour is
 * int c tau T dt = ca - cb T(l) + (cb - ca) / l * int T dt (by parts), and alpha = 1 - T(l).
 * int T dt is summed over K sub-pieces with phi taken linear on each (exact for constant
 * tau; relative error ~ ((tb - ta) l / K^2)^2 / 12 otherwise); the T at the sub-piece ends are
 * a geometric-times-Gaussian sequence, so two exp calls give all of them. Writes the
 * premultiplied colour into rgb. */
static void piece_exact(const tf_prep *tf, double S0, double Sb, double ta_, double tb_, double L,
                        double *alpha, double rgb[3])
{
    enum { K = 4 };
    double tau_a, tau_b, ca[3], cb[3];
    tf_eval(tf, S0 + Sb * ta_, &tau_a, ca);
    tf_eval(tf, S0 + Sb * tb_, &tau_b, cb);
    const double l = (tb_ - ta_) * L, h = l / K;
    if (!(l > 0)) { /* an empty piece (a breakpoint clamped onto the segment's end): the
                     * l-divisions below made it NaN (fuzz_tet_render, scalars near 1e22) */
        *alpha = 0;
        rgb[0] = rgb[1] = rgb[2] = 0;
        return;
    }
    const double d0 = h * (tau_a + (tau_b - tau_a) * h / (2 * l)); /* phi step of sub-piece 0 */
    const double dd = (tau_b - tau_a) * h * h / l;                  /* growth of the step */
    const double e0 = exp(-d0), r = exp(-dd);
    /* a steeply falling tau (huge extinction) makes r overflow while e0 underflows, and 0 * Inf
     * was a NaN pixel (fuzz_tet_render): then each sub-piece's exp is taken directly */
    const bool direct = !(r < 1e300) || !(e0 > 0);
    double T = 1, I = 0, step = d0, e = e0;
    for (int j = 0; j < K; j++) {
        if (direct)
            e = exp(-step);
        double Tn = T * e;
        I += step > 1e-9 ? h * (T - Tn) / step : h * T * (1 - 0.5 * step);
        T = Tn;
        step += dd;
        e *= r;
    }
    *alpha = 1 - T;
    /* ca - cb T + (cb - ca) I / l rearranged so that no extinction gives exactly 0 and the
     * colour slope only scales the (small, >= 0) excess of the mean transmittance over T */
    const double w = l > 0 ? fmax(I / l - T, 0.0) : 0.0;
    for (int c = 0; c < 3; c++) {
        double v = ca[c] * *alpha + (cb[c] - ca[c]) * w;
        rgb[c] = v > 0 ? v : 0;
    }
}

static void piece(const tf_prep *tf, double S0, double Sb, double ta, double tb, double L,
                  double *alpha, double rgb[3])
{
    if (tf->method == TET_TF_MIDPOINT)
        piece_midpoint(tf, S0, Sb, ta, tb, L, alpha, rgb);
    else
        piece_exact(tf, S0, Sb, ta, tb, L, alpha, rgb);
}

/* Value of a cumulative table at s (stride 1 or 3 for component c), extended linearly with the
 * end values' slopes outside the domain. */
static double cumulative(const tf_prep *tf, const double *A, int stride, int c, double s)
{
    const int n = tf->pre_n, last = tf->n - 1;
    double x = (s - tf->s[0]) / tf->pre_ds;
    if (!(x > 0)) {
        double slope = stride == 1 ? tf->tau[0] : (double)tf->tau[0] * tf->rgb[0][c];
        return A[c] + slope * (s - tf->s[0]);
    }
    if (x >= n) {
        double slope = stride == 1 ? tf->tau[last] : (double)tf->tau[last] * tf->rgb[last][c];
        return A[stride * n + c] + slope * (s - tf->s[last]);
    }
    int i = (int)x;
    double f = x - i;
    return A[stride * i + c] + f * (A[stride * (i + 1) + c] - A[stride * i + c]);
}

static void preintegrated(const tf_prep *tf, double sa, double sb, double len, double *alpha,
                          double rgb[3])
{
    double ds = sb - sa, tavg, k[3];
    if (fabs(ds) > 1e-7 * tf->span) {
        tavg = (cumulative(tf, tf->pre_T, 1, 0, sb) - cumulative(tf, tf->pre_T, 1, 0, sa)) / ds;
        for (int c = 0; c < 3; c++)
            k[c] = (cumulative(tf, tf->pre_K, 3, c, sb) - cumulative(tf, tf->pre_K, 3, c, sa)) / ds;
    } else {
        double col[3];
        tf_eval(tf, 0.5 * (sa + sb), &tavg, col);
        for (int c = 0; c < 3; c++)
            k[c] = tavg * col[c];
    }
    *alpha = tavg > 0 ? 1.0 - exp(-tavg * len) : 0.0;
    for (int c = 0; c < 3; c++)
        rgb[c] = tavg > 0 ? k[c] / tavg : 0.0;
}

int tet_tf_segment(const tf_prep *tf, double S0, double Sb, double tin, double tout, double L,
                   float out[4])
{
    double alpha, rgb[3];
    if (tf->method == TET_TF_PREINTEGRATED && tf->span > 0) {
        preintegrated(tf, S0 + Sb * tin, S0 + Sb * tout, (tout - tin) * L, &alpha, rgb);
        for (int c = 0; c < 3; c++)
            out[c] = (float)(rgb[c] * alpha);
        out[3] = (float)alpha;
        return 1;
    }
    /* breakpoints strictly inside the segment's scalar range, in ray order */
    int first = 0, count = 0, dir = 1;
    if (tf->method == TET_TF_EXACT && tf->span > 0 && Sb != 0) {
        double sa = S0 + Sb * tin, sb = S0 + Sb * tout;
        double lo = fmin(sa, sb) + tf->eps, hi = fmax(sa, sb) - tf->eps;
        if (lo < hi && lo < tf->s[tf->n - 1] && hi > tf->s[0]) {
            int i = tf->s[0] > lo ? 0 : piece_of(tf, lo) + 1;
            int j = i;
            while (j < tf->n && tf->s[j] < hi)
                j++;
            count = j - i;
            dir = Sb > 0 ? 1 : -1;
            first = dir > 0 ? i : j - 1;
        }
    }
    if (count == 0) {
        piece(tf, S0, Sb, tin, tout, L, &alpha, rgb);
        for (int c = 0; c < 3; c++)
            out[c] = (float)rgb[c];
        out[3] = (float)alpha;
        return 1;
    }
    double acc[4] = {0, 0, 0, 0}, ta = tin;
    for (int q = 0; q <= count; q++) {
        double tb = tout;
        if (q < count) {
            tb = (tf->s[first + dir * q] - S0) / Sb;
            tb = tb < ta ? ta : tb > tout ? tout : tb;
        }
        piece(tf, S0, Sb, ta, tb, L, &alpha, rgb);
        double t = 1.0 - acc[3];
        for (int c = 0; c < 3; c++)
            acc[c] += t * rgb[c];
        acc[3] += t * alpha;
        ta = tb;
    }
    for (int c = 0; c < 4; c++)
        out[c] = (float)acc[c];
    return count + 1;
}

/* exact integrals over [a, b] of tau and tau * rgb (tau linear, tau * rgb quadratic within a
 * piece: Simpson's rule is exact there) */
static void integrate(const tf_prep *tf, double a, double b, double *T, double K[3])
{
    double ta, tm, tb, ca[3], cm[3], cb[3], h = (b - a) / 6.0;
    tf_eval(tf, a, &ta, ca);
    tf_eval(tf, 0.5 * (a + b), &tm, cm);
    tf_eval(tf, b, &tb, cb);
    *T += h * (ta + 4 * tm + tb);
    for (int c = 0; c < 3; c++)
        K[c] += h * (ta * ca[c] + 4 * tm * cm[c] + tb * cb[c]);
}

static tet_result build_preintegrated(tf_prep *tf, int cells, char *err, size_t errlen)
{
    tf->pre_n = cells;
    tf->pre_ds = tf->span / cells;
    tf->pre_T = malloc((size_t)(cells + 1) * sizeof *tf->pre_T);
    tf->pre_K = malloc((size_t)(cells + 1) * 3 * sizeof *tf->pre_K);
    if (!tf->pre_T || !tf->pre_K) {
        tet_errf(err, errlen, "tet_render: out of memory for a %d-cell pre-integrated table", cells);
        return TET_ERR_OUT_OF_MEMORY;
    }
    double T = 0, K[3] = {0, 0, 0};
    tf->pre_T[0] = 0;
    memset(tf->pre_K, 0, 3 * sizeof *tf->pre_K);
    int k = 0;
    for (int i = 0; i < cells; i++) {
        double a = tf->s[0] + i * tf->pre_ds, b = i + 1 == cells ? tf->s[tf->n - 1] : a + tf->pre_ds;
        while (k + 1 < tf->n - 1 && tf->s[k + 1] <= a)
            k++;
        for (int j = k; j < tf->n - 1 && tf->s[j] < b; j++) { /* split at breakpoints */
            double lo = fmax(a, tf->s[j]), hi = fmin(b, tf->s[j + 1]);
            if (hi > lo)
                integrate(tf, lo, hi, &T, K);
        }
        tf->pre_T[i + 1] = T;
        for (int c = 0; c < 3; c++)
            tf->pre_K[3 * (i + 1) + c] = K[c];
    }
    return TET_OK;
}

#define TET_TF_MAX_RGB 1e6
static int rgb_ok(const float *c)
{
    for (int k = 0; k < 3; k++)
        if (!(c[k] >= 0 && c[k] <= TET_TF_MAX_RGB))
            return 0;
    return 1;
}

tet_result tet_tf_prepare(const tet_tf *in, tf_prep *tf, char *err, size_t errlen)
{
    tf->method = in->method;
    tf->pre_T = tf->pre_K = NULL;
    tf->pre_n = 0;
    if (in->count == 0) {
        /* found by fuzz_tet_render: a NaN domain or extinction rendered NaN pixels as success */
        if (!isfinite(in->smin) || !isfinite(in->smax) || !isfinite(in->tau_lo) || !isfinite(in->tau_hi) ||
            !(in->tau_lo >= 0) || !(in->tau_hi >= 0)) {
            tet_errf(err, errlen, "tet_render: linear transfer function smin %g smax %g tau_lo %g tau_hi %g "
                     "(finite, tau >= 0)", (double)in->smin, (double)in->smax, (double)in->tau_lo,
                     (double)in->tau_hi);
            return TET_ERR_INVALID_ARGUMENT;
        }
        if (!rgb_ok(in->color_lo) || !rgb_ok(in->color_hi)) {
            tet_errf(err, errlen, "tet_render: linear transfer function colour outside [0, %g]", TET_TF_MAX_RGB);
            return TET_ERR_INVALID_ARGUMENT;
        }
        tf->n = 2;
        tf->s[0] = in->smin, tf->s[1] = in->smax;
        tf->tau[0] = in->tau_lo, tf->tau[1] = in->tau_hi;
        memcpy(tf->rgb[0], in->color_lo, sizeof tf->rgb[0]);
        memcpy(tf->rgb[1], in->color_hi, sizeof tf->rgb[1]);
    } else {
        tf->n = in->count;
        for (int i = 0; i < in->count; i++) {
            const tet_tf_point *p = &in->points[i];
            /* colours in [0, TET_TF_MAX_RGB]: a finite 2e37 still summed to Inf pixels
             * (fuzz_tet_render) */
            if (!isfinite(p->s) || !isfinite(p->tau) || !(p->tau >= 0) || !rgb_ok(p->rgb)) {
                tet_errf(err, errlen, "tet_render: transfer function point %d is not finite, has tau < 0 or a "
                         "colour outside [0, %g]", i, TET_TF_MAX_RGB);
                return TET_ERR_INVALID_ARGUMENT;
            }
            if (i > 0 && !(p->s > in->points[i - 1].s)) {
                tet_errf(err, errlen, "tet_render: transfer function point %d (scalar %g) does not follow %g",
                         i, (double)p->s, (double)in->points[i - 1].s);
                return TET_ERR_INVALID_ARGUMENT;
            }
            tf->s[i] = p->s;
            tf->tau[i] = p->tau;
            memcpy(tf->rgb[i], p->rgb, sizeof tf->rgb[i]);
        }
    }
    tf->span = (double)tf->s[tf->n - 1] - tf->s[0];
    /* a piece shorter than a millionth of the domain carries nothing visible; splitting at a
     * breakpoint that close to a segment's end would only perturb the rounding */
    tf->eps = 1e-6 * (tf->span > 0 ? tf->span : 0);
    if (tf->method == TET_TF_PREINTEGRATED && tf->span > 0)
        return build_preintegrated(tf, in->pre_size > 0 ? in->pre_size : 1024, err, errlen);
    return TET_OK;
}

void tet_tf_release(tf_prep *tf)
{
    free(tf->pre_T);
    free(tf->pre_K);
    tf->pre_T = tf->pre_K = NULL;
}
