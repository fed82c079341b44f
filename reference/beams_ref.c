/* beams_ref.c — adaptive G7K15 with breakpoints. */
#include "beams_ref.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct quad_ctx {
    const volfx_beam_d *beams;
    uint32_t n;
    const double *o, *v;
    uint64_t evals;
} quad_ctx;

static double f(quad_ctx *q, double t)
{
    double p[3] = {q->o[0] + t * q->v[0], q->o[1] + t * q->v[1], q->o[2] + t * q->v[2]};
    double s = 0;
    for (uint32_t i = 0; i < q->n; ++i)
        s += volfx_beam_density_d(&q->beams[i], p);
    q->evals++;
    return s;
}

static const double xgk[8] = {0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
                              0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
                              0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
                              0.207784955007898467600689403773245, 0.000000000000000000000000000000000};
static const double wgk[8] = {0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
                              0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
                              0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
                              0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
static const double wg[4] = {0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                             0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

static double gk15(quad_ctx *q, double a, double b, double *err)
{
    double c = 0.5 * (a + b), h = 0.5 * (b - a);
    double fc = f(q, c), rk = fc * wgk[7], rg = fc * wg[3];
    for (int j = 0; j < 7; ++j) {
        double x = h * xgk[j];
        double f1 = f(q, c - x), f2 = f(q, c + x);
        rk += wgk[j] * (f1 + f2);
        if (j % 2 == 1)
            rg += wg[j / 2] * (f1 + f2);
    }
    *err = fabs((rk - rg) * h);
    return rk * h;
}

/* Bisects until the two halves agree with the whole to a relative rel_tol of their own value.
 * The integrand is positive, so local relative accuracy everywhere gives the same relative
 * accuracy of the total; no absolute tolerance has to be shared out among the pieces. */
static double adapt(quad_ctx *q, double a, double b, double whole, double rel_tol, int depth)
{
    double m = 0.5 * (a + b), el, er;
    double l = gk15(q, a, m, &el), r = gk15(q, m, b, &er);
    double sum = l + r, diff = fabs(sum - whole);
    /* P = o + t*v carries an absolute rounding of ~eps*|t|, so near a 1/r peak the density
     * itself is only good to ~eps*|t|/(b - a) relative: asking for more bisects forever. */
    double noise = 16.0 * DBL_EPSILON * (fabs(a) + fabs(b)) / (b - a);
    /* at least 2^4 pieces per breakpoint interval: GK15 and its halves can agree on a value
     * that misses a narrow feature entirely (false convergence). Every peak and support edge is
     * a breakpoint (graded around peaks), so 2^4 suffices: against 2^8 (the earlier floor, 20x
     * slower) the 64x48 pixels of tests/beams/test_beams_gl.c agree to 3.4e-16 and the 430 rays
     * of test_beam_field.c pass with the same float64 agreement (7.8e-10 vs 8.5e-10). */
    if ((depth >= 4 && diff <= (rel_tol + noise) * fabs(sum)) || depth > 60 || m <= a || m >= b)
        return sum;
    return adapt(q, a, m, l, rel_tol, depth + 1) + adapt(q, m, b, r, rel_tol, depth + 1);
}

/* Graded breakpoints around a peak of width w at tp: tp +- w*2^k inside [t0, t1]. A 1/r peak
 * is scale-invariant, so on these pieces the integrand is smooth relative to their length and
 * GK15 converges in a few steps instead of bisecting down to the width. */
static void peak_breaks(double tp, double w, double t0, double t1, double *out, int *n)
{
    if (!(w > 0))
        return;
    for (int k = 0; k < 64; ++k) {
        double off = w * ldexp(1.0, k);
        int inside = 0;
        if (tp - off > t0 && tp - off < t1) { out[(*n)++] = tp - off; inside = 1; }
        if (tp + off > t0 && tp + off < t1) { out[(*n)++] = tp + off; inside = 1; }
        if (!inside && (tp - off <= t0 && tp + off >= t1))
            break;
    }
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Adds the ray parameters where |P - C| = R and its closest approach to C. */
static void sphere_breaks(const double *o, const double *v, const double *c, double R, double eps,
                          double t0, double t1, double *out, int *n)
{
    double w[3] = {o[0] - c[0], o[1] - c[1], o[2] - c[2]};
    double b = w[0] * v[0] + w[1] * v[1] + w[2] * v[2];
    out[(*n)++] = -b;
    double dd = 0;
    for (int k = 0; k < 3; ++k)
        dd += (w[k] - b * v[k]) * (w[k] - b * v[k]);
    peak_breaks(-b, sqrt(dd + eps * eps), t0, t1, out, n);
    /* R^2 - dd, not b^2 - (|w|^2 - R^2): for a sphere far from the origin that difference of two
     * ~|w|^2 numbers loses the half-chord, the breakpoint misses the support edge, and the
     * quadrature then straddles the jump (6.7e-8 off on a ray grazing a beam 1e3 away) */
    double disc = R * R - dd;
    if (disc > 0) {
        out[(*n)++] = -b - sqrt(disc);
        out[(*n)++] = -b + sqrt(disc);
    }
}

/* Adds the slab planes u = 0 and u = L of the segment A + u D, and for its infinite cylinder
 * the closest approach (graded) and the crossings of |r| = R. */
static void segment_breaks(const double *o, const double *v, const double *A, const double *D, double L,
                           double R, double eps, double t0, double t1, double *br, int *m)
{
    double c = v[0] * D[0] + v[1] * D[1] + v[2] * D[2];
    double u0 = (o[0] - A[0]) * D[0] + (o[1] - A[1]) * D[1] + (o[2] - A[2]) * D[2];
    if (c != 0) {
        br[(*m)++] = -u0 / c;
        br[(*m)++] = (L - u0) / c;
    }
    double vp[3], wp[3];
    for (int k = 0; k < 3; ++k) {
        vp[k] = v[k] - c * D[k];
        wp[k] = (o[k] - A[k]) - u0 * D[k];
    }
    double Aq = vp[0] * vp[0] + vp[1] * vp[1] + vp[2] * vp[2];
    if (Aq > 0) {
        double B = wp[0] * vp[0] + wp[1] * vp[1] + wp[2] * vp[2];
        br[(*m)++] = -B / Aq;
        double dd = 0;
        for (int k = 0; k < 3; ++k)
            dd += (wp[k] - B / Aq * vp[k]) * (wp[k] - B / Aq * vp[k]);
        /* peak width along the ray: sqrt(d^2 + eps^2) / |v_perp| */
        peak_breaks(-B / Aq, sqrt((dd + eps * eps) / Aq), t0, t1, br, m);
        double disc = R * R - dd; /* as in sphere_breaks: no B^2 - A C */
        if (disc > 0) {
            br[(*m)++] = -B / Aq - sqrt(disc / Aq);
            br[(*m)++] = -B / Aq + sqrt(disc / Aq);
        }
    }
}

/* Breakpoints sphere_breaks and segment_breaks can add, at most. */
#define SPHERE_BREAKS (3 + 2 * 64)
#define SEGMENT_BREAKS (5 + 2 * 64)

double ref_beams_integral(const volfx_beam_d *beams, uint32_t n, const double o[3], const double v[3],
                              double t0, double t1, double rel_tol, uint64_t *evals)
{
    if (!(t1 > t0))
        return 0;
    size_t cap = 2;
    for (uint32_t i = 0; i < n; ++i) {
        int nj = beams[i].joint_count >= 2 ? beams[i].joint_count : 2;
        cap += (size_t)nj * SPHERE_BREAKS + (size_t)(nj - 1) * SEGMENT_BREAKS;
        cap += 2 * SPHERE_BREAKS + SEGMENT_BREAKS; /* the anatomy's head, orb and widest body */
    }
    int m = 0;
    double *br = malloc(cap * sizeof(double));
    if (!br)
        return NAN;
    br[m++] = t0;
    br[m++] = t1;
    /* Kinks where the polyline's nearest segment changes are left to the adaptive bisection:
     * no switch point of the closed form is used here, so the reference stays independent. */
    for (uint32_t i = 0; i < n; ++i) {
        const volfx_beam_d *b = &beams[i];
        double eps = b->eps > VOLFX_BEAM_EPS_FLOOR * b->radius ? b->eps : VOLFX_BEAM_EPS_FLOOR * b->radius;
        const double *j0 = b->joint_count >= 2 ? b->joints[0] : b->head;
        double src[3];
        for (int c = 0; c < 3; ++c)
            src[c] = b->joint_count >= 2 ? b->joints[b->joint_count - 1][c] : b->head[c] + b->length * b->dir[c];
        /* the anatomy's own supports; the body's varying edge is left to the bisection */
        if (b->head_radius > 0)
            sphere_breaks(o, v, j0, b->head_radius, eps, t0, t1, br, &m);
        if (b->orb_radius > 0)
            sphere_breaks(o, v, src, b->orb_radius, eps, t0, t1, br, &m);
        if (b->joint_count < 2 && b->surge > 0)
            segment_breaks(o, v, b->head, b->dir, b->length, b->radius * (1 + b->surge), eps, t0, t1, br, &m);
        if (b->joint_count >= 2) {
            for (int k = 0; k < b->joint_count; ++k)
                sphere_breaks(o, v, b->joints[k], b->radius, eps, t0, t1, br, &m);
            for (int k = 0; k + 1 < b->joint_count; ++k) {
                double D[3], L = 0;
                for (int c = 0; c < 3; ++c) {
                    D[c] = b->joints[k + 1][c] - b->joints[k][c];
                    L += D[c] * D[c];
                }
                L = sqrt(L);
                if (!(L > 0))
                    continue;
                for (int c = 0; c < 3; ++c)
                    D[c] /= L;
                segment_breaks(o, v, b->joints[k], D, L, b->radius, eps, t0, t1, br, &m);
            }
            continue;
        }
        double e[3] = {b->head[0] + b->length * b->dir[0], b->head[1] + b->length * b->dir[1],
                       b->head[2] + b->length * b->dir[2]};
        sphere_breaks(o, v, b->head, b->radius, eps, t0, t1, br, &m);
        sphere_breaks(o, v, e, b->radius, eps, t0, t1, br, &m);
        segment_breaks(o, v, b->head, b->dir, b->length, b->radius, eps, t0, t1, br, &m);
    }
    qsort(br, (size_t)m, sizeof(double), cmp);
    quad_ctx q = {beams, n, o, v, 0};
    double total = 0, err;
    for (int i = 0; i + 1 < m; ++i) {
        double a = br[i] < t0 ? t0 : br[i], b = br[i + 1] > t1 ? t1 : br[i + 1];
        if (b > a) {
            double whole = gk15(&q, a, b, &err);
            total += adapt(&q, a, b, whole, rel_tol, 0);
        }
    }
    free(br);
    if (evals)
        *evals = q.evals;
    return total;
}

double ref_beams_cond_abs(const volfx_beam_d *beams, uint32_t n, const double eye[3],
                              const double dir[3], double t0, double t1, double ulps)
{
    double total = 0, zero[3] = {0, 0, 0};
    for (uint32_t i = 0; i < n; ++i) {
        volfx_beam_d b = beams[i];
        double scale = 0;
        for (int k = 0; k < 3; ++k) {
            b.head[k] -= eye[k];
            scale = fmax(scale, fmax(fabs(eye[k]), fabs(b.head[k])));
        }
        for (int j = 0; j < b.joint_count; ++j)
            for (int k = 0; k < 3; ++k) {
                b.joints[j][k] -= eye[k];
                scale = fmax(scale, fabs(b.joints[j][k]));
            }
        double h = volfx_beam_integral_d(&b, zero, dir, t0, t1), worst = 0;
        /* a polyline's inputs are its joints (each rounded to float32 relative to the eye) */
        int nin = 3 + 3 * (b.joint_count >= 2 ? b.joint_count : 1);
        for (int k = 0; k < nin; ++k)
            for (int sgn = -1; sgn <= 1; sgn += 2) {
                double d[3] = {dir[0], dir[1], dir[2]};
                volfx_beam_d bp = b;
                if (k < 3)
                    d[k] += sgn * ulps * FLT_EPSILON;
                else if (b.joint_count >= 2)
                    bp.joints[(k - 3) / 3][(k - 3) % 3] += sgn * ulps * FLT_EPSILON * scale;
                else
                    bp.head[k - 3] += sgn * ulps * FLT_EPSILON * scale;
                double nd = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                for (int c = 0; c < 3; ++c)
                    d[c] /= nd;
                worst = fmax(worst, fabs(volfx_beam_integral_d(&bp, zero, d, t0, t1) - h));
            }
        total += worst;
    }
    return total;
}
