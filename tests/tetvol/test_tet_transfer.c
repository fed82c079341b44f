/* Transfer-function tables in the cell-projection renderer against the float64 ray march
 * (reference/tet_testmesh.c): tables of 2, 5 and 64 points and a narrow spike, each integrated
 * by splitting ray segments at the breakpoints (exact), by the pre-integrated lookup, and by
 * one midpoint evaluation per segment (what a coarse sampling does). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "tet_render.h"
#include "tet_testmesh.h"

enum { N = 6, W = 24, H = 24, STEPS = 3000 };

static tet_mesh g_mesh;
static tet_camera g_cam;

static int setup(void **state)
{
    (void)state;
    assert_int_equal(ref_testmesh_grid(N, &g_mesh), 0);
    ref_testmesh_orbit(&g_cam, W, H, 0.7f, 0.5f, 1.0f / tanf(0.5f * 1.0471976f), 0.1f, 100.0f);
    g_cam.view[14] = -4.0f;
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    free(g_mesh.points), free(g_mesh.scalar), free(g_mesh.tets);
    return 0;
}

typedef struct err2 {
    double rmse, max;
} err2;

static err2 render_vs(const tet_tf *tf, const double *ref, float *img, tet_counters *cnt)
{
    tet_options o;
    tet_options_default(&o);
    o.ert = 0;
    char err[256];
    assert_int_equal(tet_render(&g_mesh, &g_cam, tf, &o, img, cnt, err, sizeof err), TET_OK);
    err2 e = {0, 0};
    for (int i = 0; i < W * H * 4; i++) {
        assert_false(isnan(img[i]));
        double d = fabs(img[i] - ref[i]);
        e.rmse += d * d;
        e.max = fmax(e.max, d);
    }
    e.rmse = sqrt(e.rmse / (W * H * 4));
    return e;
}

/* Renders tf with the three methods against the reference; returns the errors in e[method]. */
static void compare(const char *name, tet_tf tf, err2 e[3], uint64_t pieces[3])
{
    double *ref = malloc(W * H * 4 * sizeof *ref);
    float *img = malloc(W * H * 4 * sizeof *img);
    ref_testmesh_raymarch(N, &g_mesh, &g_cam, &tf, STEPS, ref);
    double amax = 0;
    for (int i = 3; i < W * H * 4; i += 4)
        amax = fmax(amax, ref[i]);
    static const char *const mname[3] = {"exact", "preintegrated", "midpoint"};
    for (int m = 0; m < 3; m++) {
        tf.method = m;
        tet_counters c;
        e[m] = render_vs(&tf, ref, img, &c);
        pieces[m] = c.tf_pieces;
        print_message("%-10s %-13s rmse %.3g max %.3g (ref max alpha %.3f, %llu segments, %llu pieces)\n", name,
                      mname[m], e[m].rmse, e[m].max, amax, (unsigned long long)c.segments_made,
                      (unsigned long long)c.tf_pieces);
    }
    assert_true(amax > 0.2); /* the image is not empty */
    free(ref);
    free(img);
}

/* a smooth colour map (blue -> cyan -> yellow -> red) with extinction rising with the scalar */
static void colormap(double u, float rgb[3], float *tau)
{
    rgb[0] = (float)fmin(1, fmax(0, 1.5 * u - 0.2));
    rgb[1] = (float)(0.3 + 0.6 * sin(M_PI * u));
    rgb[2] = (float)fmax(0, 1 - 1.4 * u);
    *tau = (float)(0.5 + 3.0 * u * u);
}

/* The two-point table is the linear transfer function it always was: bit for bit the same
 * image as the two-end form, and one piece per segment; the midpoint method is the rule the
 * renderer used before tables. */
static void test_two_point_table_is_linear(void **state)
{
    (void)state;
    tet_tf lin = {.smin = 0, .smax = 1, .tau_lo = 0.4f, .tau_hi = 3.0f, .color_lo = {0.1f, 0.3f, 1.0f},
                  .color_hi = {1.0f, 0.6f, 0.1f}};
    tet_tf_point pts[2] = {{0, {0.1f, 0.3f, 1.0f}, 0.4f}, {1, {1.0f, 0.6f, 0.1f}, 3.0f}};
    tet_tf tab = {.points = pts, .count = 2};
    float *a = malloc(W * H * 4 * sizeof *a), *b = malloc(W * H * 4 * sizeof *b);
    tet_options o;
    tet_options_default(&o);
    char err[256];
    tet_counters ca, cb;
    assert_int_equal(tet_render(&g_mesh, &g_cam, &lin, &o, a, &ca, err, sizeof err), TET_OK);
    assert_int_equal(tet_render(&g_mesh, &g_cam, &tab, &o, b, &cb, err, sizeof err), TET_OK);
    assert_memory_equal(a, b, W * H * 4 * sizeof *a);
    /* the scalar stays inside [0, 1]: no segment crosses a breakpoint */
    assert_int_equal(cb.tf_pieces, cb.segments_made);
    err2 e[3];
    uint64_t pieces[3];
    compare("2 points", tab, e, pieces);
    /* The exact piece integral leaves the reference's own error: its midpoint rule with
     * h <= 2 sqrt(3) / 3000 = 1.2e-3 errs by O(h) only where a step straddles a tet face
     * (the scalar's slope jumps), ~1e-4 per ray: 1e-3 max, 1e-4 RMSE (measured 1.2e-4, 9.5e-6).
     * The midpoint colour rule errs by O(length^2 * dtau/dt * dc/dt); segments here are <= ~0.6
     * long with the scalar slope <= 2 per unit: a few 1e-3 per segment, a few 1e-2 along a ray,
     * and the pre-integrated colour (no attenuation inside a segment) by the same order:
     * 0.03 max and 0.008 RMSE bound both; a missing piece or a wrong opacity correction gives
     * 0.1 and more. */
    assert_true(e[0].max < 1e-3 && e[0].rmse < 1e-4);
    for (int m = 1; m < 3; m++)
        assert_true(e[m].max < 0.03 && e[m].rmse < 0.008);
    free(a), free(b);
}

static void test_five_points(void **state)
{
    (void)state;
    tet_tf_point pts[5] = {{0.00f, {0.0f, 0.0f, 0.3f}, 0.0f},
                           {0.30f, {0.1f, 0.5f, 1.0f}, 1.5f},
                           {0.45f, {0.9f, 0.9f, 0.9f}, 0.2f},
                           {0.70f, {1.0f, 0.5f, 0.0f}, 4.0f},
                           {1.00f, {1.0f, 0.0f, 0.0f}, 0.5f}};
    tet_tf tf = {.points = pts, .count = 5};
    err2 e[3];
    uint64_t pieces[3];
    compare("5 points", tf, e, pieces);
    assert_true(pieces[0] > pieces[2]); /* segments were split */
    /* exact: the reference's error (as above), larger where its steps straddle the kinks of
     * the table too (measured 2.0e-3 max, 1.2e-4 RMSE): 0.01 / 1e-3 */
    assert_true(e[0].max < 0.01 && e[0].rmse < 1e-3);
    /* pre-integrated: exact opacity, tau-weighted colour without attenuation inside a segment:
     * of the same order (measured ~1.5x the split error) */
    assert_true(e[1].max < 0.05 && e[1].rmse < 0.012);
    /* one midpoint per segment cuts the kinks: worse than the split */
    assert_true(e[2].rmse > e[0].rmse);
}

/* 64 points of a smooth colour map with a narrow spike (scalar 0.6 +- 0.005, extinction 80,
 * white): the spike is thinner than most segments' scalar range, so a midpoint evaluation
 * almost always lands beside it. */
static void test_64_points_with_spike(void **state)
{
    (void)state;
    tet_tf_point pts[64];
    int k = 0;
    for (int i = 0; i <= 61; i++) { /* the map at i/61 but 37/61, the spike's 3 after 36/61 */
        double u = i / 61.0;
        if (i == 37)
            continue;
        pts[k].s = (float)u;
        colormap(u, pts[k].rgb, &pts[k].tau);
        k++;
        if (i == 36) {
            static const double su[3] = {0.595, 0.6, 0.605};
            for (int q = 0; q < 3; q++, k++) {
                pts[k].s = (float)su[q];
                colormap(su[q], pts[k].rgb, &pts[k].tau);
                if (q == 1) {
                    pts[k].rgb[0] = pts[k].rgb[1] = pts[k].rgb[2] = 1.0f;
                    pts[k].tau = 80.0f;
                }
            }
        }
    }
    assert_int_equal(k, 64);
    for (int i = 1; i < 64; i++)
        assert_true(pts[i].s > pts[i - 1].s);
    tet_tf tf = {.points = pts, .count = 64};
    err2 e[3];
    uint64_t pieces[3];
    compare("64+spike", tf, e, pieces);
    /* exact: the spike is a few reference steps thick along a ray (0.01 / |ds/dt| with
     * |ds/dt| <= 2 -> >= 4 steps), so the reference itself errs by up to ~1e-2 there
     * (measured 6e-3 max, 4.7e-4 RMSE): 0.03 / 0.003 */
    assert_true(e[0].max < 0.03 && e[0].rmse < 0.003);
    /* the coarse sampling misses the spike: several times the split's error */
    assert_true(e[2].rmse > 3 * e[0].rmse);
    /* the pre-integrated table (1024 cells over [0,1], spike 10 cells wide) keeps its area */
    assert_true(e[1].rmse < 2 * e[0].rmse + 0.005);
}

/* A spike alone: zero extinction except a band of 0.01 in the scalar. The split renders the
 * band, the midpoint rule loses nearly all of it. */
static void test_spike_alone(void **state)
{
    (void)state;
    tet_tf_point pts[5] = {{0.0f, {0, 0, 0}, 0}, {0.595f, {0, 0, 0}, 0}, {0.6f, {1, 1, 1}, 60},
                           {0.605f, {0, 0, 0}, 0}, {1.0f, {0, 0, 0}, 0}};
    tet_tf tf = {.points = pts, .count = 5};
    err2 e[3];
    uint64_t pieces[3];
    compare("spike", tf, e, pieces);
    /* exact: as in the 64-point table (measured 1.1e-2 max, 2.1e-3 RMSE) */
    assert_true(e[0].max < 0.03 && e[0].rmse < 0.006);
    assert_true(e[2].max > 0.1 && e[2].rmse > 4 * e[0].rmse);
}

static void test_bad_tables(void **state)
{
    (void)state;
    float *img = malloc(W * H * 4 * sizeof *img);
    tet_options o;
    tet_options_default(&o);
    char err[256];
    tet_tf_point pts[3] = {{0, {1, 1, 1}, 1}, {0.5f, {1, 1, 1}, 1}, {0.4f, {1, 1, 1}, 1}};
    tet_tf tf = {.points = pts, .count = 3};
    assert_int_equal(tet_render(&g_mesh, &g_cam, &tf, &o, img, NULL, err, sizeof err), TET_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "point 2"));
    pts[2].s = 1, pts[1].tau = NAN;
    assert_int_equal(tet_render(&g_mesh, &g_cam, &tf, &o, img, NULL, err, sizeof err), TET_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "point 1"));
    pts[1].tau = 1;
    tf.count = 1;
    assert_int_equal(tet_render(&g_mesh, &g_cam, &tf, &o, img, NULL, err, sizeof err), TET_ERR_INVALID_ARGUMENT);
    tf.count = 3, tf.method = 7;
    assert_int_equal(tet_render(&g_mesh, &g_cam, &tf, &o, img, NULL, err, sizeof err), TET_ERR_INVALID_ARGUMENT);
    tf.method = TET_TF_PREINTEGRATED, tf.pre_size = 1 << 30;
    assert_int_equal(tet_render(&g_mesh, &g_cam, &tf, &o, img, NULL, err, sizeof err), TET_ERR_INVALID_ARGUMENT);
    free(img);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_two_point_table_is_linear),
        cmocka_unit_test(test_five_points),
        cmocka_unit_test(test_64_points_with_spike),
        cmocka_unit_test(test_spike_alone),
        cmocka_unit_test(test_bad_tables),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
