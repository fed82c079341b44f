/* test_beams_bin.c — the beams' CPU tile binning (plugin/beams/beams_bin.c) against brute force:
 *  - conservative: for seeded random spheres before a perspective camera, every one of 64
 *    points on and in the sphere that projects on screen lands in a tile of the rectangle
 *    (projected in double here, independently of the binning's box-corner bound);
 *  - the per-tile capsule test: for seeded random beams (segments, radii) and every tile of a
 *    640x360 camera, 16 random pixel rays of the tile (the shader's: NDC of the pixel centre
 *    unprojected) against 400 points along the segment (distance in double); any ray within
 *    the radius of a point needs the test to say "touches"; and the test must cull (a test that
 *    always says yes would pass the first check);
 *  - the lists: for every tile, exactly the beams whose rectangle holds it, in increasing order,
 *    and the empty-tile count, against a per-tile scan of all rectangles.
 * Exact integer checks: no tolerance. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <cmocka.h>

#include "beams/beams_bin.h"
#include "context.h"

static double rnd(uint64_t *st)
{
    *st = *st * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(*st >> 11) / 9007199254740992.0;
}

/* Column-major perspective (GL): fov_y 60 degrees, aspect w/h, near 0.1, far 100; the view is
 * a rotation about y by yaw (camera-relative: no translation). */
static void camera(float m[16], double aspect, double yaw)
{
    double f = 1.0 / tan(0.5 * 60.0 * 3.14159265358979 / 180.0), n = 0.1, fa = 100.0;
    double p[16] = {f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (fa + n) / (n - fa), -1, 0, 0, 2 * fa * n / (n - fa), 0};
    double c = cos(yaw), s = sin(yaw);
    double v[16] = {c, 0, -s, 0, 0, 1, 0, 0, s, 0, c, 0, 0, 0, 0, 1};
    for (int col = 0; col < 4; ++col)
        for (int r = 0; r < 4; ++r) {
            double acc = 0;
            for (int k = 0; k < 4; ++k)
                acc += p[k * 4 + r] * v[col * 4 + k];
            m[col * 4 + r] = (float)acc;
        }
}

static void test_rect_conservative(void **st)
{
    (void)st;
    volfx_beams_grid g = volfx_beams_grid_of(640, 360);
    assert_int_equal(g.tiles_x, 40);
    assert_int_equal(g.tiles_y, 23);
    float m[16];
    camera(m, 640.0 / 360.0, 0.3);
    uint64_t seed = 7;
    int visible = 0, checked = 0;
    for (int it = 0; it < 2000; ++it) {
        double c[3] = {40 * rnd(&seed) - 20, 20 * rnd(&seed) - 10, -30 * rnd(&seed) + 2};
        double rad = 0.05 + 5 * rnd(&seed);
        uint32_t rect[4];
        bool vis = volfx_beams_bin_rect(&g, m, c, rad, rect);
        for (int k = 0; k < 64; ++k) {
            double u = 2 * rnd(&seed) - 1, phi = 6.283185307179586 * rnd(&seed), r = k < 48 ? rad : rad * rnd(&seed);
            double w = sqrt(1 - u * u), p[3] = {c[0] + r * w * cos(phi), c[1] + r * w * sin(phi), c[2] + r * u};
            double cl[4];
            for (int row = 0; row < 4; ++row)
                cl[row] = m[row] * p[0] + m[4 + row] * p[1] + m[8 + row] * p[2] + m[12 + row];
            if (!(cl[3] > 1e-6))
                continue;
            double x = cl[0] / cl[3], y = cl[1] / cl[3];
            if (x < -1 || x > 1 || y < -1 || y > 1)
                continue;
            uint32_t tx = (uint32_t)fmin((x * 0.5 + 0.5) * g.width / VOLFX_BEAMS_TILE_PX, g.tiles_x - 1);
            uint32_t ty = (uint32_t)fmin((y * 0.5 + 0.5) * g.height / VOLFX_BEAMS_TILE_PX, g.tiles_y - 1);
            assert_true(vis);
            assert_true(tx >= rect[0] && tx <= rect[2] && ty >= rect[1] && ty <= rect[3]);
            checked++;
        }
        visible += vis;
    }
    assert_true(visible > 500 && checked > 10000); /* the test saw enough on-screen spheres */
}

static void test_capsule_conservative(void **st)
{
    (void)st;
    volfx_beams_grid g = volfx_beams_grid_of(640, 360);
    float m[16], inv[16], (*cones)[4] = calloc((size_t)g.tiles_x * g.tiles_y, sizeof *cones);
    camera(m, 640.0 / 360.0, -0.2);
    assert_true(volfx_mat4_invert(m, inv)); /* the test camera's inverse (plugin/context.c) */
    volfx_beams_grid_cones(&g, inv, cones);
    uint64_t seed = 5;
    long touching = 0, culled = 0;
    for (int it = 0; it < 12; ++it) {
        /* straight beams (2 points) and polylines of 3 and 4 joints */
        volfx_beams_capsule c = {.r = 0.05 + 1.5 * rnd(&seed), .n = 2 + (uint32_t)(it % 3)};
        for (uint32_t j = 0; j < c.n; ++j) {
            for (int k = 0; k < 3; ++k)
                c.p[j][k] = 24 * rnd(&seed) - 12;
            c.p[j][2] -= 14; /* mostly in front (the camera looks down -z, yawed) */
        }
        for (uint32_t t = 0; t < g.tiles_x * g.tiles_y; ++t) {
            bool says = volfx_beams_capsule_touches(&c, cones[t]);
            culled += !says;
            bool near = false;
            for (int r = 0; r < 16 && !near; ++r) {
                double px = (t % g.tiles_x) * VOLFX_BEAMS_TILE_PX + floor(16 * rnd(&seed)) + 0.5;
                double py = (t / g.tiles_x) * VOLFX_BEAMS_TILE_PX + floor(16 * rnd(&seed)) + 0.5;
                double nx = 2 * px / g.width - 1, ny = 2 * py / g.height - 1, h[4], v[3], n = 0;
                for (int k = 0; k < 4; ++k)
                    h[k] = inv[k] * nx + inv[4 + k] * ny + inv[12 + k];
                for (int k = 0; k < 3; ++k)
                    v[k] = h[k] / h[3], n += v[k] * v[k];
                for (int k = 0; k < 3; ++k)
                    v[k] /= sqrt(n);
                for (int j = 0; j <= 400 * (int)(c.n - 1) && !near; ++j) {
                    double p[3], d2 = 0, tp = 0, u = j / 400.0;
                    int sgi = (int)u < (int)c.n - 1 ? (int)u : (int)c.n - 2;
                    for (int k = 0; k < 3; ++k)
                        p[k] = c.p[sgi][k] + (c.p[sgi + 1][k] - c.p[sgi][k]) * (u - sgi), tp += p[k] * v[k];
                    tp = fmax(tp, 0.0);
                    for (int k = 0; k < 3; ++k)
                        d2 += (p[k] - tp * v[k]) * (p[k] - tp * v[k]);
                    near = d2 < c.r * c.r;
                }
            }
            touching += near;
            if (near && !says)
                fail_msg("capsule %d tile %u: a pixel ray passes within r, the test culled it", it, t);
        }
    }
    assert_true(touching > 100);
    assert_true(culled > 2000); /* it culls: 12 beams x 920 tiles, most tiles far from a beam */
    free(cones);
}

static void test_lists_brute_force(void **st)
{
    (void)st;
    volfx_beams_grid g = volfx_beams_grid_of(200, 120);
    enum { N = 37 };
    uint32_t rects[N][4];
    bool vis[N];
    uint64_t seed = 11;
    for (int i = 0; i < N; ++i) {
        uint32_t x0 = (uint32_t)(rnd(&seed) * g.tiles_x), y0 = (uint32_t)(rnd(&seed) * g.tiles_y);
        uint32_t x1 = x0 + (uint32_t)(rnd(&seed) * (g.tiles_x - x0)), y1 = y0 + (uint32_t)(rnd(&seed) * (g.tiles_y - y0));
        rects[i][0] = x0, rects[i][1] = y0, rects[i][2] = x1 < g.tiles_x ? x1 : g.tiles_x - 1;
        rects[i][3] = y1 < g.tiles_y ? y1 : g.tiles_y - 1;
        vis[i] = rnd(&seed) > 0.2;
    }
    uint64_t pairs = volfx_beams_bin_pairs((const uint32_t(*)[4])rects, vis, N);
    uint32_t ntiles = g.tiles_x * g.tiles_y, *ranges = calloc(2 * (size_t)ntiles, 4), *list = calloc(pairs + 1, 4);
    uint64_t written = 0;
    uint32_t empty = volfx_beams_bin_fill(&g, (const uint32_t(*)[4])rects, vis, N, NULL, NULL, ranges, list, &written);
    assert_int_equal(written, pairs);
    uint32_t want_empty = 0;
    uint64_t total = 0;
    for (uint32_t ty = 0; ty < g.tiles_y; ++ty)
        for (uint32_t tx = 0; tx < g.tiles_x; ++tx) {
            uint32_t t = ty * g.tiles_x + tx, k = 0;
            for (uint32_t i = 0; i < N; ++i)
                if (vis[i] && tx >= rects[i][0] && tx <= rects[i][2] && ty >= rects[i][1] && ty <= rects[i][3]) {
                    assert_true(k < ranges[2 * t + 1]);
                    assert_int_equal(list[ranges[2 * t] + k], i);
                    k++;
                }
            assert_int_equal(k, ranges[2 * t + 1]);
            want_empty += k == 0;
            total += k;
        }
    assert_int_equal(empty, want_empty);
    assert_int_equal(total, pairs);
    free(ranges);
    free(list);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rect_conservative),
        cmocka_unit_test(test_capsule_conservative),
        cmocka_unit_test(test_lists_brute_force),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
