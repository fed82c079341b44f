/* Beams in the water (docs/beams.md "In the water"): a beam dipping into a pool of real water
 * (the water effect over a slab of particles, the sample host), each pixel's ray split at the
 * water's surface by the integrate pass: H over [0, t_water] (composited over the water) and
 * H over [t_water, t_scene] (seen through the water's refraction), each held to the float64
 * quadrature of the raw density over the same interval (reference/beams_ref.c), like
 * test_beams_gl.c holds the unsplit H. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app.h"
#include "beams_ref.h"
#include "lab/beam_field_d.h"
#include "beams/beams_impact.h"
#include "debug.h"
#include "test_camera.h"
#include "test_util.h"

#define W 64
#define H 48
#define T_FAR 50.0 /* the camera's far plane: where a ray with no surface ends */

static game_app *g_app;
static const ref_camera g_cam = {{0.2, 1.3, 4}, {0, -0.2, 0}, {0, 1, 0}, 0.9, W, H, 0.05, T_FAR};
static test_log g_log;
/* the beam dips from above the pool into it: its lower half is under the surface (y ~ 0) */
static const vfx_beam k_beam = {.type = VFX_TYPE_BEAM, .head = {-1.5f, 0.1f, 0.0f}, .dir = {1, -0.1f, 0},
                                .length = 2.5f, .radius = 0.5f, .a = 0.4f, .b = 0.25f, .eps = 0.05f,
                                .falloff = VFX_BEAM_FALLOFF_HARD, .ramp = VFX_BEAM_RAMP_THESIS};

static int setup(void **state)
{
    (void)state;
    g_app = test_app_with_camera(&g_cam, &g_log);
    assert_int_equal(game_app_add_beams(g_app, &k_beam, 1), VFX_OK);
    g_app->beams_view = (vfx_beams_view){.type = VFX_TYPE_BEAMS_VIEW, .bloom = VFX_BEAMS_BLOOM_OFF};
    /* a slab of water, spacing 0.08, its top at y ~ 0 */
    enum { NX = 40, NY = 6, NZ = 25 };
    static float px[NX * NY * NZ], py[NX * NY * NZ], pz[NX * NY * NZ];
    uint32_t n = 0;
    for (int i = 0; i < NX; ++i)
        for (int j = 0; j < NY; ++j)
            for (int k = 0; k < NZ; ++k, ++n)
                px[n] = -1.6f + 0.08f * i, py[n] = -0.04f - 0.08f * j, pz[n] = -1.0f + 0.08f * k;
    assert_int_equal(rt_particles_spawn(g_app->world, &g_app->particles, n, px, py, pz, false), VFX_OK);
    g_app->water_enabled = true;
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    game_app_destroy(g_app);
    return 0;
}

/* Every pixel: the front and the behind H against the quadrature over the same interval, with
 * the same float32 t_water the GPU used (read back from the water's distance image). Tolerance as
 * test_beams_gl.c's: 1e-5 ref + cond + cut where ref > 1e-6 of the image maximum (1e-6 of the
 * maximum below), cond = the change of the exact H when a float32 input (ray, head) moves by 2 ulps
 * (ref_beams_cond_abs, over the interval), cut = rho(t_water) x 1e-6 t_water: the split point
 * enters the closed form as a float32 ray parameter measured from the closest approach, rounded
 * to a few ulps of t (2^-24 t each), which moves H by rho there. */
static void test_split_matches_reference(void **state)
{
    (void)state;
    vfx_result fr = game_app_frame(g_app, 0.f);
    if (fr)
        printf("frame: %s\n", g_log.last);
    assert_int_equal(fr, VFX_OK);
    float *wd = malloc(W * H * sizeof(float)), *split = malloc(2 * W * H * sizeof(float));
    assert_int_equal(g_app->api->read_raw(g_app->ctx, VFX_EFFECT_WATER, wd, W * H), VFX_OK);
    assert_int_equal(volfx_beams_debug_split(g_app->ctx, split, 2 * W * H), VFX_OK);
    volfx_beam_d b;
    char err[128];
    assert_int_equal(volfx_beam_validate(&k_beam, &b, err, sizeof err), VFX_OK);
    double *ref = malloc(2 * W * H * sizeof(double)), hmax = 0;
    for (uint32_t k = 0; k < W * H; ++k) {
        double dir[3], tw = wd[k] >= 0 ? fmin(wd[k], T_FAR) : T_FAR;
        ref_pixel_ray(&g_cam, k % W, k / W, dir);
        ref[2 * k] = ref_beams_integral(&b, 1, g_cam.eye, dir, 0.0, tw, 1e-10, NULL);
        ref[2 * k + 1] = tw < T_FAR ? ref_beams_integral(&b, 1, g_cam.eye, dir, tw, T_FAR, 1e-10, NULL) : 0.0;
        hmax = fmax(hmax, ref[2 * k] + ref[2 * k + 1]);
    }
    int bad = 0, pixels = 0, split_px = 0, cond_needed = 0;
    double max_ratio = 0, max_rel_wc = 0;
    for (uint32_t k = 0; k < W * H; ++k) {
        double dir[3], end[3], tw = wd[k] >= 0 ? fmin(wd[k], T_FAR) : T_FAR;
        ref_pixel_ray(&g_cam, k % W, k / W, dir);
        for (int c = 0; c < 3; ++c)
            end[c] = g_cam.eye[c] + tw * dir[c];
        double cut = tw < T_FAR ? volfx_beam_density_d(&b, end) * 1e-6 * tw : 0.0;
        if (ref[2 * k + 1] > 1e-3 * hmax && ref[2 * k] > 1e-3 * hmax)
            split_px++;
        for (int part = 0; part < 2; ++part) {
            double r = ref[2 * k + part], e = fabs(split[2 * k + part] - r);
            double cond = ref_beams_cond_abs(&b, 1, g_cam.eye, dir, part ? tw : 0.0, part ? T_FAR : tw, 2.0);
            bool bright = r > 1e-6 * hmax;
            double tol = (bright ? 1e-5 * r : 1e-6 * hmax) + cond + cut;
            max_ratio = fmax(max_ratio, e / tol);
            if (bright) {
                pixels++;
                if (cond + cut < 1e-6 * r)
                    max_rel_wc = fmax(max_rel_wc, e / r);
                if (e / r > 1e-5)
                    cond_needed++;
            }
            if (e > tol) {
                printf("pixel %u %s: gpu %.7g ref %.7g err %.3g tol %.3g (cond %.3g cut %.3g, t_water %.6g)\n", k,
                       part ? "behind" : "front", split[2 * k + part], r, e, tol, cond, cut, tw);
                bad++;
            }
        }
    }
    printf("split at the water: %d pixels both sides above 1e-3 of max; %d pixel-parts above 1e-6 of max: "
           "max rel err %.3g where well conditioned, %d above 1e-5 (within their conditioning), max err/tol %.3g\n",
           split_px, pixels, max_rel_wc, cond_needed, max_ratio);
    assert_int_equal(bad, 0);
    assert_true(split_px >= 50);          /* the beam does cross the surface in view */
    assert_true(max_rel_wc <= 1e-5);      /* the target, where the inputs allow it */
    free(wd);
    free(split);
    free(ref);
}

/* A beam striking the water from above: its impact is found on the water's surface (not on the
 * sky behind it: this scene has no host geometry at all), flagged as the water's, and reported as
 * a water impact event with the beam's direction of travel. */
static void test_impact_on_water(void **state)
{
    (void)state;
    uint32_t nb;
    vfx_beam *b = game_app_beams(g_app, &nb);
    assert_int_equal(nb, 1);
    /* head 0.25 under the slab's top particles, the trail rising to the caster above and behind */
    const float head[3] = {0.3f, -0.3f, 0.2f}, dir[3] = {-0.8f, 0.6f, 0.0f};
    *b = k_beam;
    memcpy(b->head, head, sizeof head);
    memcpy(b->dir, dir, sizeof dir);
    b->length = 2.0f;
    b->radius = 0.15f;
    for (int f = 0; f < 4; ++f) /* the events are read back one to three frames late */
        assert_int_equal(game_app_frame(g_app, 1.f / 60), VFX_OK);
    volfx_beams_impact *im = volfx_beams_impact_of(g_app->ctx);
    assert_non_null(im);
    float hits[1][8];
    assert_int_equal(volfx_beams_impact_debug_hits(im, hits, 1), 1);
    printf("hit at (%.3f, %.3f, %.3f), normal (%.3f, %.3f, %.3f), on the water: %g\n", hits[0][0], hits[0][1],
           hits[0][2], hits[0][4], hits[0][5], hits[0][6], hits[0][7]);
    assert_true(hits[0][3] == 1.f); /* a hit, */
    assert_true(hits[0][7] == 1.f); /* on the water */
    /* on the axis, at the water's surface: between the top particles (y -0.04) and a kernel
     * radius above them (the metaball surface lies there) */
    assert_true(hits[0][1] > -0.06f && hits[0][1] < 0.12f);
    double t = (hits[0][1] - head[1]) / dir[1];
    assert_float_equal(hits[0][0], head[0] + t * dir[0], 0.02);
    assert_float_equal(hits[0][2], head[2], 0.02);
    assert_true(hits[0][5] > 0.5f); /* the surface faces up */
    volfx_impact_event ev[2];
    assert_int_equal(volfx_beams_impact_water_events(im, ev, 2), 1);
    /* travel: from the caster toward the head, i.e. -dir */
    assert_float_equal(ev[0].direction[0], 0.8f, 1e-5);
    assert_float_equal(ev[0].direction[1], -0.6f, 1e-5);
    assert_true(ev[0].energy > 0 && ev[0].beam == 0);
    *b = k_beam;
}

/* The stat's value in the last frame, -1 when the frame did not set it. */
static double last_stat(const char *name)
{
    for (uint32_t k = 0; k < g_app->ctx->last_stats.count; ++k)
        if (!strcmp(g_app->ctx->last_stats.entries[k].name, name))
            return g_app->ctx->last_stats.entries[k].value;
    return -1;
}

/* Preset low switches the water's loop over the plugin's lights off (docs/water.md "Presets"):
 * with the beam over the pool, the default preset packs its lights for the shading (stat
 * water.effect_lights: the shade program's WATER_EFFECT_LIGHTS variant runs only then), low packs
 * none and the frame still draws the beams' light split at the surface without error. */
static void test_preset_low_drops_the_lights(void **state)
{
    (void)state;
    uint32_t preset = g_app->water.preset;
    double lights[2];
    for (int k = 0; k < 2; ++k) {
        g_app->water.preset = k ? VFX_WATER_PRESET_LOW : VFX_WATER_PRESET_DEFAULT;
        for (int f = 0; f < 3; ++f) /* the impact lights are read back one to three frames late */
            assert_int_equal(game_app_frame(g_app, 1.f / 60), VFX_OK);
        lights[k] = last_stat("water.effect_lights");
        printf("preset %s: water.effect_lights %g, beams.lights %g\n", k ? "low" : "default", lights[k],
               last_stat("beams.lights"));
        assert_true(last_stat("beams.lights") > 0); /* the beams do give lights */
    }
    g_app->water.preset = preset;
    assert_true(lights[0] > 0);
    assert_true(lights[1] < 0); /* low never packs them */
    assert_int_equal(g_log.errors, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_split_matches_reference),
        cmocka_unit_test(test_impact_on_water),
        cmocka_unit_test(test_preset_low_drops_the_lights),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
