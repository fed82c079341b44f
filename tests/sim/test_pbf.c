/* Position Based Fluids (runtime/sim/sph_pbf.c): the stiff cases the WCSPH suite runs (particles
 * on one point, a column dropped onto a thin wall, speeds at the cap), bitwise determinism over
 * thread counts, and a closed tank at rest whose energy must not grow. Every case checks the
 * invariants of test_sph: finite columns, every particle inside the domain. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pbf_cases.h"
#include "sim/sph.h"

static void check_state(rt_sph *s)
{
    const rt_sph_desc *p = rt_sph_params(s);
    rt_sph_columns c = rt_sph_get_columns(s);
    for (uint32_t i = 0; i < c.count; ++i) {
        float v[7] = {c.x[i], c.y[i], c.z[i], c.vx[i], c.vy[i], c.vz[i], c.density[i]};
        for (int k = 0; k < 7; ++k)
            assert_true(isfinite(v[k]));
        for (int a = 0; a < 3; ++a) {
            float q = a == 0 ? c.x[i] : a == 1 ? c.y[i] : c.z[i];
            assert_true(q >= p->domain_min[a] && q <= p->domain_max[a]);
        }
    }
}

static void test_pbf_params(void **state)
{
    (void)state;
    rt_sph *s = pbf_make(pbf_small_box(2));
    const rt_sph_desc *p = rt_sph_params(s);
    assert_int_equal(p->solver, RT_SPH_SOLVER_PBF);
    assert_int_equal(p->pbf_iterations, 5);
    assert_true(fabsf(p->pbf_chebyshev_rho - 0.8f) < 1e-9f);
    assert_true(fabsf(p->pbf_relaxation - 0.5f) < 1e-9f);
    assert_true(fabsf(p->pbf_max_step - 1.f / 60.f) < 1e-9f);
    rt_sph_destroy(s);
    rt_sph_desc bad = pbf_small_box(2);
    bad.solver = 7;
    rt_sph *t = NULL;
    char err[256];
    assert_int_equal(rt_sph_create(&bad, &t, err, sizeof err), VFX_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "desc.solver"));
    bad.solver = RT_SPH_SOLVER_PBF;
    bad.pbf_scorr_dq = 1.5f;
    assert_int_equal(rt_sph_create(&bad, &t, err, sizeof err), VFX_ERR_INVALID_ARGUMENT);
    bad.pbf_scorr_dq = 0.f;
    bad.pbf_chebyshev_rho = 1.f; /* the weights 4 / (4 - rho^2 omega) grow without bound */
    assert_int_equal(rt_sph_create(&bad, &t, err, sizeof err), VFX_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "pbf_chebyshev_rho"));
}

/* One step of a 10 cm column compressed 2% per axis, at rest in a tank as narrow as the column,
 * under gravity (the game's case: a pool): the positions after I iterations against the
 * projection's converged positions (the same solver with 400 plain Jacobi iterations: the
 * reference is the fixed point that both methods approach). Chebyshev acceleration (rho 0.8, the
 * default, all at the default eps 0.5 D0) after 4 iterations must be nearer to it than plain
 * Jacobi after 4 (measured 0.74x; 0.79x at the earlier rho 0.7 and eps 0.2) and no farther than
 * Jacobi after 6 (0.89x; 0.99x); 0.9x and 1.1x bound them. (Not so for a compressed block floating free in zero gravity: there 4 accelerated
 * iterations overshoot, 3.3x farther than 4 plain ones at rho 0.7: docs/simulation-pbf.md.) */
static double pbf_one_step(uint32_t iters, bool chebyshev, float **ref, uint32_t *count)
{
    rt_sph_desc d = {.spacing = 0.01f, .domain_min = {-0.05f, -0.05f, -0.05f}, .domain_max = {0.05f, 0.4f, 0.05f},
                      .threads = 2, .flags = chebyshev ? 0u : RT_SPH_PBF_NO_CHEBYSHEV, .pbf_iterations = iters};
    rt_sph *s = pbf_make(d);
    enum { N = 10 };
    static float x[N * N * N], y[N * N * N], z[N * N * N];
    uint32_t n = 0;
    for (int i = 0; i < N; ++i)
        for (int j = 0; j < N; ++j)
            for (int k = 0; k < N; ++k, ++n)
                x[n] = 0.0098f * (i - 4.5f), y[n] = 0.0098f * (j - 4.5f), z[n] = 0.0098f * (k - 4.5f);
    assert_int_equal(rt_sph_add_particles(s, n, x, y, z, NULL, NULL, NULL, NULL, 0), VFX_OK);
    rt_sph_report r;
    assert_int_equal(rt_sph_step(s, 1.f / 60.f, &r, NULL, 0), VFX_OK);
    check_state(s);
    rt_sph_columns c = rt_sph_get_columns(s);
    double e2 = 0.0;
    if (!*ref) { /* the reference run: keep its positions by particle id */
        *ref = calloc(3 * (size_t)c.count, sizeof(float));
        *count = c.count;
        for (uint32_t i = 0; i < c.count; ++i)
            (*ref)[3 * c.id[i]] = c.x[i], (*ref)[3 * c.id[i] + 1] = c.y[i], (*ref)[3 * c.id[i] + 2] = c.z[i];
    } else {
        assert_int_equal(c.count, *count);
        for (uint32_t i = 0; i < c.count; ++i) {
            const float *q = *ref + 3 * c.id[i];
            e2 += pow(c.x[i] - q[0], 2) + pow(c.y[i] - q[1], 2) + pow(c.z[i] - q[2], 2);
        }
    }
    rt_sph_destroy(s);
    return sqrt(e2 / n);
}

/* The weights against Wang 2015's closed recurrence evaluated here in float64: omega_1 = 1,
 * omega_2 = 2 / (2 - rho^2), omega_k+1 = 4 / (4 - rho^2 omega_k), for the default rho 0.8 and
 * two others; tolerance 1e-6 relative (float32 rounding over 8 steps of a contraction). */
static void test_pbf_chebyshev_weights(void **state)
{
    (void)state;
    const double rhos[3] = {0.8, 0.5, 0.95};
    for (int r = 0; r < 3; ++r) {
        double rho2 = rhos[r] * rhos[r], w = 1.0;
        assert_true(rt_sph_chebyshev_weight((float)rhos[r], 0) == 1.f);
        for (uint32_t k = 1; k <= 8; ++k) {
            w = k == 1 ? 1.0 : k == 2 ? 2.0 / (2.0 - rho2) : 4.0 / (4.0 - rho2 * w);
            double got = rt_sph_chebyshev_weight((float)rhos[r], k);
            assert_true(fabs(got - w) <= 1e-6 * w);
        }
        /* the weights approach 2 / (1 + sqrt(1 - rho^2)) (the optimal SOR factor) */
        assert_true(fabs(w - 2.0 / (1.0 + sqrt(1.0 - rho2))) < 0.02);
    }
}

static void test_pbf_chebyshev_converges(void **state)
{
    (void)state;
    float *ref = NULL;
    uint32_t n = 0;
    pbf_one_step(400, false, &ref, &n);
    double j4 = pbf_one_step(4, false, &ref, &n), j6 = pbf_one_step(6, false, &ref, &n);
    double c4 = pbf_one_step(4, true, &ref, &n);
    print_message("PBF one step of a 2%%-compressed column, rms distance to the converged projection: Jacobi 4 "
                  "%.3g m, Jacobi 6 %.3g m, Chebyshev 4 %.3g m (%.2fx, %.2fx)\n", j4, j6, c4, c4 / j4, c4 / j6);
    assert_true(c4 < 0.9 * j4);
    assert_true(c4 < 1.1 * j6);
    free(ref);
}

/* 300 particles on one point: the coincident pairs are pushed apart along fixed directions, each
 * iteration moves a particle at most H/2, so the cloud spreads without a blow-up. */
static void test_pbf_all_at_one_point(void **state)
{
    (void)state;
    rt_sph *s = pbf_case_one_point(2);
    rt_sph_report r;
    assert_int_equal(rt_sph_step(s, 0.f, &r, NULL, 0), VFX_OK);
    assert_true(r.max_density_error > 10.f);
    const rt_sph_desc *p = rt_sph_params(s);
    for (int f = 0; f < 30; ++f) {
        assert_int_equal(rt_sph_step(s, 1.f / 60.f, &r, NULL, 0), VFX_OK);
        check_state(s);
        /* per step a particle moves at most iterations * H/2 by the corrections plus what it
         * had: the speed after a step is bounded by the velocity limit (the solver's cap) */
        assert_true(r.max_speed <= p->velocity_limit * 1.0001f);
    }
    print_message("PBF one point: max density error after 0.5 s %.3f, max speed %.3f\n", r.max_density_error,
                  r.max_speed);
    assert_true(r.max_density_error < 1.0f); /* spread: from > 1000% to below 100% */
    rt_sph_destroy(s);
}

/* Speeds beyond the limit are held at it (PBF has no dt to halve: the state stays valid). */
static void test_pbf_speed_cap(void **state)
{
    (void)state;
    rt_sph *s = pbf_case_speed_cap(2);
    rt_sph_report r;
    assert_int_equal(rt_sph_step(s, 1.f / 60.f, &r, NULL, 0), VFX_OK);
    check_state(s);
    assert_true(r.speed_clamped >= 1);
    assert_true(r.max_speed <= 1.0001f);
    rt_sph_destroy(s);
}

/* A column dropped onto a wall one spacing thick (a box collider): nothing passes into it. */
static void test_pbf_thin_wall(void **state)
{
    (void)state;
    rt_sph *s = pbf_case_thin_wall(2);
    rt_sph_report r;
    for (int f = 0; f < 60; ++f) {
        assert_int_equal(rt_sph_step(s, 1.f / 60.f, &r, NULL, 0), VFX_OK);
        check_state(s);
        rt_sph_columns c = rt_sph_get_columns(s);
        for (uint32_t i = 0; i < c.count; ++i)
            assert_false(fabsf(c.y[i] - 0.08f) < 0.005f); /* not inside the plate */
        assert_true(r.max_density_error < 0.5f);
    }
    rt_sph_destroy(s);
}

/* One and two threads over 3 chunks: the columns bitwise equal (fixed iteration counts and
 * chunk-ordered reductions). */
static void test_pbf_threads_bitwise(void **state)
{
    (void)state;
    rt_sph *s[2];
    for (int t = 0; t < 2; ++t) {
        rt_sph_desc d = {.spacing = 0.01f, .domain_min = {0, 0, 0}, .domain_max = {0.3f, 0.2f, 0.1f},
                          .threads = (uint32_t)(t + 1)};
        s[t] = pbf_make(d);
        float lo[3] = {0, 0, 0}, hi[3] = {0.12f, 0.2f, 0.1f};
        assert_int_equal(rt_sph_add_block(s[t], lo, hi, NULL, NULL, 0), VFX_OK); /* 2,400: 3 chunks */
        rt_sph_report r;
        for (int f = 0; f < 10; ++f)
            assert_int_equal(rt_sph_step(s[t], 1.f / 60.f, &r, NULL, 0), VFX_OK);
    }
    rt_sph_columns c[2] = {rt_sph_get_columns(s[0]), rt_sph_get_columns(s[1])};
    assert_int_equal(rt_sph_thread_count(s[1]), 2);
    assert_int_equal(c[0].count, c[1].count);
    assert_memory_equal(c[0].x, c[1].x, c[0].count * sizeof(float));
    assert_memory_equal(c[0].vy, c[1].vy, c[0].count * sizeof(float));
    assert_memory_equal(c[0].density, c[1].density, c[0].count * sizeof(float));
    rt_sph_destroy(s[0]);
    rt_sph_destroy(s[1]);
}

/* The default passes (sph_pbf_lin.c: the lambda pass stores each pair's terms, the position pass
 * reads them and skips the clamp far from the walls) against the original ones
 * (RT_SPH_PBF_RECOMPUTE): the same operations in the same order, so bitwise the same state after
 * 20 frames of a column falling past a moving box paddle (colliders, walls, clamps, Verlet walks
 * and rebuilds), and for 12 frames of particles started on one point (the coincident pairs).
 * Checked by mutation: the neighbours' multipliers left out of the stored sum, the clamp never
 * run, or the stored coincident count zeroed each fail it. */
static void test_pbf_stored_pairs_bitwise(void **state)
{
    (void)state;
    for (int c = 0; c < 2; ++c) {
        rt_sph *s[2];
        for (int m = 0; m < 2; ++m) {
            rt_sph_desc d = {.spacing = 0.01f, .domain_min = {0, 0, 0}, .domain_max = {0.2f, 0.25f, 0.06f},
                              .threads = 2, .flags = m ? RT_SPH_PBF_RECOMPUTE : 0u};
            s[m] = pbf_make(d);
            if (c == 0) {
                rt_sph_collider p = {.kind = RT_SPH_BOX, .center = {0.14f, 0.05f, 0.03f}, .half = {0.005f, 0.05f, 0.03f},
                                      .motion_axis = {1, 0, 0}, .motion_amplitude = 0.03f, .motion_frequency = 2.f};
                assert_int_equal(rt_sph_add_collider(s[m], &p, NULL, NULL, 0), VFX_OK);
                float lo[3] = {0, 0, 0}, hi[3] = {0.08f, 0.2f, 0.06f};
                assert_int_equal(rt_sph_add_block(s[m], lo, hi, NULL, NULL, 0), VFX_OK);
            } else {
                float x[64], y[64], z[64];
                for (int k = 0; k < 64; ++k)
                    x[k] = 0.1f, y[k] = 0.05f, z[k] = 0.03f;
                assert_int_equal(rt_sph_add_particles(s[m], 64, x, y, z, NULL, NULL, NULL, NULL, 0), VFX_OK);
            }
            rt_sph_report r;
            for (int f = 0; f < (c ? 12 : 20); ++f)
                assert_int_equal(rt_sph_step(s[m], 1.f / 60.f, &r, NULL, 0), VFX_OK);
            check_state(s[m]);
        }
        rt_sph_columns k[2] = {rt_sph_get_columns(s[0]), rt_sph_get_columns(s[1])};
        assert_int_equal(k[0].count, k[1].count);
        assert_memory_equal(k[0].id, k[1].id, k[0].count * sizeof(uint32_t));
        assert_memory_equal(k[0].x, k[1].x, k[0].count * sizeof(float));
        assert_memory_equal(k[0].y, k[1].y, k[0].count * sizeof(float));
        assert_memory_equal(k[0].z, k[1].z, k[0].count * sizeof(float));
        assert_memory_equal(k[0].vx, k[1].vx, k[0].count * sizeof(float));
        assert_memory_equal(k[0].density, k[1].density, k[0].count * sizeof(float));
        rt_sph_destroy(s[0]);
        rt_sph_destroy(s[1]);
    }
}

/* A paddle whose amplitude ramps in (rt_sph_collider.motion_ramp_s): its face is where the
 * float64 formula puts it, A u^2 (3 - 2u) sin(2 pi f t) with u = t / ramp, at t = 1/60 s (where
 * the unramped paddle has already moved 1 cm: it started at its peak speed), mid-ramp and
 * after the ramp (where both agree). Tolerance 2e-6 m: float32 positions of a box ~0.5 m from
 * the origin (6e-8 m per ulp) through a distance evaluation. */
static void test_pbf_paddle_ramp(void **state)
{
    (void)state;
    const double A = 0.1, f = 1.0, ramp = 1.0, pi = 3.14159265358979323846;
    const double times[3] = {1.0 / 60.0, 0.25, 1.5};
    for (int m = 0; m < 2; ++m) {
        rt_sph_desc d = {.spacing = 0.02f, .domain_min = {0, 0, 0}, .domain_max = {1.f, 0.5f, 0.2f}, .threads = 1};
        rt_sph *s = pbf_make(d);
        rt_sph_collider c = {.kind = RT_SPH_BOX, .center = {0.3f, 0.25f, 0.1f}, .half = {0.01f, 0.25f, 0.1f},
                              .motion_axis = {1, 0, 0}, .motion_amplitude = (float)A, .motion_frequency = (float)f,
                              .motion_ramp_s = m ? 0.f : (float)ramp};
        assert_int_equal(rt_sph_add_collider(s, &c, NULL, NULL, 0), VFX_OK);
        float x[1] = {0.9f}, y[1] = {0.01f}, z[1] = {0.1f}; /* one particle, far from the paddle */
        assert_int_equal(rt_sph_add_particles(s, 1, x, y, z, NULL, NULL, NULL, NULL, 0), VFX_OK);
        double t = 0.0;
        for (int k = 0; k < 3; ++k) {
            rt_sph_report r;
            assert_int_equal(rt_sph_step(s, (float)(times[k] - t), &r, NULL, 0), VFX_OK);
            t = rt_sph_time(s);
            double u = t < ramp ? t / ramp : 1.0, rr = m ? 1.0 : u * u * (3.0 - 2.0 * u);
            double face = 0.3 + A * rr * sin(2.0 * pi * f * t) + 0.01; /* the +x face */
            const float p[3] = {0.8f, 0.25f, 0.1f};
            double dist = rt_sph_collider_distance(s, 0, p);
            assert_true(fabs(dist - (0.8 - face)) <= 2e-6);
            if (k == 0 && !m)
                assert_true(fabs(face - 0.31) < 1e-4); /* ramped: still at rest to 0.1 mm */
            if (k == 0 && m)
                assert_true(face - 0.31 > 0.01);      /* unramped: 1 cm in the first frame */
        }
        rt_sph_destroy(s);
    }
    rt_sph_collider bad = {.kind = RT_SPH_BOX, .half = {1, 1, 1}, .motion_ramp_s = -1.f};
    rt_sph *s = pbf_make(pbf_small_box(2));
    assert_int_equal(rt_sph_add_collider(s, &bad, NULL, NULL, 0), VFX_ERR_INVALID_ARGUMENT);
    rt_sph_destroy(s);
}

/* The paddle's velocity mid-ramp against a central difference of its own positions (t = 0.25 s
 * of a 1 s ramp, h = 1 ms): the walls push with that velocity, so a wrong derivative of the
 * ramp (the ramp's own term d/dt[A u^2 (3 - 2u)] sin(wt) dropped: 0.11 m/s here) moves the
 * fluid wrongly while the positions stay right. Tolerance 2e-3 m/s: the difference's
 * truncation A (2 pi f)^3 h^2 / 6 ~ 4e-6 m/s plus float32 positions near 0.4 m (3e-8 m per
 * ulp over 2 ms: 1.5e-5 m/s), far below the dropped term. Also the settle: it holds the clock,
 * so a block settled beside a ramped paddle ends bitwise where it ends beside a still one. */
static void test_pbf_paddle_velocity_and_settle(void **state)
{
    (void)state;
    const double A = 0.1, f = 1.0, pi = 3.14159265358979323846;
    rt_sph_desc d = {.spacing = 0.02f, .domain_min = {0, 0, 0}, .domain_max = {1.f, 0.5f, 0.2f}, .threads = 1};
    rt_sph *s = pbf_make(d);
    rt_sph_collider c = {.kind = RT_SPH_BOX, .center = {0.3f, 0.25f, 0.1f}, .half = {0.01f, 0.25f, 0.1f},
                          .motion_axis = {1, 0, 0}, .motion_amplitude = (float)A, .motion_frequency = (float)f,
                          .motion_ramp_s = 1.f};
    assert_int_equal(rt_sph_add_collider(s, &c, NULL, NULL, 0), VFX_OK);
    float x[1] = {0.9f}, y[1] = {0.01f}, z[1] = {0.1f};
    assert_int_equal(rt_sph_add_particles(s, 1, x, y, z, NULL, NULL, NULL, NULL, 0), VFX_OK);
    rt_sph_report r;
    const float h = 1e-3f;
    assert_int_equal(rt_sph_step(s, 0.25f - h, &r, NULL, 0), VFX_OK);
    float p0[3], v0[3], p1[3], v1[3], p2[3], v2[3];
    assert_int_equal(rt_sph_collider_motion(s, 0, p0, v0), VFX_OK);
    assert_int_equal(rt_sph_step(s, h, &r, NULL, 0), VFX_OK);
    assert_int_equal(rt_sph_collider_motion(s, 0, p1, v1), VFX_OK);
    double t1 = rt_sph_time(s);
    assert_int_equal(rt_sph_step(s, h, &r, NULL, 0), VFX_OK);
    assert_int_equal(rt_sph_collider_motion(s, 0, p2, v2), VFX_OK);
    double fd = ((double)p2[0] - p0[0]) / (2.0 * h);
    /* the float64 derivative of A u^2 (3 - 2u) sin(2 pi f t), u = t / 1 s */
    double u = t1, w = 2.0 * pi * f;
    double ref = A * (6.0 * u * (1.0 - u) * sin(w * t1) + u * u * (3.0 - 2.0 * u) * w * cos(w * t1));
    print_message("paddle at t = %.4f s: velocity %.5f m/s, central difference %.5f, float64 %.5f\n", t1, v1[0], fd,
                  ref);
    assert_true(fabs(v1[0] - fd) <= 2e-3);
    assert_true(fabs(v1[0] - ref) <= 1e-4);
    assert_true(v1[1] == 0.f && v1[2] == 0.f);
    assert_int_equal(rt_sph_collider_motion(s, 1, p0, v0), VFX_ERR_INVALID_ARGUMENT);
    rt_sph_destroy(s);
    /* settled beside a ramped paddle (amplitude 0.1, 1 s ramp) and beside a still one (0) */
    rt_sph_columns col[2];
    rt_sph *t[2];
    for (int k = 0; k < 2; ++k) {
        rt_sph_desc dd = {.spacing = 0.02f, .domain_min = {0, 0, 0}, .domain_max = {0.6f, 0.4f, 0.3f}, .threads = 1};
        t[k] = pbf_make(dd);
        rt_sph_collider pc = {.kind = RT_SPH_BOX, .center = {0.15f, 0.2f, 0.15f}, .half = {0.01f, 0.2f, 0.15f},
                               .motion_axis = {1, 0, 0}, .motion_amplitude = k ? 0.f : 0.1f, .motion_frequency = 0.5f,
                               .motion_ramp_s = 2.f};
        assert_int_equal(rt_sph_add_collider(t[k], &pc, NULL, NULL, 0), VFX_OK);
        float lo[3] = {0.2f, 0, 0}, hi[3] = {0.6f, 0.12f, 0.3f};
        assert_int_equal(rt_sph_add_block(t[k], lo, hi, NULL, NULL, 0), VFX_OK);
        rt_sph_settle_desc sd = {.max_steps = 30, .speed_tol = 1e-9f};
        rt_sph_settle_report sr;
        assert_int_equal(rt_sph_settle(t[k], &sd, &sr, NULL, 0), VFX_OK);
        assert_int_equal(sr.steps, 30);
        col[k] = rt_sph_get_columns(t[k]);
    }
    assert_int_equal(col[0].count, col[1].count);
    for (uint32_t i = 0; i < col[0].count; ++i) {
        assert_int_equal(col[0].id[i], col[1].id[i]);
        assert_true(col[0].x[i] == col[1].x[i] && col[0].y[i] == col[1].y[i] && col[0].z[i] == col[1].z[i]);
    }
    rt_sph_destroy(t[0]);
    rt_sph_destroy(t[1]);
}

/* A closed tank at rest (no paddle): total energy (kinetic + gravity; PBF has no internal energy)
 * must not grow by more than 1% of the initial energy between sampled points. */
static void test_pbf_closed_tank_energy(void **state)
{
    (void)state;
    rt_sph *s = pbf_case_pool(2);
    rt_sph_report r;
    assert_int_equal(rt_sph_step(s, 0.f, &r, NULL, 0), VFX_OK);
    double e0 = r.kinetic_energy + r.potential_energy, prev = e0, vmax = 0;
    for (int f = 0; f < 120; ++f) {
        assert_int_equal(rt_sph_step(s, 1.f / 60.f, &r, NULL, 0), VFX_OK);
        check_state(s);
        vmax = r.max_speed > vmax ? r.max_speed : vmax;
        if (f % 10 == 9) {
            double e = r.kinetic_energy + r.potential_energy;
            assert_true(e <= prev + 0.01 * fabs(e0));
            prev = e;
        }
    }
    print_message("PBF closed tank: energy %.4g -> %.4g J, max speed %.3f m/s, mean compression %.4f\n", e0, prev,
                  vmax, r.mean_density_error);
    rt_sph_destroy(s);
}

/* Issue 22's start at rest: the closed tank of the test above (6 layers, as the default pool)
 * started from the calibrated lattice sinks into PBF's own hydrostatic state (~1.3% mean
 * compression here) at up to 0.44 m/s over frames 2-60; rt_sph_settle does that sinking before
 * frame 0. Measured (AMD EPYC, 2026-12-03, 5 Chebyshev iterations): 0.44 m/s without, 0.080 m/s
 * after 120 settle steps. The 0.05 m/s is not met: what is left is the
 * wall layers pressed into the walls (docs/simulation.md "Start at rest"). The bounds sit between
 * the two with a 2x margin each way (the settled run is chaotic at the 0.01 m/s level): the
 * unsettled start must exceed 0.3 m/s (the problem is reproduced), the settled one stay below
 * 0.15 m/s. The settle also leaves the clock and the velocities at zero. */
static void test_pbf_settled_tank_at_rest(void **state)
{
    (void)state;
    float vmax[2] = {0.f, 0.f};
    for (int k = 0; k < 2; ++k) {
        rt_sph *s = pbf_case_pool(2);
        if (k) {
            rt_sph_settle_desc sd = {.max_steps = 120};
            rt_sph_settle_report sr;
            char err[256];
            assert_int_equal(rt_sph_settle(s, &sd, &sr, err, sizeof err), VFX_OK);
            assert_true(sr.steps >= 1 && sr.steps <= 120);
            assert_true(sr.max_speed_first > sr.max_speed_last);
            assert_true(rt_sph_time(s) == 0.0);
            rt_sph_columns c = rt_sph_get_columns(s);
            for (uint32_t i = 0; i < c.count; ++i)
                assert_true(c.vx[i] == 0.f && c.vy[i] == 0.f && c.vz[i] == 0.f);
            print_message("settle: %u steps, max speed %.3f -> %.3f m/s, compression %.4f, %.2f CPU s\n", sr.steps,
                          sr.max_speed_first, sr.max_speed_last, sr.compression, sr.cpu_s);
            /* the settled compression: 1.33% with the Chebyshev acceleration as written; 1.67-2.49%
             * with its history buffers swapped (plain over-relaxation) or omega dropped from the
             * update (measured by planting each): 1.5% lies between */
            assert_true(sr.compression <= 0.015f);
        }
        rt_sph_report r;
        for (int f = 0; f < 60; ++f) {
            assert_int_equal(rt_sph_step(s, 1.f / 60.f, &r, NULL, 0), VFX_OK);
            if (f >= 1)
                vmax[k] = r.max_speed > vmax[k] ? r.max_speed : vmax[k];
        }
        check_state(s);
        rt_sph_destroy(s);
    }
    print_message("resting tank, max speed over frames 2-60: %.3f m/s from the lattice, %.3f settled\n", vmax[0],
                  vmax[1]);
    assert_true(vmax[0] > 0.3f);
    assert_true(vmax[1] < 0.15f);
    /* bad arguments are refused by name */
    rt_sph *s = pbf_make(pbf_small_box(2));
    char err[256];
    rt_sph_settle_desc bad = {.damping = 1.5f};
    assert_int_equal(rt_sph_settle(s, &bad, NULL, err, sizeof err), VFX_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "damping"));
    assert_int_equal(rt_sph_settle(NULL, NULL, NULL, err, sizeof err), VFX_ERR_INVALID_ARGUMENT);
    assert_int_equal(rt_sph_settle(s, NULL, NULL, err, sizeof err), VFX_OK); /* no particles: nothing to do */
    /* quasi-static: the velocities are zero after every step, so the report's speeds are each
     * step's own; 3 particles resting on the floor */
    float x[3] = {0.02f, 0.05f, 0.08f}, y[3] = {0.005f, 0.005f, 0.005f}, z[3] = {0.03f, 0.03f, 0.03f};
    assert_int_equal(rt_sph_add_particles(s, 3, x, y, z, NULL, NULL, NULL, NULL, 0), VFX_OK);
    rt_sph_settle_desc qs = {.max_steps = 5, .quasi_static = true};
    rt_sph_settle_report qr;
    assert_int_equal(rt_sph_settle(s, &qs, &qr, err, sizeof err), VFX_OK);
    assert_true(qr.steps >= 1 && qr.steps <= 5);
    rt_sph_columns c = rt_sph_get_columns(s);
    for (uint32_t i = 0; i < c.count; ++i)
        assert_true(c.vx[i] == 0.f && c.vy[i] == 0.f && c.vz[i] == 0.f && c.y[i] < 0.01f);
    rt_sph_destroy(s);
}

/* The pool of the test above, settled (at the 1/60 s the game settles with), then stepped as the
 * game's clock does for water.simulation.dt = h: 4 steps of h per frame, 30 frames. For every h in
 * the documented (0, 0.1] the pool must stay at rest: max speed <= 0.5 m/s (the bound;
 * the settled pool moves at ~0.06 m/s at 1/60 s). Before the mixing eps followed the step
 * (sph_pbf.c, pbf_step_eps) a step of 1e-5 s released the pool's 1.3% rest compression at once,
 * 2 mm per particle in 1e-5 s: 186 m/s in the first frame; 1e-3 s reached 1.9 m/s. The mean
 * compression must also stay within 0.3 points of the settled state's (it jumped to 0). */
static void test_pbf_resting_pool_every_dt(void **state)
{
    (void)state;
    const float hs[4] = {1e-5f, 1e-3f, 1.f / 60.f, 0.1f};
    for (int k = 0; k < 4; ++k) {
        rt_sph *s = pbf_case_pool(2);
        rt_sph_settle_desc sd = {.max_steps = 120};
        rt_sph_settle_report sr;
        assert_int_equal(rt_sph_settle(s, &sd, &sr, NULL, 0), VFX_OK);
        float vmax = 0.f, c = 0.f;
        rt_sph_report r;
        for (int f = 0; f < 30; ++f)
            for (int q = 0; q < 4; ++q) {
                assert_int_equal(rt_sph_step(s, hs[k], &r, NULL, 0), VFX_OK);
                vmax = r.max_speed > vmax ? r.max_speed : vmax;
                c = r.mean_density_error;
            }
        check_state(s);
        print_message("resting pool, steps of %g s: max speed %.4f m/s over 30 frames, compression %.2f%% "
                      "(settled %.2f%%)\n", (double)hs[k], vmax, 100.0 * c, 100.0 * sr.compression);
        assert_true(vmax <= 0.5f);
        assert_true(fabsf(c - sr.compression) <= 0.003f);
        rt_sph_destroy(s);
    }
}

/* A free block in zero gravity with 5 mm/s of noise (far from every wall): PBF's projection and
 * XSPH can only take kinetic energy away, so it must not grow over 60 frames; the reference is
 * the initial kinetic energy itself (float64 sum here). With the artificial pressure s_corr on
 * (k = 0.001, the old default) it grew 2.5x in 40 frames and 9x in 2 s
 * (docs/simulation-pbf.md): the check fails then. Both runs are measured; the slack 1e-3 of the
 * initial energy is far below that growth and above the float32 rounding of the energy sums. */
static void test_pbf_free_block_energy(void **state)
{
    (void)state;
    for (int k = 0; k < 2; ++k) {
        rt_sph_desc d = {.spacing = 0.05f, .domain_min = {-1, -1, -1}, .domain_max = {1, 1, 1}, .threads = 2,
                          .flags = RT_SPH_NO_GRAVITY, .pbf_scorr_k = k ? 0.001f : 0.f};
        rt_sph *s = pbf_make(d);
        float lo[3] = {-0.3f, -0.3f, -0.3f}, hi[3] = {0.3f, 0.3f, 0.3f};
        assert_int_equal(rt_sph_add_block(s, lo, hi, NULL, NULL, 0), VFX_OK);
        rt_sph_columns c = rt_sph_get_columns(s);
        double ke0 = 0.0, m = rt_sph_particle_mass(s);
        uint32_t q = 12345u; /* a fixed LCG: the same noise on every platform */
        for (uint32_t i = 0; i < c.count; ++i) {
            float *v[3] = {c.vx, c.vy, c.vz};
            for (int a = 0; a < 3; ++a) {
                q = q * 1664525u + 1013904223u;
                v[a][i] = 0.01f * ((float)(q >> 8) / 16777216.f - 0.5f);
                ke0 += 0.5 * m * (double)v[a][i] * v[a][i];
            }
        }
        rt_sph_report r;
        for (int f = 0; f < 60; ++f)
            assert_int_equal(rt_sph_step(s, 1.f / 60.f, &r, NULL, 0), VFX_OK);
        check_state(s);
        print_message("PBF free block, s_corr k = %g: kinetic energy %.4g -> %.4g J\n", (double)d.pbf_scorr_k, ke0,
                      r.kinetic_energy);
        if (k == 0)
            assert_true(r.kinetic_energy <= ke0 * (1.0 + 1e-3));
        else
            assert_true(r.kinetic_energy > ke0); /* the measured cause, still there */
        rt_sph_destroy(s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pbf_params),       cmocka_unit_test(test_pbf_all_at_one_point),
        cmocka_unit_test(test_pbf_speed_cap),    cmocka_unit_test(test_pbf_thin_wall),
        cmocka_unit_test(test_pbf_threads_bitwise), cmocka_unit_test(test_pbf_closed_tank_energy),
        cmocka_unit_test(test_pbf_free_block_energy), cmocka_unit_test(test_pbf_stored_pairs_bitwise),
        cmocka_unit_test(test_pbf_paddle_ramp),  cmocka_unit_test(test_pbf_chebyshev_converges),
        cmocka_unit_test(test_pbf_chebyshev_weights), cmocka_unit_test(test_pbf_paddle_velocity_and_settle),
        cmocka_unit_test(test_pbf_settled_tank_at_rest), cmocka_unit_test(test_pbf_resting_pool_every_dt),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
