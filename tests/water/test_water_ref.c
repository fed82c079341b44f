/* Tests of the float64 metaball reference itself (reference/water_ref.c) against
 * closed forms: one particle is a sphere of radius h(1 - T); two particles' merged waist. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "water_ref.h"

static ref_water_camera camera_z(uint32_t w, uint32_t h, double eye_z, double fov_deg)
{
    ref_water_camera c = {{0, 0, eye_z}, {0, 0, -1}, {0, 1, 0}, fov_deg * M_PI / 180.0, w, h};
    return c;
}

/* One particle: sqrt(P) = 1 - r/h = T  ->  sphere of radius R = h(1 - T) at the particle. */
static void test_single_particle_is_sphere(void **state)
{
    (void)state;
    ref_water_params p = ref_water_default_params();
    const float x = 0.1f, y = -0.05f, z = 0.0f;
    ref_water_camera cam = camera_z(64, 64, 1.0, 30.0);
    float *dist = malloc(64 * 64 * sizeof *dist), *nrm = malloc(3 * 64 * 64 * sizeof *nrm);
    char err[256];
    assert_int_equal(ref_water_render(&cam, &x, &y, &z, 1, &p, dist, nrm, NULL, err), 0);
    double R = p.h * (1.0 - p.threshold), c[3] = {x, y, z};
    uint32_t hits = 0;
    for (uint32_t j = 0; j < 64; ++j)
        for (uint32_t i = 0; i < 64; ++i) {
            double d[3], oc[3];
            ref_water_pixel_dir(&cam, i, j, d);
            for (int k = 0; k < 3; ++k) oc[k] = cam.eye[k] - c[k];
            double b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
            double disc = b * b - (oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - R * R);
            float t = dist[j * 64 + i];
            /* A ray whose chord through the sphere is shorter than the sampling step may fall
             * between two samples: only those grazing rays may disagree on hit/miss. */
            double chord = disc > 0 ? 2 * sqrt(disc) : 0;
            if (chord < p.step) continue;
            assert_true(t >= 0);
            hits++;
            double ta = -b - sqrt(disc);
            /* bisection to 1e-12 then float32 storage: 1e-6 absolute at t ~ 1 */
            assert_true(fabs(t - ta) < 1e-6);
            double q[3], nn[3];
            for (int k = 0; k < 3; ++k) q[k] = cam.eye[k] + ta * d[k] - c[k];
            for (int k = 0; k < 3; ++k) nn[k] = q[k] / R;
            double dot = 0;
            for (int k = 0; k < 3; ++k) dot += nn[k] * nrm[3 * (j * 64 + i) + k];
            assert_true(dot > 1 - 1e-6); /* normal = outward radial direction */
        }
    assert_true(hits > 20);
    free(dist);
    free(nrm);
}

/* Two particles at +-d/2 on x, merged (d < 2h(1 - T/sqrt 2)): on the plane x = 0 both are at
 * r = sqrt(d^2/4 + s^2), so sqrt(2)(1 - r/h) = T gives the waist s = sqrt(r^2 - d^2/4). The
 * centre pixel of an odd-sized image looks exactly along -z through x = y = 0. */
static void test_two_particles_waist(void **state)
{
    (void)state;
    ref_water_params p = ref_water_default_params();
    double d = 0.4;
    float x[2] = {(float)(-d / 2), (float)(d / 2)}, y[2] = {0, 0}, z[2] = {0, 0};
    ref_water_camera cam = camera_z(33, 33, 2.0, 20.0);
    float dist[33 * 33];
    char err[256];
    assert_int_equal(ref_water_render(&cam, x, y, z, 2, &p, dist, NULL, NULL, err), 0);
    double dd = (double)x[1] - x[0];
    double r = p.h * (1 - p.threshold / sqrt(2.0));
    double s = sqrt(r * r - dd * dd / 4);
    assert_true(fabs(dist[16 * 33 + 16] - (2.0 - s)) < 1e-6);
    /* Separated (d > 2h): two spheres, the gap at x = 0 is a miss. */
    x[0] = -0.7f; x[1] = 0.7f;
    assert_int_equal(ref_water_render(&cam, x, y, z, 2, &p, dist, NULL, NULL, err), 0);
    assert_true(dist[16 * 33 + 16] < 0);
}

/* Every hit lies on I = 0 by the brute-force field (no grid), the normal is -grad I / |grad I|
 * from brute force, and the grid never drops a particle: same image at h/32 and h/64 except
 * pixels whose feature is thinner than a step. */
static void test_blobs_against_brute_force_field(void **state)
{
    (void)state;
    enum { N = 300, W = 48, H = 40 };
    float x[N], y[N], z[N];
    ref_water_blobs(N, 4, 1.0, 0.35, 7, x, y, z);
    ref_water_params p = ref_water_default_params();
    ref_water_camera cam = {{0.3, 0.5, 4.0}, {-0.05, -0.1, -1}, {0, 1, 0}, 0.9, W, H};
    float dist[W * H], nrm[3 * W * H], dist2[W * H];
    char err[256];
    ref_water_stats st;
    assert_int_equal(ref_water_render(&cam, x, y, z, N, &p, dist, nrm, &st, err), 0);
    assert_true(st.hits > W * H / 10);
    for (uint32_t pix = 0; pix < W * H; ++pix) {
        if (dist[pix] < 0) continue;
        double dir[3], q[3], g[3];
        ref_water_pixel_dir(&cam, pix % W, pix / W, dir);
        for (int k = 0; k < 3; ++k) q[k] = cam.eye[k] + dist[pix] * dir[k];
        double f = ref_water_field(x, y, z, N, &p, q, g);
        /* float32 t (rel 6e-8 of t ~ 4) times |grad I| (<= a few / h): well under 1e-4 */
        assert_true(fabs(f) < 1e-4);
        double gl = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        double dot = -(g[0] * nrm[3 * pix] + g[1] * nrm[3 * pix + 1] + g[2] * nrm[3 * pix + 2]) / gl;
        assert_true(dot > 1 - 1e-3);
    }
    p.step = p.h / 64;
    assert_int_equal(ref_water_render(&cam, x, y, z, N, &p, dist2, NULL, NULL, err), 0);
    ref_water_error e;
    assert_int_equal(ref_water_compare(dist, NULL, dist2, NULL, W * H, p.h, &e), 0);
    /* Halving the step only finds features thinner than h/32: at most a few pixels. */
    assert_true(e.hole_rate < 0.01);
    assert_true(e.false_hit_rate == 0.0);
    assert_true(e.dist_p99_rel_h < 1e-3);
}

/* NaN positions are skipped and counted: the image equals the one without them. */
static void test_nan_particles_skipped(void **state)
{
    (void)state;
    float x[3] = {0, NAN, 0.2f}, y[3] = {0, 0, INFINITY}, z[3] = {0, 0, 0};
    float xs[1] = {0}, ys[1] = {0}, zs[1] = {0};
    ref_water_params p = ref_water_default_params();
    ref_water_camera cam = camera_z(32, 32, 1.0, 30.0);
    float a[32 * 32], b[32 * 32];
    ref_water_stats st;
    char err[256];
    assert_int_equal(ref_water_render(&cam, x, y, z, 3, &p, a, NULL, &st, err), 0);
    assert_int_equal(st.nan_skipped, 2);
    assert_int_equal(ref_water_render(&cam, xs, ys, zs, 1, &p, b, NULL, NULL, err), 0);
    assert_memory_equal(a, b, sizeof a);
    assert_true(st.hits > 0);
}

static void test_zero_particles_and_eye_inside(void **state)
{
    (void)state;
    ref_water_params p = ref_water_default_params();
    ref_water_camera cam = camera_z(16, 16, 0.0, 60.0);
    float d[256];
    char err[256];
    ref_water_stats st;
    assert_int_equal(ref_water_render(&cam, NULL, NULL, NULL, 0, &p, d, NULL, &st, err), 0);
    for (int k = 0; k < 256; ++k) assert_true(d[k] == -1.0f);
    assert_int_equal(st.samples, 0);
    /* Eye at the centre of one particle: I > 0 at the eye, every ray starts inside: t = 0. */
    float x = 0, y = 0, z = 0;
    assert_int_equal(ref_water_render(&cam, &x, &y, &z, 1, &p, d, NULL, NULL, err), 0);
    for (int k = 0; k < 256; ++k) assert_true(d[k] == 0.0f);
    /* Bad camera: refused with a message. */
    cam.width = 0;
    err[0] = 0;
    assert_int_equal(ref_water_render(&cam, &x, &y, &z, 1, &p, d, NULL, NULL, err), -1);
    assert_true(strstr(err, "camera") != NULL);
}

/* h tiny against the extent: the grid's cell count is capped (cells grow) and results stay
 * exact; a lone tiny particle is still a sphere of radius h(1 - T). */
static void test_tiny_h(void **state)
{
    (void)state;
    ref_water_params p = ref_water_default_params();
    p.h = 1e-3;
    p.step = p.h / 32;
    float x[2] = {0, 1000}, y[2] = {0, 1000}, z[2] = {0, -1000};
    ref_water_camera cam = camera_z(9, 9, 0.01, 1.0);
    float d[81];
    char err[256];
    assert_int_equal(ref_water_render(&cam, x, y, z, 2, &p, d, NULL, NULL, err), 0);
    double R = p.h * (1 - p.threshold);
    assert_true(fabs(d[4 * 9 + 4] - (0.01 - R)) < 1e-7);
}

static void test_compare_metrics(void **state)
{
    (void)state;
    float ref[4] = {1.0f, 2.0f, -1.0f, -1.0f}, got[4] = {1.061f, -1.0f, 3.0f, -1.0f};
    float rn[12] = {0, 0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0}, gn[12] = {0, 1, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0};
    ref_water_error e;
    assert_int_equal(ref_water_compare(got, gn, ref, rn, 4, 0.61, &e), 0);
    assert_true(fabs(e.hole_rate - 0.5) < 1e-12);
    assert_true(fabs(e.false_hit_rate - 0.5) < 1e-12);
    assert_true(fabs(e.dist_mean_rel_h - 0.1) < 1e-5);
    assert_true(fabs(e.normal_mean_deg - 45.0) < 1e-4);
}

/* The paper's layout: 24x24 per layer, layers stacked at `spacing`. */
static void test_layers(void **state)
{
    (void)state;
    enum { N = 4096 };
    float *x = malloc(N * sizeof *x), *y = malloc(N * sizeof *y), *z = malloc(N * sizeof *z);
    ref_water_layers(N, 0.3, x, y, z);
    assert_true(fabs(x[0] + 11.5f * 0.3f) < 1e-6 && fabs(x[23] - 11.5f * 0.3f) < 1e-6);
    assert_true(y[575] == 0.0f && fabs(y[576] - 0.3f) < 1e-6);
    assert_true(fabs(y[N - 1] - 7 * 0.3f) < 1e-6); /* 4096 = 7 full layers + 64 */
    free(x);
    free(y);
    free(z);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_single_particle_is_sphere),
        cmocka_unit_test(test_two_particles_waist),
        cmocka_unit_test(test_blobs_against_brute_force_field),
        cmocka_unit_test(test_nan_particles_skipped),
        cmocka_unit_test(test_zero_particles_and_eye_inside),
        cmocka_unit_test(test_tiny_h),
        cmocka_unit_test(test_compare_metrics),
        cmocka_unit_test(test_layers),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
