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
#include "volfx_lab.h"
#include "beams_ref.h"
#include "lab/beam_field_d.h"
#include "debug.h"
#include "depth_modes.h"
#include "test_camera.h"
#include "test_util.h"

#define W 64
#define H 48

static game_app *g_app;
/* the camera the host renders with; the references trace its rays in float64 */
static const ref_camera g_cam = {{0.2, 0.3, 4}, {0, 0, 0}, {0, 1, 0}, 0.9, W, H, 0.05, 50};
static test_log g_log;
static int g_smooth; /* the falloff the references integrate (set with use_v2) */
static uint32_t g_nj;  /* joints of the bending beam the references integrate (0: straight) */

/* the thesis's look: the hard support, the thesis ramp (what the references integrate unless a
 * test asks for the smooth support) */
static const vfx_beam k_beam = {.type = VFX_TYPE_BEAM, .head = {-1.5f, 0.1f, 0.0f}, .dir = {1, 0.2f, 0}, .length = 2.5f,
                                .radius = 0.5f, .a = 0.4f, .b = 0.25f, .eps = 0.05f,
                                .falloff = VFX_BEAM_FALLOFF_HARD, .ramp = VFX_BEAM_RAMP_THESIS};

/* The one beam entity the tests draw. */
static vfx_beam *beam0(void)
{
    uint32_t n;
    vfx_beam *b = game_app_beams(g_app, &n);
    assert_int_equal(n, 1);
    return b;
}

static int setup(void **state)
{
    (void)state;
    g_app = test_app_with_camera(&g_cam, &g_log);
    assert_int_equal(game_app_add_beams(g_app, &k_beam, 1), VFX_OK);
    g_app->beams_view = (vfx_beams_view){.type = VFX_TYPE_BEAMS_VIEW, .bloom = VFX_BEAMS_BLOOM_OFF};
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    game_app_destroy(g_app);
    return 0;
}

static float *render_raw(void)
{
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_OK);
    float *raw = malloc(W * H * sizeof(float));
    assert_int_equal(g_app->api->read_raw(g_app->ctx, VFX_EFFECT_BEAMS, raw, W * H), VFX_OK);
    return raw;
}

/* float64 reference of pixel (i, j), integrated to t1. */
static double ref_pixel(uint32_t i, uint32_t j, double t1)
{
    volfx_beam_d b;
    char err[128];
    assert_int_equal(volfx_beam_validate(beam0(), &b, err, sizeof err), VFX_OK);
    b.smooth = g_smooth;
    assert_int_equal(volfx_beam_set_joints(&b, &g_app->joints[0][0], g_nj, err, sizeof err), VFX_OK);
    double dir[3];
    ref_pixel_ray(&g_cam, i, j, dir);
    return ref_beams_integral(&b, 1, g_cam.eye, dir, 0.0, t1, 1e-10, NULL);
}

/* The float32 inputs the GPU works from: the pixel direction, unprojected in float32 from the
 * pixel centre (a 4-term matrix-vector product, a divide and a normalise: a few ulps per
 * component), and the head relative to the eye, rounded to float once from an eye that the effect
 * recovers from the float view matrix (a few ulps of max(|eye|, |M - eye|)). cond_abs is the
 * largest change of the exact H (float64 closed form, itself within 1e-9 of the quadrature) when
 * one of these moves by 2 ulps: no float32 pipeline fed these inputs can be more accurate than
 * that. At a hard support edge it is large: a grazing ray whose chord through the support is 2h
 * has relative condition ~(R/h)^2 in the distance d of the ray from the centre or axis, and d
 * moves by ~eps |M - eye| (docs/beams.md, "What float32 can reach"). cond_abs is
 * ref_beams_cond_abs at 2 ulps. */
typedef struct image_errors {
    double max_rel;       /* over pixels with H > 1e-6 of the image maximum */
    double max_rel_wc;    /* the same, where cond_abs + cut < 1e-6 H (well conditioned) */
    double max_ratio;     /* max of error / tolerance */
    int cond_needed;      /* pixels above 1e-5 relative (all within their conditioning) */
    int pixels;           /* pixels with H > 1e-6 of the maximum */
} image_errors;

/* Every pixel against the float64 quadrature: |gpu - ref| <= 1e-5 ref + cond_abs + cut where
 * ref > 1e-6 of the image maximum (the criterion; 1e-5 is the target, cond_abs what the
 * float32 inputs allow), <= 1e-6 max + cond_abs + cut below that (the support edge, and pixels
 * outside it, which must stay 0). cut: where the ray ends on a surface, the end distance comes
 * from the float32 depth buffer, unprojected in float32 (relative error ~2e-5 measured at these
 * depths: t^2 (1/n - 1/f) times a depth ulp, and the unprojection's rounding), which moves H by
 * rho(end) dt. Returns the number of failing pixels. */
static int compare_image(const float *gpu, double (*t1_of)(uint32_t, uint32_t), image_errors *ie)
{
    volfx_beam_d b;
    char err[128];
    assert_int_equal(volfx_beam_validate(beam0(), &b, err, sizeof err), VFX_OK);
    b.smooth = g_smooth;
    assert_int_equal(volfx_beam_set_joints(&b, &g_app->joints[0][0], g_nj, err, sizeof err), VFX_OK);
    int bad = 0;
    double *ref = malloc(W * H * sizeof(double)), hmax = 0;
    for (uint32_t j = 0; j < H; ++j)
        for (uint32_t i = 0; i < W; ++i) {
            ref[j * W + i] = ref_pixel(i, j, t1_of(i, j));
            hmax = fmax(hmax, ref[j * W + i]);
        }
    assert_true(hmax > 0.1);
    memset(ie, 0, sizeof *ie);
    for (uint32_t k = 0; k < W * H; ++k) {
        double e = fabs(gpu[k] - ref[k]);
        uint32_t i = k % W, j = k / W;
        double t1 = t1_of(i, j), dir[3], end[3];
        ref_pixel_ray(&g_cam, i, j, dir);
        for (int c = 0; c < 3; ++c)
            end[c] = g_cam.eye[c] + t1 * dir[c];
        double cut = t1 < 50.0 ? volfx_beam_density_d(&b, end) * 2e-5 * t1 : 0.0;
        double cond = ref_beams_cond_abs(&b, 1, g_cam.eye, dir, 0.0, t1, 2.0);
        int bright = ref[k] > 1e-6 * hmax;
        double tol = (bright ? 1e-5 * ref[k] : 1e-6 * hmax) + cond + cut;
        ie->max_ratio = fmax(ie->max_ratio, e / tol);
        if (bright) {
            double rel = e / ref[k];
            ie->pixels++;
            ie->max_rel = fmax(ie->max_rel, rel);
            if (cond + cut < 1e-6 * ref[k])
                ie->max_rel_wc = fmax(ie->max_rel_wc, rel);
            if (rel > 1e-5)
                ie->cond_needed++;
        }
        if (e > tol) {
            printf("pixel %u: gpu %.7g ref %.7g err %.3g tol %.3g (cond %.3g cut %.3g, max %.4g)\n", k,
                   gpu[k], ref[k], e, tol, cond, cut, hmax);
            bad++;
        }
    }
    free(ref);
    return bad;
}

static void print_errors(const char *what, const image_errors *ie)
{
    printf("%s: %d pixels above 1e-6 of max: max relative error %.3g (%.3g where well conditioned), "
           "%d above 1e-5 (within their conditioning), max error/tolerance %.3g\n",
           what, ie->pixels, ie->max_rel, ie->max_rel_wc, ie->cond_needed, ie->max_ratio);
}

static double t_far(uint32_t i, uint32_t j) { (void)i, (void)j; return 50.0; }

static void test_matches_reference(void **state)
{
    (void)state;
    float *raw = render_raw();
    image_errors ie;
    assert_int_equal(compare_image(raw, t_far, &ie), 0);
    print_errors("open sky", &ie);
    assert_true(ie.max_rel_wc <= 1e-5); /* the target, where the inputs allow it */
    /* tiles the beam cannot touch were culled: the counter says so and their pixels are 0 */
    vfx_stats st = {.type = VFX_TYPE_STATS};
    assert_int_equal(g_app->api->get_stats(g_app->ctx, &st), VFX_OK);
    double pairs = -1, culled = -1;
    for (uint32_t k = 0; k < st.count; ++k) {
        if (!strcmp(st.entries[k].name, "beams.pairs")) pairs = st.entries[k].value;
        if (!strcmp(st.entries[k].name, "beams.pairs_culled")) culled = st.entries[k].value;
    }
    assert_true(pairs >= 1 && culled >= 0 && pairs + culled == 12); /* 4x3 tiles of 16 px */
    free(raw);
    /* a small beam in the top-right corner: most tiles culled, their pixels exactly 0 */
    *beam0() = (vfx_beam){.type = VFX_TYPE_BEAM, .head = {1.6f, 1.1f, 0}, .dir = {1, 0, 0}, .length = 0.1f, .radius = 0.1f,
                          .a = 0.4f, .b = 0.25f, .eps = 0.05f, .falloff = VFX_BEAM_FALLOFF_HARD,
                          .ramp = VFX_BEAM_RAMP_THESIS};
    raw = render_raw();
    assert_int_equal(g_app->api->get_stats(g_app->ctx, &st), VFX_OK);
    for (uint32_t k = 0; k < st.count; ++k)
        if (!strcmp(st.entries[k].name, "beams.pairs_culled"))
            culled = st.entries[k].value;
    printf("small beam: %g of 12 beam-tile pairs culled\n", culled);
    assert_true(culled >= 9);
    assert_true(raw[(H - 1) * W + 0] == 0.f && raw[(H / 2) * W + W / 2] == 0.f);
    free(raw);
    *beam0() = k_beam;
}

static double g_wall_z;
/* distance along pixel (i,j)'s ray to the plane z = g_wall_z (the wall faces the camera) */
static double t_wall(uint32_t i, uint32_t j)
{
    double d[3];
    ref_pixel_ray(&g_cam, i, j, d);
    double t = (g_wall_z - g_cam.eye[2]) / d[2];
    return t > 0 && t < 50 ? t : 50.0;
}

static void test_hidden_by_depth(void **state)
{
    (void)state;
    /* a wall through the middle of the beam's support, covering the whole view */
    g_wall_z = 0.1;
    rt_entity wall;
    assert_int_equal(game_app_add_box(g_app, (float[3]){-20, -20, (float)g_wall_z - 1}, (float[3]){20, 20, (float)g_wall_z},
                                     (float[3]){0.5f, 0.5f, 0.5f}, &wall), VFX_OK);
    float *raw = render_raw();
    image_errors ie;
    int bad = compare_image(raw, t_wall, &ie);
    free(raw);
    rt_mesh_component *m = rt_world_get(g_app->world, wall, g_app->meshes.mesh, 0);
    rt_mesh_gpu_destroy(&m->gpu);
    assert_int_equal(rt_world_despawn(g_app->world, wall), VFX_OK);
    char what[64];
    snprintf(what, sizeof what, "wall at z=%.2f", g_wall_z);
    print_errors(what, &ie);
    assert_int_equal(bad, 0);
}

/* An Assimp model (Debian's assimp-testmodels box.obj, a cube of side 1) scaled and placed so the
 * beam passes through it: each ray ends at the model's front face. */
static double g_box_min[3], g_box_max[3];
static double t_box(uint32_t i, uint32_t j)
{
    double d[3], t0 = 0, t1 = 50;
    ref_pixel_ray(&g_cam, i, j, d);
    for (int k = 0; k < 3; ++k) { /* slab test, float64 */
        double a = (g_box_min[k] - g_cam.eye[k]) / d[k], b = (g_box_max[k] - g_cam.eye[k]) / d[k];
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
    rt_entity e;
    assert_int_equal(game_app_add_mesh_file(g_app, model, m, (float[3]){0.7f, 0.3f, 0.3f}, &e), VFX_OK);
    for (int k = 0; k < 3; ++k)
        g_box_min[k] = c[k] - 0.5 * s, g_box_max[k] = c[k] + 0.5 * s;
    float *raw = render_raw();
    image_errors ie;
    int bad = compare_image(raw, t_box, &ie);
    free(raw);
    rt_mesh_component *mm = rt_world_get(g_app->world, e, g_app->meshes.mesh, 0);
    rt_mesh_gpu_destroy(&mm->gpu);
    assert_int_equal(rt_world_despawn(g_app->world, e), VFX_OK);
    print_errors("beam through box.obj", &ie);
    assert_true(ie.max_rel_wc <= 1e-5);
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
        rt_entity wall;
        assert_int_equal(game_app_add_box(g_app, (float[3]){-20, -20, (float)zs[k] - 1}, (float[3]){20, 20, (float)zs[k]},
                                         (float[3]){0.5f, 0.5f, 0.5f}, &wall), VFX_OK);
        float *raw = render_raw();
        double h = raw[cy * W + cx];
        free(raw);
        rt_mesh_component *m = rt_world_get(g_app->world, wall, g_app->meshes.mesh, 0);
        rt_mesh_gpu_destroy(&m->gpu);
        assert_int_equal(rt_world_despawn(g_app->world, wall), VFX_OK);
        g_wall_z = zs[k];
        double t1 = t_wall(cx, cy), ref = ref_pixel(cx, cy, t1), dir[3], end[3];
        volfx_beam_d b;
        char err[128];
        assert_int_equal(volfx_beam_validate(beam0(), &b, err, sizeof err), VFX_OK);
        ref_pixel_ray(&g_cam, cx, cy, dir);
        for (int c = 0; c < 3; ++c)
            end[c] = g_cam.eye[c] + t1 * dir[c];
        /* the bound of compare_image: 1e-5, the inputs' conditioning, the depth-derived end */
        double tol = 1e-5 * ref + ref_beams_cond_abs(&b, 1, g_cam.eye, dir, 0.0, t1, 2.0) +
                     (t1 < 50.0 ? volfx_beam_density_d(&b, end) * 2e-5 * t1 : 0.0);
        printf("m_z %.2f: H %.6g (reference %.6g, error %.3g, bound %.3g)\n", zs[k], h, ref, fabs(h - ref), tol);
        assert_true(fabs(h - ref) <= tol);
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
    vfx_lab_beams lab = {.type = VFX_TYPE_LAB_BEAMS, .method = VFX_BEAMS_METHOD_MARCH}; /* chained by the test */
    g_app->beams_next = &lab;
    /* the baseline is the lab's: libvolfx alone refuses the struct by name */
    g_app->ctx->lab = NULL;
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_ERR_UNSUPPORTED);
    assert_true(test_last_error_is(g_app->api, g_app->ctx, VFX_LOG_ID_BEAMS_VIEW_FIELD,
                                   "beams: a vfx_lab_beams (type 0x4c414202) is chained into vfx_beams_view"));
    assert_int_equal(volfx_lab_attach(g_app->ctx), VFX_OK);
    for (int k = 0; k < 2; ++k) {
        lab.method = VFX_BEAMS_METHOD_MARCH;
        lab.march_samples = samples[k];
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
    g_app->beams_next = NULL;
    printf("marching mean relative error: 8 samples %.3g, 120 samples %.3g\n", err[0], err[1]);
    assert_true(err[1] < err[0]); /* converges towards the closed form */
    assert_true(err[1] < 0.05);
    free(closed);
}

static void test_bad_input_and_absence(void **state)
{
    (void)state;
    beam0()->radius = -1.f;
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_ERR_INVALID_ARGUMENT);
    assert_true(test_last_error_is(g_app->api, g_app->ctx, VFX_LOG_ID_PARAM_RANGE, "beams[0]"));
    *beam0() = k_beam;
    beam0()->head[1] = NAN;
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_ERR_INVALID_ARGUMENT);
    assert_true(test_last_error_is(g_app->api, g_app->ctx, VFX_LOG_ID_PARAM_RANGE, "beams[0]: vfx_beam.head[1] nan outside"));
    *beam0() = k_beam;
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_OK);
    assert_non_null(g_app->ctx->effect_state[VFX_EFFECT_BEAMS]);
    /* no beams: the effect's state is freed, no pass runs, and once the timer results of the
     * last frames with beams have drained (a ring of 4 frames), no beams stat is reported */
    game_app_clear_beams(g_app);
    for (int f = 0; f < 5; ++f)
        assert_int_equal(game_app_frame(g_app, 0.f), VFX_OK);
    assert_null(g_app->ctx->effect_state[VFX_EFFECT_BEAMS]);
    vfx_stats st = {.type = VFX_TYPE_STATS};
    g_app->api->get_stats(g_app->ctx, &st);
    for (uint32_t k = 0; k < st.count; ++k)
        assert_null(strstr(st.entries[k].name, "beams."));
    assert_int_equal(game_app_add_beams(g_app, &k_beam, 1), VFX_OK);
}

/* The beam entity as k_beam with the look (this falloff, the hot ramp, a blue colour, bloom as
 * given), or k_beam in the thesis's look again, bloom off (v2 = false). */
static void use_v2(bool v2, bool smooth, bool bloom)
{
    g_smooth = v2 && smooth;
    vfx_beam *b = beam0();
    *b = k_beam;
    g_app->beams_view.bloom = VFX_BEAMS_BLOOM_OFF;
    g_app->beams_view.bloom_levels = 0;
    if (!v2)
        return;
    b->falloff = smooth ? VFX_BEAM_FALLOFF_SMOOTH : VFX_BEAM_FALLOFF_HARD;
    b->ramp = VFX_BEAM_RAMP_HOT;
    b->intensity = 1.f;
    b->color[0] = 0.2f, b->color[1] = 0.5f, b->color[2] = 1.f, b->color[3] = 1.f;
    g_app->beams_view.bloom = bloom ? VFX_BEAMS_BLOOM_ON : VFX_BEAMS_BLOOM_OFF;
}

static double stat_of(const char *name)
{
    vfx_stats st = {.type = VFX_TYPE_STATS};
    assert_int_equal(g_app->api->get_stats(g_app->ctx, &st), VFX_OK);
    for (uint32_t k = 0; k < st.count; ++k)
        if (!strcmp(st.entries[k].name, name))
            return st.entries[k].value;
    return -1;
}

/* The smooth support through a version 2 view: every pixel against the quadrature of the
 * smooth field, with compare_image's bound (1e-5 + the inputs' conditioning). */
static void test_smooth_matches_reference(void **state)
{
    (void)state;
    use_v2(true, true, false);
    float *raw = render_raw();
    image_errors ie;
    assert_int_equal(compare_image(raw, t_far, &ie), 0);
    print_errors("open sky, smooth support", &ie);
    assert_true(ie.max_rel_wc <= 1e-5);
    free(raw);
    use_v2(false, false, false);
}

/* A bending beam (a bend of 60 degrees and a slight one) through a version 2 view: every
 * pixel's H against the quadrature of the raw polyline field, compare_image's bound. */
static void test_polyline_matches_reference(void **state)
{
    (void)state;
    static const float J[4][3] = {{-1.6f, -0.2f, 0}, {-0.3f, 0.1f, 0.2f}, {0.4f, 0.9f, 0.1f}, {1.5f, 1.0f, -0.3f}};
    /* the smooth support only: the hard one's polyline pieces are the same code, and the CPU
     * test (test_beam_field.c) runs both; the quadrature per pixel is this test's cost */
    for (int smooth = 1; smooth < 2; ++smooth) {
        use_v2(true, smooth, false);
        memcpy(g_app->joints, J, sizeof J);
        g_app->joint_count = 4;
        beam0()->joint_first = 0;
        beam0()->joint_count = 4;
        g_nj = 4;
        float *raw = render_raw();
        image_errors ie;
        assert_int_equal(compare_image(raw, t_far, &ie), 0);
        print_errors(smooth ? "bending beam, smooth support" : "bending beam, hard support", &ie);
        assert_true(ie.max_rel_wc <= 1e-5);
        free(raw);
    }
    g_nj = 0;
    g_app->joint_count = 0;
    use_v2(false, false, false);
}

/* Final colours (tone-mapped RGBA8) of one frame. */
static uint8_t *render_rgba(void)
{
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_OK);
    uint8_t *px = malloc(W * H * 4);
    assert_int_equal(rt_renderer_read_rgba(g_app->renderer, px), VFX_OK);
    return px;
}

/* Emission: outside the support (H = 0) the frame is exactly the background without bloom and
 * brighter with it (glow spills past the field); the core is white-hot (channels near equal and
 * bright) while the glow's edge keeps the beam's blue; the bloom passes are timed; a version 1
 * view keeps version 1's image (no bloom). */
static void test_emission_and_bloom(void **state)
{
    (void)state;
    game_app_clear_beams(g_app);
    uint8_t *bg = render_rgba();
    assert_int_equal(game_app_add_beams(g_app, &k_beam, 1), VFX_OK);
    use_v2(true, true, false);
    beam0()->exposure = 3.f; /* x = 8 H: the core (H ~ 0.6) is well past the white point */
    float *raw = render_raw();
    uint8_t *plain = render_rgba();
    use_v2(true, true, true);
    beam0()->exposure = 3.f;
    uint8_t *glow = render_rgba();
    int outside = 0, spilled = 0, kmax = 0;
    /* raw (read_raw) and the RGBA read-back are both top row first: index k is one pixel */
    for (int k = 0; k < W * H; ++k) {
        if (raw[k] > raw[kmax])
            kmax = k;
        if (raw[k] != 0.f)
            continue;
        outside++;
        for (int c = 0; c < 3; ++c)
            assert_int_equal(plain[4 * k + c], bg[4 * k + c]);
        spilled += glow[4 * k + 2] > bg[4 * k + 2] + 2;
    }
    const uint8_t *core = &plain[4 * kmax];
    printf("emission: %d pixels outside the support, %d brightened by bloom; core rgb %u %u %u\n", outside,
           spilled, core[0], core[1], core[2]);
    assert_true(outside > 100 && spilled > outside / 20);
    assert_true(core[0] > 200 && core[1] > 200 && core[2] > 200); /* white-hot */
    /* the glow's edge: the dimmest lit pixel keeps the beam's colour (blue over red) */
    int kedge = -1;
    for (int k = 0; k < W * H; ++k)
        if (raw[k] > 0.02f * raw[kmax] && raw[k] < 0.1f * raw[kmax] && plain[4 * k + 2] > bg[4 * k + 2] + 8)
            kedge = k;
    assert_true(kedge >= 0);
    assert_true(plain[4 * kedge + 2] - bg[4 * kedge + 2] > 2 * (plain[4 * kedge + 0] - bg[4 * kedge + 0]));
    /* the bloom passes are timed (results arrive a few frames later) */
    for (int f = 0; f < 5; ++f)
        assert_int_equal(game_app_frame(g_app, 0.f), VFX_OK);
    printf("GPU ms: integrate %.3g, bloom_down %.3g, bloom_up %.3g, composite %.3g; %g levels\n",
           stat_of("beams.integrate.gpu_ms"), stat_of("beams.bloom_down.gpu_ms"), stat_of("beams.bloom_up.gpu_ms"),
           stat_of("beams.composite.gpu_ms"), stat_of("beams.bloom_levels"));
    assert_true(stat_of("beams.bloom_down.gpu_ms") >= 0 && stat_of("beams.bloom_up.gpu_ms") >= 0);
    assert_true(stat_of("beams.bloom_levels") >= 1);
    use_v2(false, false, false);
    free(render_rgba());
    assert_true(stat_of("beams.bloom_levels") == 0);
    free(bg), free(raw), free(plain), free(glow);
}

/* use_v2's beam and its look plus the anatomy of `anat`. */
static void use_v3(const vfx_beam *anat)
{
    use_v2(true, true, false);
    vfx_beam *b = beam0();
    b->head_radius = anat->head_radius, b->orb_radius = anat->orb_radius, b->orb_strength = anat->orb_strength;
    b->orb_pulse = anat->orb_pulse, b->orb_pulse_hz = anat->orb_pulse_hz, b->taper = anat->taper;
    b->surge_amount = anat->surge_amount, b->surge_wavelength = anat->surge_wavelength;
    b->surge_speed = anat->surge_speed, b->flow_kind = anat->flow_kind, b->flow_twist = anat->flow_twist;
    b->core = anat->core;
}

/* The anatomy on the GPU: H per pixel against the float64 closed form of the same field (head at
 * its own radius, orb, taper and a surge; the model is measured against the quadrature in
 * test_beam_anatomy.c). Bound: 1e-4 of the image maximum, the float32 path's rounding through
 * the slab cuts (the slab count span / step can differ by one between float32 and float64 for a
 * pixel at a count's edge; then the pixel differs by the model's own error, measured below
 * 3.5e-3 of the maximum, so such pixels are allowed 5e-3 and counted, at most 2%). */
static void test_anatomy_matches_closed_form(void **state)
{
    (void)state;
    vfx_beam an = {.type = VFX_TYPE_BEAM, .head_radius = 0.8f, .orb_radius = 0.45f, .orb_strength = 0.6f, .taper = 0.5f,
                    .surge_amount = 0.6f, .surge_wavelength = 0.9f, .surge_speed = 0.f};
    use_v3(&an);
    float *raw = render_raw();
    volfx_beam_d b;
    char err[128];
    assert_int_equal(volfx_beam_validate(beam0(), &b, err, sizeof err), VFX_OK);
    b.smooth = 1;
    b.head_radius = 0.8, b.orb_radius = 0.45, b.orb_a = 0.6, b.taper = 0.5, b.surge = 0.6;
    b.surge_inv_wl = 1.0 / 0.9, b.surge_phase = 0;
    double *ref = malloc(W * H * sizeof(double)), hmax = 0, worst = 0;
    const ref_camera cam = test_ref_camera(&g_app->camera);
    for (uint32_t k = 0; k < W * H; ++k) {
        double dir[3];
        ref_pixel_ray(&cam, k % W, k / W, dir);
        ref[k] = volfx_beam_integral_d(&b, g_app->camera.eye, dir, 0.0, t_far(k % W, k / W));
        hmax = fmax(hmax, ref[k]);
    }
    int loose = 0, lit = 0;
    for (uint32_t k = 0; k < W * H; ++k) {
        double e = fabs(raw[k] - ref[k]) / hmax;
        worst = fmax(worst, e);
        lit += ref[k] > 1e-3 * hmax;
        if (e > 1e-4)
            loose++;
        if (!(e <= 5e-3))
            fail_msg("pixel %u: GPU %.7g, float64 closed form %.7g (max %.4g)", k, (double)raw[k], ref[k], hmax);
    }
    printf("anatomy on the GPU: %d lit pixels, max |error| / max H %.3g, %d above 1e-4\n", lit, worst, loose);
    assert_true(lit > 200 && loose <= lit / 50);
    free(raw), free(ref);
    /* bad anatomy is refused naming the beam and the struct; then it works again */
    beam0()->taper = 2.f;
    assert_int_not_equal(game_app_frame(g_app, 0.f), VFX_OK);
    assert_true(test_last_error_is(g_app->api, g_app->ctx, VFX_LOG_ID_PARAM_RANGE, "beams[0]: vfx_beam"));
    beam0()->taper = 0.5f, beam0()->orb_radius = NAN;
    assert_int_not_equal(game_app_frame(g_app, 0.f), VFX_OK);
    beam0()->orb_radius = 0.45f;
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_OK);
    use_v2(false, false, false);
}

/* Distance from pixel k's ray to the beam's axis segment (k_beam's; the head is its end). */
static double ray_axis_distance(int k)
{
    double V[3], M[3], D[3], n = 0;
    const ref_camera cam = test_ref_camera(&g_app->camera);
    ref_pixel_ray(&cam, (uint32_t)(k % W), (uint32_t)(k / W), V);
    for (int c = 0; c < 3; ++c)
        M[c] = k_beam.head[c] - g_app->camera.eye[c], D[c] = k_beam.dir[c], n += D[c] * D[c];
    double b = 0, d = 0, e = 0;
    for (int c = 0; c < 3; ++c)
        D[c] /= sqrt(n), b += V[c] * D[c], d -= V[c] * M[c], e -= D[c] * M[c];
    double u = 1 - b * b > 1e-9 ? (e - b * d) / (1 - b * b) : e;
    u = fmin(fmax(u, 0.0), k_beam.length);
    double P[3], t = 0, r2 = 0;
    for (int c = 0; c < 3; ++c)
        P[c] = M[c] + u * D[c], t += P[c] * V[c];
    for (int c = 0; c < 3; ++c)
        r2 += (fmax(t, 0.0) * V[c] - P[c]) * (fmax(t, 0.0) * V[c] - P[c]);
    return sqrt(r2);
}

/* Hue kept (issue 25): a blue beam driven far past its white point (exposure 3, as in
 * test_emission_and_bloom), bloom on, read back after the host's tone map. Every halo pixel
 * (its ray passes 0.4 R to R from the axis, outside the core of 0.2 R: the white weight there is
 * below exp(-4)) minus the background must stay in the beam colour's hue sector: C = (0.2,
 * 0.5, 1) has r < g < b, and the light is a positive mix of C and white, which keeps that order,
 * as does a tone map that is one increasing curve per channel; so the hue stays within [180, 240]
 * degrees (cyan to blue), C's own being 217.5. Its saturation (max - min) / max must stay >= 0.4:
 * C itself through the host's ACES and sRGB encoding measures about 0.5 at full brightness (the
 * tone curve compresses the channels' ratios), so 0.4 allows the bloom's spill of the core; the
 * version 2 ramp, which whitens wherever H is large, is measured well below it on the same
 * pixels (printed, and asserted below 0.3 so the test can tell the two apart). */
static void halo_colour(const uint8_t *px, const uint8_t *bg, const float *raw, double *min_sat, double *hue_lo,
                        double *hue_hi, int *n)
{
    *min_sat = 1, *hue_lo = 360, *hue_hi = 0, *n = 0;
    for (int k = 0; k < W * H; ++k) {
        double r = ray_axis_distance(k) / k_beam.radius;
        if (!(raw[k] > 0.f && r > 0.4 && r < 1.0))
            continue;
        double c[3];
        for (int i = 0; i < 3; ++i)
            c[i] = fmax(0.0, (double)px[4 * k + i] - bg[4 * k + i]);
        double mx = fmax(c[0], fmax(c[1], c[2])), mn = fmin(c[0], fmin(c[1], c[2]));
        if (mx < 8) /* too dim to carry a hue in 8 bits */
            continue;
        double hue;
        if (mx == c[2])
            hue = 240 + 60 * (c[0] - c[1]) / (mx - mn + 1e-9);
        else if (mx == c[1])
            hue = 120 + 60 * (c[2] - c[0]) / (mx - mn + 1e-9);
        else
            hue = fmod(360 + 60 * (c[1] - c[2]) / (mx - mn + 1e-9), 360);
        *min_sat = fmin(*min_sat, (mx - mn) / mx);
        *hue_lo = fmin(*hue_lo, hue), *hue_hi = fmax(*hue_hi, hue);
        (*n)++;
    }
}

static void test_hue_kept(void **state)
{
    (void)state;
    game_app_clear_beams(g_app);
    uint8_t *bg = render_rgba();
    assert_int_equal(game_app_add_beams(g_app, &k_beam, 1), VFX_OK);
    vfx_beam an = {.type = VFX_TYPE_BEAM, .core = 0.2f};
    use_v3(&an);
    beam0()->exposure = 3.f;
    g_app->beams_view.bloom = VFX_BEAMS_BLOOM_ON;
    float *raw = render_raw();
    uint8_t *px = render_rgba();
    double sat, lo, hi, sat_v2, lo2, hi2;
    int n, n2;
    halo_colour(px, bg, raw, &sat, &lo, &hi, &n);
    an.core = 0; /* the version 2 ramp on the same beam */
    use_v3(&an);
    beam0()->exposure = 3.f;
    g_app->beams_view.bloom = VFX_BEAMS_BLOOM_ON;
    uint8_t *px2 = render_rgba();
    halo_colour(px2, bg, raw, &sat_v2, &lo2, &hi2, &n2);
    printf("halo (%d px): hue %.1f..%.1f, min saturation %.2f; version 2 ramp: hue %.1f..%.1f, min saturation %.2f\n",
           n, lo, hi, sat, lo2, hi2, sat_v2);
    assert_true(n > 100);
    assert_true(lo >= 180 && hi <= 240);
    assert_true(sat >= 0.4);
    assert_true(sat_v2 < 0.3);
    free(bg), free(raw), free(px), free(px2);
    use_v2(false, false, false);
}

/* A bad version 2 beam is refused with its index and field; a v1 view then works again. */
static void test_bad_v2_input(void **state)
{
    (void)state;
    use_v2(true, true, true);
    beam0()->falloff = 7;
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_ERR_INVALID_ARGUMENT);
    assert_true(test_last_error_is(g_app->api, g_app->ctx, VFX_LOG_ID_PARAM_RANGE, "beams[0]: vfx_beam.falloff 7 outside"));
    use_v2(true, true, true);
    beam0()->flow_amount = 2.f;
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_ERR_INVALID_ARGUMENT);
    assert_true(test_last_error_is(g_app->api, g_app->ctx, VFX_LOG_ID_PARAM_RANGE, "flow_amount"));
    use_v2(true, true, true);
    g_app->beams_view.bloom_levels = 99;
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_ERR_INVALID_ARGUMENT);
    assert_true(test_last_error_is(g_app->api, g_app->ctx, VFX_LOG_ID_PARAM_RANGE, "bloom_levels"));
    use_v2(false, false, false);
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_OK);
}

/* The engine's own depth (tests/common/depth_modes.h): the open sky and the wall through the
 * beam's support against the same float64 quadrature with the same bounds as the standard path
 * (compare_image), when the depth comes in a renderbuffer, reversed-Z with an infinite far plane
 * under GL_ZERO_TO_ONE, row-flipped, with an infinite far plane, and all at once. The bound's
 * "cut" term (2e-5 of the end distance) covers the converted depth too: the mode's depth is the
 * standard float32 depth turned into view depth and back in double, each rounding once to float32
 * (2^-24 relative in near/D, ~1e-7 of D here, or one standard-depth ulp: D^2/near x 6e-8 =
 * 2e-5 D at D = 4 with near 0.05 ... the same size as the standard path's own rounding). */
static void test_depth_modes_match_reference(void **state)
{
    (void)state;
    g_wall_z = 0.1;
    rt_entity wall;
    for (size_t m = 0; m < DEPTH_MODES_COUNT; ++m) {
        depth_mode_set(g_app, depth_modes_all[m].mode);
        float *raw = render_raw();
        image_errors ie;
        int bad = compare_image(raw, t_far, &ie);
        free(raw);
        char what[96];
        snprintf(what, sizeof what, "open sky, %s", depth_modes_all[m].name);
        print_errors(what, &ie);
        assert_int_equal(bad, 0);
        assert_true(ie.max_rel_wc <= 1e-5);
        assert_int_equal(game_app_add_box(g_app, (float[3]){-20, -20, (float)g_wall_z - 1}, (float[3]){20, 20, (float)g_wall_z},
                                         (float[3]){0.5f, 0.5f, 0.5f}, &wall), VFX_OK);
        raw = render_raw();
        bad = compare_image(raw, t_wall, &ie);
        free(raw);
        rt_mesh_component *mm = rt_world_get(g_app->world, wall, g_app->meshes.mesh, 0);
        rt_mesh_gpu_destroy(&mm->gpu);
        assert_int_equal(rt_world_despawn(g_app->world, wall), VFX_OK);
        snprintf(what, sizeof what, "wall at z=%.2f, %s", g_wall_z, depth_modes_all[m].name);
        print_errors(what, &ie);
        assert_int_equal(bad, 0);
    }
    depth_mode_set(g_app, DEPTH_STANDARD);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matches_reference),
        cmocka_unit_test(test_hidden_by_depth),
        cmocka_unit_test(test_depth_modes_match_reference),
        cmocka_unit_test(test_hidden_by_assimp_mesh),
        cmocka_unit_test(test_mz_sweep),
        cmocka_unit_test(test_marching_baseline),
        cmocka_unit_test(test_bad_input_and_absence),
        cmocka_unit_test(test_smooth_matches_reference),
        cmocka_unit_test(test_polyline_matches_reference),
        cmocka_unit_test(test_emission_and_bloom),
        cmocka_unit_test(test_bad_v2_input),
        cmocka_unit_test(test_anatomy_matches_closed_form),
        cmocka_unit_test(test_hue_kept),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
