/* The SPH solver as the ECS system "vfx.sim.sph": writes the particle SoA columns. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "ecs/particles.h"
#include "ecs/world.h"
#include "sim/sim_system.h"

static void test_system_writes_columns(void **state)
{
    (void)state;
    rt_world *w = rt_world_create(NULL);
    assert_non_null(w);
    rt_sph_desc d = {.spacing = 0.01f, .domain_min = {0, 0, 0}, .domain_max = {0.1f, 0.2f, 0.06f}, .threads = 2};
    rt_sim_system *sys;
    char err[256];
    assert_int_equal(rt_sim_system_create(w, &d, &sys, err, sizeof err), VFX_OK);
    assert_int_equal(rt_world_system_count(w), 1);
    assert_string_equal(rt_world_system_name(w, 0), "vfx.sim.sph");
    rt_particle_components pc;
    assert_int_equal(rt_particles_register(w, &pc), VFX_OK);
    /* a 5 x 10 x 6 block, 5 cm above the floor */
    enum { N = 300 };
    float x[N], y[N], z[N];
    for (int i = 0; i < N; ++i) {
        x[i] = 0.025f + 0.01f * (float)(i % 5);
        y[i] = 0.055f + 0.01f * (float)((i / 5) % 10);
        z[i] = 0.005f + 0.01f * (float)(i / 50);
    }
    assert_int_equal(rt_particles_spawn(w, &pc, N, x, y, z, false), VFX_OK);
    rt_sph_emitter e = {.center = {0.08f, 0.18f, 0.03f}, .direction = {0, -1, 0}, .speed = 1.f,
                         .radius = 0.01f, .max_emit = 20};
    assert_int_equal(rt_sph_add_emitter(rt_sim_system_solver(sys), &e, NULL, 0), VFX_OK);
    for (int f = 0; f < 20; ++f) {
        assert_int_equal(rt_world_run_phase(w, RT_PHASE_SIMULATE, f / 60.0, 1.f / 60.f), VFX_OK);
        assert_true(rt_sim_system_report(sys)->substeps > 0);
    }
    /* the emitter's particles became entities */
    assert_int_equal(rt_world_entity_count(w), N + 20);
    rt_component terms[3] = {pc.position, pc.velocity, pc.density};
    rt_query_iter it = rt_query_begin(w, terms, 3);
    uint32_t seen = 0;
    double ymean = 0;
    while (rt_query_next(&it)) {
        const float *py = rt_query_column(&it, pc.position, 1);
        const float *px = rt_query_column(&it, pc.position, 0);
        const float *rho = rt_query_column(&it, pc.density, 0);
        const float *vy = rt_query_column(&it, pc.velocity, 1);
        for (uint32_t i = 0; i < it.rows; ++i, ++seen) {
            assert_true(isfinite(px[i]) && isfinite(py[i]) && isfinite(vy[i]));
            assert_true(py[i] > 0.f && py[i] < 0.2f && px[i] > 0.f && px[i] < 0.1f);
            /* the density column is written: from a lone drop (self term ~0.196 rho0) to a
             * compressed bottom layer */
            assert_true(rho[i] > 150.f && rho[i] < 1100.f);
            ymean += py[i];
        }
    }
    assert_int_equal(seen, N + 20);
    /* the block (centre 0.1 m) fell onto the floor in 1/3 s */
    assert_true(ymean / seen < 0.07);
    /* An unchanged world keeps the solver's state between frames: its Verlet lists survive
     * (a re-import would rebuild them at the first substep of every frame). */
    /* Short frames (1e-4 s, one substep or two): a re-import would rebuild at the first
     * substep of each; kept lists rebuild only when a particle has moved half the skin. */
    uint32_t rebuilds = 0;
    for (int f = 0; f < 20; ++f) {
        assert_int_equal(rt_world_run_phase(w, RT_PHASE_SIMULATE, 0.35 + f * 1e-4, 1e-4f), VFX_OK);
        rebuilds += rt_sim_system_report(sys)->neighbor_rebuilds;
    }
    print_message("20 frames of 1e-4 s with the world unchanged: %u rebuilds\n", rebuilds);
    assert_true(rebuilds < 10);
    /* ... and an edit by the game is seen: a particle moved 4 cm sideways lands there. The
     * solver steps the table in place and sorts its rows by grid cell, so the particle is
     * followed by entity, not by row. */
    it = rt_query_begin(w, terms, 3);
    assert_true(rt_query_next(&it));
    rt_entity edited = it.entities[0];
    float *qx = rt_query_column(&it, pc.position, 0);
    float *qy = rt_query_column(&it, pc.position, 1);
    float *qv[3] = {rt_query_column(&it, pc.velocity, 0), rt_query_column(&it, pc.velocity, 1),
                    rt_query_column(&it, pc.velocity, 2)};
    float x_new = qx[0] < 0.05f ? qx[0] + 0.04f : qx[0] - 0.04f;
    qx[0] = x_new, qy[0] = 0.15f;
    qv[0][0] = qv[1][0] = qv[2][0] = 0.f; /* at rest, in the air above the fluid */
    assert_int_equal(rt_world_run_phase(w, RT_PHASE_SIMULATE, 26 / 60.0, 1.f / 60.f), VFX_OK);
    qx = rt_world_get(w, edited, pc.position, 0);
    qy = rt_world_get(w, edited, pc.position, 1);
    assert_non_null(qx);
    assert_non_null(qy);
    /* in 1/60 s from rest it falls g t^2 / 2 = 1.4 mm and does not move sideways */
    print_message("edited particle: x %.4f (set %.4f), y %.4f (set 0.15)\n", qx[0], x_new, qy[0]);
    assert_true(fabsf(qx[0] - x_new) < 0.002f && qy[0] > 0.147f && qy[0] < 0.1495f);
    /* The particle is held once: the solver's state columns are the table's. */
    it = rt_query_begin(w, terms, 3);
    assert_true(rt_query_next(&it));
    rt_sph_columns sc = rt_sph_get_columns(rt_sim_system_solver(sys));
    assert_int_equal(sc.count, it.rows);
    assert_ptr_equal(sc.x, rt_query_column(&it, pc.position, 0));
    assert_ptr_equal(sc.vz, rt_query_column(&it, pc.velocity, 2));
    assert_ptr_equal(sc.density, rt_query_column(&it, pc.density, 0));
    /* A structural change moves the table's revision: the system binds again (the despawned
     * row is gone from the solver, the lists are rebuilt at once). */
    assert_int_equal(rt_world_despawn(w, it.entities[3]), VFX_OK);
    assert_int_equal(rt_world_run_phase(w, RT_PHASE_SIMULATE, 27 / 60.0, 1e-4f), VFX_OK);
    assert_int_equal(rt_sph_get_columns(rt_sim_system_solver(sys)).count, N + 19);
    assert_true(rt_sim_system_report(sys)->neighbor_rebuilds >= 1);
    rt_world_destroy(w);
    rt_sim_system_destroy(sys);
}

/* rt_sim_system_settle_next: the first run settles the block (counted in the stats and logged
 * through the logger, a progress line and a summary), later runs do not. */
static void count_log(void *user, vfx_log_level level, const char *message)
{
    (void)level;
    if (strstr(message, "settl"))
        ++*(int *)user;
}

static void test_system_settles_once(void **state)
{
    (void)state;
    rt_world *w = rt_world_create(NULL);
    assert_non_null(w);
    rt_sph_desc d = {.spacing = 0.01f, .domain_min = {0, 0, 0}, .domain_max = {0.1f, 0.2f, 0.06f}, .threads = 2,
                      .solver = RT_SPH_SOLVER_PBF};
    rt_sim_system *sys;
    char err[256];
    assert_int_equal(rt_sim_system_create(w, &d, &sys, err, sizeof err), VFX_OK);
    rt_particle_components pc;
    assert_int_equal(rt_particles_register(w, &pc), VFX_OK);
    enum { N = 300 }; /* a 10 x 5 x 6 block on the floor, on the solver's lattice */
    float x[N], y[N], z[N];
    for (int i = 0; i < N; ++i) {
        x[i] = 0.005f + 0.01f * (float)(i % 10);
        y[i] = 0.005f + 0.01f * (float)((i / 10) % 5);
        z[i] = 0.005f + 0.01f * (float)(i / 50);
    }
    assert_int_equal(rt_particles_spawn(w, &pc, N, x, y, z, false), VFX_OK);
    int lines = 0;
    rt_logger log = {count_log, &lines};
    rt_sph_settle_desc sd = {.max_steps = 30, .progress_every = 10};
    assert_int_equal(rt_sim_system_settle_next(sys, &sd, &log), VFX_OK);
    assert_int_equal(rt_world_run_phase(w, RT_PHASE_SIMULATE, 0.0, 1.f / 60.f), VFX_OK);
    const rt_sim_stats *st = rt_sim_system_stats(sys);
    assert_true(st->settle_steps >= 1 && st->settle_steps <= 30);
    assert_true(st->settle_cpu_s >= 0.0);
    assert_int_equal(st->steps, 1);
    /* a progress line per 10 steps, one at the end (may coincide), and the summary */
    assert_true(lines >= 2 && lines <= 5);
    print_message("settled in %u steps, %d log lines\n", st->settle_steps, lines);
    /* frame 0 ran one step of 1/60 s after the settle: the clock did not run during it */
    assert_true(fabs(rt_sph_time(rt_sim_system_solver(sys)) - 1.0 / 60.0) < 1e-6);
    assert_int_equal(rt_world_run_phase(w, RT_PHASE_SIMULATE, 1 / 60.0, 1.f / 60.f), VFX_OK);
    assert_int_equal(rt_sim_system_stats(sys)->settle_steps, 0);
    assert_int_equal(rt_sim_system_settle_next(NULL, NULL, NULL), VFX_ERR_INVALID_ARGUMENT);
    rt_world_destroy(w);
    rt_sim_system_destroy(sys);
}

/* rt_sim_system_warn_slow: a step over the bound is said once, as a warning naming the particle
 * count and the tank, from the settle's first step when there is one; under the bound nothing. */
typedef struct slow_log {
    int warnings;
    char last[512];
} slow_log;

static void slow_sink(void *user, vfx_log_level level, const char *message)
{
    slow_log *l = user;
    if (level == VFX_LOG_WARN && strstr(message, "solver step")) {
        l->warnings++;
        snprintf(l->last, sizeof l->last, "%s", message);
    }
}

static void test_system_warns_slow_step(void **state)
{
    (void)state;
    for (int settle = 0; settle < 2; ++settle)
        for (int slow = 0; slow < 2; ++slow) {
            rt_world *w = rt_world_create(NULL);
            rt_sph_desc d = {.spacing = 0.01f, .domain_min = {0, 0, 0}, .domain_max = {0.1f, 0.2f, 0.06f},
                              .threads = 1, .solver = RT_SPH_SOLVER_PBF};
            rt_sim_system *sys;
            assert_int_equal(rt_sim_system_create(w, &d, &sys, NULL, 0), VFX_OK);
            rt_particle_components pc;
            assert_int_equal(rt_particles_register(w, &pc), VFX_OK);
            enum { N = 300 };
            float x[N], y[N], z[N];
            for (int i = 0; i < N; ++i) {
                x[i] = 0.005f + 0.01f * (float)(i % 10);
                y[i] = 0.005f + 0.01f * (float)((i / 10) % 5);
                z[i] = 0.005f + 0.01f * (float)(i / 50);
            }
            assert_int_equal(rt_particles_spawn(w, &pc, N, x, y, z, false), VFX_OK);
            slow_log l = {0};
            rt_logger log = {slow_sink, &l};
            /* 1 ns: every step is slower; 1000 s: none is */
            assert_int_equal(rt_sim_system_warn_slow(sys, slow ? 1e-9 : 1e3, &log), VFX_OK);
            const double origin[3] = {10, 0, 0}; /* the tank as the scene wrote it: x + 10 */
            assert_int_equal(rt_sim_system_set_label(sys, "scene water.simulation", origin), VFX_OK);
            rt_sph_settle_desc sd = {.max_steps = 5};
            if (settle)
                assert_int_equal(rt_sim_system_settle_next(sys, &sd, &log), VFX_OK);
            for (int f = 0; f < 3; ++f)
                assert_int_equal(rt_world_run_phase(w, RT_PHASE_SIMULATE, f / 60.0, 1.f / 60.f), VFX_OK);
            assert_int_equal(l.warnings, slow);
            if (slow) {
                print_message("%s\n", l.last);
                assert_non_null(strstr(l.last, "300 particles"));
                assert_non_null(strstr(l.last, "[10, 0, 0]..[10.1, 0.2, 0.06]"));
                assert_non_null(strstr(l.last, settle ? "settling" : "took"));
            }
            rt_world_destroy(w);
            rt_sim_system_destroy(sys);
        }
    assert_int_equal(rt_sim_system_warn_slow(NULL, 1.0, NULL), VFX_ERR_INVALID_ARGUMENT);
}

static void test_system_reports_bad_column(void **state)
{
    (void)state;
    rt_world *w = rt_world_create(NULL);
    rt_sim_system *sys;
    assert_int_equal(rt_sim_system_create(w, NULL, &sys, NULL, 0), VFX_OK);
    assert_int_equal(rt_sim_system_set_label(sys, "scene water.simulation", NULL), VFX_OK);
    rt_particle_components pc;
    assert_int_equal(rt_particles_register(w, &pc), VFX_OK);
    float x[3] = {0.5f, 0.5f, 0.5f}, y[3] = {0.5f, 0.6f, 0.7f}, z[3] = {0.5f, 0.5f, 0.5f};
    assert_int_equal(rt_particles_spawn(w, &pc, 3, x, y, z, false), VFX_OK);
    /* the game writes a NaN velocity into row 1: the system refuses, naming the particle */
    rt_query_iter it = rt_query_begin(w, &pc.velocity, 1);
    assert_true(rt_query_next(&it));
    ((float *)rt_query_column(&it, pc.velocity, 2))[1] = NAN;
    assert_int_equal(rt_world_run_phase(w, RT_PHASE_SIMULATE, 0.0, 1.f / 60.f), VFX_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(rt_world_last_error(w), "particle 1"));
    /* the failure names where the fluid came from */
    assert_non_null(strstr(rt_world_last_error(w), "vfx.sim.sph (scene water.simulation): rt_sph_bind"));
    assert_non_null(strstr(rt_world_last_error(w), "vz"));
    rt_world_destroy(w);
    rt_sim_system_destroy(sys);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_system_writes_columns),
        cmocka_unit_test(test_system_reports_bad_column),
        cmocka_unit_test(test_system_settles_once),
        cmocka_unit_test(test_system_warns_slow_step),
    };
    return cmocka_run_group_tests_name("sim_system", tests, NULL, NULL);
}
