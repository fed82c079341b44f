/* GL tests of the water effect against the float64 reference (sample_game/water/water_ref.c):
 * the GPU distance image (read_raw) is compared pixel by pixel, for the paper's method and the
 * two compute baselines (BRUTE over all particles, GRID over a uniform grid). */
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

#include "plugin_internal.h"
#include "reference/reference.h"
#include "test_util.h"
#include "water/water_ref.h"

typedef struct scene {
    vfx_test_log log;
    float *x, *y, *z;
    uint32_t n, chunk; /* particles per chunk: several chunks exercise the concatenation */
    vfx_water_params params;
} scene;

static uint32_t chunk_count(void *user)
{
    scene *s = user;
    return s->n ? (s->n + s->chunk - 1) / s->chunk : 0;
}

static vfx_result chunk_view(void *user, uint32_t index, vfx_particle_view *out)
{
    scene *s = user;
    uint32_t first = index * s->chunk, count = s->n - first < s->chunk ? s->n - first : s->chunk;
    out->count = count;
    out->pos[0] = s->x + first;
    out->pos[1] = s->y + first;
    out->pos[2] = s->z + first;
    return VFX_OK;
}

static vfx_result water_params(void *user, vfx_water_params *out)
{
    *out = ((scene *)user)->params;
    return VFX_OK;
}

/* Renders the scene with the plugin and the reference; returns the error; *stats optional. */
static vfx_water_ref_error render_and_compare(scene *s, const vfx_ref_camera *cam, vfx_stats *stats_out)
{
    vfx_host_api host = {.size = sizeof host, .version = VFX_HOST_API_VERSION, .user = s,
                         .log = vfx_test_log_fn, .particle_chunk_count = chunk_count,
                         .particle_chunk = chunk_view, .water_params = water_params};
    /* the logger's user is the scene, whose first member is the vfx_test_log */
    vfx_plugin_api api = {.size = sizeof api};
    assert_int_equal(vfx_plugin_entry(VFX_ABI_VERSION, NULL, &api), VFX_OK);
    vfx_context *ctx;
    assert_int_equal(api.create(&host, &ctx), VFX_OK);
    uint32_t w = cam->width, h = cam->height;
    GLuint fbo, col;
    glCreateTextures(GL_TEXTURE_2D, 1, &col);
    glTextureStorage2D(col, 1, GL_RGBA8, (GLsizei)w, (GLsizei)h);
    glCreateFramebuffers(1, &fbo);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, col, 0);
    vfx_frame_view fv = {.size = sizeof fv, .version = VFX_FRAME_VIEW_VERSION, .framebuffer = fbo,
                         .width = w, .height = h, .fov_y = (float)cam->fov_y, .near_plane = 0.1f,
                         .far_plane = 100.0f};
    for (int k = 0; k < 3; ++k) fv.eye[k] = (float)cam->eye[k];
    vfx_ref_camera_matrices(cam, fv.view, fv.proj);
    assert_int_equal(api.update(ctx, 0.0, 0.0f), VFX_OK);
    assert_int_equal(api.render(ctx, &fv), VFX_OK);
    float *gpu = malloc((size_t)w * h * sizeof *gpu), *ref = malloc((size_t)w * h * sizeof *ref);
    vfx_water_ref_error e;
    memset(&e, 0, sizeof e);
    if (s->n) {
        assert_int_equal(api.read_raw(ctx, VFX_EFFECT_WATER, gpu, (size_t)w * h), VFX_OK);
        double fwd[3], right[3], up[3];
        vfx_ref_camera_basis(cam, fwd, right, up);
        vfx_water_ref_camera rc = {{cam->eye[0], cam->eye[1], cam->eye[2]}, {fwd[0], fwd[1], fwd[2]},
                                   {up[0], up[1], up[2]}, cam->fov_y, w, h};
        vfx_water_ref_params rp = vfx_water_ref_default_params();
        rp.h = s->params.h > 0 ? s->params.h : 0.61;
        rp.step = rp.h / 32;
        char err[256];
        assert_int_equal(vfx_water_ref_render(&rc, s->x, s->y, s->z, s->n, &rp, ref, NULL, NULL, err), 0);
        assert_int_equal(vfx_water_ref_compare(gpu, NULL, ref, NULL, (size_t)w * h, rp.h, &e), 0);
    }
    if (stats_out) {
        stats_out->size = sizeof *stats_out;
        stats_out->version = VFX_STATS_VERSION;
        assert_int_equal(api.get_stats(ctx, stats_out), VFX_OK);
    }
    free(gpu);
    free(ref);
    api.destroy(ctx);
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &col);
    return e;
}

static double stat_of(const vfx_stats *st, const char *name)
{
    for (uint32_t k = 0; k < st->count; ++k)
        if (!strcmp(st->entries[k].name, name)) return st->entries[k].value;
    return -1;
}

static scene make_scene(uint32_t n)
{
    scene s;
    memset(&s, 0, sizeof s);
    s.n = n;
    s.chunk = 97;
    s.x = malloc((n + 1) * sizeof(float));
    s.y = malloc((n + 1) * sizeof(float));
    s.z = malloc((n + 1) * sizeof(float));
    s.params.size = sizeof s.params;
    s.params.version = VFX_WATER_PARAMS_VERSION;
    s.params.method = VFX_WATER_METHOD_BRUTE;
    return s;
}

static void free_scene(scene *s) { free(s->x); free(s->y); free(s->z); }

/* Blobs at 64x64 in 4 chunks: the brute-force march (step h/8, cap 64, 3 regula falsi
 * iterations, float32) against the float64 reference (step h/32 + bisection). */
static void test_blobs_vs_reference(void **state)
{
    (void)state;
    scene s = make_scene(300);
    vfx_water_ref_blobs(s.n, 4, 1.0, 0.35, 7, s.x, s.y, s.z);
    vfx_ref_camera cam = {{0.5, 1.0, 5.0}, {0, 0, 0}, {0, 1, 0}, 0.8, 64, 64, 0.1, 100};
    vfx_stats st;
    vfx_water_ref_error e = render_and_compare(&s, &cam, &st);
    print_message("blobs: ref hits %u holes %.4f false %.4f dist mean %.2e p99 %.2e (x h)\n",
                  e.ref_hits, e.hole_rate, e.false_hit_rate, e.dist_mean_rel_h, e.dist_p99_rel_h);
    assert_true(e.ref_hits > 400);
    /* A step of h/8 can step over a feature thinner than h/8 that the h/32 reference finds:
     * only silhouette pixels, well under 2% of the hits. */
    assert_true(e.hole_rate < 0.02);
    assert_true(e.false_hit_rate < 0.01);
    /* Regula falsi on a smooth I(t) bracketed within h/8, then float32 (t ~ 5, ulp 5e-7):
     * mean under 1e-3 h; p99 under 1e-2 h (kinks where a particle's support ends). */
    assert_true(e.dist_mean_rel_h < 1e-3);
    assert_true(e.dist_p99_rel_h < 1e-2);
    assert_true(stat_of(&st, "water.particles") == 300);
    free_scene(&s);
}

/* One particle: a sphere of radius h(1 - T). Camera inside the fluid: every pixel at t = 0. */
static void test_one_particle_and_camera_inside(void **state)
{
    (void)state;
    for (uint32_t m = 0; m < 3; ++m) {
    scene s = make_scene(1);
    s.params.method = m; /* PAPER, BRUTE, GRID */
    s.x[0] = s.y[0] = s.z[0] = 0;
    vfx_ref_camera cam = {{0, 0, 1.0}, {0, 0, 0}, {0, 1, 0}, 0.5, 48, 48, 0.1, 100};
    vfx_water_ref_error e = render_and_compare(&s, &cam, NULL);
    assert_true(e.ref_hits > 50);
    assert_true(e.hole_rate < 0.05 && e.false_hit_rate < 0.01); /* only grazing pixels */
    assert_true(e.dist_p99_rel_h < 1e-2);
    vfx_ref_camera inside = {{0.01, 0, 0.02}, {0, 0, -5}, {0, 1, 0}, 0.8, 32, 32, 0.1, 100};
    e = render_and_compare(&s, &inside, NULL);
    assert_int_equal(e.ref_hits, 32 * 32);
    assert_true(e.hole_rate == 0.0 && e.dist_p99_rel_h < 1e-6);
    free_scene(&s);
    }
}

/* Coincident particles: n at one point give sqrt(n)(1 - r/h) = T, a sphere of radius
 * h(1 - T/sqrt n); NaN positions are skipped (counted in water.nan_skipped) and change nothing. */
static void test_coincident_and_nan(void **state)
{
    (void)state;
    for (uint32_t m = 0; m < 3; ++m) {
    scene s = make_scene(12);
    s.params.method = m; /* PAPER, BRUTE, GRID */
    for (uint32_t k = 0; k < 12; ++k) s.x[k] = s.y[k] = s.z[k] = 0.25f;
    s.x[3] = NAN;
    s.y[7] = INFINITY;
    vfx_ref_camera cam = {{0, 0, 3.0}, {0.25, 0.25, 0.25}, {0, 1, 0}, 0.6, 48, 48, 0.1, 100};
    vfx_stats st;
    vfx_water_ref_error e = render_and_compare(&s, &cam, &st);
    assert_true(stat_of(&st, "water.nan_skipped") == 2);
    assert_true(e.ref_hits > 50);
    assert_true(e.hole_rate < 0.05 && e.false_hit_rate < 0.01);
    assert_true(e.dist_p99_rel_h < 2e-2);
    free_scene(&s);
    }
}

/* h huge (3.0, ten times the 0.3 spacing: one smooth blob over a 4x4x4 lattice) and h tiny
 * (0.08: separate spheres of radius 0.019), paper method against the reference. The reference
 * samples at h/32 of the same h, the renderer at its default h/8. */
static void test_h_huge_and_tiny(void **state)
{
    (void)state;
    const float hs[2] = {3.0f, 0.08f};
    for (int k = 0; k < 2; ++k) {
        scene s = make_scene(64);
        s.params.method = VFX_WATER_METHOD_PAPER;
        s.params.h = hs[k];
        for (uint32_t i = 0; i < 64; ++i) {
            s.x[i] = 0.3f * (float)(i % 4) - 0.45f;
            s.y[i] = 0.3f * (float)((i / 4) % 4) - 0.45f;
            s.z[i] = 0.3f * (float)(i / 16) - 0.45f;
        }
        double dist = k == 0 ? 9.0 : 1.6;
        vfx_ref_camera cam = {{0.2, 0.3, dist}, {0, 0, 0}, {0, 1, 0}, 0.8, 48, 48, 0.1, 100};
        vfx_water_ref_error e = render_and_compare(&s, &cam, NULL);
        print_message("h %.2f: ref hits %u holes %.4f false %.4f dist p99 %.2e (x h)\n", hs[k],
                      e.ref_hits, e.hole_rate, e.false_hit_rate, e.dist_p99_rel_h);
        assert_true(e.ref_hits > 20);
        /* tiny spheres are a few pixels wide: silhouette pixels are a larger share */
        assert_true(e.hole_rate < (k == 0 ? 0.02 : 0.15));
        assert_true(e.false_hit_rate < 0.01);
        assert_true(e.dist_p99_rel_h < 5e-2);
        free_scene(&s);
    }
}

/* The paper's method (every technique on) on the blob scene against the reference. */
static void test_paper_blobs_vs_reference(void **state)
{
    (void)state;
    scene s = make_scene(300);
    s.params.method = VFX_WATER_METHOD_PAPER;
    vfx_water_ref_blobs(s.n, 4, 1.0, 0.35, 7, s.x, s.y, s.z);
    vfx_ref_camera cam = {{0.5, 1.0, 5.0}, {0, 0, 0}, {0, 1, 0}, 0.8, 64, 64, 0.1, 100};
    vfx_stats st;
    vfx_water_ref_error e = render_and_compare(&s, &cam, &st);
    print_message("paper blobs: ref hits %u holes %.4f false %.4f dist mean %.2e p99 %.2e (x h) samples %.0f culled %.0f\n",
                  e.ref_hits, e.hole_rate, e.false_hit_rate, e.dist_mean_rel_h, e.dist_p99_rel_h,
                  stat_of(&st, "water.samples"), stat_of(&st, "water.fragments_culled"));
    assert_true(e.ref_hits > 400);
    assert_true(e.hole_rate < 0.02);
    assert_true(e.false_hit_rate < 0.01);
    assert_true(e.dist_mean_rel_h < 1e-2);
    assert_true(e.dist_p99_rel_h < 5e-2);
    free_scene(&s);
}

/* Each technique switched off in turn still gives the surface (ablation bits). */
static void test_paper_ablation_bits(void **state)
{
    (void)state;
    static const uint32_t bits[] = {VFX_WATER_NO_BILLBOARD_INIT, VFX_WATER_NO_SKIP, VFX_WATER_NO_BLEND,
                                    VFX_WATER_NO_PACK4, VFX_WATER_NO_PYRAMID, VFX_WATER_NO_REFINE};
    for (unsigned b = 0; b < sizeof bits / sizeof bits[0]; ++b) {
        scene s = make_scene(200);
        s.params.method = VFX_WATER_METHOD_PAPER;
        s.params.disable = bits[b];
        vfx_water_ref_blobs(s.n, 3, 0.8, 0.3, 11, s.x, s.y, s.z);
        vfx_ref_camera cam = {{0.3, 0.8, 4.0}, {0, 0, 0}, {0, 1, 0}, 0.8, 48, 48, 0.1, 100};
        vfx_water_ref_error e = render_and_compare(&s, &cam, NULL);
        print_message("disable 0x%x: ref hits %u holes %.4f false %.4f dist mean %.2e p99 %.2e (x h)\n",
                      bits[b], e.ref_hits, e.hole_rate, e.false_hit_rate, e.dist_mean_rel_h, e.dist_p99_rel_h);
        assert_true(e.ref_hits > 200);
        assert_true(e.hole_rate < 0.02);
        assert_true(e.false_hit_rate < 0.01);
        /* Potentials accumulate in RGBA16F (10-bit mantissa: ~1e-3 relative per add), so I is off by
         * ~1e-3 and t by ~1e-3 h (|dI/dt| ~ 1/h): measured mean 7e-4 h, p99 3.7e-3 h; linear
         * interpolation only (NO_REFINE) p99 1.4e-2 h. Bounds leave a factor ~3. */
        assert_true(e.dist_mean_rel_h < 5e-3);
        assert_true(e.dist_p99_rel_h < 5e-2);
        free_scene(&s);
    }
}

/* GRID on the blob scene with the bounds of the BRUTE test (same sampling rule, same float32
 * arithmetic; only the neighbour search differs), and its counters: every pixel ends in exactly
 * one of found / sample cap / left. Then with gap skipping off (fixed steps after the first
 * sphere entry, BRUTE's rule): the same bounds, and strictly more samples, which is what the
 * skipping is for. */
static void test_grid_blobs_vs_reference(void **state)
{
    (void)state;
    double samples[2];
    for (int k = 0; k < 2; ++k) {
        scene s = make_scene(300);
        s.params.method = VFX_WATER_METHOD_GRID;
        s.params.disable = k ? VFX_WATER_NO_SKIP : 0;
        vfx_water_ref_blobs(s.n, 4, 1.0, 0.35, 7, s.x, s.y, s.z);
        vfx_ref_camera cam = {{0.5, 1.0, 5.0}, {0, 0, 0}, {0, 1, 0}, 0.8, 64, 64, 0.1, 100};
        vfx_stats st;
        vfx_water_ref_error e = render_and_compare(&s, &cam, &st);
        samples[k] = stat_of(&st, "water.samples");
        print_message("grid blobs%s: ref hits %u holes %.4f false %.4f dist mean %.2e p99 %.2e (x h) samples %.0f cells %.0f visited %.0f\n",
                      k ? " (no skip)" : "", e.ref_hits, e.hole_rate, e.false_hit_rate, e.dist_mean_rel_h,
                      e.dist_p99_rel_h, samples[k], stat_of(&st, "water.grid_cells"),
                      stat_of(&st, "water.grid_cells_visited"));
        assert_true(e.ref_hits > 400);
        /* as the BRUTE test: a step of h/8 misses only features thinner than h/8 */
        assert_true(e.hole_rate < 0.02);
        assert_true(e.false_hit_rate < 0.01);
        assert_true(e.dist_mean_rel_h < 1e-3);
        assert_true(e.dist_p99_rel_h < 1e-2);
        assert_true(stat_of(&st, "water.pixels_found") + stat_of(&st, "water.pixels_sample_cap") +
                    stat_of(&st, "water.pixels_left") == 64 * 64);
        assert_true(stat_of(&st, "water.pixels_found") >= e.ref_hits * (1 - e.hole_rate) - 1);
        assert_true(stat_of(&st, "water.grid_cells") > 1 && stat_of(&st, "water.method_fallback") < 0);
        free_scene(&s);
    }
    assert_true(samples[0] > 0 && samples[0] < samples[1]);
}

/* GRID with h huge and tiny against the spacing (as the paper-method test), then h = 1e-3
 * with one particle 1000 away: 1e6 cells of h along x, so the cell grows (cap 2^20 cells) and
 * the sphere must still be found. */
static void test_grid_h_extremes(void **state)
{
    (void)state;
    const float hs[2] = {3.0f, 0.08f};
    for (int k = 0; k < 2; ++k) {
        scene s = make_scene(64);
        s.params.method = VFX_WATER_METHOD_GRID;
        s.params.h = hs[k];
        for (uint32_t i = 0; i < 64; ++i) {
            s.x[i] = 0.3f * (float)(i % 4) - 0.45f;
            s.y[i] = 0.3f * (float)((i / 4) % 4) - 0.45f;
            s.z[i] = 0.3f * (float)(i / 16) - 0.45f;
        }
        double dist = k == 0 ? 9.0 : 1.6;
        vfx_ref_camera cam = {{0.2, 0.3, dist}, {0, 0, 0}, {0, 1, 0}, 0.8, 48, 48, 0.1, 100};
        vfx_stats st;
        vfx_water_ref_error e = render_and_compare(&s, &cam, &st);
        print_message("grid h %.2f: ref hits %u holes %.4f false %.4f dist p99 %.2e (x h), %.0f cells\n", hs[k],
                      e.ref_hits, e.hole_rate, e.false_hit_rate, e.dist_p99_rel_h, stat_of(&st, "water.grid_cells"));
        assert_true(e.ref_hits > 20);
        /* BRUTE-like sampling: float32 and the h/8 step against the h/32 reference; tiny spheres
         * are a few pixels wide, so silhouette pixels are a larger share of the hits */
        assert_true(e.hole_rate < (k == 0 ? 0.02 : 0.15));
        assert_true(e.false_hit_rate < 0.01);
        assert_true(e.dist_p99_rel_h < 5e-2);
        free_scene(&s);
    }
    scene s = make_scene(2);
    s.params.method = VFX_WATER_METHOD_GRID;
    s.params.h = 1e-3f;
    s.x[0] = s.y[0] = s.z[0] = 0;
    s.x[1] = 1000.0f;
    s.y[1] = s.z[1] = 0;
    /* sphere radius h(1 - T) = 2.3e-4 seen from 1e-2 away: about 18 pixels across */
    vfx_ref_camera cam = {{0, 0, 1e-2}, {0, 0, 0}, {0, 1, 0}, 0.06, 32, 32, 1e-4, 100};
    vfx_stats st;
    vfx_water_ref_error e = render_and_compare(&s, &cam, &st);
    print_message("grid h 1e-3, 1000 apart: ref hits %u holes %.4f false %.4f dist p99 %.2e (x h), cell %.3g, %.0f cells\n",
                  e.ref_hits, e.hole_rate, e.false_hit_rate, e.dist_p99_rel_h,
                  stat_of(&st, "water.grid_cell_size"), stat_of(&st, "water.grid_cells"));
    assert_true(stat_of(&st, "water.grid_cells") <= (1 << 20));
    assert_true(stat_of(&st, "water.grid_cell_size") > 1e-3);
    assert_true(e.ref_hits > 100);
    assert_true(e.hole_rate < 0.05 && e.false_hit_rate < 0.01); /* only grazing pixels */
    /* t ~ 1e-2 in float32 (ulp 1e-9) is far below h, so this is the sampling's error: a sphere
     * 18 pixels wide has a large share of grazing pixels, where I(t) is flat and 3 regula falsi
     * steps leave ~1e-2 h (measured p99 1.6e-2 h): the tiny-h bound above */
    assert_true(e.dist_p99_rel_h < 5e-2);
    free_scene(&s);
}

/* Every particle non-finite: GRID builds an empty grid and draws nothing (no NaN reaches a cell
 * index); all of them counted. */
static void test_grid_all_nan(void **state)
{
    (void)state;
    scene s = make_scene(5);
    s.params.method = VFX_WATER_METHOD_GRID;
    for (uint32_t k = 0; k < 5; ++k) s.x[k] = s.y[k] = s.z[k] = 0;
    s.x[0] = NAN; s.y[1] = INFINITY; s.z[2] = -INFINITY; s.x[3] = NAN; s.y[4] = NAN;
    vfx_ref_camera cam = {{0, 0, 2.0}, {0, 0, 0}, {0, 1, 0}, 0.6, 16, 16, 0.1, 100};
    vfx_stats st;
    vfx_water_ref_error e = render_and_compare(&s, &cam, &st);
    assert_int_equal(e.ref_hits, 0);
    assert_true(e.false_hit_rate == 0.0);
    assert_true(stat_of(&st, "water.nan_skipped") == 5);
    assert_true(stat_of(&st, "water.pixels_left") == 16 * 16);
    free_scene(&s);
}

/* 4,096 particles in the paper's layout, BRUTE and GRID. llvmpipe stops every loop of a shader
 * invocation after 65535 iterations in all; BRUTE's plain loop over 4,096 particles per sample
 * ran out after ~15 samples and left 2.5% holes at this size (0.64% at 128^2) until its loops
 * took 32 particles per iteration. Bounds: one silhouette pixel of the ~200 hits is 0.5%. */
static void test_loop_budget_4096(void **state)
{
    (void)state;
    for (uint32_t m = 1; m < 3; ++m) {
        scene s = make_scene(4096);
        s.params.method = m;
        vfx_water_ref_layers(s.n, 0.3, s.x, s.y, s.z);
        double top = (double)((s.n - 1) / 576) * 0.3;
        vfx_ref_camera cam = {{0, top + 4.0, 8.0}, {0, top * 0.5, 0}, {0, 1, 0}, 0.9, 20, 20, 0.1, 100};
        vfx_water_ref_error e = render_and_compare(&s, &cam, NULL);
        print_message("%s 4096 layers: ref hits %u holes %.4f false %.4f dist p99 %.2e (x h)\n", m == 1 ? "brute" : "grid",
                      e.ref_hits, e.hole_rate, e.false_hit_rate, e.dist_p99_rel_h);
        assert_true(e.ref_hits > 100);
        assert_true(e.hole_rate < 0.01 && e.false_hit_rate < 0.01);
        assert_true(e.dist_p99_rel_h < 1e-2); /* as the blob test: h/8 steps + 3 regula falsi */
        free_scene(&s);
    }
}

/* An unknown method value: the frame fails with a message naming it (nothing silently drawn). */
static void test_unknown_method(void **state)
{
    (void)state;
    scene s = make_scene(3);
    s.params.method = 7;
    for (uint32_t k = 0; k < 3; ++k) s.x[k] = s.y[k] = s.z[k] = 0.1f * (float)k;
    vfx_host_api host = {.size = sizeof host, .version = VFX_HOST_API_VERSION, .user = &s,
                         .log = vfx_test_log_fn, .particle_chunk_count = chunk_count,
                         .particle_chunk = chunk_view, .water_params = water_params};
    vfx_plugin_api api = {.size = sizeof api};
    assert_int_equal(vfx_plugin_entry(VFX_ABI_VERSION, NULL, &api), VFX_OK);
    vfx_context *ctx;
    assert_int_equal(api.create(&host, &ctx), VFX_OK);
    vfx_ref_camera cam = {{0, 0, 3.0}, {0, 0, 0}, {0, 1, 0}, 0.6, 16, 16, 0.1, 100};
    vfx_frame_view fv = {.size = sizeof fv, .version = VFX_FRAME_VIEW_VERSION, .framebuffer = 0,
                         .width = 16, .height = 16, .fov_y = 0.6f, .near_plane = 0.1f, .far_plane = 100.0f};
    fv.eye[2] = 3.0f;
    vfx_ref_camera_matrices(&cam, fv.view, fv.proj);
    assert_int_equal(api.update(ctx, 0.0, 0.0f), VFX_OK);
    assert_int_equal(api.render(ctx, &fv), VFX_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(api.last_error(ctx), "unknown method 7"));
    api.destroy(ctx);
    free_scene(&s);
}

/* Zero particles: the effect is absent, no state, no pass, no stat. */
static void test_zero_particles(void **state)
{
    (void)state;
    scene s = make_scene(0);
    vfx_ref_camera cam = {{0, 0, 3.0}, {0, 0, 0}, {0, 1, 0}, 0.6, 16, 16, 0.1, 100};
    vfx_stats st;
    render_and_compare(&s, &cam, &st);
    assert_int_equal(st.count, 0);
    free_scene(&s);
}

int main(void)
{
    vfx_gl_context *gl = vfx_test_gl_or_skip();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_blobs_vs_reference),
        cmocka_unit_test(test_one_particle_and_camera_inside),
        cmocka_unit_test(test_coincident_and_nan),
        cmocka_unit_test(test_zero_particles),
        cmocka_unit_test(test_paper_blobs_vs_reference),
        cmocka_unit_test(test_paper_ablation_bits),
        cmocka_unit_test(test_h_huge_and_tiny),
        cmocka_unit_test(test_grid_blobs_vs_reference),
        cmocka_unit_test(test_grid_h_extremes),
        cmocka_unit_test(test_grid_all_nan),
        cmocka_unit_test(test_unknown_method),
        cmocka_unit_test(test_loop_budget_4096),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    vfx_gl_context_destroy(gl); /* LeakSanitizer in CI's sanitizer run checks this */
    return rc;
}
