/* Beam impacts (issue 25) through the real host on llvmpipe: the hit of a beam with the host's
 * depth found on the GPU against a float64 march of the same depth buffer read back (and the
 * floor's plane, analytically), a beam that only passes behind a pillar makes no impact, sparks
 * never go below a flat floor's depth, the counts stay bounded and agree with the pools, and the
 * lights of api3. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <epoxy/gl.h>

#include "app.h"
#include "beams/beams_impact.h"
#include "debug.h"
#include "depth_modes.h"
#include "test_camera.h"
#include "test_util.h"

#define W 96
#define H 64
#define DT (1.f / 30.f)

static game_app *g_app;
static test_log g_log;
/* the camera the host renders with; the reference marches its rays in float64 */
static const ref_camera g_cam = {{0.3, 2.2, 3.0}, {0, 0, 0}, {0, 1, 0}, 1.0, W, H, 0.05, 50};

/* A beam from src (its source) whose head is at head (its front, which strikes). */
static vfx_beam beam_from_to(const double src[3], const double head[3], float radius)
{
    /* the thesis's look (hard support, thesis ramp), as these measurements were taken */
    vfx_beam b = {.type = VFX_TYPE_BEAM, .radius = radius, .a = 0.6f, .b = 0.4f, .eps = 0.05f,
                  .color = {1.f, 0.5f, 0.2f, 1.f}, .falloff = VFX_BEAM_FALLOFF_HARD, .ramp = VFX_BEAM_RAMP_THESIS};
    double d[3], l = 0;
    for (int k = 0; k < 3; ++k)
        d[k] = src[k] - head[k], l += d[k] * d[k];
    l = sqrt(l);
    for (int k = 0; k < 3; ++k)
        b.head[k] = (float)head[k], b.dir[k] = (float)(d[k] / l);
    b.length = (float)l;
    return b;
}

static int setup(void **state)
{
    (void)state;
    g_app = test_app_with_camera(&g_cam, &g_log);
    const float grey[3] = {0.5f, 0.5f, 0.5f};
    /* the floor, top at y = 0; a pillar at x = 1.2 in front of z = 0 */
    assert_int_equal(game_app_add_box(g_app, (float[3]){-6, -0.2f, -6}, (float[3]){6, 0, 6}, grey, NULL), VFX_OK);
    assert_int_equal(game_app_add_box(g_app, (float[3]){1.1f, 0, 0.9f}, (float[3]){1.3f, 1.6f, 1.1f}, grey, NULL),
                     VFX_OK);
    g_app->beams_view = (vfx_beams_view){.type = VFX_TYPE_BEAMS_VIEW, .bloom = VFX_BEAMS_BLOOM_OFF};
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    game_app_destroy(g_app);
    return 0;
}

/* ------------------------------------------------ the float64 reference: a march of the depth */

typedef struct depth_ref {
    const ref_camera *cam;
    const float *depth; /* W x H, GL rows (bottom first) */
} depth_ref;

/* The surface seen at pixel (i, jb) (jb from the bottom), from its depth: false for the far plane. */
static bool ref_surface(const depth_ref *r, int i, int jb, double S[3])
{
    float d = r->depth[(size_t)jb * W + i];
    if (d >= 1.f)
        return false;
    double f[3], rt[3], up[3], dir[3];
    ref_camera_basis(r->cam, f, rt, up);
    ref_pixel_ray(r->cam, (uint32_t)i, (uint32_t)(H - 1 - jb), dir);
    double n = r->cam->near_plane, fa = r->cam->far_plane, z = 2.0 * d - 1.0;
    double ze = 2.0 * fa * n / ((fa + n) - z * (fa - n)); /* view depth of a GL perspective */
    double t = ze / (dir[0] * f[0] + dir[1] * f[1] + dir[2] * f[2]);
    for (int k = 0; k < 3; ++k)
        S[k] = r->cam->eye[k] + t * dir[k];
    return true;
}

/* 0 unknown, 1 in front, 2 behind the tangent plane of the surface at P's pixel (the shader's
 * rule, impact_depth.glsl, in float64). */
static int ref_classify(const depth_ref *r, const double P[3], double S[3], double nrm[3])
{
    double f[3], rt[3], up[3], q[3];
    ref_camera_basis(r->cam, f, rt, up);
    for (int k = 0; k < 3; ++k)
        q[k] = P[k] - r->cam->eye[k];
    double zc = q[0] * f[0] + q[1] * f[1] + q[2] * f[2];
    if (!(zc > 0))
        return 0;
    double t = tan(r->cam->fov_y * 0.5);
    double nx = (q[0] * rt[0] + q[1] * rt[1] + q[2] * rt[2]) / (zc * t * W / H);
    double ny = (q[0] * up[0] + q[1] * up[1] + q[2] * up[2]) / (zc * t);
    if (fabs(nx) > 1 || fabs(ny) > 1)
        return 0;
    int i = (int)fmin(floor((nx * 0.5 + 0.5) * W), W - 1), jb = (int)fmin(floor((ny * 0.5 + 0.5) * H), H - 1);
    if (!ref_surface(r, i, jb, S))
        return 0;
    double d[2][3];
    for (int a = 0; a < 2; ++a) {
        int di = a == 0, dj = a == 1;
        double A[3], B[3];
        bool ha = (a == 0 ? i < W - 1 : jb < H - 1) && ref_surface(r, i + di, jb + dj, A);
        bool hb = (a == 0 ? i > 0 : jb > 0) && ref_surface(r, i - di, jb - dj, B);
        double da2 = 0, db2 = 0;
        for (int k = 0; k < 3; ++k)
            da2 += (A[k] - S[k]) * (A[k] - S[k]) * ha, db2 += (S[k] - B[k]) * (S[k] - B[k]) * hb;
        for (int k = 0; k < 3; ++k)
            d[a][k] = ha && (!hb || da2 <= db2) ? A[k] - S[k] : (hb ? S[k] - B[k] : 0.0);
    }
    nrm[0] = d[0][1] * d[1][2] - d[0][2] * d[1][1];
    nrm[1] = d[0][2] * d[1][0] - d[0][0] * d[1][2];
    nrm[2] = d[0][0] * d[1][1] - d[0][1] * d[1][0];
    double l = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]), side = 0, behind = 0;
    for (int k = 0; k < 3; ++k)
        nrm[k] /= l, side += nrm[k] * (S[k] - r->cam->eye[k]);
    for (int k = 0; k < 3; ++k)
        nrm[k] *= side > 0 ? -1 : 1, behind += (P[k] - S[k]) * nrm[k];
    return behind < 0 ? 2 : 1;
}

/* The first front-to-behind crossing along src -> head -> R past it, bisected in float64. */
static bool ref_hit(const depth_ref *r, const double src[3], const double head[3], double R, double hit[3])
{
    double axis[3], len = 0;
    for (int k = 0; k < 3; ++k)
        axis[k] = head[k] - src[k], len += axis[k] * axis[k];
    len = sqrt(len);
    double total = len + R, S[3], n[3], prev[3] = {src[0], src[1], src[2]};
    int pc = ref_classify(r, prev, S, n);
    for (int j = 1; j <= 4096; ++j) { /* finer than the GPU's 128: the first crossing all the same */
        double s = total * j / 4096.0, Q[3];
        for (int k = 0; k < 3; ++k)
            Q[k] = src[k] + axis[k] / len * s;
        int c = ref_classify(r, Q, S, n);
        if (pc == 1 && c == 2) {
            double a[3], b[3];
            memcpy(a, prev, sizeof a), memcpy(b, Q, sizeof b);
            for (int it = 0; it < 60; ++it) {
                double m[3];
                for (int k = 0; k < 3; ++k)
                    m[k] = 0.5 * (a[k] + b[k]);
                int cm = ref_classify(r, m, S, n);
                if (cm == 0)
                    return false;
                memcpy(cm == 2 ? b : a, m, sizeof m);
            }
            for (int k = 0; k < 3; ++k)
                hit[k] = 0.5 * (a[k] + b[k]);
            return true;
        }
        memcpy(prev, Q, sizeof prev);
        pc = c;
    }
    return false;
}

static float *read_depth(void)
{
    rt_renderer_targets tg;
    rt_renderer_get_targets(g_app->renderer, &tg);
    float *d = malloc(sizeof(float) * W * H);
    assert_non_null(d);
    glGetTextureImage(tg.scene_depth, 0, GL_DEPTH_COMPONENT, GL_FLOAT, (GLsizei)(sizeof(float) * W * H), d);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    return d;
}

static double stat(const char *name)
{
    vfx_stats st = {.type = VFX_TYPE_STATS};
    assert_int_equal(g_app->api->get_stats(g_app->ctx, &st), VFX_OK);
    for (uint32_t i = 0; i < st.count; ++i)
        if (!strcmp(st.entries[i].name, name))
            return st.entries[i].value;
    fail_msg("stat %s not set", name);
    return 0;
}

/* ------------------------------------------------------------------------------ tests */

/* The app's beam entities, n of them, zeroed (respawned: the beams of the last test go). */
static vfx_beam *beam_entities(uint32_t n)
{
    game_app_clear_beams(g_app);
    assert_int_equal(game_app_add_beams(g_app, NULL, n), VFX_OK);
    uint32_t have;
    vfx_beam *b = game_app_beams(g_app, &have);
    assert_int_equal(have, n);
    return b;
}

/* A beam struck into the floor at an angle: the GPU's hit against the float64 march of the same
 * depth buffer, and against the floor's plane y = 0. Tolerances: both converge to the plane the
 * depth-reconstructed points span (the crossing is judged against the tangent plane, not the
 * pixel), so they differ by the float32 reconstruction of that plane: DEPTH32F near 1 keeps 2^-24
 * in window depth, dz = z^2/near x 2^-24 = 1e-5 m at 3.3 m, and the float32 unprojection adds a
 * few ulps of 3 m; 1e-3 m along a 45-degree beam covers 30x that. Against the analytic plane the
 * tangent plane of a pixel's neighbours is the floor's up to the same depth error: 2e-3 m. */
static void test_hit_matches_reference(void **state)
{
    (void)state;
    const double src[3] = {-1.5, 1.5, 0.2}, head[3] = {0.1, -0.1, 0.2}, R = 0.25;
    beam_entities(1)[0] = beam_from_to(src, head, (float)R);
    assert_int_equal(game_app_frame(g_app, DT), VFX_OK);
    volfx_beams_impact *im = volfx_beams_impact_of(g_app->ctx);
    assert_non_null(im);
    float gpu[1][8];
    assert_int_equal(volfx_beams_impact_debug_hits(im, gpu, 1), 1);
    assert_true(gpu[0][3] == 1.f);
    float *depth = read_depth();
    depth_ref r = {&g_cam, depth};
    double ref[3];
    assert_true(ref_hit(&r, src, head, R, ref));
    free(depth);
    double e_ref = 0, e_plane = 0;
    /* the analytic hit: src + s (head - src) at y = 0 */
    double s = src[1] / (src[1] - head[1]), plane[3];
    for (int k = 0; k < 3; ++k) {
        plane[k] = src[k] + s * (head[k] - src[k]);
        e_ref = fmax(e_ref, fabs(gpu[0][k] - ref[k]));
        e_plane = fmax(e_plane, fabs(gpu[0][k] - plane[k]));
    }
    printf("hit gpu (%.6f %.6f %.6f) ref (%.6f %.6f %.6f) |gpu-ref| %.2e |gpu-plane| %.2e normal (%.4f %.4f %.4f)\n",
           gpu[0][0], gpu[0][1], gpu[0][2], ref[0], ref[1], ref[2], e_ref, e_plane, gpu[0][4], gpu[0][5], gpu[0][6]);
    assert_true(e_ref < 1e-3);
    assert_true(e_plane < 2e-3);
    /* the floor's normal: float32 differences of neighbouring reconstructed points */
    assert_true(fabs(gpu[0][5] - 1.0) < 1e-3);
}

/* A beam whose head stops in the air, and one that passes behind the pillar and ends in the air
 * beyond it: no impact (the second crosses the pillar's depth, but not its surface). */
static void test_no_false_hit(void **state)
{
    (void)state;
    const double src[3] = {-1.5, 1.2, 0.0}, head[3] = {0.0, 1.0, 0.0};
    vfx_beam *b = beam_entities(2);
    b[0] = beam_from_to(src, head, 0.2f);
    /* behind the pillar (x 1.1..1.3, z 0.9..1.1) as the camera at z = 3 sees it: z = -0.5 */
    const double s2[3] = {0.6, 0.8, -0.5}, h2[3] = {2.2, 0.8, -0.5};
    b[1] = beam_from_to(s2, h2, 0.1f);
    assert_int_equal(game_app_frame(g_app, DT), VFX_OK);
    float gpu[2][8];
    assert_int_equal(volfx_beams_impact_debug_hits(volfx_beams_impact_of(g_app->ctx), gpu, 2), 2);
    assert_true(gpu[0][3] == 0.f);
    assert_true(gpu[1][3] == 0.f);
}

/* Sparks from a beam struck into the floor, 45 frames at 30 Hz: none ever below the floor's
 * top (y = 0). A spark is put back on the tangent plane the depth gives, 3 mm above it; the
 * plane's error is the depth's (1e-5 m, above), so -1e-3 m has 100x room. Some sparks must
 * reach the floor (they fall), so the test is not passed by sparks that never come down. */
static void test_sparks_stay_above_floor(void **state)
{
    (void)state;
    const double src[3] = {-1.5, 1.5, 0.2}, head[3] = {0.1, -0.1, 0.2};
    beam_entities(1)[0] = beam_from_to(src, head, 0.25f);
    static float sp[VOLFX_IMPACT_MAX_SPARKS][12];
    uint32_t near_floor = 0, live_max = 0;
    double lowest = 1e9;
    for (int f = 0; f < 45; ++f) {
        assert_int_equal(game_app_frame(g_app, DT), VFX_OK);
        uint32_t n = volfx_beams_impact_debug_sparks(volfx_beams_impact_of(g_app->ctx), sp, VOLFX_IMPACT_MAX_SPARKS);
        uint32_t live = 0;
        for (uint32_t i = 0; i < n; ++i) {
            if (!(sp[i][7] > 0) || sp[i][3] >= sp[i][7])
                continue;
            live++;
            lowest = fmin(lowest, sp[i][1]);
            near_floor += sp[i][1] < 0.02f && sp[i][3] > 0.2f;
            if (sp[i][1] < -1e-3f)
                fail_msg("frame %d: spark %u at (%g %g %g), below the floor", f, i, (double)sp[i][0], (double)sp[i][1], (double)sp[i][2]);
        }
        live_max = live > live_max ? live : live_max;
    }
    printf("sparks: at most %u alive, lowest y %.5f, %u spark-frames on the floor\n", live_max, lowest, near_floor);
    assert_true(live_max > 20);
    assert_true(near_floor > 0);
}

/* 200 beams struck into the floor: every one an impact, the sparks bounded by the pool, and the
 * stats (read back without a stall, so a few frames late: settled with dt = 0 frames, which
 * neither emit nor move) equal to what the pools hold. */
static void test_counts_bounded(void **state)
{
    (void)state;
    uint32_t n = 200;
    vfx_beam *b = beam_entities(n);
    for (uint32_t i = 0; i < n; ++i) {
        double x = -1.5 + 3.0 * (i % 20) / 19.0, z = -1.0 + 1.5 * (i / 20) / 9.0;
        const double src[3] = {x - 0.5, 1.5, z}, head[3] = {x + 0.1, -0.1, z};
        b[i] = beam_from_to(src, head, 0.05f);
    }
    for (int f = 0; f < 6; ++f)
        assert_int_equal(game_app_frame(g_app, DT), VFX_OK);
    for (int f = 0; f < 4; ++f)
        assert_int_equal(game_app_frame(g_app, 0.f), VFX_OK);
    static float sp[VOLFX_IMPACT_MAX_SPARKS][12];
    uint32_t pool = volfx_beams_impact_debug_sparks(volfx_beams_impact_of(g_app->ctx), sp, VOLFX_IMPACT_MAX_SPARKS);
    uint32_t live = 0;
    for (uint32_t i = 0; i < pool; ++i)
        live += sp[i][7] > 0 && sp[i][3] < sp[i][7];
    double impacts = stat("beams.impacts"), sparks = stat("beams.sparks");
    printf("impacts %.0f, sparks %.0f (pool %u, %u alive)\n", impacts, sparks, pool, live);
    assert_int_equal(pool, VOLFX_IMPACT_MAX_SPARKS);
    assert_true(impacts >= n - 10); /* beams hidden behind the pillar make none */
    assert_true(sparks <= VOLFX_IMPACT_MAX_SPARKS);
    assert_true(sparks == live);
    assert_true(live > VOLFX_IMPACT_MAX_SPARKS / 2); /* 200 impacts x 6 a frame fill the pool */
}

/* Plugin api 3's lights for one beam struck into the floor: its trail as a line light from head
 * to source, its head as a point, and (once read back) the impact as a point half a radius above
 * the hit; a short array gets the first ones and the total; a wrong version is refused. */
static void test_lights(void **state)
{
    (void)state;
    vfx_plugin_api api = {.type = VFX_TYPE_PLUGIN_API};
    assert_int_equal(vfx_plugin_entry(VFX_ABI_VERSION, &g_app->host, &api), VFX_OK);
    assert_non_null(api.get_lights);
    const double src[3] = {-1.5, 1.5, 0.2}, head[3] = {0.1, -0.1, 0.2}, R = 0.25;
    beam_entities(1)[0] = beam_from_to(src, head, (float)R);
    for (int f = 0; f < 5; ++f)
        assert_int_equal(game_app_frame(g_app, DT), VFX_OK);
    vfx_light l[8];
    vfx_lights out = {.type = VFX_TYPE_LIGHTS, .capacity = 8, .lights = l};
    assert_int_equal(api.get_lights(g_app->ctx, &out), VFX_OK);
    assert_int_equal(out.total, 3);
    assert_int_equal(out.count, 3);
    assert_true(stat("beams.lights") == 3);
    assert_int_equal(l[0].kind, VFX_LIGHT_LINE);
    assert_int_equal(l[0].source, VFX_LIGHT_BEAM_BODY);
    assert_int_equal(l[1].kind, VFX_LIGHT_POINT);
    assert_int_equal(l[1].source, VFX_LIGHT_BEAM_HEAD);
    assert_int_equal(l[2].source, VFX_LIGHT_BEAM_IMPACT);
    for (int k = 0; k < 3; ++k) {
        /* the beam as the host gave it, in float (the plugin normalised D in double) */
        assert_true(fabs(l[0].p0[k] - head[k]) < 1e-5 && fabs(l[0].p1[k] - src[k]) < 1e-5);
        double hit = src[k] + src[1] / (src[1] - head[1]) * (head[k] - src[k]) + (k == 1 ? 0.5 * R : 0.0);
        assert_true(fabs(l[2].p0[k] - hit) < 2e-3); /* the hit's tolerance (test above) */
    }
    assert_true(fabs(fmaxf(l[0].color[0], fmaxf(l[0].color[1], l[0].color[2])) - 1.f) < 1e-6);
    assert_true(l[0].intensity > 0 && l[2].radius > 0);
    out.capacity = 1;
    assert_int_equal(api.get_lights(g_app->ctx, &out), VFX_OK);
    assert_int_equal(out.count, 1);
    assert_int_equal(out.total, 3);
    out.type = (vfx_struct_type)7;
    assert_int_equal(api.get_lights(g_app->ctx, &out), VFX_ERR_ABI);
    assert_true(test_last_error_is(&api, g_app->ctx, VFX_LOG_ID_STRUCT_TYPE, "vfx_lights has type 7"));
}

/* A head 0.5 R above the floor still strikes it: the hit is searched R past the head (a head
 * within its radius of a surface touches it), and lands on the floor's plane within the hit's
 * tolerance (test_hit_matches_reference). A march stopped at the head finds nothing. */
static void test_head_near_floor_hits(void **state)
{
    (void)state;
    const double R = 0.2, src[3] = {-0.4, 1.5, 0.2}, head[3] = {0.1, 0.5 * R, 0.2};
    beam_entities(1)[0] = beam_from_to(src, head, (float)R);
    assert_int_equal(game_app_frame(g_app, DT), VFX_OK);
    float gpu[1][8];
    assert_int_equal(volfx_beams_impact_debug_hits(volfx_beams_impact_of(g_app->ctx), gpu, 1), 1);
    printf("head 0.5 R above the floor: hit %g at (%.4f %.4f %.4f)\n", gpu[0][3], gpu[0][0], gpu[0][1], gpu[0][2]);
    assert_true(gpu[0][3] == 1.f);
    assert_true(fabs(gpu[0][1]) < 2e-3);
}

/* A beam aimed at the sky (its head in the air, nothing within R past it) gives its body and head
 * lights and no impact light: none at the origin, where an unset hit would put one. */
static void test_sky_beam_no_impact_light(void **state)
{
    (void)state;
    vfx_plugin_api api = {.type = VFX_TYPE_PLUGIN_API};
    assert_int_equal(vfx_plugin_entry(VFX_ABI_VERSION, &g_app->host, &api), VFX_OK);
    const double src[3] = {-0.5, 0.6, 0.2}, head[3] = {0.2, 2.5, 0.0};
    beam_entities(1)[0] = beam_from_to(src, head, 0.2f);
    for (int f = 0; f < 5; ++f) /* impacts are read back 1-3 frames late */
        assert_int_equal(game_app_frame(g_app, DT), VFX_OK);
    vfx_light l[8];
    vfx_lights out = {.type = VFX_TYPE_LIGHTS, .capacity = 8, .lights = l};
    assert_int_equal(api.get_lights(g_app->ctx, &out), VFX_OK);
    assert_int_equal(out.total, 2);
    for (uint32_t i = 0; i < out.count; ++i) {
        assert_true(l[i].source != VFX_LIGHT_BEAM_IMPACT);
        assert_false(l[i].p0[0] == 0 && l[i].p0[1] == 0 && l[i].p0[2] == 0);
    }
}

/* Irradiance at distance d from the middle of a segment of length L (I per unit length), on a
 * surface facing it: the integral of I cos(theta) / r^2 over the segment by 5-point
 * Gauss-Legendre on 2,000 pieces, in double (independent of the plugin's closed form). */
static double line_irradiance(double I, double L, double d)
{
    static const double x[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
    static const double w[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
                                0.2369268850561891};
    const int pieces = 2000;
    double e = 0, hp = L / pieces / 2;
    for (int p = 0; p < pieces; ++p) {
        double c = -L / 2 + (2 * p + 1) * hp;
        for (int k = 0; k < 5; ++k) {
            double s = c + hp * x[k], r2 = s * s + d * d;
            e += w[k] * hp * I * (d / sqrt(r2)) / r2;
        }
    }
    return e;
}

/* The lights' formulas against their contract, computed independently: a line light's intensity
 * 3 x intensity x 2^exposure x b / 0.5 per unit length and a head's 4 x ... x a, both times the
 * colour's largest channel (the colour divided by it); a line's radius is where its irradiance,
 * facing the segment's middle, falls to 1/256 of that at 1 unit: at most 1/256 there (1e-6 of
 * quadrature slack) and not far beyond it (above 1/256 x 0.99: the radius is the one asked, not
 * a loose bound); a point's I / d^2 gives 16. Lengths 0.05 (point-like), 2.26 (the
 * transition, where the former 16 sqrt(L / 2) fell 13% short) and 40 (line-like). */
static void test_light_formulas(void **state)
{
    (void)state;
    vfx_plugin_api api = {.type = VFX_TYPE_PLUGIN_API};
    assert_int_equal(vfx_plugin_entry(VFX_ABI_VERSION, &g_app->host, &api), VFX_OK);
    const double lens[3] = {0.05, 2.26, 40.0};
    for (int c = 0; c < 3; ++c) {
        const double src[3] = {-0.5, 1.2 + lens[c], 0.2}, head[3] = {-0.5, 1.2, 0.2};
        vfx_beam *b = beam_entities(1);
        b[0] = beam_from_to(src, head, 0.1f);
        b[0].intensity = 2.f, b[0].exposure = 1.f, b[0].a = 0.3f, b[0].b = 0.4f;
        b[0].color[0] = 0.5f, b[0].color[1] = 0.25f, b[0].color[2] = 0.1f;
        assert_int_equal(game_app_frame(g_app, DT), VFX_OK);
        vfx_light l[8];
        vfx_lights out = {.type = VFX_TYPE_LIGHTS, .capacity = 8, .lights = l};
        assert_int_equal(api.get_lights(g_app->ctx, &out), VFX_OK);
        assert_true(out.count >= 2);
        assert_int_equal(l[0].kind, VFX_LIGHT_LINE);
        assert_int_equal(l[1].source, VFX_LIGHT_BEAM_HEAD);
        double gain = 2.0 * 2.0, cmax = 0.5;
        double want_line = 3.0 * gain * 0.4 / 0.5 * cmax, want_head = 4.0 * gain * 0.3 * cmax;
        assert_true(fabs(l[0].intensity - want_line) <= 1e-6 * want_line);
        assert_true(fabs(l[1].intensity - want_head) <= 1e-6 * want_head);
        assert_true(fabsf(l[0].color[0] - 1.f) < 1e-6f && fabsf(l[0].color[1] - 0.5f) < 1e-6f
                    && fabsf(l[0].color[2] - 0.2f) < 1e-6f);
        double L = lens[c], I = l[0].intensity;
        double ratio = line_irradiance(I, L, l[0].radius) / line_irradiance(I, L, 1.0);
        printf("line light L %.2f: radius %.3f, irradiance there / at 1 unit = 1/%.1f\n", L, (double)l[0].radius,
               1.0 / ratio);
        assert_true(ratio <= (1.0 + 1e-6) / 256.0);
        assert_true(ratio >= 0.99 / 256.0);
        assert_true(l[1].radius == 16.f); /* I / 16^2 = (I / 1^2) / 256 */
    }
}

/* The engine's own depth (tests/common/depth_modes.h): the same hit against the same float64
 * reference with the same bounds, the same non-hits, and sparks that stay above the floor, when
 * the plugin gets the host's depth in a renderbuffer, reversed-Z with an infinite far plane under
 * GL_ZERO_TO_ONE, row-flipped, and all three at once. The reversed depth is rounded once to
 * float32 from the view depth (double): near/D keeps 2^-24 relative, a view depth error of
 * 2^-24 D = 2e-7 m at 3.3 m, under the standard path's 1e-5 m, so the bounds hold as they are. */
static void in_depth_mode(int mode, void (*test)(void **))
{
    depth_mode_set(g_app, mode);
    test(NULL);
    depth_mode_set(g_app, DEPTH_STANDARD);
}

static void test_own_depth_renderbuffer(void **state)
{
    (void)state;
    in_depth_mode(DEPTH_RENDERBUFFER, test_hit_matches_reference);
    in_depth_mode(DEPTH_RENDERBUFFER, test_no_false_hit);
}

static void test_own_depth_reversed_z(void **state)
{
    (void)state;
    in_depth_mode(DEPTH_REVERSED, test_hit_matches_reference);
    in_depth_mode(DEPTH_REVERSED, test_no_false_hit);
}

static void test_own_depth_flipped(void **state)
{
    (void)state;
    in_depth_mode(DEPTH_FLIPPED, test_hit_matches_reference);
    in_depth_mode(DEPTH_FLIPPED, test_no_false_hit);
}

static void test_own_depth_engine(void **state)
{
    (void)state;
    in_depth_mode(DEPTH_ENGINE, test_hit_matches_reference);
    in_depth_mode(DEPTH_ENGINE, test_no_false_hit);
    in_depth_mode(DEPTH_ENGINE, test_sparks_stay_above_floor);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hit_matches_reference),
        cmocka_unit_test(test_no_false_hit),
        cmocka_unit_test(test_sparks_stay_above_floor),
        cmocka_unit_test(test_counts_bounded),
        cmocka_unit_test(test_lights),
        cmocka_unit_test(test_head_near_floor_hits),
        cmocka_unit_test(test_sky_beam_no_impact_light),
        cmocka_unit_test(test_light_formulas),
        cmocka_unit_test(test_own_depth_renderbuffer),
        cmocka_unit_test(test_own_depth_reversed_z),
        cmocka_unit_test(test_own_depth_flipped),
        cmocka_unit_test(test_own_depth_engine),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
