/* test_camera.c — the runtime camera (runtime/gfx/camera.h) against the float64 reference
 * camera (reference/camera_ref.h): its matrices put every reference pixel-centre ray through
 * that pixel's centre, and equal the reference's matrices to float rounding. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <float.h>
#include <math.h>
#include <string.h>

#include "camera_ref.h"
#include "gfx/camera.h"

static const rt_camera k_cams[] = {
    {{0, 2, 6}, {0, 0.5, 0}, {0, 1, 0}, 60.0 * M_PI / 180.0, 320, 180, 0.05, 200.0}, /* the game's default */
    {{0.3, 0.4, 3.5}, {0, 0, 0}, {0, 1, 0}, 0.9, 48, 36, 0.05, 50},
    {{-2, 1, -3}, {1, -0.5, 2}, {0.2, 1, 0.1}, 1.9, 17, 61, 0.5, 1e4},  /* tilted up, wide, tall */
    {{3e5, 1e3, 2e5}, {3e5 - 4, 1e3, 2e5 - 3}, {0, 1, 0}, 0.8, 64, 48, 0.1, 100}, /* far from 0 */
};

static ref_camera as_ref(const rt_camera *c)
{
    return (ref_camera){{c->eye[0], c->eye[1], c->eye[2]}, {c->target[0], c->target[1], c->target[2]},
                        {c->up[0], c->up[1], c->up[2]}, c->fov_y, c->width, c->height, c->near_plane, c->far_plane};
}

/* Each element equals the reference's: both round the same float64 value once; 1 ulp of slack
 * for a compiler that contracts a product into an FMA in one of them. */
static void test_matrices_equal_reference(void **state)
{
    (void)state;
    for (size_t n = 0; n < sizeof k_cams / sizeof k_cams[0]; ++n) {
        float v[16], p[16], rv[16], rp[16];
        rt_camera_view(&k_cams[n], v);
        rt_camera_proj(&k_cams[n], p);
        ref_camera rc = as_ref(&k_cams[n]);
        ref_camera_matrices(&rc, rv, rp);
        for (int i = 0; i < 16; ++i) {
            assert_true(fabsf(v[i] - rv[i]) <= FLT_EPSILON * fmaxf(1.f, fabsf(rv[i])));
            assert_true(fabsf(p[i] - rp[i]) <= FLT_EPSILON * fmaxf(1.f, fabsf(rp[i])));
        }
    }
}

/* A point 50 units along the reference's ray through pixel (i, j), taken through the runtime's
 * view and projection in float64, lands on that pixel's centre. The matrices are float32: near
 * the origin an element's rounding (2^-24 relative) moves the point by ~1e-5 pixel, under the
 * 1e-3 allowed. The camera 3.6e5 units out rounds its view translation to float32's ulp there
 * (2^-24 x 3.6e5 ~ 0.02 units per axis; a pixel at 50 units is 50 x 2 tan(0.4) / 48 ~ 0.88
 * units): ~0.03 pixel, allowed 0.1 (what the frame view's origin is for). */
static void test_pixel_rays_hit_pixel_centres(void **state)
{
    (void)state;
    for (size_t n = 0; n < sizeof k_cams / sizeof k_cams[0]; ++n) {
        const rt_camera *c = &k_cams[n];
        ref_camera rc = as_ref(c);
        float v[16], p[16];
        rt_camera_view(c, v);
        rt_camera_proj(c, p);
        double tol = c->eye[0] > 1e5 ? 1e-1 : 1e-3;
        for (uint32_t j = 0; j < c->height; j += 5)
            for (uint32_t i = 0; i < c->width; i += 3) {
                double d[3], w[4], e[4] = {0, 0, 0, 0}, cl[4] = {0, 0, 0, 0};
                ref_pixel_ray(&rc, i, j, d);
                for (int k = 0; k < 3; ++k)
                    w[k] = c->eye[k] + 50.0 * d[k];
                w[3] = 1;
                for (int r = 0; r < 4; ++r)
                    for (int k = 0; k < 4; ++k)
                        e[r] += (double)v[k * 4 + r] * w[k];
                for (int r = 0; r < 4; ++r)
                    for (int k = 0; k < 4; ++k)
                        cl[r] += (double)p[k * 4 + r] * e[k];
                double px = (cl[0] / cl[3] * 0.5 + 0.5) * c->width, py = (0.5 - cl[1] / cl[3] * 0.5) * c->height;
                assert_true(fabs(px - (i + 0.5)) < tol);
                assert_true(fabs(py - (j + 0.5)) < tol);
            }
    }
}

static void test_basis_and_moves(void **state)
{
    (void)state;
    rt_camera c = k_cams[2];
    ref_camera rc = as_ref(&c);
    double f[3], r[3], u[3], rf[3], rr[3], ru[3];
    rt_camera_basis(&c, f, r, u);
    ref_camera_basis(&rc, rf, rr, ru);
    for (int k = 0; k < 3; ++k) { /* float64 both: the same to a few ulp */
        assert_true(fabs(f[k] - rf[k]) < 1e-15);
        assert_true(fabs(r[k] - rr[k]) < 1e-15);
        assert_true(fabs(u[k] - ru[k]) < 1e-15);
    }
    const double d[3] = {0.5, -1, 2};
    rt_camera_translate(&c, d);
    for (int k = 0; k < 3; ++k) {
        assert_true(c.eye[k] == k_cams[2].eye[k] + d[k]);
        assert_true(c.target[k] == k_cams[2].target[k] + d[k]);
    }
    /* a yaw keeps the horizontal distance to the target (the offset turns clockwise seen from
     * above: atan2(x, z) goes down by yaw); dy adds to the height */
    c = k_cams[0];
    rt_camera_orbit(&c, 0.7, 0.25);
    double h0 = hypot(k_cams[0].eye[0] - k_cams[0].target[0], k_cams[0].eye[2] - k_cams[0].target[2]);
    assert_true(fabs(hypot(c.eye[0] - c.target[0], c.eye[2] - c.target[2]) - h0) < 1e-12);
    assert_true(fabs(c.eye[1] - (k_cams[0].eye[1] + 0.25)) < 1e-12);
    assert_true(fabs(atan2(c.eye[0], c.eye[2]) - atan2(k_cams[0].eye[0], k_cams[0].eye[2]) + 0.7) < 1e-12);
}

static void test_check_refuses(void **state)
{
    (void)state;
    char err[256];
    assert_int_equal(rt_camera_check(&k_cams[0], err, sizeof err), VFX_OK);
    rt_camera bad[5];
    for (int i = 0; i < 5; ++i)
        bad[i] = k_cams[0];
    bad[0].width = 0;
    bad[1].fov_y = M_PI;
    bad[2].near_plane = 0;
    bad[3].far_plane = bad[3].near_plane;
    bad[4].eye[1] = NAN;
    for (int i = 0; i < 5; ++i)
        assert_int_equal(rt_camera_check(&bad[i], err, sizeof err), VFX_ERR_INVALID_ARGUMENT);
    assert_int_equal(rt_camera_check(NULL, err, sizeof err), VFX_ERR_INVALID_ARGUMENT);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matrices_equal_reference),
        cmocka_unit_test(test_pixel_rays_hit_pixel_centres),
        cmocka_unit_test(test_basis_and_moves),
        cmocka_unit_test(test_check_refuses),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
