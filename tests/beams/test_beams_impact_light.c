/* The sample host's lighting by the plugin's lights (issue 25): the closed-form irradiance of an
 * isotropic line segment (and of a point) on a Lambertian floor, as shaders/host/mesh.frag
 * computes it, against a float64 Gauss-Legendre quadrature over the segment, at every pixel of
 * the floor; a segment dipping through the floor (clipped to the half-space above it); a light
 * of an unknown kind refused. Runs the host renderer alone on llvmpipe (no plugin). */
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

#include "gfx/mesh_import.h"
#include "gfx/renderer.h"
#include "test_camera.h"
#include "test_util.h"

#define W 64
#define H 48

static const ref_camera g_cam = {{0.4, 3.0, 2.5}, {0, 0, 0}, {0, 1, 0}, 1.1, W, H, 0.05, 50};
static rt_gl_context *g_gl;
static rt_renderer *g_r;
static rt_mesh_gpu g_floor;

static int setup(void **state)
{
    (void)state;
    g_gl = test_gl_or_skip();
    assert_int_equal(rt_renderer_create(NULL, &g_r), VFX_OK);
    assert_int_equal(rt_renderer_set_hdr(g_r, true, 1.f), VFX_OK); /* RGBA16F linear radiance */
    assert_int_equal(rt_renderer_resize(g_r, W, H), VFX_OK);
    rt_mesh_data box;
    assert_int_equal(rt_mesh_make_box((float[3]){-6, -0.2f, -6}, (float[3]){6, 0, 6}, &box), VFX_OK);
    assert_int_equal(rt_mesh_upload(&box, &g_floor), VFX_OK);
    rt_mesh_data_free(&box);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    rt_mesh_gpu_destroy(&g_floor);
    rt_renderer_destroy(g_r);
    rt_gl_context_destroy(g_gl);
    return 0;
}

/* The floor's linear radiance (RGBA, GL rows) lit by these lights; drawn with its box
 * (rt_renderer_draw_mesh_bounded) when `bounded`. */
static void render_mesh(const vfx_light *l, uint32_t n, float *rgba, bool bounded)
{
    assert_int_equal(rt_renderer_set_lights(g_r, l, n), VFX_OK);
    rt_camera cam = test_rt_camera(&g_cam);
    float view[16], proj[16];
    rt_camera_view(&cam, view);
    rt_camera_proj(&cam, proj);
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    rt_renderer_begin_scene(g_r, view, proj, (float[3]){0, 0, 0});
    if (bounded)
        rt_renderer_draw_mesh_bounded(g_r, &g_floor, identity, (float[3]){1, 1, 1}, (float[3]){-6, -0.2f, -6},
                                      (float[3]){6, 0, 6});
    else
        rt_renderer_draw_mesh(g_r, &g_floor, identity, (float[3]){1, 1, 1});
    rt_renderer_targets tg;
    rt_renderer_end_scene(g_r, &tg);
    glGetTextureImage(tg.scene_color, 0, GL_RGBA, GL_FLOAT, (GLsizei)(sizeof(float) * 4 * W * H), rgba);
    assert_int_equal(glGetError(), GL_NO_ERROR);
}

static void render(const vfx_light *l, uint32_t n, float *rgba)
{
    render_mesh(l, n, rgba, false);
}

/* float64 Gauss-Legendre (5 points on each of 4000 pieces) of I max(n.(p - x), 0) / |p - x|^3
 * over the segment, n = +y: the reference the closed form must meet. A kink where the segment
 * crosses the floor's plane costs O(piece^2) there: below 1e-9 relative at 4000 pieces. */
static double quad_irradiance(const vfx_light *l, const double x[3])
{
    static const double gx[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                                 0.9061798459386640};
    static const double gw[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
                                 0.2369268850561891};
    if (l->kind == VFX_LIGHT_POINT) {
        double v[3] = {l->p0[0] - x[0], l->p0[1] - x[1], l->p0[2] - x[2]};
        double d2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        return l->intensity * fmax(v[1], 0.0) / (d2 * sqrt(d2));
    }
    double e[3] = {l->p1[0] - l->p0[0], l->p1[1] - l->p0[1], l->p1[2] - l->p0[2]};
    double L = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]), sum = 0;
    int pieces = 4000;
    for (int k = 0; k < pieces; ++k)
        for (int q = 0; q < 5; ++q) {
            double t = (k + 0.5 + 0.5 * gx[q]) / pieces, v[3];
            for (int c = 0; c < 3; ++c)
                v[c] = l->p0[c] + t * e[c] - x[c];
            double d2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
            sum += 0.5 * gw[q] / pieces * fmax(v[1], 0.0) / (d2 * sqrt(d2));
        }
    return l->intensity * L * sum;
}

static double seg_dist(const vfx_light *l, const double x[3])
{
    double e[3], a[3], ee = 0, ae = 0;
    for (int c = 0; c < 3; ++c)
        e[c] = l->p1[c] - l->p0[c], a[c] = x[c] - l->p0[c], ee += e[c] * e[c], ae += a[c] * e[c];
    double t = ee > 0 ? fmin(fmax(ae / ee, 0.0), 1.0) : 0.0, d2 = 0;
    for (int c = 0; c < 3; ++c)
        d2 += (a[c] - t * e[c]) * (a[c] - t * e[c]);
    return sqrt(d2);
}

/* Every floor pixel: E from the image, pi (lit - unlit) / unlit x the shader's sun term
 * (0.25 + 0.75 n.l, l = normalize(0.4, 0.8, 0.45): mesh.frag's default look, which multiplies
 * the same albedo and checker, so they cancel), against the quadrature. Tolerance: both images
 * are RGBA16F (11-bit significands: a relative 2^-11 each), so E carries pi k (lit + unlit)
 * 2^-11 / unlit, and 2e-5 E for the float32 closed form (no cancellation at these distances);
 * pixels within 5 cm of a segment are left out (there E grows as 1/distance and the pixel's
 * footprint decides it). */
static void check_lights(const vfx_light *l, uint32_t n, const char *what)
{
    static float base[W * H * 4], lit[W * H * 4];
    render(NULL, 0, base);
    render(l, n, lit);
    double k = 0.25 + 0.75 * 0.8 / sqrt(0.4 * 0.4 + 0.8 * 0.8 + 0.45 * 0.45);
    double worst = 0, emax = 0;
    uint32_t checked = 0;
    for (uint32_t j = 0; j < H; ++j)
        for (uint32_t i = 0; i < W; ++i) {
            double d[3], x[3];
            ref_pixel_ray(&g_cam, i, j, d);
            double t = -g_cam.eye[1] / d[1];
            for (int c = 0; c < 3; ++c)
                x[c] = g_cam.eye[c] + t * d[c];
            if (!(t > 0) || fabs(x[0]) > 5.5 || fabs(x[2]) > 5.5)
                continue;
            bool near = false;
            for (uint32_t m = 0; m < n; ++m)
                near |= seg_dist(&l[m], x) < 0.05;
            if (near)
                continue;
            double ref = 0;
            for (uint32_t m = 0; m < n; ++m)
                ref += quad_irradiance(&l[m], x);
            size_t p = 4 * ((size_t)(H - 1 - j) * W + i);
            for (int c = 0; c < 3; ++c) {
                double b = base[p + c], v = lit[p + c];
                assert_true(b > 0.1);
                double e = M_PI * k * (v - b) / b;
                double tol = 1.5 * (M_PI * k * (v + b) * ldexp(1.0, -11) / b) + 2e-5 * ref + 1e-6;
                worst = fmax(worst, fabs(e - ref) / tol);
                if (fabs(e - ref) > tol)
                    fail_msg("%s: pixel (%u, %u) channel %d at (%.3f, %.3f): E %.6g, quadrature %.6g, |diff| %.3g > %.3g",
                             what, i, j, c, x[0], x[2], e, ref, fabs(e - ref), tol);
            }
            emax = fmax(emax, ref);
            checked++;
        }
    printf("%s: %u floor pixels, E up to %.3f, worst |E - quadrature| / tolerance %.3f\n", what, checked, emax, worst);
    assert_true(checked > W * H / 2);
    assert_true(emax > 0.5); /* the lights do light the floor */
}

static vfx_light line(float x0, float y0, float z0, float x1, float y1, float z1, float I)
{
    return (vfx_light){.kind = VFX_LIGHT_LINE, .p0 = {x0, y0, z0}, .p1 = {x1, y1, z1}, .color = {1, 1, 1},
                       .intensity = I, .radius = 100.f};
}

static void test_line_and_point(void **state)
{
    (void)state;
    vfx_light l[2] = {line(-1.5f, 1.0f, -0.5f, 1.2f, 0.6f, 0.3f, 2.f),
                      {.kind = VFX_LIGHT_POINT, .p0 = {0.8f, 0.5f, 0.9f}, .p1 = {0.8f, 0.5f, 0.9f},
                       .color = {1, 1, 1}, .intensity = 1.5f, .radius = 100.f}};
    check_lights(l, 1, "line");
    check_lights(l + 1, 1, "point");
    check_lights(l, 2, "line + point");
}

/* A segment that goes through the floor: only the part above it lights it (the clip). */
static void test_line_through_floor(void **state)
{
    (void)state;
    vfx_light l = line(-1.f, 0.8f, 1.f, 1.f, -0.5f, -0.5f, 1.f);
    check_lights(&l, 1, "line through the floor");
}

static void test_unknown_kind(void **state)
{
    (void)state;
    vfx_light l = line(0, 1, 0, 1, 1, 0, 1.f);
    l.kind = 9;
    assert_int_equal(rt_renderer_set_lights(g_r, &l, 1), VFX_ERR_ABI);
    assert_int_equal(rt_renderer_set_lights(g_r, NULL, 1), VFX_ERR_INVALID_ARGUMENT);
}

/* The per-mesh culling (rt_renderer_lights_near_box): a box far from every light gets none of
 * them, a box next to them keeps every one, and the reach it uses matches its bound: at the
 * reach the float64 quadrature of the strongest
 * light, straight below its middle, is under the cutoff, so a culled light adds nothing seen. */
static void test_cull_far_mesh(void **state)
{
    (void)state;
    vfx_light l[3] = {line(-1.f, 0.8f, 0.f, 1.f, 0.8f, 0.f, 4.f), line(0, 0.5f, -1, 0, 0.5f, 1, 1.f),
                      {.kind = VFX_LIGHT_POINT, .p0 = {0.5f, 0.3f, 0.5f}, .p1 = {0.5f, 0.3f, 0.5f},
                       .color = {1, 0.5f, 0.2f}, .intensity = 2.f, .radius = 40.f}};
    uint32_t keep[3] = {9, 9, 9};
    assert_int_equal(rt_renderer_lights_near_box(l, 3, (float[3]){-6, -0.2f, -6}, (float[3]){6, 0, 6}, keep), 3);
    assert_int_equal(keep[0], 0);
    assert_int_equal(keep[2], 2);
    assert_int_equal(rt_renderer_lights_near_box(l, 3, (float[3]){500, 0, 500}, (float[3]){510, 5, 510}, keep), 0);
    /* only the point reaches a box just past the lines' reach: the point's radius is 40 */
    float r0 = sqrtf(rt_renderer_light_reach2(&l[0]));
    assert_true(r0 < 200.f && r0 > 10.f);
    assert_int_equal(rt_renderer_lights_near_box(l, 3, (float[3]){-1, 0.8f - r0 - 1.f, -1}, (float[3]){1, 0.8f - r0 - 0.5f, 1}, keep), 0);
    assert_int_equal(rt_renderer_lights_near_box(l, 3, (float[3]){-1, 0.8f - r0 + 0.5f, -1}, (float[3]){1, 0.8f - r0 + 1.f, 1}, keep), 1);
    /* the bound behind the reach: at d = r0 below the segment's middle, facing it */
    double x[3] = {0, 0.8 - r0, 0};
    l[0].p0[1] = l[0].p1[1] = 0.8f;
    double E = quad_irradiance(&l[0], x);
    assert_true(E > 0);
    assert_true(E < RT_RENDERER_LIGHT_CUTOFF);
    /* drawn with its box, the floor keeps both near lights (the same image, bit for bit) and
     * loses a far one: the image with it equals the unlit one */
    static float all[W * H * 4], culled[W * H * 4], unlit[W * H * 4];
    render_mesh(l, 2, all, false);
    render_mesh(l, 2, culled, true);
    assert_memory_equal(all, culled, sizeof all);
    vfx_light far = line(36, 1, 0, 37, 1, 0, 4.f); /* 30 m from the box, past its 25.5 m reach */
    render_mesh(&far, 1, culled, true);
    render_mesh(NULL, 0, unlit, false);
    assert_memory_equal(unlit, culled, sizeof unlit);
    /* what the cut light would have added: under the cutoff's radiance (albedo 1, checker and
     * sun term <= 1), plus one half-float ulp of the unlit value */
    render_mesh(&far, 1, all, false);
    for (size_t i = 0; i < (size_t)W * H * 4; ++i)
        assert_true(fabsf(all[i] - unlit[i]) <= RT_RENDERER_LIGHT_CUTOFF / 3.14159265f + unlit[i] * 0x1p-10f);
    /* a light through NaN is never cut (it is the plugin's bug to see, not to hide) */
    l[1].p0[0] = NAN;
    assert_int_equal(rt_renderer_lights_near_box(l + 1, 1, (float[3]){500, 0, 500}, (float[3]){510, 5, 510}, keep), 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_line_and_point),
        cmocka_unit_test(test_line_through_floor),
        cmocka_unit_test(test_unknown_kind),
        cmocka_unit_test(test_cull_far_mesh),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
