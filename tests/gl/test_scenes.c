/* Every sample scene (sample_game/scenes/NAME.json) and the built-in default load into the real
 * host and render frames; effects a scene lacks allocate nothing. Small size for llvmpipe. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "demo_scene.h"
#include "debug.h"
#include "test_util.h"

static void run_scene(const char *file, bool expect_water, bool expect_beams, bool expect_volume)
{
    char path[1024];
    const char *root = getenv("VFX_SOURCE_ROOT");
    if (file)
        snprintf(path, sizeof path, "%s/sample_game/scenes/%s", root ? root : ".", file);
    test_log log = {0};
    game_app_desc d = {.mode = RT_GL_HEADLESS, .width = 64, .height = 36, .logger = {test_log_fn, &log}};
    game_app *app;
    if (game_app_create(&d, &app) != VFX_OK)
        exit(VFX_TEST_SKIP);
    game_demo demo;
    assert_int_equal(game_demo_load(app, &demo, file ? path : NULL, 0), VFX_OK);
    for (int f = 0; f < 2; ++f) {
        game_demo_animate(app, &demo, 1.f / 60.f);
        assert_int_equal(game_app_frame(app, 1.f / 60.f), VFX_OK);
    }
    assert_true((app->ctx->effect_state[VFX_EFFECT_WATER] != NULL) == expect_water);
    assert_true((app->ctx->effect_state[VFX_EFFECT_BEAMS] != NULL) == expect_beams);
    assert_true((app->ctx->effect_state[VFX_EFFECT_VOLUME] != NULL) == expect_volume);
    assert_int_equal(log.errors, 0);
    game_demo_free(app, &demo);
    game_app_destroy(app);
}

static void test_default(void **s) { (void)s; run_scene(NULL, true, true, true); }
static void test_default_file(void **s) { (void)s; run_scene("default.json", true, true, true); }
static void test_beams_only(void **s) { (void)s; run_scene("beams-only.json", false, true, false); }
static void test_water_only(void **s) { (void)s; run_scene("water-only.json", true, false, false); }
static void test_beam_over_water(void **s) { (void)s; run_scene("beam-over-water.json", true, true, false); }
static void test_empty(void **s) { (void)s; run_scene("empty.json", false, false, false); }
static void test_long_run(void **s) { (void)s; run_scene("long-run.json", true, true, true); }

static void test_bad_scene_refused(void **state)
{
    (void)state;
    test_log log = {0};
    game_app_desc d = {.mode = RT_GL_HEADLESS, .width = 32, .height = 32, .logger = {test_log_fn, &log}};
    game_app *app;
    if (game_app_create(&d, &app) != VFX_OK)
        exit(VFX_TEST_SKIP);
    game_demo demo;
    assert_int_equal(game_demo_load(app, &demo, "/no/such/scene.json", 0), VFX_ERR_IO);
    assert_non_null(strstr(log.last, "/no/such/scene.json"));
    game_demo_free(app, &demo);
    game_app_destroy(app);
}

/* The game's --gpu-particles and --effects-layer: the default scene's particles reach the water
 * from the game's GL buffer (every one of them, none outside the box it used) and the effects
 * through the layer the game composites, with no error. */
static void test_gpu_particles_and_layer(void **state)
{
    (void)state;
    test_log log = {0};
    game_app_desc d = {.mode = RT_GL_HEADLESS, .width = 64, .height = 36, .logger = {test_log_fn, &log},
                       .gpu_particles = true, .effects_layer = true};
    game_app *app;
    if (game_app_create(&d, &app) != VFX_OK)
        exit(VFX_TEST_SKIP);
    game_demo demo;
    assert_int_equal(game_demo_load(app, &demo, NULL, 0), VFX_OK);
    for (int f = 0; f < 3; ++f) {
        game_demo_animate(app, &demo, 1.f / 60.f);
        assert_int_equal(game_app_frame(app, 1.f / 60.f), VFX_OK);
    }
    double gpu = -1, total = -2, outside = -1;
    for (uint32_t k = 0; k < app->ctx->last_stats.count; ++k) {
        const vfx_stat *e = &app->ctx->last_stats.entries[k];
        if (!strcmp(e->name, "water.gpu_particles")) gpu = e->value;
        if (!strcmp(e->name, "water.particles")) total = e->value;
        if (!strcmp(e->name, "water.gpu_box_outside")) outside = e->value;
    }
    assert_true(total > 0 && gpu == total);
    assert_true(outside == 0);
    assert_int_equal(log.errors, 0);
    game_demo_free(app, &demo);
    game_app_destroy(app);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_default), cmocka_unit_test(test_default_file),
        cmocka_unit_test(test_beams_only), cmocka_unit_test(test_water_only), cmocka_unit_test(test_beam_over_water),
        cmocka_unit_test(test_empty),
        cmocka_unit_test(test_long_run), cmocka_unit_test(test_bad_scene_refused),
        cmocka_unit_test(test_gpu_particles_and_layer),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
