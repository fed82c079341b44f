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

/* One piece of length l over which tau runs linearly from ta to tb: with phi(t) = ta t +
 * (tb - ta) t^2 / (2 l) and T = exp(-phi), alpha = 1 - T(l) and (see piece_aw) w = mean T -
 * T(l). int T dt is summed over K sub-pieces with phi taken linear on each (exact for constant
 * tau; relative error ~ ((tb - ta) l / K^2)^2 / 12 otherwise); the T at the sub-piece ends are
 * a geometric-times-Gaussian sequence, so two exp calls give all of them. */
static void subpieces_aw(double tau_a, double tau_b, double l, double *alpha, double *w)
{
    enum { K = 4 };
    const double h = l / K;
    if (!(l > 0)) { /* an empty piece (a breakpoint clamped onto the segment's end): the
                     * l-divisions below made it NaN (fuzz_tet_render, scalars near 1e22) */
        *alpha = *w = 0;
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
    /* the colour slope only scales the (small, >= 0) excess of the mean transmittance over T */
    const double m = I / l - T;
    *w = m > 0 ? m : 0.0;
}

/* The sub-piece rule with the colour: ca alpha + (cb - ca) w, each channel >= 0. */
static void piece_subpieces(double tau_a, double tau_b, const double ca[3], const double cb[3],
                            double l, double *alpha, double rgb[3])
{
    double w;
    subpieces_aw(tau_a, tau_b, l, alpha, &w);
    for (int c = 0; c < 3; c++) {
        double v = ca[c] * *alpha + (cb[c] - ca[c]) * w;
        rgb[c] = v > 0 ? v : 0;
    }
}

/* The sub-piece rule on [ta_, tb_] of a segment, the ends looked up in the table (the form
 * the midpoint/pre-integrated dispatch below calls). */
static void piece_exact(const tf_prep *tf, double S0, double Sb, double ta_, double tb_, double L,
                        double *alpha, double rgb[3])
{
    double tau_a, tau_b, ca[3], cb[3];
    tf_eval(tf, S0 + Sb * ta_, &tau_a, ca);
    tf_eval(tf, S0 + Sb * tb_, &tau_b, cb);
    piece_subpieces(tau_a, tau_b, ca, cb, (tb_ - ta_) * L, alpha, rgb);
}

/* The emission-absorption integral of one piece of length l over which tau runs linearly from
 * ta to tb: with u in [0,1] along it, x = l (ta + tb) / 2 (its optical depth) and
 * d = l (tb - ta) / 2, the transmittance is T(u) = exp(-x u + d u (1 - u)), alpha = 1 - exp(-x)
 * exactly, and by parts a colour running linearly from ca to cb emits ca alpha + (cb - ca) w
 * with w = int_0^1 T du - T(1). Expanding exp(d u (1 - u)) in d (|d| <= x since tau >= 0):
 * w = F0(x) - exp(-x) + d F1(x) + d^2 / 2 F2(x) + d^3 / 6 F3(x) + ..., where
 * Fk(x) = int_0^1 (u (1 - u))^k exp(-x u) du; truncation error <= d^4 / 24 F4 <= d^4 / 15120.
 * For x >= 0.1, Fk come from the moments Gn = int u^n exp(-x u) du = (n G(n-1) - exp(-x)) / x
 * (the upward recursion loses at most 720 / x^6 ulps by G6): one exp, one division. Below 0.1
 * alpha, F0 - exp(-x) and Fk are their Taylor series (no exp at all; the first term left out
 * is < 3e-11). For |d| > 1 (a steep extinction ramp across one piece, rare) the sub-piece sum
 * is used instead. That sum (4 sub-pieces, tau constant on each, the rule before this one) has
 * an error of ~(2 d / 16)^2 / 12 of w: measured 7e-3 against 3.8e-5 for this series at
 * |d| = 1 (brute-force quadrature, 4,000 pieces). */
static void piece_aw(double ta, double tb, double l, double *alpha, double *w)
{
    const double x = 0.5 * (ta + tb) * l, d = 0.5 * (tb - ta) * l;
    if (!(x > 0)) { /* no extinction, or an empty piece: nothing emitted */
        *alpha = *w = 0;
        return;
    }
    if (fabs(d) > 1) {
        subpieces_aw(ta, tb, l, alpha, w);
        return;
    }
    double a, f0, f1, f2, f3; /* alpha, F0 - exp(-x), F1, F2, F3 */
    if (x < 0.1) {
        a = x * (1 - x * (1.0 / 2 - x * (1.0 / 6 - x * (1.0 / 24 - x * (1.0 / 120 - x * (1.0 / 720))))));
        /* constants as products: x / 840 would be a division (no -ffast-math) in the chain */
        f0 = x * (1.0 / 2 + x * (-1.0 / 3 + x * (1.0 / 8 + x * (-1.0 / 30 + x * (1.0 / 144 - x * (1.0 / 840))))));
        f1 = 1.0 / 6 + x * (-1.0 / 12 + x * (1.0 / 40 + x * (-1.0 / 180 + x * (1.0 / 1008))));
        f2 = 1.0 / 30 + x * (-1.0 / 60 + x * (1.0 / 210 - x * (1.0 / 1008)));
        f3 = 1.0 / 140 - x * (1.0 / 280);
    } else {
        const double E = exp(-x), ix = 1.0 / x;
        const double g0 = (1 - E) * ix, g1 = (g0 - E) * ix, g2 = (2 * g1 - E) * ix;
        const double g3 = (3 * g2 - E) * ix, g4 = (4 * g3 - E) * ix, g5 = (5 * g4 - E) * ix;
        const double g6 = (6 * g5 - E) * ix;
        a = 1 - E;
        f0 = g0 - E;
        f1 = g1 - g2;
        f2 = g2 - 2 * g3 + g4;
        f3 = g3 - 3 * g4 + 3 * g5 - g6;
    }
    const double v = f0 + d * (f1 + d * (0.5 * f2 + d * (f3 * (1.0 / 6))));
    *alpha = a;
    *w = v > 0 ? v : 0;
}

static inline double clamp01(double u)
{
    return u < 0 ? 0 : u > 1 ? 1 : u;
}

/* The first breakpoint index i with s[i] > v (n when none). */
static int upper_index(const tf_prep *tf, double v)
{
    int lo = 0, hi = tf->n;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (tf->s[mid] > v)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

/* One piece of the walk, of length l, inside table piece kr (-1 below the table, n - 1 above
 * it: clamped, so tau and colour are the end values there) from scalar sf at its front to sk
 * at its back, composited under acc. With ua, ub the piece fractions at the two ends the
 * colour is c_k + (c_k+1 - c_k) u, so the emitted colour c_k alpha + (c_k+1 - c_k) (ua alpha +
 * (ub - ua) w) needs no colour lookups. */
static void walk_piece(const tf_prep *tf, int kr, double sf, double sk, double l, double acc[4])
{
    const int k = kr < 0 ? 0 : kr > tf->n - 2 ? tf->n - 2 : kr;
    const struct tf_piece *pc = &tf->pc[k];
    const double ua = clamp01((sf - pc->s0) * pc->ir);
    const double ub = clamp01((sk - pc->s0) * pc->ir);
    double alpha, w;
    piece_aw(pc->tau0 + pc->dtau * ua, pc->tau0 + pc->dtau * ub, l, &alpha, &w);
    const double beta = ua * alpha + (ub - ua) * w, T = 1.0 - acc[3];
    for (int c = 0; c < 3; c++) {
        const double v = pc->c0[c] * alpha + pc->dc[c] * beta;
        acc[c] += T * (v > 0 ? v : 0);
    }
    acc[3] += T * alpha;
}

/* The exact integrator along [tin, tout]: the scalar S0 + Sb t crosses the breakpoints
 * i..j-1 (those more than eps inside its range); the pieces between them are walked in ray
 * order, each one's table piece known (one search per segment, none per piece). Returns the
 * pieces. */
static int segment_exact(const tf_prep *tf, double S0, double Sb, double tin, double tout, double L,
                         float out[4])
{
    const double sa = S0 + Sb * tin, sb = S0 + Sb * tout;
    const double lo = (sa < sb ? sa : sb) + tf->eps, hi = (sa < sb ? sb : sa) - tf->eps;
    const int n = tf->n;
    const int i = n == 2 ? (tf->s[0] > lo ? 0 : tf->s[1] > lo ? 1 : 2) : upper_index(tf, lo);
    int j = i;
    if (lo < hi && Sb != 0 && tf->span > 0)
        while (j < n && tf->s[j] < hi)
            j++;
    const int count = j - i;
    double acc[4] = {0, 0, 0, 0};
    if (count == 0) { /* one piece, in table piece i - 1 */
        walk_piece(tf, i - 1, sa, sb, (tout - tin) * L, acc);
    } else {
        const double iSb = 1.0 / Sb;
        const int dir = Sb > 0 ? 1 : -1;
        int bp = dir > 0 ? i : j - 1, kr = dir > 0 ? i - 1 : j - 1; /* next breakpoint, piece */
        double t0 = tin, s0 = sa;
        for (int q = 0; q < count; q++, bp += dir, kr += dir) {
            double t1 = (tf->s[bp] - S0) * iSb;
            t1 = t1 < t0 ? t0 : t1 > tout ? tout : t1;
            walk_piece(tf, kr, s0, tf->s[bp], (t1 - t0) * L, acc);
            t0 = t1;
            s0 = tf->s[bp];
        }
        walk_piece(tf, kr, s0, sb, (tout - t0) * L, acc);
    }
    for (int c = 0; c < 4; c++)
        out[c] = (float)acc[c];
    return count + 1;
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
    if (tf->method == TET_TF_EXACT)
        return segment_exact(tf, S0, Sb, tin, tout, L, out);
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
    for (int k = 0; k + 1 < tf->n; k++) {
        double range = (double)tf->s[k + 1] - tf->s[k];
        tf->inv_range[k] = range > 0 ? 1.0 / range : 0.0;
        struct tf_piece *pc = &tf->pc[k];
        pc->s0 = tf->s[k];
        pc->ir = tf->inv_range[k];
        pc->tau0 = tf->tau[k];
        pc->dtau = (double)tf->tau[k + 1] - tf->tau[k];
        for (int c = 0; c < 3; c++) {
            pc->c0[c] = tf->rgb[k][c];
            pc->dc[c] = (double)tf->rgb[k + 1][c] - tf->rgb[k][c];
        }
    }
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
