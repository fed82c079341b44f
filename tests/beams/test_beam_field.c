/* test_beam_field.c — the closed form against the float64 adaptive quadrature of the raw density
 * (reference/beams_ref.c): a torture set of singular and near-singular rays plus seeded random
 * beams and rays. The float32 closed form is the shader's own, shaders/beams/beam_field.glsl run
 * on these rays by a compute probe (beam_probe.h) on the test's GL (llvmpipe in CI); the float64
 * one is the lab's C closed form, plugin/lab/beam_field_d.c.
 *
 * Tolerances.
 *  - float32 closed form (GLSL): relative error <= 1e-6 + cond, where cond is the spread of the exact
 *    answer (float64 closed form) when the float32 inputs (ray origin, direction, head M, end
 *    t1) move by 2 float32 ulps. A float32 algorithm cannot do better than the float32 rounding
 *    of its own inputs: a ray 1e6 units away from a beam of radius 1 moves by 0.1 when its
 *    direction moves by one ulp. Where the inputs are well conditioned (cond << 1e-5) this is
 *    the issue's 1e-5 target with 10x margin (3.6e-7 is the largest seen there). Where cond
 *    dominates, the error measured is at most 0.5 cond (2026-12-01): the float32 algorithm is as
 *    accurate as about one ulp of its inputs, so 1 cond keeps a 2x margin. The test also counts
 *    how many cases needed the cond term.
 *  - float64 closed form: 1e-8 + cond * (DBL_EPSILON / FLT_EPSILON). The quadrature is asked
 *    for 1e-12 relative but near a 1/r peak at the 1e-6 R softening floor the density itself is
 *    only good to ~eps*|t|/width (see beams_ref.c); 2.7e-10 is the largest difference seen.
 * Cases whose reference H is 0 must give 0 (outside the support nothing is added) unless the
 * ray grazes the support (cond-limited), where |H| <= 1e-6 * (a + b) is accepted. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lab/beam_field_d.h"
#include "beams_ref.h"
#include "beam_probe.h"

static vfx_context *g_ctx; /* the probe's plugin context */

typedef struct tcase {
    const char *name;
    vfx_beam beam;
    float o[3], v[3];
    float t0, t1;
    int smooth; /* falloff: 0 hard, 1 smooth (w = (1 - (r/R)^2)^2) */
} tcase;

static void normalize3f(float v[3])
{
    double n = sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]);
    for (int i = 0; i < 3; ++i)
        v[i] = (float)(v[i] / n);
}

static double closed_d(const tcase *c, const float o[3], const float v[3], const vfx_beam *b,
                       double t1)
{
    double od[3] = {o[0], o[1], o[2]}, vd[3] = {v[0], v[1], v[2]};
    double vn = sqrt(vd[0] * vd[0] + vd[1] * vd[1] + vd[2] * vd[2]);
    for (int k = 0; k < 3; ++k)
        vd[k] /= vn;
    volfx_beam_d bd;
    char err[256];
    if (volfx_beam_validate(b, &bd, err, sizeof err) != VFX_OK)
        return NAN;
    bd.smooth = c->smooth;
    return volfx_beam_integral_d(&bd, od, vd, c->t0, t1);
}

/* Relative spread of the exact H over 2-ulp moves of the float32 inputs. */
static double conditioning(const tcase *c, double h)
{
    double worst = 0.0;
    for (int k = 0; k < 10; ++k) {
        for (int sgn = -1; sgn <= 1; sgn += 2) {
            float o[3] = {c->o[0], c->o[1], c->o[2]}, v[3] = {c->v[0], c->v[1], c->v[2]};
            vfx_beam b = c->beam;
            double t1 = c->t1;
            float *x = k < 3 ? &o[k] : k < 6 ? &v[k - 3] : k < 9 ? &b.head[k - 6] : NULL;
            if (x) {
                float mag = fabsf(*x);
                /* moving a zero component by its neighbours' ulp, not by a denormal */
                float ref = fmaxf(mag, k < 3 ? fmaxf(fabsf(o[0]), fmaxf(fabsf(o[1]), fabsf(o[2])))
                                       : k < 6 ? 1.0f
                                               : fmaxf(fabsf(b.head[0]), fmaxf(fabsf(b.head[1]), fabsf(b.head[2]))));
                *x += (float)sgn * 2.0f * FLT_EPSILON * ref;
            } else {
                if (!isfinite(t1))
                    continue;
                t1 *= 1.0 + sgn * 2.0 * FLT_EPSILON;
            }
            double hp = closed_d(c, o, v, &b, t1);
            double rel = fabs(hp - h) / fmax(fabs(h), 1e-300);
            if (rel > worst)
                worst = rel;
        }
    }
    return worst;
}

typedef struct tally {
    int cases, failures, cond_limited;
    double max_rel_f, max_rel_d, max_rel_f_wellcond, max_ratio_f;
} tally;

static void check(tally *t, const tcase *c, float hf)
{
    double od[3] = {c->o[0], c->o[1], c->o[2]}, vd[3] = {c->v[0], c->v[1], c->v[2]};
    /* The float direction is unit only to ~6e-8; the float64 paths take t as arc length, so
     * they get the exactly normalised direction (else both would be off by |v| - 1). */
    double vn = sqrt(vd[0] * vd[0] + vd[1] * vd[1] + vd[2] * vd[2]);
    for (int k = 0; k < 3; ++k)
        vd[k] /= vn;
    double ref = NAN;
    volfx_beam_d bd;
    char err[256];
    t->cases++;
    if (volfx_beam_validate(&c->beam, &bd, err, sizeof err) != VFX_OK) {
        printf("FAIL %s: valid beam refused: %s\n", c->name, err);
        t->failures++;
        return;
    }
    bd.smooth = c->smooth;
    uint64_t evals = 0;
    if (getenv("VFX_TEST_VERBOSE"))
        fprintf(stderr, "case %s\n", c->name);
    ref = ref_beams_integral(&bd, 1, od, vd, c->t0, c->t1, 1e-12, &evals);
    if (getenv("VFX_TEST_VERBOSE"))
        fprintf(stderr, "  %llu evaluations\n", (unsigned long long)evals);
    double hd = volfx_beam_integral_d(&bd, od, vd, c->t0, c->t1);
    if (!isfinite(hf) || !isfinite(hd)) {
        printf("FAIL %s: non-finite H (f32 %g, f64 %g)\n", c->name, hf, hd);
        t->failures++;
        return;
    }
    double cond = conditioning(c, hd);
    if (ref == 0.0) {
        double lim = 1e-6 * (c->beam.a + c->beam.b);
        if (fabs(hf) > lim || fabs(hd) > lim) {
            printf("FAIL %s (%s): reference 0, closed form f32 %g f64 %g\n", c->name, c->smooth ? "smooth" : "hard", hf, hd);
            t->failures++;
        }
        return;
    }
    double ef = fabs(hf - ref) / ref, ed = fabs(hd - ref) / ref;
    double tol_f = 1e-6 + cond, tol_d = 1e-8 + cond * (DBL_EPSILON / FLT_EPSILON);
    if (ef > 1e-5)
        t->cond_limited++;
    if (ef > 1e-5 && getenv("VFX_TEST_VERBOSE"))
        fprintf(stderr, "  above 1e-5: %s (%s) rel %.3g cond %.3g\n", c->name, c->smooth ? "smooth" : "hard", ef, cond);
    if (ef / tol_f > t->max_ratio_f)
        t->max_ratio_f = ef / tol_f;
    if (ef > t->max_rel_f)
        t->max_rel_f = ef;
    if (ed > t->max_rel_d)
        t->max_rel_d = ed;
    if (cond < 1e-6 && ef > t->max_rel_f_wellcond)
        t->max_rel_f_wellcond = ef;
    if ((ef > tol_f || ed > tol_d) && getenv("VFX_TEST_BRUTE")) {
        /* third opinion for diagnosis: midpoint rule with 2^22 samples */
        int N = 1 << 22;
        double t1 = c->t1, sum = 0, hstep = (t1 - c->t0) / N;
        for (int i = 0; i < N; ++i) {
            double tt = c->t0 + (i + 0.5) * hstep;
            double pp[3] = {od[0] + tt * vd[0], od[1] + tt * vd[1], od[2] + tt * vd[2]};
            sum += volfx_beam_density_d(&bd, pp);
        }
        printf("  brute %.12g\n", sum * hstep);
    }
    if (ef > tol_f || ed > tol_d) {
        printf("FAIL %s (%s): ref %.17g f32 %.9g (rel %.3g, tol %.3g) f64 %.17g (rel %.3g, tol %.3g)\n",
               c->name, c->smooth ? "smooth" : "hard", ref, hf, ef, tol_f, hd, ed, tol_d);
        t->failures++;
    }
}

static vfx_beam mk_beam(float mx, float my, float mz, float dx, float dy, float dz, float L,
                        float R, float a, float b, float eps)
{
    vfx_beam v = {.type = VFX_TYPE_BEAM, .head = {mx, my, mz}, .length = L, .dir = {dx, dy, dz}, .radius = R,
                  .a = a, .b = b, .eps = eps};
    return v;
}

static tcase mk(const char *name, vfx_beam b, float ox, float oy, float oz, float vx, float vy,
                float vz, float t1)
{
    tcase c = {name, b, {ox, oy, oz}, {vx, vy, vz}, 0.0f, t1, 0};
    normalize3f(c.v);
    return c;
}

/* Seeded xorshift: the random cases are the same on every run. */
static double rnd(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return (double)(*s >> 11) / 9007199254740992.0;
}

static int run(int smooth)
{
    tally t = {0};
    vfx_beam std = mk_beam(0, 0, 0, 1, 0, 0, 10, 1, 1, 1, 0);
    vfx_beam soft = mk_beam(0, 0, 0, 1, 0, 0, 10, 1, 1, 1, 0.05f);
    tcase fixed[] = {
        mk("perpendicular through the slab", std, 5, -5, 0.3f, 0, 1, 0, 100),
        mk("perpendicular through the axis, eps=0", std, 5, -5, 0, 0, 1, 0, 100),
        mk("through M exactly, eps=0", std, -3, -4, 0, 3, 4, 0, 100),
        mk("through M+L*D exactly, eps=0", std, 7, -4, 0, 3, 4, 0, 100),
        mk("along the axis (parallel, on it)", std, -5, 0, 0, 1, 0, 0, 100),
        mk("parallel to the axis, off it", std, -5, 0.2f, 0.1f, 1, 0, 0, 100),
        mk("parallel, backwards", std, 20, 0.5f, 0, -1, 0, 0, 100),
        mk("nearly parallel 1e-6 rad", std, -5, 0.3f, 0, 1, 1e-6f, 0, 100),
        mk("nearly parallel 1e-3 rad", std, -5, 0.3f, 0, 1, 1e-3f, 0, 100),
        mk("nearly parallel 1e-8 rad through axis", std, -5, 0, 0, 1, 1e-8f, 0, 100),
        mk("camera inside the cylinder", std, 4, 0.1f, 0.2f, 0.3f, 0.5f, -0.2f, 100),
        mk("camera inside the head sphere", std, 0.1f, 0.1f, 0, -1, 0.2f, 0.1f, 100),
        mk("camera on M, eps=0", std, 0, 0, 0, 0, 1, 0, 100),
        mk("camera on the axis, eps=0", std, 3, 0, 0, 0, 0, 1, 100),
        mk("depth cuts inside the beam", std, 5, -5, 0.3f, 0, 1, 0, 5.2f),
        mk("depth before the beam", std, 5, -5, 0.3f, 0, 1, 0, 3.0f),
        mk("tangent to the support", std, 5, -5, 1.0f, 0, 1, 0, 100),
        mk("softened through M", soft, -3, -4, 0, 3, 4, 0, 100),
        mk("softened along the axis", soft, -5, 0, 0, 1, 0, 0, 100),
        mk("L = 0 sphere", mk_beam(0, 0, 0, 0, 0, 1, 0, 1, 2, 1, 0), 0.3f, -5, 0.1f, 0, 1, 0, 100),
        mk("a = 0", mk_beam(0, 0, 0, 1, 0, 0, 3, 1, 0, 1, 0), -2, -2, 0, 1, 1, 0, 100),
        mk("b = 0", mk_beam(0, 0, 0, 1, 0, 0, 3, 1, 1, 0, 0), -2, -2, 0.1f, 1, 1, 0, 100),
        mk("far: beam 1e4 away", mk_beam(1e4f, 0, 0, 0, 1, 0, 5, 1, 1, 1, 0), 0, 0, 0, 1, 0.2f / 1e4f, 0, 3e4f),
        mk("far: beam 1e6 away, R=100", mk_beam(1e6f, 0, 0, 0, 0, 1, 500, 100, 1, 1, 0), 0, 0, 0, 1, 0, 3e-5f, 3e6f),
        mk("far: along a 1e6 long beam", mk_beam(0, 0, 0, 1, 0, 0, 1e6f, 10, 1, 1, 0), -50, 3, 0, 1, 0, 0, 2e6f),
        mk("far: 1e6 long beam, nearly parallel", mk_beam(0, 0, 0, 1, 0, 0, 1e6f, 10, 1, 1, 0), -50, 3, 0, 1, -3e-6f, 1e-6f, 2e6f),
        mk("tiny: R = 1e-4", mk_beam(1e-3f, 0, 0, 0, 1, 0, 3e-4f, 1e-4f, 1, 1, 0), 0, 0, 0, 1, 2e-2f, 0, 1),
        mk("tiny: R = 1e-4 through axis", mk_beam(1e-3f, 0, 0, 0, 1, 0, 3e-4f, 1e-4f, 1, 1, 0), 0, 1.5e-4f, 0, 1, 0, 0, 1),
        mk("large close asinh arguments", mk_beam(0, 0, 0, 1, 0, 0, 1e5f, 1e3f, 1, 1, 0), 1e4f, 1, 0, 1, 1e-5f, 0, 5e4f),
        mk("ray starts beyond, looks back along the axis", std, 50, 0, 1e-3f, -1, 0, 0, 1e3f),
        /* grazing the hard support edge: H ~ 2 b h / R with relative condition ~ (R/h)^2 */
        mk("grazing the head sphere, h = 0.09 R", std, -0.3f, -5, 0.95f, 0, 1, 0, 100),
        mk("grazing the head sphere, h = 0.01 R", std, -0.3f, -5, 0.953887f, 0, 1, 0, 100),
        mk("grazing the cylinder, h = 0.014 R", std, 5, -5, 0.9999f, 0, 1, 0, 100),
        mk("grazing the cylinder, h = 1.4e-3 R", std, 5, -5, 0.999999f, 0, 1, 0, 100),
        mk("grazing the cylinder, cut by depth mid-chord", std, 5, -5, 0.9999f, 0, 1, 0, 5),
        mk("grazing the cylinder, cut just inside", std, 5, -5, 0.99f, 0, 1, 0, 4.9f),
        mk("grazing the cap beyond", std, 10.3f, -5, 0.95f, 0, 1, 0, 100),
        mk("grazing a beam 1e3 away", mk_beam(1e3f, 0, 0, 0, 0, 1, 5, 1, 1, 1, 0), 0, 0, 2, 1, 0.9995e-3f, 0, 3e3f),
        mk("grazing obliquely, cut by depth", std, 2, -5, -3, 0.3f, 1, 0.6f, 5.5f),
        /* near the support edge from inside: the smooth integrand vanishes like (R - r)^2 there,
         * so these pieces are where an antiderivative would cancel (edge series instead) */
        mk("camera inside at r = 0.999 R, looking out", std, 5, 0.999f, 0, 0, 1, 0, 100),
        mk("camera inside at r = 0.99 R, looking out obliquely", std, 5, 0.7f, 0.7f, 0.3f, 0.7f, 0.6f, 100),
        mk("depth cut 1e-3 after entering", std, 5, -5, 0.3f, 0, 1, 0, 5.0f - 0.953939f + 1e-3f),
        mk("parallel to the axis at r = 0.99 R", std, -5, 0.99f, 0, 1, 0, 0, 100),
        mk("parallel to the axis at r = 0.9999 R", std, -5, 0.9999f, 0, 1, 0, 0, 100),
    };
    enum { NFIXED = sizeof fixed / sizeof fixed[0], NRANDOM = 400 };
    static tcase all[NFIXED + NRANDOM];
    int nc = 0;
    for (size_t i = 0; i < NFIXED; ++i) {
        fixed[i].smooth = smooth;
        all[nc++] = fixed[i];
    }
    int fixed_cases = nc;

    uint64_t seed = 0x5eed0005beau;
    static char names[NRANDOM][48];
    for (int i = 0; i < NRANDOM; ++i) {
        double S = pow(10.0, -3.0 + 8.0 * rnd(&seed)); /* scene scale 1e-3 .. 1e5 */
        vfx_beam b;
        memset(&b, 0, sizeof b);
        for (int k = 0; k < 3; ++k) {
            b.head[k] = (float)(S * (2.0 * rnd(&seed) - 1.0));
            b.dir[k] = (float)(2.0 * rnd(&seed) - 1.0);
        }
        b.length = rnd(&seed) < 0.15 ? 0.0f : (float)(S * 3.0 * rnd(&seed));
        b.radius = (float)(S * (0.02 + rnd(&seed)));
        b.a = (float)(0.1 + rnd(&seed));
        b.b = rnd(&seed) < 0.5 ? b.a : (float)(0.1 + rnd(&seed));
        b.eps = rnd(&seed) < 0.5 ? 0.0f : (float)(b.radius * pow(10.0, -4.0 + 3.0 * rnd(&seed)));
        double dn = sqrt((double)b.dir[0] * b.dir[0] + (double)b.dir[1] * b.dir[1] + (double)b.dir[2] * b.dir[2]);
        /* aim at a point near the segment so that most rays hit the support */
        double u = rnd(&seed) * b.length, target[3];
        for (int k = 0; k < 3; ++k)
            target[k] = b.head[k] + u * b.dir[k] / dn + 1.2 * b.radius * (2.0 * rnd(&seed) - 1.0);
        tcase c;
        memset(&c, 0, sizeof c);
        snprintf(names[i], sizeof names[i], "random %d (scale %.3g)", i, S);
        c.name = names[i];
        c.beam = b;
        double dist = S * pow(10.0, -1.0 + 3.0 * rnd(&seed));
        double dirv[3] = {2 * rnd(&seed) - 1, 2 * rnd(&seed) - 1, 2 * rnd(&seed) - 1};
        if (i % 5 == 0) /* every fifth ray nearly parallel to the axis */
            for (int k = 0; k < 3; ++k)
                dirv[k] = b.dir[k] / dn + 1e-4 * dirv[k];
        double n = sqrt(dirv[0] * dirv[0] + dirv[1] * dirv[1] + dirv[2] * dirv[2]);
        for (int k = 0; k < 3; ++k) {
            c.o[k] = (float)(target[k] - dist * dirv[k] / n);
            c.v[k] = (float)(dirv[k] / n);
        }
        normalize3f(c.v);
        c.t0 = 0.0f;
        c.t1 = rnd(&seed) < 0.3 ? (float)(dist * (0.5 + rnd(&seed))) : (float)(dist * 10.0 + 10.0 * S);
        c.smooth = smooth;
        all[nc++] = c;
    }
    /* the shader's H of every case in one dispatch, then each case against the references */
    static volfx_beam_d bds[NFIXED + NRANDOM];
    static beam_probe_ray rays[NFIXED + NRANDOM];
    static float hf[NFIXED + NRANDOM];
    for (int i = 0; i < nc; ++i) {
        char err[256];
        if (volfx_beam_validate(&all[i].beam, &bds[i], err, sizeof err) != VFX_OK)
            memset(&bds[i], 0, sizeof bds[i]); /* refused: check() reports it */
        bds[i].smooth = all[i].smooth;
        rays[i] = (beam_probe_ray){&bds[i], {all[i].o[0], all[i].o[1], all[i].o[2]},
                                   {all[i].v[0], all[i].v[1], all[i].v[2]}, all[i].t0, all[i].t1};
    }
    if (!beam_probe_eval(g_ctx, rays, (uint32_t)nc, hf)) {
        printf("FAIL the shader probe did not run\n");
        return 1;
    }
    for (int i = 0; i < nc; ++i)
        check(&t, &all[i], hf[i]);
    printf("beam field, %s support: %d cases (%d torture, %d random), %d failures\n", smooth ? "smooth" : "hard", t.cases, fixed_cases,
           t.cases - fixed_cases, t.failures);
    printf("max relative error: float32 (GLSL) %.3g (%.3g where cond < 1e-6; %d cases above 1e-5, all "
           "within their input conditioning; max error / (1e-6 + cond) %.3g), float64 %.3g\n",
           t.max_rel_f, t.max_rel_f_wellcond, t.cond_limited, t.max_ratio_f, t.max_rel_d);
    return t.failures;
}

/* Bending beams: polylines against the quadrature of the raw field (r = distance to the
 * polyline, straight from the definition), float32 held to 1e-6 + cond (cond: 2-ulp moves of the
 * direction and of each joint relative to the ray origin, ref_beams_cond_abs), float64 to
 * 1e-8 + cond scaled to double. Seeded rays aimed near a random point of the polyline, a third
 * of them cut short; plus a sweep of rays across a joint, and a collinear joint that must give
 * the straight beam's H (no bright or dark joint). */
static int run_polylines(int smooth)
{
    static const float P[][VOLFX_BEAM_MAX_JOINTS][3] = {
        {{0, 0, 0}, {3, 0, 0}, {3, 3, 0}},                              /* right-angle bend */
        {{0, 0, 0}, {2, 0, 0}, {4, 0.7f, 0}, {6, 0.7f, 0.5f}},          /* shallow bends */
        {{0, 0, 0}, {4, 0, 0}, {4, 1.2f, 0}, {0, 1.2f, 0}},             /* U-turn: legs 1.2 apart */
        {{0, 0, 0}, {2, 0, 0}, {5, 0, 0}},                              /* collinear joint */
        {{0, 0, 0}, {1, 1, 0}, {2, 0, 0.3f}, {3, 1, 0}, {4, 0, -0.2f}, {5, 1, 0}}, /* zig-zag, 6 joints */
        {{0, 0, 0}, {2, 0, 0}, {2, 0, 0}, {2, 2, 0}},                   /* coincident joints */
        {{1000, 0, 0}, {1003, 0, 0}, {1003, 2, 1}},                     /* a bend 1e3 away */
    };
    static const int nj[] = {3, 4, 4, 3, 6, 4, 3};
    const char *names[] = {"right angle", "shallow", "U-turn", "collinear", "zig-zag", "coincident", "far bend"};
    int failures = 0, cases = 0, cond_limited = 0;
    double max_f = 0, max_d = 0, max_ratio = 0, max_wc = 0;
    uint64_t seed = 0xbe4d5u + (uint64_t)smooth;
    for (size_t p = 0; p < sizeof nj / sizeof nj[0]; ++p) {
        vfx_beam vb = mk_beam(0, 0, 0, 1, 0, 0, 1, 0.9f, 1, 0.8f, p % 2 ? 0.05f : 0.0f);
        volfx_beam_d bd;
        char err[256];
        if (volfx_beam_validate(&vb, &bd, err, sizeof err) || volfx_beam_set_joints(&bd, &P[p][0][0], (uint32_t)nj[p], err, sizeof err)) {
            printf("FAIL polyline %s refused: %s\n", names[p], err);
            return 1;
        }
        bd.smooth = smooth;
        enum { NRAYS = 70 };
        float os[NRAYS][3], vs[NRAYS][3], hfs[NRAYS];
        double t1s[NRAYS];
        beam_probe_ray rays[NRAYS];
        for (int r = 0; r < NRAYS; ++r) {
            float *o = os[r], *v = vs[r];
            double t1;
            if (r < 10) { /* a sweep across joint 1 along the ray direction z, 0.3 off the line */
                const float *J = P[p][1];
                o[0] = J[0] - 0.45f + 0.1f * (float)r, o[1] = J[1] + 0.3f, o[2] = J[2] - 8.f;
                v[0] = 0, v[1] = 0, v[2] = 1;
                t1 = 100;
            } else {
                int k = (int)(rnd(&seed) * (nj[p] - 1));
                double u = rnd(&seed), tgt[3], dir[3] = {2 * rnd(&seed) - 1, 2 * rnd(&seed) - 1, 2 * rnd(&seed) - 1};
                for (int c = 0; c < 3; ++c)
                    tgt[c] = P[p][k][c] + u * (P[p][k + 1][c] - P[p][k][c]) + 1.1 * bd.radius * (2 * rnd(&seed) - 1);
                double n = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]), dist = 3 + 15 * rnd(&seed);
                for (int c = 0; c < 3; ++c) {
                    v[c] = (float)(dir[c] / n);
                    o[c] = (float)(tgt[c] - dist * dir[c] / n);
                }
                normalize3f(v);
                t1 = rnd(&seed) < 0.3 ? dist * (0.7 + 0.6 * rnd(&seed)) : 100.0;
            }
            t1s[r] = t1;
            rays[r] = (beam_probe_ray){&bd, {o[0], o[1], o[2]}, {v[0], v[1], v[2]}, 0.f, (float)t1};
        }
        if (!beam_probe_eval(g_ctx, rays, NRAYS, hfs)) {
            printf("FAIL the shader probe did not run\n");
            return 1;
        }
        for (int r = 0; r < NRAYS; ++r) {
            const float *o = os[r], *v = vs[r];
            double t1 = t1s[r];
            float hf = hfs[r];
            double od[3] = {o[0], o[1], o[2]}, vd[3] = {v[0], v[1], v[2]};
            double vn = sqrt(vd[0] * vd[0] + vd[1] * vd[1] + vd[2] * vd[2]);
            for (int c = 0; c < 3; ++c)
                vd[c] /= vn;
            double ref = ref_beams_integral(&bd, 1, od, vd, 0, t1, 1e-12, NULL);
            double hd = volfx_beam_integral_d(&bd, od, vd, 0, t1);
            double cond = ref_beams_cond_abs(&bd, 1, od, vd, 0, t1, 2.0);
            cases++;
            double ef = fabs(hf - ref), ed = fabs(hd - ref);
            double tf = 1e-6 * ref + cond, td = 1e-8 * ref + cond * (DBL_EPSILON / FLT_EPSILON);
            if (ref == 0.0)
                tf = td = 1e-6 * (bd.a + bd.b) + cond;
            if (ref > 0) {
                max_f = fmax(max_f, ef / ref), max_d = fmax(max_d, ed / ref);
                if (cond < 1e-6 * ref)
                    max_wc = fmax(max_wc, ef / ref);
                cond_limited += ef > 1e-5 * ref;
            }
            max_ratio = fmax(max_ratio, ef / tf);
            if (!(ef <= tf) || !(ed <= td)) {
                printf("FAIL polyline %s (%s) ray %d: ref %.12g f32 %.9g (err %.3g, tol %.3g) f64 %.12g (err %.3g, tol %.3g)\n",
                       names[p], smooth ? "smooth" : "hard", r, ref, hf, ef, tf, hd, ed, td);
                failures++;
            }
        }
        if (p == 3) { /* collinear joint: the straight beam J0 -> J2 */
            volfx_beam_d st = bd;
            st.joint_count = 0;
            st.length = 5;
            for (int r = 0; r < 20; ++r) {
                double o[3] = {0.25 * r - 1, 0.2 + 0.03 * r, -6}, v[3] = {0.05, 0, 1};
                double n = sqrt(v[0] * v[0] + v[2] * v[2]);
                v[0] /= n, v[2] /= n;
                double a = volfx_beam_integral_d(&bd, o, v, 0, 100), b = volfx_beam_integral_d(&st, o, v, 0, 100);
                if (!(fabs(a - b) <= 1e-12 * b + 1e-15)) {
                    printf("FAIL collinear joint (%s): polyline %.15g straight %.15g\n", smooth ? "smooth" : "hard", a, b);
                    failures++;
                }
            }
        }
    }
    printf("bending beams, %s support: %d rays over %zu polylines, %d failures; max relative error float32 %.3g "
           "(%.3g where cond < 1e-6; %d above 1e-5, within their conditioning; max error / tolerance %.3g), "
           "float64 %.3g\n", smooth ? "smooth" : "hard", cases, sizeof nj / sizeof nj[0], failures, max_f, max_wc,
           cond_limited, max_ratio, max_d);
    return failures;
}

int main(void)
{
    rt_gl_context *gl = test_gl_or_skip();
    const vfx_plugin_api *api = NULL;
    if (!(g_ctx = beam_probe_open(&api))) {
        printf("FAIL no plugin context for the shader probe\n");
        return 1;
    }
    int failures = run(0);
    failures += run(1);
    failures += run_polylines(0);
    failures += run_polylines(1);
    api->destroy(g_ctx);
    rt_gl_context_destroy(gl);
    return failures ? 1 : 0;
}
