/* Diffuse particles (plugin/water/water_diffuse.c, shaders/water/diffuse.comp; Ihmsen et al.
 * 2012): the GPU's generation potentials against a float64 brute-force reference on a small
 * particle set, each diffuse particle's class against its fluid neighbours counted on the CPU,
 * the class stats against the pool, a repeat run, the pool's cap, and the parameters' checks. */
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

#include "debug.h"
#include "test_particle_host.h"
#include "water_test_session.h"
#include "test_util.h"
#include "water/water_effect.h"

/* the shader's constants (diffuse.comp) the reference mirrors */
#define SURFACE 0.12
#define CREST_VN 0.6

/* the particles with velocities, one chunk */
typedef test_particle_host host;

typedef water_session session;

/* the camera looks at the slab from above and in front: the draws run too */
static void session_open(session *ss, host *h)
{
    const float eye[3] = {0.5f, 1.5f, 2.5f};
    water_session_open(ss, h, 32, 32, eye);
}

static void session_frame(session *ss, float dt) { water_session_frame(ss, dt); }

static double stat_of(session *ss, const char *name) { return water_session_stat(ss, name); }

static void session_close(session *ss) { water_session_close(ss); }

/* A jittered slab of nx x ny x nz particles at spacing h/2 from the origin, with a velocity field
 * that moves the top layers up and sideways and shears the body (every potential takes values
 * inside and past its clamp range). */
static host make_host(uint32_t nx, uint32_t ny, uint32_t nz, float h)
{
    host s;
    memset(&s, 0, sizeof s);
    s.n = nx * ny * nz;
    float **cols[] = {&s.x, &s.y, &s.z, &s.vx, &s.vy, &s.vz};
    for (int k = 0; k < 6; ++k) *cols[k] = malloc(s.n * sizeof(float));
    uint32_t i = 0, seed = 12345;
    for (uint32_t a = 0; a < nx; ++a)
        for (uint32_t b = 0; b < ny; ++b)
            for (uint32_t c = 0; c < nz; ++c, ++i) {
                float j[3];
                for (int k = 0; k < 3; ++k) {
                    seed = seed * 1664525u + 1013904223u;
                    j[k] = ((float)(seed >> 8) / 16777216.0f - 0.5f) * 0.2f * h;
                }
                s.x[i] = 0.5f * h * a + j[0], s.y[i] = 0.5f * h * b + j[1], s.z[i] = 0.5f * h * c + j[2];
                float top = (float)b / (float)(ny - 1);
                s.vx[i] = 2.5f * sinf(9.0f * s.x[i] + 4.0f * s.z[i]);
                s.vy[i] = 3.5f * top * top * (1.0f + 0.5f * sinf(11.0f * s.x[i]));
                s.vz[i] = 0.7f * cosf(5.0f * s.z[i] - 2.0f * s.x[i]);
            }
    s.params.type = VFX_TYPE_WATER_PARAMS;
    s.params.h = h;
    /* clamp ranges and rates set explicitly (not the defaults): the field spans them */
    s.params.trapped_air[0] = 1.5f, s.params.trapped_air[1] = 6.0f;
    s.params.wave_crest[0] = 0.3f, s.params.wave_crest[1] = 1.5f;
    s.params.energy[0] = 0.5f, s.params.energy[1] = 4.0f;
    s.params.rate_trapped_air = 40.0f, s.params.rate_wave_crest = 60.0f;
    return s;
}

static void free_host(host *s) { test_particle_host_free(s); }

static double phi(double I, double lo, double hi) { return (fmin(I, hi) - fmin(I, lo)) / (hi - lo); }

/* The potentials in double, brute force over every pair (make_host's parameters).
 * pot: 4 doubles a particle; ambiguous[i] set where a decision the shader takes in float32
 * (inside h, at the surface, moving along the normal, behind the normal) lies within 1e-4 of
 * its threshold, so float32 may take the other branch. */
static void reference_potentials(const host *s, double h, double dt, double *pot, bool *ambiguous)
{
    uint32_t n = s->n;
    double *nrm = calloc(4 * (size_t)n, sizeof(double));
    const double eps = 1e-4;
    for (uint32_t i = 0; i < n; ++i) {
        double g[3] = {0, 0, 0}, S = 0;
        ambiguous[i] = false;
        for (uint32_t j = 0; j < n; ++j) {
            double d[3] = {(double)s->x[i] - s->x[j], (double)s->y[i] - s->y[j], (double)s->z[i] - s->z[j]};
            double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            if (fabs(r - h) < eps * h) ambiguous[i] = true;
            if (!(r < h)) continue;
            double W = 1 - r / h;
            for (int k = 0; k < 3; ++k) g[k] += W * d[k];
            S += W;
        }
        double gl = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        for (int k = 0; k < 3; ++k) nrm[4 * i + k] = gl > 0 ? g[k] / gl : 0;
        nrm[4 * i + 3] = S > 0 ? gl / (h * S) : 0;
        if (fabs(nrm[4 * i + 3] - SURFACE) < eps) ambiguous[i] = true;
    }
    const double vref = sqrt(9.81 * h);
    for (uint32_t i = 0; i < n; ++i) {
        const double *ni = nrm + 4 * i;
        double v[3] = {s->vx[i], s->vy[i], s->vz[i]};
        bool surf = ni[3] >= SURFACE;
        double ta = 0, wc = 0;
        for (uint32_t j = 0; j < n; ++j) {
            if (j == i) continue;
            double d[3] = {(double)s->x[i] - s->x[j], (double)s->y[i] - s->y[j], (double)s->z[i] - s->z[j]};
            double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            if (!(r < h)) continue;
            if (fabs(nrm[4 * j + 3] - SURFACE) < eps) ambiguous[i] = true;
            double W = 1 - r / h;
            double vij[3] = {v[0] - s->vx[j], v[1] - s->vy[j], v[2] - s->vz[j]};
            double lv = sqrt(vij[0] * vij[0] + vij[1] * vij[1] + vij[2] * vij[2]);
            if (lv > 0 && r > 0)
                ta += lv * (1 - (vij[0] * d[0] + vij[1] * d[1] + vij[2] * d[2]) / (lv * r)) * W;
            const double *nj = nrm + 4 * j;
            double behind = d[0] * ni[0] + d[1] * ni[1] + d[2] * ni[2];
            if (surf && nj[3] >= SURFACE && fabs(behind) < eps * h) ambiguous[i] = true;
            if (surf && nj[3] >= SURFACE && behind > 0)
                wc += (1 - (ni[0] * nj[0] + ni[1] * nj[1] + ni[2] * nj[2])) * W;
        }
        double sp = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        double vn = sp > 0 ? (v[0] * ni[0] + v[1] * ni[1] + v[2] * ni[2]) / sp : 0;
        if (wc > 0 && fabs(vn - CREST_VN) < eps) ambiguous[i] = true;
        if (!(sp > 0) || vn < CREST_VN) wc = 0;
        ta /= vref;
        double ek = sp * sp / (vref * vref);
        if (fabs(ek - 0.5) < eps) ambiguous[i] = true; /* the energy clamp's minimum: skipped or not */
        double *o = pot + 4 * i;
        o[0] = ta, o[1] = wc, o[2] = ek;
        o[3] = phi(ek, 0.5, 4.0) * (40.0 * phi(ta, 1.5, 6.0) + 60.0 * phi(wc, 0.3, 1.5)) * dt;
    }
    free(nrm);
}

/* The GPU's potentials of one step against the reference: every unambiguous particle within
 * 2e-4 of each value relative to max(1, |value|) (float32 sums of ~30 terms of order 1 round to
 * ~1e-6 each; measured worst 5e-7), and the potentials span their clamp ranges (the test sees
 * particles below, inside and above each). */
static void test_potentials_vs_reference(void **state)
{
    (void)state;
    const float h = 0.2f, dt = 1.0f / 60.0f;
    host s = make_host(12, 6, 10, h);
    session ss;
    session_open(&ss, &s);
    session_frame(&ss, dt);
    float *pot = malloc(4 * sizeof(float) * s.n);
    uint32_t alive = 0;
    assert_int_equal(volfx_water_debug_diffuse(ss.ctx, pot, s.n, NULL, 0, &alive), VFX_OK);
    double *ref = malloc(4 * sizeof(double) * s.n);
    bool *amb = malloc(s.n * sizeof(bool));
    reference_potentials(&s, h, dt, ref, amb);
    double worst[4] = {0, 0, 0, 0};
    uint32_t skipped = 0, crest = 0, over[3] = {0, 0, 0}, inside[3] = {0, 0, 0};
    const double lo[3] = {1.5, 0.3, 0.5}, hi[3] = {6.0, 1.5, 4.0};
    for (uint32_t i = 0; i < s.n; ++i) {
        if (amb[i]) { ++skipped; continue; }
        /* at or below the energy clamp's minimum nothing can be generated and the GPU does not
         * visit the neighbours: trapped air and wave crest read 0 there */
        bool slow = ref[4 * i + 2] <= 0.5;
        if (slow) assert_true(pot[4 * i] == 0 && pot[4 * i + 1] == 0 && pot[4 * i + 3] == 0);
        for (int k = slow ? 2 : 0; k < 4; ++k) {
            double e = fabs(pot[4 * i + k] - ref[4 * i + k]) / fmax(1.0, fabs(ref[4 * i + k]));
            worst[k] = fmax(worst[k], e);
        }
        crest += ref[4 * i + 1] > 0;
        for (int k = 0; k < 3; ++k) {
            over[k] += ref[4 * i + k] > hi[k];
            inside[k] += ref[4 * i + k] > lo[k] && ref[4 * i + k] < hi[k];
        }
    }
    print_message("potentials: %u particles, %u ambiguous skipped, %u on a crest; worst relative error "
                  "trapped air %.2e, wave crest %.2e, energy %.2e, new particles %.2e; %u alive after the step\n",
                  s.n, skipped, crest, worst[0], worst[1], worst[2], worst[3], alive);
    print_message("  inside / above the clamp range: trapped air %u / %u, wave crest %u / %u, energy %u / %u\n",
                  inside[0], over[0], inside[1], over[1], inside[2], over[2]);
    for (int k = 0; k < 4; ++k) assert_true(worst[k] < 2e-4);
    assert_true(skipped < s.n / 20);
    assert_true(crest > 10);
    for (int k = 0; k < 3; ++k) assert_true(inside[k] > 10 && over[k] > 0);
    assert_true(alive > 0 && stat_of(&ss, "water.diffuse_generated") >= alive);
    free(pot), free(ref), free(amb);
    session_close(&ss);
    free_host(&s);
}

/* Fluid neighbours of p within h, brute force; *ambiguous when one lies within 1e-4 h of h. */
static uint32_t fluid_neighbours(const host *s, const float *p, double h, bool *ambiguous)
{
    uint32_t n = 0;
    for (uint32_t j = 0; j < s->n; ++j) {
        double d[3] = {(double)p[0] - s->x[j], (double)p[1] - s->y[j], (double)p[2] - s->z[j]};
        double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (fabs(r - h) < 1e-4 * h) *ambiguous = true;
        n += r < h;
    }
    return n;
}

/* Classification: after 12 steps a paused frame (dt 0: nothing generated, nothing moved)
 * classifies the pool where it lies; each particle's class is the one its brute-force fluid
 * neighbour count gives (fewer than 6 spray, more than 20 bubble, else foam), every class is
 * present, and the class stats count the pool exactly. */
static void test_classification(void **state)
{
    (void)state;
    const float h = 0.2f;
    host s = make_host(12, 6, 10, h);
    session ss;
    session_open(&ss, &s);
    for (int f = 0; f < 12; ++f) session_frame(&ss, 1.0f / 60.0f);
    session_frame(&ss, 0.0f);
    uint32_t alive = 0;
    assert_int_equal(volfx_water_debug_diffuse(ss.ctx, NULL, 0, NULL, 0, &alive), VFX_OK);
    float *pool = malloc((size_t)(alive ? alive : 1) * 32);
    assert_int_equal(volfx_water_debug_diffuse(ss.ctx, NULL, 0, pool, alive, &alive), VFX_OK);
    uint32_t cls_count[3] = {0, 0, 0}, wrong = 0, skipped = 0;
    for (uint32_t i = 0; i < alive; ++i) {
        const float *e = pool + 8 * (size_t)i;
        uint32_t cls = (uint32_t)e[7];
        assert_true(cls <= 2);
        ++cls_count[cls];
        bool amb = false;
        uint32_t nb = fluid_neighbours(&s, e, h, &amb);
        uint32_t want = nb < 6 ? 0 : nb > 20 ? 2 : 1;
        if (amb) { ++skipped; continue; }
        wrong += want != cls;
    }
    print_message("classification: %u alive: %u spray, %u foam, %u bubbles; %u misclassified, %u at a neighbour's "
                  "edge skipped\n", alive, cls_count[0], cls_count[1], cls_count[2], wrong, skipped);
    assert_int_equal(wrong, 0);
    for (int k = 0; k < 3; ++k) assert_true(cls_count[k] > 0);
    assert_true(stat_of(&ss, "water.diffuse_spray") == cls_count[0]);
    assert_true(stat_of(&ss, "water.diffuse_foam") == cls_count[1]);
    assert_true(stat_of(&ss, "water.diffuse_bubbles") == cls_count[2]);
    free(pool);
    session_close(&ss);
    free_host(&s);
}

static int cmp_entry(const void *a, const void *b)
{
    const float *x = a, *y = b;
    for (int k = 7; k >= 0; --k) { /* class first, then velocity, lifetime, position */
        if (x[k] < y[k]) return -1;
        if (x[k] > y[k]) return 1;
    }
    return 0;
}

/* Runs `frames` steps of the slab and returns the pool (sorted), its size in *alive, and the
 * largest pool seen after any step in *peak. */
static float *run_pool(host *s, int frames, uint32_t *alive, uint32_t *peak, double *generated)
{
    session ss;
    session_open(&ss, s);
    *peak = 0;
    *generated = 0;
    for (int f = 0; f < frames; ++f) {
        session_frame(&ss, 1.0f / 60.0f);
        assert_int_equal(volfx_water_debug_diffuse(ss.ctx, NULL, 0, NULL, 0, alive), VFX_OK);
        *peak = *alive > *peak ? *alive : *peak;
        *generated += stat_of(&ss, "water.diffuse_generated");
        double classes = stat_of(&ss, "water.diffuse_spray") + stat_of(&ss, "water.diffuse_foam") +
                         stat_of(&ss, "water.diffuse_bubbles");
        assert_true(classes == *alive);
    }
    float *pool = malloc((size_t)(*alive ? *alive : 1) * 32);
    assert_int_equal(volfx_water_debug_diffuse(ss.ctx, NULL, 0, pool, *alive, alive), VFX_OK);
    qsort(pool, *alive, 32, cmp_entry);
    session_close(&ss);
    return pool;
}

/* Determinism and boundedness. Two runs of 20 steps give the same pool: the same size and, sorted,
 * every entry within 1e-4 h / 1e-4 v of the other run's (the neighbour grid's order within a
 * bucket comes from atomics, so sums may round differently; the random numbers hash the
 * particle and the frame). With a cap of 200 and rates of 1e4 the pool never passes the cap
 * while the potentials ask for many more. */
static void test_repeat_and_cap(void **state)
{
    (void)state;
    const float h = 0.2f;
    host s = make_host(12, 6, 10, h);
    uint32_t a_n, b_n, peak;
    double gen;
    float *a = run_pool(&s, 20, &a_n, &peak, &gen);
    float *b = run_pool(&s, 20, &b_n, &peak, &gen);
    assert_int_equal(a_n, b_n);
    double worst = 0;
    for (size_t i = 0; i < 8 * (size_t)a_n; ++i) worst = fmax(worst, fabs(a[i] - b[i]));
    print_message("repeat: %u particles after 20 steps, worst difference %.2e\n", a_n, worst);
    assert_true(a_n > 0 && worst < 1e-4 * h);
    free(a), free(b);

    s.params.diffuse_max = 200;
    s.params.rate_trapped_air = s.params.rate_wave_crest = 1e4f;
    float *c = run_pool(&s, 20, &a_n, &peak, &gen);
    print_message("cap 200: peak %u, %u at the end, %.0f asked for over 20 steps\n", peak, a_n, gen);
    assert_true(peak <= 200 && gen > 20 * 200);
    free(c);
    free_host(&s);
}

/* Out-of-range parameters are refused with VFX_ERR_INVALID_ARGUMENT and a message naming the
 * field (the message is the contract: the host's only clue). */
static void test_refused(void **state)
{
    (void)state;
    const char *names[] = {"diffuse_max", "trapped_air", "spray_below", "lifetime", "gravity"};
    for (int k = 0; k < 5; ++k) {
        host s = make_host(4, 4, 4, 0.2f);
        if (k == 0) s.params.diffuse_max = (1u << 22) + 1;
        if (k == 1) s.params.trapped_air[0] = 5, s.params.trapped_air[1] = 2;
        if (k == 2) s.params.spray_below = 30, s.params.bubble_above = 10;
        if (k == 3) s.params.lifetime = -1;
        if (k == 4) s.params.gravity[1] = NAN;
        session ss;
        session_open(&ss, &s);
        assert_int_equal(ss.api.update(ss.ctx, 0.0, 1.0f / 60.0f), VFX_ERR_INVALID_ARGUMENT);
        const char *msg = ss.api.last_error(ss.ctx, NULL);
        print_message("refused (%s): %s\n", names[k], msg);
        assert_true(test_last_error_is(&ss.api, ss.ctx, k == 1 || k == 2 ? VFX_LOG_ID_WATER_PARAM : VFX_LOG_ID_PARAM_RANGE, names[k]));
        session_close(&ss);
        free_host(&s);
    }
}

/* Bubble drag with drag x dt > 1 (drag 60, dt 0.05: 3) does not overshoot: the pull towards the
 * fluid's velocity is at most the whole difference. After 12 steps of the moving slab the fluid
 * is stopped (every velocity 0) and one step taken: every bubble then moves at the fluid's 0 plus
 * the step's buoyancy, k_b |g| dt = 2 x 9.81 x 0.05 up, within 1e-4 (float32 sums of weights
 * times 0; the buoyancy's rounding is 1e-7). An unclamped drag gives -2 v + buoyancy: the
 * bubbles before the stop moved at up to 0.2 and more, checked, so it cannot pass. */
static void test_bubble_drag_no_overshoot(void **state)
{
    (void)state;
    host s = make_host(12, 6, 10, 0.2f);
    s.params.drag = 60.0f;
    session ss;
    session_open(&ss, &s);
    for (int f = 0; f < 12; ++f) session_frame(&ss, 1.0f / 60.0f);
    uint32_t alive = 0;
    assert_int_equal(volfx_water_debug_diffuse(ss.ctx, NULL, 0, NULL, 0, &alive), VFX_OK);
    float *pool = malloc((size_t)(alive ? alive : 1) * 32);
    assert_int_equal(volfx_water_debug_diffuse(ss.ctx, NULL, 0, pool, alive, &alive), VFX_OK);
    uint32_t bubbles = 0;
    double vmax = 0;
    for (uint32_t i = 0; i < alive; ++i) {
        const float *e = pool + 8 * (size_t)i;
        if (e[7] != 2.f) continue;
        ++bubbles;
        vmax = fmax(vmax, sqrt((double)e[4] * e[4] + (double)e[5] * e[5] + (double)e[6] * e[6]));
    }
    free(pool);
    print_message("bubble drag: %u bubbles moving at up to %.3f before the fluid stops\n", bubbles, vmax);
    assert_true(bubbles > 0 && vmax > 0.2);
    memset(s.vx, 0, s.n * sizeof(float));
    memset(s.vy, 0, s.n * sizeof(float));
    memset(s.vz, 0, s.n * sizeof(float));
    const float dt = 0.05f;
    session_frame(&ss, dt);
    assert_int_equal(volfx_water_debug_diffuse(ss.ctx, NULL, 0, NULL, 0, &alive), VFX_OK);
    pool = malloc((size_t)(alive ? alive : 1) * 32);
    assert_int_equal(volfx_water_debug_diffuse(ss.ctx, NULL, 0, pool, alive, &alive), VFX_OK);
    const double up = 2.0 * 9.81 * dt;
    double worst = 0;
    uint32_t after = 0;
    for (uint32_t i = 0; i < alive; ++i) {
        const float *e = pool + 8 * (size_t)i;
        if (e[7] != 2.f) continue;
        ++after;
        worst = fmax(worst, fmax(fabs(e[4]), fmax(fabs(e[5] - up), fabs(e[6]))));
    }
    print_message("bubble drag: %u bubbles after the step, worst |v - buoyancy| %.2e\n", after, worst);
    assert_true(after > 0);
    assert_true(worst < 1e-4);
    free(pool);
    session_close(&ss);
    free_host(&s);
}

int main(void)
{
    rt_gl_context *gl = test_gl_or_skip();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_potentials_vs_reference),
        cmocka_unit_test(test_classification),
        cmocka_unit_test(test_repeat_and_cap),
        cmocka_unit_test(test_refused),
        cmocka_unit_test(test_bubble_drag_no_overshoot),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    rt_gl_context_destroy(gl);
    return rc;
}
