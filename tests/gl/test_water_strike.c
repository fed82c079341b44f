/* A beam striking the water through the whole sample game (docs/simulation.md "Impacts"): the
 * plugin finds the beam's impact on the water and reports it (vfx_impact_events chained into
 * get_lights), the scene's fluid takes the impulse there (water.simulation.impact_strength), the
 * particles near the hit move away from it, spray rises at the hit within a few frames (thrown by
 * the plugin where the impact falls on the water: water.foam.impacts) and the largest speed stays
 * bounded. The same scene with impact_strength 0 is the control: the beam and its light are the
 * same, the fluid is not pushed (the spray still rises); with water.foam.impacts off, none does. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "demo_scene.h"
#include "debug.h"
#include "sim/sim_system.h"
#include "test_util.h"

#define STRENGTH 4.0
#define RADIUS 0.2

/* A 1.2 x 0.6 x 1.2 m tank, 3,000 particles, a beam from above whose head is under the surface
 * at the centre. */
static const char *scene_text(double strength, bool spray)
{
    static char buf[4096];
    snprintf(buf, sizeof buf,
             "{\"version\": 1, \"name\": \"strike\","
             "\"camera\": {\"eye\": [1.6, 1.3, 1.8], \"target\": [0, 0.1, 0], \"up\": [0, 1, 0], \"fov_y_deg\": 55,"
             "  \"width\": 96, \"height\": 64, \"near\": 0.05, \"far\": 50},"
             "\"meshes\": [{\"box\": {\"min\": [-5, -0.2, -5], \"max\": [5, 0, 5]}, \"color\": [0.5, 0.5, 0.5]}],"
             "\"water\": {\"source\": \"simulation\", \"simulation\": {"
             "  \"tank\": {\"min\": [-0.6, 0, -0.6], \"max\": [0.6, 0.8, 0.6]},"
             "  \"fluid\": {\"min\": [-0.58, 0.01, -0.58], \"max\": [0.58, 0.2, 0.58]},"
             "  \"particle_count\": 3000, \"gravity\": [0, -9.81, 0], \"dt\": 0.016666667, \"solver\": \"pbf\","
             "  \"settle_steps\": 60, \"impact_strength\": %g, \"impact_radius\": %g},"
             "  \"quality\": {\"method\": \"tile\"}, \"foam\": {\"impacts\": \"%s\"}},"
             "\"beams\": [{\"head\": [0.0, 0.1, 0.0], \"dir\": [0.3, 1, 0.2], \"length\": 1.5, \"radius\": 0.08,"
             "  \"a\": 0.6, \"b\": 0.4, \"eps\": 0.02, \"color\": [0.7, 0.6, 1.0, 1]}]}",
             strength, RADIUS, spray ? "on" : "off");
    return buf;
}

typedef struct run_result {
    int first_event;       /* frame the host first got an impact event on the water (-1: never) */
    int first_spray;       /* frame water.diffuse_spray first rose above the control's level */
    double spray_max;      /* largest water.diffuse_spray over the run */
    double away_mean;      /* mean speed away from the hit, the frame after the first push, of the
                            * particles then within RADIUS / 2 of it */
    float vmax;            /* largest sim.max_speed over the run */
} run_result;

static double stat(game_app *app, const char *name)
{
    vfx_stats st = {.type = VFX_TYPE_STATS};
    if (app->api->get_stats(app->ctx, &st) != VFX_OK)
        return NAN;
    for (uint32_t k = 0; k < st.count; ++k)
        if (!strcmp(st.entries[k].name, name))
            return st.entries[k].value;
    return 0;
}

static run_result run(double strength, bool spray, int frames)
{
    char path[] = "/tmp/volfx-strike-XXXXXX.json";
    int fd = mkstemps(path, 5);
    assert_true(fd >= 0);
    FILE *f = fdopen(fd, "w");
    fputs(scene_text(strength, spray), f);
    fclose(f);
    test_log log = {0};
    game_app_desc d = {.mode = RT_GL_HEADLESS, .width = 96, .height = 64, .logger = {test_log_fn, &log}};
    game_app *app;
    if (game_app_create(&d, &app) != VFX_OK)
        exit(VFX_TEST_SKIP);
    game_demo demo;
    vfx_result lr = game_demo_load(app, &demo, path, 0);
    if (lr)
        printf("load: %s\n", log.last);
    assert_int_equal(lr, VFX_OK);
    remove(path);
    run_result res = {-1, -1, 0, 0, 0};
    float hit[3] = {0};
    uint32_t *near = NULL;
    for (int fr = 0; fr < frames; ++fr) {
        bool pushed_now = demo.impacts_applied > 0 && res.first_event < 0;
        if (pushed_now) {
            res.first_event = fr;
            memcpy(hit, demo.last_impact, sizeof hit);
            /* the particles near the hit now (by id: steps reorder the rows) */
            rt_sph_columns c = rt_sph_get_columns(rt_sim_system_solver(demo.spawned.sim));
            near = calloc(c.count + 1, sizeof *near);
            for (uint32_t i = 0; i < c.count; ++i) {
                float o[3] = {c.x[i] - hit[0], c.y[i] - hit[1], c.z[i] - hit[2]};
                if (sqrtf(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]) < 0.5f * RADIUS && c.id[i] <= c.count)
                    near[c.id[i]] = 1;
            }
        }
        game_demo_animate(app, &demo, 1.f / 60.f);
        assert_int_equal(game_app_frame(app, 1.f / 60.f), VFX_OK);
        if (pushed_now) {
            rt_sph_columns c = rt_sph_get_columns(rt_sim_system_solver(demo.spawned.sim));
            double sum = 0;
            uint32_t n = 0;
            for (uint32_t i = 0; i < c.count; ++i) {
                if (c.id[i] > c.count || !near[c.id[i]])
                    continue;
                float o[3] = {c.x[i] - hit[0], c.y[i] - hit[1], c.z[i] - hit[2]};
                float r = sqrtf(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
                sum += r > 0 ? (c.vx[i] * o[0] + c.vy[i] * o[1] + c.vz[i] * o[2]) / r : 0;
                n++;
            }
            res.away_mean = n ? sum / n : 0;
            printf("  first push at frame %d, hit (%.3f, %.3f, %.3f): %u particles near it, mean speed away %.3f m/s\n",
                   fr, hit[0], hit[1], hit[2], n, res.away_mean);
        }
        double spray = stat(app, "water.diffuse_spray");
        if (getenv("STRIKE_TRACE"))
            printf("frame %d spray %g generated %g foam %g\n", fr, spray, stat(app, "water.diffuse_generated"),
                   stat(app, "water.diffuse_foam"));
        res.spray_max = fmax(res.spray_max, spray);
        res.vmax = fmaxf(res.vmax, rt_sim_system_stats(demo.spawned.sim)->max_speed);
        if (res.first_event >= 0 && res.first_spray < 0 && spray > 0)
            res.first_spray = fr;
    }
    free(near);
    assert_int_equal(log.errors, 0);
    game_demo_free(app, &demo);
    game_app_destroy(app);
    return res;
}

static void test_strike_splashes(void **state)
{
    (void)state;
    run_result ctl = run(0.0, true, 16), hit = run(STRENGTH, true, 16), dry = run(STRENGTH, false, 16);
    printf("control (impact_strength 0): spray from frame %d (at most %g), max speed %.3f m/s\n", ctl.first_spray,
           ctl.spray_max, ctl.vmax);
    printf("struck (impact_strength %g): event at frame %d, spray from frame %d (at most %g), max speed %.3f m/s\n",
           STRENGTH, hit.first_event, hit.first_spray, hit.spray_max, hit.vmax);
    printf("struck, water.foam.impacts off: spray at most %g\n", dry.spray_max);
    assert_true(hit.first_event >= 0 && hit.first_event <= 5); /* read back 1-3 frames late */
    assert_true(hit.away_mean > 0.1 * STRENGTH);               /* the particles near the hit move away */
    /* spray rises at the hit within a few frames of the first event (the plugin throws it where
     * the impact falls on the water, water.foam.impacts), with or without the fluid's push; the
     * pool alone makes none in these 16 frames (impacts off: the push's own diffuse particles are
     * foam on this small pool) */
    assert_true(hit.first_spray >= 0 && hit.first_spray <= hit.first_event + 3);
    assert_true(hit.spray_max >= 10);
    assert_true(ctl.spray_max >= 10);
    assert_true(dry.spray_max < 0.2 * hit.spray_max);
    /* bounded: the push's speed plus what a fall through the tank's height gives, sqrt(2 g 0.8) = 4 */
    assert_true(hit.vmax <= STRENGTH + 4.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_strike_splashes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
