/* Beams on the GPU (llvmpipe in CI) through the real host: H per pixel against the float64
 * quadrature of the raw density, hidden-surface removal by the host depth, the thesis' m_z
 * sweep (a wall moved through the beam), the ray-marching baseline, tile culling counters,
 * bad input. Small images: llvmpipe runs fragment shaders on the CPU. */
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
#include "beams/beams_ref.h"
#include "plugin_internal.h"
#include "test_util.h"

#define W 64
#define H 48

static vfx_app *g_app;
static vfx_test_log g_log;

static const vfx_beam k_beam = {.head = {-1.5f, 0.1f, 0.0f}, .dir = {1, 0.2f, 0}, .length = 2.5f,
                                .radius = 0.5f, .a = 0.4f, .b = 0.25f, .eps = 0.05f};

static int setup(void **state)
{
    (void)state;
    memset(&g_log, 0, sizeof g_log);
    vfx_app_desc d = {.mode = VFX_GL_HEADLESS, .width = W, .height = H, .logger = {vfx_test_log_fn, &g_log}};
    if (vfx_app_create(&d, &g_app) != VFX_OK)
        exit(VFX_TEST_SKIP);
    vfx_ref_camera cam = {{0.2, 0.3, 4}, {0, 0, 0}, {0, 1, 0}, 0.9, W, H, 0.05, 50};
    assert_int_equal(vfx_app_set_camera(g_app, &cam), VFX_OK);
    g_app->beams[0] = k_beam;
    g_app->beam_count = 1;
    g_app->beams_view = (vfx_beams_view){.size = sizeof(vfx_beams_view), .version = VFX_BEAMS_VIEW_VERSION};
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    vfx_app_destroy(g_app);
    return 0;
}

static float *render_raw(void)
{
    assert_int_equal(vfx_app_frame(g_app, 0.f), VFX_OK);
    float *raw = malloc(W * H * sizeof(float));
    assert_int_equal(g_app->api->read_raw(g_app->ctx, VFX_EFFECT_BEAMS, raw, W * H), VFX_OK);
    return raw;
}

/* float64 reference of pixel (i, j), integrated to t1. */
static double ref_pixel(uint32_t i, uint32_t j, double t1)
{
    vfx_beam_d b;
    char err[128];
    assert_int_equal(vfx_beam_validate(&g_app->beams[0], &b, err, sizeof err), VFX_OK);
    double dir[3];
    vfx_ref_pixel_ray(&g_app->camera, i, j, dir);
    return vfx_beams_ref_integral(&b, 1, g_app->camera.eye, dir, 0.0, t1, 1e-10, NULL);
}

/* Tolerance: the GPU ray comes from unprojecting the pixel centre in float32 (direction good to
 * ~1e-6), the closed form is good to ~1e-6 relative (tests/beams/test_beam_field.c), so 1e-4
 * relative is generous where H is above 5% of the image maximum; nearer the hard support edge a
 * 1e-6 direction change moves H by more (the integrand jumps there), so those pixels get an
 * absolute bound of 1e-3 of the maximum. Where the ray ends on a surface, the end distance comes
 * from a float32 depth unprojected in float32 (relative error ~2e-5 measured at these depths),
 * which moves H by rho(end) * dt: that term is added. Returns the number of failing pixels. */
static int compare_image(const float *gpu, double (*t1_of)(uint32_t, uint32_t), double *max_rel)
{
    vfx_beam_d b;
    char err[128];
    assert_int_equal(vfx_beam_validate(&g_app->beams[0], &b, err, sizeof err), VFX_OK);
    int bad = 0;
    double *ref = malloc(W * H * sizeof(double)), hmax = 0;
    for (uint32_t j = 0; j < H; ++j)
        for (uint32_t i = 0; i < W; ++i) {
            ref[j * W + i] = ref_pixel(i, j, t1_of(i, j));
            hmax = fmax(hmax, ref[j * W + i]);
        }
    assert_true(hmax > 0.1);
    *max_rel = 0;
    for (uint32_t k = 0; k < W * H; ++k) {
        double e = fabs(gpu[k] - ref[k]);
        uint32_t i = k % W, j = k / W;
        double t1 = t1_of(i, j), dir[3], end[3];
        vfx_ref_pixel_ray(&g_app->camera, i, j, dir);
        for (int c = 0; c < 3; ++c)
            end[c] = g_app->camera.eye[c] + t1 * dir[c];
        double cut = t1 < 50.0 ? vfx_beam_density_d(&b, end) * 2e-5 * t1 : 0.0;
        if (ref[k] > 0.05 * hmax) {
            *max_rel = fmax(*max_rel, e / ref[k]);
            if (e > 1e-4 * ref[k] + cut) {
                printf("pixel %u: gpu %.7g ref %.7g rel %.3g\n", k, gpu[k], ref[k], e / ref[k]);
                bad++;
            }
        } else if (e > 1e-3 * hmax + cut) {
            printf("pixel %u: gpu %.7g ref %.7g abs %.3g (max %.4g)\n", k, gpu[k], ref[k], e, hmax);
            bad++;
        }
    }
    free(ref);
    return bad;
}

static double t_far(uint32_t i, uint32_t j) { (void)i, (void)j; return 50.0; }

static void test_matches_reference(void **state)
{
    (void)state;
    float *raw = render_raw();
    double max_rel;
    assert_int_equal(compare_image(raw, t_far, &max_rel), 0);
    printf("open sky: max relative error %.3g\n", max_rel);
    /* tiles the beam cannot touch were culled: the counter says so and their pixels are 0 */
    vfx_stats st = {.size = sizeof st, .version = VFX_STATS_VERSION};
    assert_int_equal(g_app->api->get_stats(g_app->ctx, &st), VFX_OK);
    double pairs = -1, culled = -1;
    for (uint32_t k = 0; k < st.count; ++k) {
        if (!strcmp(st.entries[k].name, "beams.pairs")) pairs = st.entries[k].value;
        if (!strcmp(st.entries[k].name, "beams.pairs_culled")) culled = st.entries[k].value;
    }
    assert_true(pairs >= 1 && culled >= 0 && pairs + culled == 12); /* 4x3 tiles of 16 px */
    free(raw);
    /* a small beam in the top-right corner: most tiles culled, their pixels exactly 0 */
    g_app->beams[0] = (vfx_beam){.head = {1.6f, 1.1f, 0}, .dir = {1, 0, 0}, .length = 0.1f, .radius = 0.1f,
                                 .a = 0.4f, .b = 0.25f, .eps = 0.05f};
    raw = render_raw();
    assert_int_equal(g_app->api->get_stats(g_app->ctx, &st), VFX_OK);
    for (uint32_t k = 0; k < st.count; ++k)
        if (!strcmp(st.entries[k].name, "beams.pairs_culled"))
            culled = st.entries[k].value;
    printf("small beam: %g of 12 beam-tile pairs culled\n", culled);
    assert_true(culled >= 9);
    assert_true(raw[(H - 1) * W + 0] == 0.f && raw[(H / 2) * W + W / 2] == 0.f);
    free(raw);
    g_app->beams[0] = k_beam;
}

static double g_wall_z;
/* distance along pixel (i,j)'s ray to the plane z = g_wall_z (the wall faces the camera) */
static double t_wall(uint32_t i, uint32_t j)
{
    double d[3];
    vfx_ref_pixel_ray(&g_app->camera, i, j, d);
    double t = (g_wall_z - g_app->camera.eye[2]) / d[2];
    return t > 0 && t < 50 ? t : 50.0;
}

static void test_hidden_by_depth(void **state)
{
    (void)state;
    /* a wall through the middle of the beam's support, covering the whole view */
    g_wall_z = 0.1;
    vfx_entity wall;
    assert_int_equal(vfx_app_add_box(g_app, (float[3]){-20, -20, (float)g_wall_z - 1}, (float[3]){20, 20, (float)g_wall_z},
                                     (float[3]){0.5f, 0.5f, 0.5f}, &wall), VFX_OK);
    float *raw = render_raw();
    double max_rel;
    int bad = compare_image(raw, t_wall, &max_rel);
    free(raw);
    vfx_app_mesh *m = vfx_world_get(g_app->world, wall, g_app->mesh_comp, 0);
    vfx_mesh_gpu_destroy(&m->gpu);
    assert_int_equal(vfx_world_despawn(g_app->world, wall), VFX_OK);
    printf("wall at z=%.2f: max relative error %.3g\n", g_wall_z, max_rel);
    assert_int_equal(bad, 0);
}

/* An Assimp model (Debian's assimp-testmodels box.obj, a cube of side 1) scaled and placed so the
 * beam passes through it: each ray ends at the model's front face. */
static double g_box_min[3], g_box_max[3];
static double t_box(uint32_t i, uint32_t j)
{
    double d[3], t0 = 0, t1 = 50;
    vfx_ref_pixel_ray(&g_app->camera, i, j, d);
    for (int k = 0; k < 3; ++k) { /* slab test, float64 */
        double a = (g_box_min[k] - g_app->camera.eye[k]) / d[k], b = (g_box_max[k] - g_app->camera.eye[k]) / d[k];
        if (a > b) { double t = a; a = b; b = t; }
        t0 = fmax(t0, a), t1 = fmin(t1, b);
    }
    return t0 < t1 ? t0 : 50.0;
}

static void test_hidden_by_assimp_mesh(void **state)
{
    (void)state;
    const char *model = "/usr/share/assimp/models/OBJ/box.obj";
    FILE *f = fopen(model, "rb");
    if (!f)
        skip(); /* assimp-testmodels not installed */
    fclose(f);
    const float s = 0.6f, c[3] = {0.0f, 0.2f, 0.0f};
    float m[16] = {s, 0, 0, 0, 0, s, 0, 0, 0, 0, s, 0, c[0], c[1], c[2], 1};
    vfx_entity e;
    assert_int_equal(vfx_app_add_mesh_file(g_app, model, m, (float[3]){0.7f, 0.3f, 0.3f}, &e), VFX_OK);
    for (int k = 0; k < 3; ++k)
        g_box_min[k] = c[k] - 0.5 * s, g_box_max[k] = c[k] + 0.5 * s;
    float *raw = render_raw();
    double max_rel;
    int bad = compare_image(raw, t_box, &max_rel);
    free(raw);
    vfx_app_mesh *mm = vfx_world_get(g_app->world, e, g_app->mesh_comp, 0);
    vfx_mesh_gpu_destroy(&mm->gpu);
    assert_int_equal(vfx_world_despawn(g_app->world, e), VFX_OK);
    printf("beam through box.obj: max relative error %.3g\n", max_rel);
    assert_int_equal(bad, 0);
}

static void test_mz_sweep(void **state)
{
    (void)state;
    /* thesis figs. 4.8-4.13: a wall moved from behind the beam to in front of it; H at the
     * beam's centre pixel falls monotonically from the open-sky value to 0 */
    float *open = render_raw();
    const uint32_t cx = 31, cy = 22; /* the beam crosses the image centre */
    double full = open[cy * W + cx];
    assert_true(full > 0.1);
    free(open);
    double prev = INFINITY;
    const double zs[] = {-2.0, -0.6, -0.3, 0.0, 0.3, 0.6, 2.0};
    for (size_t k = 0; k < sizeof zs / sizeof zs[0]; ++k) {
        vfx_entity wall;
        assert_int_equal(vfx_app_add_box(g_app, (float[3]){-20, -20, (float)zs[k] - 1}, (float[3]){20, 20, (float)zs[k]},
                                         (float[3]){0.5f, 0.5f, 0.5f}, &wall), VFX_OK);
        float *raw = render_raw();
        double h = raw[cy * W + cx];
        free(raw);
        vfx_app_mesh *m = vfx_world_get(g_app->world, wall, g_app->mesh_comp, 0);
        vfx_mesh_gpu_destroy(&m->gpu);
        assert_int_equal(vfx_world_despawn(g_app->world, wall), VFX_OK);
        g_wall_z = zs[k];
        double ref = ref_pixel(cx, cy, t_wall(cx, cy));
        printf("m_z %.2f: H %.6g (reference %.6g)\n", zs[k], h, ref);
        assert_true(fabs(h - ref) <= 1e-4 * full);
        assert_true(h <= prev + 1e-6);
        prev = h;
        if (zs[k] <= -2.0)
            assert_true(fabs(h - full) <= 1e-4 * full); /* wall behind the support: no effect */
        if (zs[k] >= 2.0)
            assert_true(h == 0.0); /* wall in front of the support: hidden */
    }
}

static void test_marching_baseline(void **state)
{
    (void)state;
    float *closed = render_raw();
    double err[2];
    const uint32_t samples[2] = {8, 120};
    for (int k = 0; k < 2; ++k) {
        g_app->beams_view.method = 1;
        g_app->beams_view.march_samples = samples[k];
        float *m = render_raw();
        double e = 0, n = 0;
        for (uint32_t p = 0; p < W * H; ++p)
            if (closed[p] > 0.05f) {
                e += fabs(m[p] - closed[p]) / closed[p];
                n += 1;
            }
        err[k] = e / n;
        free(m);
    }
    g_app->beams_view.method = 0;
    printf("marching mean relative error: 8 samples %.3g, 120 samples %.3g\n", err[0], err[1]);
    assert_true(err[1] < err[0]); /* converges towards the closed form */
    assert_true(err[1] < 0.05);
    free(closed);
}

static void test_bad_input_and_absence(void **state)
{
    (void)state;
    g_app->beams[0].radius = -1.f;
    assert_int_not_equal(vfx_app_frame(g_app, 0.f), VFX_OK);
    assert_non_null(strstr(g_app->api->last_error(g_app->ctx), "beams[0]"));
    g_app->beams[0] = k_beam;
    g_app->beams[0].head[1] = NAN;
    assert_int_not_equal(vfx_app_frame(g_app, 0.f), VFX_OK);
    assert_non_null(strstr(g_app->api->last_error(g_app->ctx), "not finite"));
    g_app->beams[0] = k_beam;
    assert_int_equal(vfx_app_frame(g_app, 0.f), VFX_OK);
    assert_non_null(g_app->ctx->effect_state[VFX_EFFECT_BEAMS]);
    /* no beams: the effect's state is freed, no pass runs, and once the timer results of the
     * last frames with beams have drained (a ring of 4 frames), no beams stat is reported */
    g_app->beam_count = 0;
    for (int f = 0; f < 5; ++f)
        assert_int_equal(vfx_app_frame(g_app, 0.f), VFX_OK);
    assert_null(g_app->ctx->effect_state[VFX_EFFECT_BEAMS]);
    vfx_stats st = {.size = sizeof st, .version = VFX_STATS_VERSION};
    g_app->api->get_stats(g_app->ctx, &st);
    for (uint32_t k = 0; k < st.count; ++k)
        assert_null(strstr(st.entries[k].name, "beams."));
    g_app->beam_count = 1;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matches_reference),
        cmocka_unit_test(test_hidden_by_depth),
        cmocka_unit_test(test_hidden_by_assimp_mesh),
        cmocka_unit_test(test_mz_sweep),
        cmocka_unit_test(test_marching_baseline),
        cmocka_unit_test(test_bad_input_and_absence),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
