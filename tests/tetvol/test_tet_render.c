/* Tests of the CPU cell-projection renderer (seed 002) against an independent float64 reference:
 * per pixel, the ray is marched in fine steps through the tets with a point-in-tet test. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "tetvol/tet_render.h"

/* cube [-1,1]^3 split into 5 tets (a corner-cut decomposition), scalar = x+y+z+3 scaled */
static const float cube_pts[8 * 3] = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1,
                                      -1, -1, 1,  1, -1, 1,  1, 1, 1,  -1, 1, 1};
static const uint32_t cube_tets[5 * 4] = {0, 1, 3, 4, 1, 2, 3, 6, 1, 4, 5, 6,
                                          3, 4, 6, 7, 1, 3, 4, 6};

static void make_cube(vfx_tet_mesh *m, float *pts, float *sc, uint32_t *tets)
{
    memset(m, 0, sizeof *m);
    memcpy(pts, cube_pts, sizeof cube_pts);
    memcpy(tets, cube_tets, sizeof cube_tets);
    for (int i = 0; i < 8; i++)
        sc[i] = (pts[3 * i] + pts[3 * i + 1] + pts[3 * i + 2] + 3.0f) / 6.0f;
    m->point_count = 8;
    m->tet_count = 5;
    m->points = pts;
    m->tets = tets;
    m->scalar = sc;
}

/* camera at (0,0,dist) looking down -z, 60 degree vertical fov */
static void make_cam(vfx_tet_camera *c, int w, int h, float dist, float near)
{
    memset(c, 0, sizeof *c);
    c->width = w;
    c->height = h;
    c->view[0] = c->view[5] = c->view[10] = c->view[15] = 1;
    c->view[14] = -dist;
    float f = 1.0f / tanf(0.5f * 1.0471976f), far = 100.0f;
    c->proj[0] = f * h / (float)w;
    c->proj[5] = f;
    c->proj[10] = (far + near) / (near - far);
    c->proj[11] = -1;
    c->proj[14] = 2 * far * near / (near - far);
}

static void make_tf(vfx_tet_tf *tf, float tau)
{
    memset(tf, 0, sizeof *tf);
    tf->smin = 0;
    tf->smax = 1;
    tf->tau_lo = 0.2f * tau;
    tf->tau_hi = tau;
    tf->color_lo[0] = 0.1f; tf->color_lo[1] = 0.3f; tf->color_lo[2] = 1.0f;
    tf->color_hi[0] = 1.0f; tf->color_hi[1] = 0.6f; tf->color_hi[2] = 0.1f;
}

/* float64 reference: emission-absorption along each pixel ray, the scalar interpolated linearly
 * in the containing tet, midpoint rule with n steps through the bounding cube. */
static void reference(const vfx_tet_mesh *m, const vfx_tet_camera *c, const vfx_tet_tf *tf,
                      double dist, double near, int n, double *out)
{
    int W = c->width, H = c->height;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double dx = (((x + 0.5) / W) * 2 - 1) / c->proj[0];
            double dy = (((y + 0.5) / H) * 2 - 1) / c->proj[5];
            double il = 1 / sqrt(dx * dx + dy * dy + 1);
            double d[3] = {dx * il, dy * il, -il};
            double t0 = near / il, t1 = dist + 2.0;
            double h = (t1 - t0) / n, T = 1, col[3] = {0, 0, 0};
            for (int i = 0; i < n; i++) {
                double t = t0 + (i + 0.5) * h;
                double p[3] = {d[0] * t, d[1] * t, d[2] * t + dist};
                double s = NAN;
                for (uint32_t k = 0; k < m->tet_count && isnan(s); k++) {
                    const uint32_t *tt = &m->tets[4 * k];
                    double v[4][3];
                    for (int j = 0; j < 4; j++)
                        for (int r = 0; r < 3; r++)
                            v[j][r] = m->points[3 * tt[j] + r];
                    /* barycentric by signed volumes */
                    double lam[4], vol = 0;
                    for (int j = 0; j < 4; j++) {
                        double q[4][3];
                        memcpy(q, v, sizeof q);
                        memcpy(q[j], p, sizeof q[j]);
                        double a[3], b[3], e[3];
                        for (int r = 0; r < 3; r++) {
                            a[r] = q[1][r] - q[0][r];
                            b[r] = q[2][r] - q[0][r];
                            e[r] = q[3][r] - q[0][r];
                        }
                        lam[j] = a[0] * (b[1] * e[2] - b[2] * e[1]) - a[1] * (b[0] * e[2] - b[2] * e[0]) +
                                 a[2] * (b[0] * e[1] - b[1] * e[0]);
                        vol += lam[j];
                    }
                    int in = 1;
                    for (int j = 0; j < 4; j++)
                        if (lam[j] / vol < -1e-12) in = 0;
                    if (in) {
                        s = 0;
                        for (int j = 0; j < 4; j++)
                            s += lam[j] / vol * m->scalar[tt[j]];
                    }
                }
                if (isnan(s))
                    continue;
                double u = (s - tf->smin) / (tf->smax - tf->smin);
                u = u < 0 ? 0 : u > 1 ? 1 : u;
                double tau = tf->tau_lo + (tf->tau_hi - tf->tau_lo) * u;
                double a = 1 - exp(-tau * h);
                for (int r = 0; r < 3; r++)
                    col[r] += T * a * (tf->color_lo[r] + (tf->color_hi[r] - tf->color_lo[r]) * u);
                T *= 1 - a;
            }
            for (int r = 0; r < 3; r++)
                out[4 * ((size_t)y * W + x) + r] = col[r];
            out[4 * ((size_t)y * W + x) + 3] = 1 - T;
        }
}

/* The renderer uses the midpoint scalar of each segment (a one-point rule per cell segment),
 * which differs from the exact linear-scalar integral by O(length^2 * ds/dt * dtau/ds); with
 * segments up to ~2.8 long and the scalar slope <= 0.29/unit the colour/opacity error is a few
 * 1e-2 at most; 0.05 max abs and 0.015 RMSE bound it with margin, while a wrong depth order,
 * a missing tet or a missing thickness correction give errors of 0.1..0.5. */
static void test_cube_vs_reference(void **state)
{
    (void)state;
    vfx_tet_mesh m; float pts[24], sc[8]; uint32_t tets[20];
    make_cube(&m, pts, sc, tets);
    vfx_tet_camera cam; make_cam(&cam, 24, 24, 4.0f, 0.1f);
    /* tilt the cube so segments cross several tets: rotate the view about x and y */
    float ca = cosf(0.5f), sa = sinf(0.5f), cb = cosf(0.7f), sb = sinf(0.7f);
    /* view = T(0,0,-4) * Rx(a) * Ry(b), column-major */
    float R[9] = {cb, sa * sb, -ca * sb, 0, ca, sa, sb, -sa * cb, ca * cb};
    for (int c = 0; c < 3; c++)
        for (int r = 0; r < 3; r++)
            cam.view[c * 4 + r] = R[c * 3 + r];
    vfx_tet_tf tf; make_tf(&tf, 1.0f);
    vfx_tet_options o; vfx_tet_options_default(&o); o.ert = 0;
    float *img = calloc(24 * 24 * 4, sizeof *img);
    double *ref = calloc(24 * 24 * 4, sizeof *ref);
    char err[256];
    vfx_tet_counters cnt;
    assert_int_equal(vfx_tet_render(&m, &cam, &tf, &o, img, &cnt, err), 0);
    /* reference in the rotated frame: rotate the points instead of the camera */
    float rp[24];
    for (int i = 0; i < 8; i++)
        for (int r = 0; r < 3; r++)
            rp[3 * i + r] = R[0 * 3 + r] * pts[3 * i] + R[1 * 3 + r] * pts[3 * i + 1] + R[2 * 3 + r] * pts[3 * i + 2];
    vfx_tet_mesh mr = m; mr.points = rp;
    reference(&mr, &cam, &tf, 4.0, 0.1, 2000, ref);
    double se = 0, mx = 0, amax = 0;
    for (int i = 0; i < 24 * 24 * 4; i++) {
        double e = fabs(img[i] - ref[i]);
        se += e * e;
        if (e > mx) mx = e;
        if (ref[i] > amax) amax = ref[i];
    }
    double rmse = sqrt(se / (24 * 24 * 4));
    print_message("cube vs float64 reference: rmse %.4g max %.4g (ref max %.3g) segments %llu merged %llu\n",
                  rmse, mx, amax, (unsigned long long)cnt.segments_made,
                  (unsigned long long)cnt.segments_merged);
    assert_true(amax > 0.3); /* the image is not empty */
    assert_true(mx < 0.05);
    assert_true(rmse < 0.015);
    free(img);
    free(ref);
}

/* ERT with threshold 1.0 can only skip behind pixels of opacity exactly 1: the image equals the
 * no-ERT image bit for bit; a threshold of 0.9 skips cells and stays within 1 - 0.9 = 0.1 of it. */
static void test_ert_threshold(void **state)
{
    (void)state;
    /* a 6x6x6 grid of cubes, 5 tets each */
    enum { N = 6, NP = (N + 1) * (N + 1) * (N + 1), NT = N * N * N * 5 };
    float *pts = malloc(NP * 3 * sizeof *pts), *sc = malloc(NP * sizeof *sc);
    uint32_t *tets = malloc(NT * 4 * sizeof *tets);
    for (int k = 0, i = 0; k <= N; k++)
        for (int j = 0; j <= N; j++)
            for (int l = 0; l <= N; l++, i++) {
                pts[3 * i] = -1 + 2.0f * l / N;
                pts[3 * i + 1] = -1 + 2.0f * j / N;
                pts[3 * i + 2] = -1 + 2.0f * k / N;
                sc[i] = 0.5f + 0.5f * sinf(3 * pts[3 * i]) * cosf(2 * pts[3 * i + 1]);
            }
    uint32_t t = 0;
    for (int k = 0; k < N; k++)
        for (int j = 0; j < N; j++)
            for (int l = 0; l < N; l++) {
                uint32_t c[8];
                for (int q = 0; q < 8; q++) {
                    int dl = q & 1 ? 1 : 0, dj = q & 2 ? 1 : 0, dk = q & 4 ? 1 : 0;
                    c[q] = (uint32_t)((k + dk) * (N + 1) * (N + 1) + (j + dj) * (N + 1) + l + dl);
                }
                /* corner order 0..7 as in cube_pts: (0,0,0)(1,0,0)(1,1,0)(0,1,0)... */
                uint32_t o8[8] = {c[0], c[1], c[3], c[2], c[4], c[5], c[7], c[6]};
                int flip = (l + j + k) & 1; /* alternate so faces match between cubes */
                for (int q = 0; q < 20; q++) {
                    uint32_t idx = cube_tets[q];
                    if (flip) {
                        static const uint32_t mirror[8] = {1, 0, 3, 2, 5, 4, 7, 6};
                        idx = mirror[idx];
                    }
                    tets[(size_t)((t + q / 4) * 4 + q % 4)] = o8[idx];
                }
                t += 5;
            }
    vfx_tet_mesh m = {0};
    m.point_count = NP; m.tet_count = NT; m.points = pts; m.tets = tets; m.scalar = sc;
    vfx_tet_camera cam; make_cam(&cam, 40, 40, 4.0f, 0.1f);
    vfx_tet_tf tf; make_tf(&tf, 20.0f);
    vfx_tet_options o; vfx_tet_options_default(&o); o.tiles_d = 8; o.update_c = 50;
    float *a = calloc(40 * 40 * 4, sizeof *a), *b = calloc(40 * 40 * 4, sizeof *b);
    char err[256];
    vfx_tet_counters c0, c1, c2;
    o.ert = 0; o.ert_threshold = 1.0f; /* same merge stop as the ERT 1.0 run */
    assert_int_equal(vfx_tet_render(&m, &cam, &tf, &o, a, &c0, err), 0);
    o.ert = 1; o.ert_threshold = 1.0f;
    assert_int_equal(vfx_tet_render(&m, &cam, &tf, &o, b, &c1, err), 0);
    assert_memory_equal(a, b, 40 * 40 * 4 * sizeof *a);
    o.ert_threshold = 0.9f;
    assert_int_equal(vfx_tet_render(&m, &cam, &tf, &o, b, &c2, err), 0);
    double mx = 0;
    for (int i = 0; i < 40 * 40 * 4; i++)
        mx = fmax(mx, fabs(a[i] - b[i]));
    print_message("ERT 0.9: skipped %llu of %u cells (scanned %llu, updates %llu, alpha0 %.3f), max diff %.4g\n",
                  (unsigned long long)c2.cells_skipped_ert, NT, (unsigned long long)c2.cells_scanned, (unsigned long long)c2.table_updates, a[4 * (20 * 40 + 20) + 3], mx);
    assert_true(c2.cells_skipped_ert > 0);
    assert_true(mx <= 0.1 + 1e-5); /* skipped light is attenuated by at least 1 - 0.9 */

    /* Workers: without ERT, 1 vs 4 workers (with and without DLB) differ only by the float
     * association of partial compositing (different segments merge on each worker): 1e-5 is
     * ~100 float32 ulps of values <= 1. With ERT 0.9, SHARE/DLB on/off only change which
     * hidden cells are skipped, so each stays within 0.1 of the no-ERT image. */
    float *c = calloc(40 * 40 * 4, sizeof *c);
    vfx_tet_counters pw[4];
    for (int mode = 0; mode < 4; mode++) {
        o.ert = 0; o.ert_threshold = 1.0f; o.workers = 4; o.share = mode & 1; o.dlb = (mode >> 1) & 1;
        assert_int_equal(vfx_tet_render_workers(&m, &cam, &tf, &o, c, &c1, pw, err), 0);
        double dmax = 0;
        for (int i = 0; i < 40 * 40 * 4; i++)
            dmax = fmax(dmax, fabs(a[i] - c[i]));
        assert_true(dmax < 1e-5);
        uint64_t sum = 0;
        for (int i = 0; i < 4; i++)
            sum += pw[i].cells_scanned;
        assert_int_equal(sum, c0.cells_scanned);
        o.ert = 1; o.ert_threshold = 0.9f;
        assert_int_equal(vfx_tet_render_workers(&m, &cam, &tf, &o, c, &c1, pw, err), 0);
        dmax = 0;
        for (int i = 0; i < 40 * 40 * 4; i++)
            dmax = fmax(dmax, fabs(a[i] - c[i]));
        print_message("4 workers share=%d dlb=%d: ERT 0.9 skipped %llu, max diff %.4g, scanned per worker %llu %llu %llu %llu\n",
                      o.share, o.dlb, (unsigned long long)c1.cells_skipped_ert, dmax,
                      (unsigned long long)pw[0].cells_scanned, (unsigned long long)pw[1].cells_scanned,
                      (unsigned long long)pw[2].cells_scanned, (unsigned long long)pw[3].cells_scanned);
        assert_true(dmax <= 0.1 + 1e-5);
    }
    o.workers = 1;
    free(c);
    free(a); free(b); free(pts); free(sc); free(tets);
}

/* Camera inside the cube, and the cube crossing the near plane: cells crossing the plane are
 * ray-clipped at the near plane (counted), nothing is NaN, and the opacity matches the
 * reference from the near plane on. NaN scalars skip the cell with a count. */
static void test_camera_inside_and_nan(void **state)
{
    (void)state;
    vfx_tet_mesh m; float pts[24], sc[8]; uint32_t tets[20];
    make_cube(&m, pts, sc, tets);
    vfx_tet_camera cam; make_cam(&cam, 16, 16, 0.5f, 0.05f); /* eye at z = 0.5, inside */
    vfx_tet_tf tf; make_tf(&tf, 1.0f);
    vfx_tet_options o; vfx_tet_options_default(&o);
    float img[16 * 16 * 4];
    double ref[16 * 16 * 4];
    char err[256];
    vfx_tet_counters cnt;
    assert_int_equal(vfx_tet_render(&m, &cam, &tf, &o, img, &cnt, err), 0);
    assert_true(cnt.cells_near_crossing > 0);
    reference(&m, &cam, &tf, 0.5, 0.05, 2000, ref);
    double mx = 0;
    for (int i = 0; i < 16 * 16 * 4; i++) {
        assert_false(isnan(img[i]));
        mx = fmax(mx, fabs(img[i] - ref[i]));
    }
    print_message("camera inside: max diff %.4g, near-crossing cells %llu\n", mx,
                  (unsigned long long)cnt.cells_near_crossing);
    assert_true(mx < 0.05); /* same midpoint-rule bound as the cube test */
    /* everything behind the camera: nothing drawn, all counted */
    make_cam(&cam, 16, 16, -3.0f, 0.05f);
    assert_int_equal(vfx_tet_render(&m, &cam, &tf, &o, img, &cnt, err), 0);
    assert_int_equal(cnt.cells_behind, 5);
    for (int i = 0; i < 16 * 16 * 4; i++)
        assert_true(img[i] == 0.0f);
    /* NaN scalar at one vertex: its cells are skipped and counted, the rest renders */
    sc[6] = NAN;
    make_cam(&cam, 16, 16, 4.0f, 0.1f);
    assert_int_equal(vfx_tet_render(&m, &cam, &tf, &o, img, &cnt, err), 0);
    assert_true(cnt.cells_nan >= 1);
    for (int i = 0; i < 16 * 16 * 4; i++)
        assert_false(isnan(img[i]));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cube_vs_reference),
        cmocka_unit_test(test_ert_threshold),
        cmocka_unit_test(test_camera_inside_and_nan),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
