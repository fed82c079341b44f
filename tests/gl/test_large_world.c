/* Large worlds: one scene (a water box, two beams, a generated volume) written at the origin and
 * again with every coordinate shifted by 1e4 and by 1e5 in each axis, with "origin": "camera".
 * The scene is read in double and stored relative to its origin, the game hands the origin to the
 * plugin in frame view 2, and the shifted renders must match the one at the origin: beams H to
 * 1e-5 relative, water with no hole and a p99 distance difference <= 1% of h, volume opacity RMSE
 * <= 1e-4. The 1e4 scene without an "origin" key (camera-relative by default) must meet the same
 * bounds. The same 1e5 scene with "origin": [0, 0, 0] (the opt-out: float32 world coordinates, what
 * a host without an origin does) is measured too: its beams miss 1e-5, which is what the origin
 * buys. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app.h"
#include "demo_scene.h"
#include "test_util.h"

#define W 96
#define H 54
#define WATER_H 0.61 /* the plugin's default kernel radius (the scene sets none) */

typedef struct raw3 {
    float water[W * H], beams[W * H], volume[W * H];
} raw3;

/* The scene with every position plus d; origin: the "origin" key's JSON value, NULL for none. */
static void write_scene(const char *path, double d, const char *origin)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f,
            "{%s%s%s\n"
            " \"camera\": {\"eye\": [%.17g, %.17g, %.17g], \"target\": [%.17g, %.17g, %.17g], \"fov_y_deg\": 55,"
            " \"near\": 0.05, \"far\": 60},\n"
            " \"water\": {\"source\": \"generator\", \"generator\": {\"kind\": \"box\", \"count\": 2744,"
            " \"min\": [%.17g, %.17g, %.17g], \"max\": [%.17g, %.17g, %.17g]}},\n"
            " \"beams\": [{\"head\": [%.17g, %.17g, %.17g], \"dir\": [1, 0, 0], \"length\": 2.5, \"radius\": 0.4,"
            " \"a\": 0.3, \"b\": 0.3, \"eps\": 0.02},\n"
            "            {\"head\": [%.17g, %.17g, %.17g], \"dir\": [-1, 0.2, 0.1], \"length\": 1.5, \"radius\": 0.3,"
            " \"a\": 0.3, \"b\": 0.3, \"eps\": 0.02}],\n"
            " \"beam_settings\": {\"bloom\": false},\n"
            " \"volume\": {\"generator\": {\"cells\": 4, \"min\": [-0.5, -0.5, -0.5], \"max\": [0.5, 0.5, 0.5]},"
            " \"translate\": [%.17g, %.17g, %.17g], \"workers\": 1,"
            " \"transfer\": [{\"scalar\": 0, \"rgba\": [0.2, 0.4, 1, 0.5]}, {\"scalar\": 1, \"rgba\": [1, 0.8, 0.2, 3]}]}}\n",
            origin ? "\"origin\": " : "", origin ? origin : "", origin ? "," : "", d + 0.2, d + 1.2, d + 4.5, d, d + 0.1, d, d - 0.7, d - 0.6, d - 0.7, d + 0.1, d + 0.2, d + 0.1,
            d - 2.0, d + 1.0, d - 0.5, d + 2.0, d + 0.6, d - 0.3, d + 1.3, d - 0.2, d - 0.4);
    fclose(f);
}

static void render_scene(double d, const char *origin, raw3 *out)
{
    char path[96];
    snprintf(path, sizeof path, "/tmp/volfx-large-world-%d.json", (int)getpid());
    write_scene(path, d, origin);
    game_app_desc desc = {.mode = RT_GL_HEADLESS, .width = W, .height = H};
    game_app *app;
    if (game_app_create(&desc, &app) != VFX_OK)
        exit(VFX_TEST_SKIP);
    game_demo demo;
    assert_int_equal(game_demo_load(app, &demo, path, 0), VFX_OK);
    remove(path);
    for (int i = 0; i < 2; ++i) { /* the volume clips with the previous frame's distances */
        game_demo_animate(app, &demo, 0.f);
        assert_int_equal(game_app_frame(app, 0.f), VFX_OK);
    }
    assert_int_equal(app->api->read_raw(app->ctx, VFX_EFFECT_WATER, out->water, W * H), VFX_OK);
    assert_int_equal(app->api->read_raw(app->ctx, VFX_EFFECT_BEAMS, out->beams, W * H), VFX_OK);
    assert_int_equal(app->api->read_raw(app->ctx, VFX_EFFECT_VOLUME, out->volume, W * H), VFX_OK);
    game_demo_free(app, &demo);
    game_app_destroy(app);
}

typedef struct diff {
    double beams_rel;          /* max |H - H0| / H0 where H0 > 1e-6 of its maximum */
    uint32_t water_hits, holes, false_hits;
    double water_p99_h;        /* p99 of |t - t0| / h over pixels both hit */
    double volume_rmse;
} diff;

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static diff compare(const raw3 *ref, const raw3 *r)
{
    diff d = {0};
    double hmax = 0, se = 0;
    for (int i = 0; i < W * H; ++i)
        hmax = fmax(hmax, ref->beams[i]);
    static double e[W * H];
    uint32_t n = 0;
    for (int i = 0; i < W * H; ++i) {
        if (ref->beams[i] > 1e-6 * hmax)
            d.beams_rel = fmax(d.beams_rel, fabs((double)r->beams[i] - ref->beams[i]) / ref->beams[i]);
        bool h0 = ref->water[i] >= 0, h1 = r->water[i] >= 0;
        d.water_hits += h0;
        d.holes += h0 && !h1;
        d.false_hits += !h0 && h1;
        if (h0 && h1)
            e[n++] = fabs((double)r->water[i] - ref->water[i]) / WATER_H;
        double dv = (double)r->volume[i] - ref->volume[i];
        se += dv * dv;
    }
    qsort(e, n, sizeof *e, cmp_double);
    d.water_p99_h = n ? e[(size_t)ceil(0.99 * n) - 1] : 0;
    d.volume_rmse = sqrt(se / (W * H));
    return d;
}

static void test_shifted_worlds(void **state)
{
    (void)state;
    static raw3 ref, r;
    render_scene(0, "\"camera\"", &ref);
    uint32_t lit_b = 0, lit_v = 0;
    for (int i = 0; i < W * H; ++i)
        lit_b += ref.beams[i] > 1e-3f, lit_v += ref.volume[i] > 1e-3f;
    diff self = compare(&ref, &ref);
    printf("at the origin: %u water hits, %u beam pixels, %u volume pixels\n", self.water_hits, lit_b, lit_v);
    assert_true(self.water_hits > 50 && lit_b > 200 && lit_v > 100); /* every effect is in view */
    static const double shifts[2] = {1e4, 1e5};
    for (int k = 0; k < 2; ++k) {
        render_scene(shifts[k], "\"camera\"", &r);
        diff d = compare(&ref, &r);
        printf("shifted by %g, origin camera: beams max rel %.3g, water holes %u false %u p99 %.3g h, volume rmse %.3g\n",
               shifts[k], d.beams_rel, d.holes, d.false_hits, d.water_p99_h, d.volume_rmse);
        assert_true(d.beams_rel <= 1e-5);
        assert_int_equal(d.holes, 0);
        assert_true(d.water_p99_h <= 0.01);
        assert_true(d.volume_rmse <= 1e-4);
    }
    /* no "origin" key: camera-relative by default, the held-out 1e4 case within the same bounds */
    render_scene(1e4, NULL, &r);
    diff n = compare(&ref, &r);
    printf("shifted by 1e4, no origin key (camera-relative by default): beams max rel %.3g, water holes %u false %u "
           "p99 %.3g h, volume rmse %.3g\n", n.beams_rel, n.holes, n.false_hits, n.water_p99_h, n.volume_rmse);
    assert_true(n.beams_rel <= 1e-5);
    assert_int_equal(n.holes, 0);
    assert_true(n.water_p99_h <= 0.01);
    assert_true(n.volume_rmse <= 1e-4);
    /* the opt-out, float32 world coordinates: the beams lose the 1e-5 */
    render_scene(1e5, "[0, 0, 0]", &r);
    diff z = compare(&ref, &r);
    printf("shifted by 1e5, origin [0,0,0] (float32 world coordinates): beams max rel %.3g, water holes %u "
           "false %u p99 %.3g h, volume rmse %.3g\n", z.beams_rel, z.holes, z.false_hits, z.water_p99_h, z.volume_rmse);
    assert_true(z.beams_rel > 1e-5);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shifted_worlds),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
