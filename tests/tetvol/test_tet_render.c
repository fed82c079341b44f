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

#include "tet_render.h"
#include "tet_testmesh.h"

/* cube [-1,1]^3 split into 5 tets (a corner-cut decomposition), scalar = x+y+z+3 scaled */
static const float cube_pts[8 * 3] = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1,
                                      -1, -1, 1,  1, -1, 1,  1, 1, 1,  -1, 1, 1};
static const uint32_t cube_tets[5 * 4] = {0, 1, 3, 4, 1, 2, 3, 6, 1, 4, 5, 6,
                                          3, 4, 6, 7, 1, 3, 4, 6};

static void make_cube(tet_mesh *m, float *pts, float *sc, uint32_t *tets)
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
static void make_cam(tet_camera *c, int w, int h, float dist, float near)
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

static void make_tf(tet_tf *tf, float tau)
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
static void reference_range(const tet_mesh *m, const tet_camera *c, const tet_tf *tf,
                            double dist, double near, double tmax, int n, double *out)
{
    int W = c->width, H = c->height;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double dx = (((x + 0.5) / W) * 2 - 1) / c->proj[0];
            double dy = (((y + 0.5) / H) * 2 - 1) / c->proj[5];
            double il = 1 / sqrt(dx * dx + dy * dy + 1);
            double d[3] = {dx * il, dy * il, -il};
            double t0 = near / il, t1 = tmax;
            double h = (t1 - t0) / n, T = 1, col[3] = {0, 0, 0};
            for (int i = 0; i < n; i++) {
                double t = t0 + (i + 0.5) * h;
                double p[3] = {d[0] * t, d[1] * t, d[2] * t + dist};
                double s = NAN;
                for (uint32_t k = 0; k < m->tet_count && isnan(s); k++) {
                    const uint32_t *tt = &m->tets[4 * k];
                    double sk = ref_testmesh_tet_scalar(m, tt, p);
                    if (!isnan(sk))
                        s = sk;
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

/* the rays end behind the [-1,1]^3 scene */
static void reference(const tet_mesh *m, const tet_camera *c, const tet_tf *tf,
                      double dist, double near, int n, double *out)
{
    reference_range(m, c, tf, dist, near, dist + 2.0, n, out);
}

/* An N^3 grid of cubes over [-1,1]^3, 5 tets each, alternating so faces match. */
static void make_grid(int N, tet_mesh *m, float **pts_out, float **sc_out, uint32_t **tets_out)
{
    const int NP = (N + 1) * (N + 1) * (N + 1), NT = N * N * N * 5;
    float *pts = malloc((size_t)NP * 3 * sizeof *pts), *sc = malloc((size_t)NP * sizeof *sc);
    uint32_t *tets = malloc((size_t)NT * 4 * sizeof *tets);
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
    memset(m, 0, sizeof *m);
    m->point_count = (uint32_t)NP; m->tet_count = (uint32_t)NT;
    m->points = pts; m->tets = tets; m->scalar = sc;
    *pts_out = pts; *sc_out = sc; *tets_out = tets;
}

/* The renderer uses the midpoint scalar of each segment (a one-point rule per cell segment),
 * which differs from the exact linear-scalar integral by O(length^2 * ds/dt * dtau/ds); with
 * segments up to ~2.8 long and the scalar slope <= 0.29/unit the colour/opacity error is a few
 * 1e-2 at most; 0.05 max abs and 0.015 RMSE bound it with margin, while a wrong depth order,
 * a missing tet or a missing thickness correction give errors of 0.1..0.5. */
static void test_cube_vs_reference(void **state)
{
    (void)state;
    tet_mesh m; float pts[24], sc[8]; uint32_t tets[20];
    make_cube(&m, pts, sc, tets);
    tet_camera cam; make_cam(&cam, 24, 24, 4.0f, 0.1f);
    /* tilt the cube so segments cross several tets: rotate the view about x and y */
    float ca = cosf(0.5f), sa = sinf(0.5f), cb = cosf(0.7f), sb = sinf(0.7f);
    /* view = T(0,0,-4) * Rx(a) * Ry(b), column-major */
    float R[9] = {cb, sa * sb, -ca * sb, 0, ca, sa, sb, -sa * cb, ca * cb};
    for (int c = 0; c < 3; c++)
        for (int r = 0; r < 3; r++)
            cam.view[c * 4 + r] = R[c * 3 + r];
    tet_tf tf; make_tf(&tf, 1.0f);
    tet_options o; tet_options_default(&o); o.ert = 0;
    float *img = calloc(24 * 24 * 4, sizeof *img);
    double *ref = calloc(24 * 24 * 4, sizeof *ref);
    char err[256];
    tet_counters cnt;
    assert_int_equal(tet_render(&m, &cam, &tf, &o, img, &cnt, err, sizeof err), 0);
    /* reference in the rotated frame: rotate the points instead of the camera */
    float rp[24];
    for (int i = 0; i < 8; i++)
        for (int r = 0; r < 3; r++)
            rp[3 * i + r] = R[0 * 3 + r] * pts[3 * i] + R[1 * 3 + r] * pts[3 * i + 1] + R[2 * 3 + r] * pts[3 * i + 2];
    tet_mesh mr = m; mr.points = rp;
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
    enum { N = 6, NT = N * N * N * 5 };
    tet_mesh m;
    float *pts, *sc;
    uint32_t *tets;
    make_grid(N, &m, &pts, &sc, &tets);
    tet_camera cam; make_cam(&cam, 40, 40, 4.0f, 0.1f);
    tet_tf tf; make_tf(&tf, 20.0f);
    tet_options o; tet_options_default(&o); o.tiles_d = 8; o.update_c = 50;
    float *a = calloc(40 * 40 * 4, sizeof *a), *b = calloc(40 * 40 * 4, sizeof *b);
    char err[256];
    tet_counters c0, c1, c2;
    o.ert = 0; o.ert_threshold = 1.0f; /* same merge stop as the ERT 1.0 run */
    assert_int_equal(tet_render(&m, &cam, &tf, &o, a, &c0, err, sizeof err), 0);
    o.ert = 1; o.ert_threshold = 1.0f;
    assert_int_equal(tet_render(&m, &cam, &tf, &o, b, &c1, err, sizeof err), 0);
    assert_memory_equal(a, b, 40 * 40 * 4 * sizeof *a);
    o.ert_threshold = 0.9f;
    assert_int_equal(tet_render(&m, &cam, &tf, &o, b, &c2, err, sizeof err), 0);
    double mx = 0;
    for (int i = 0; i < 40 * 40 * 4; i++)
        mx = fmax(mx, fabs(a[i] - b[i]));
    print_message("ERT 0.9: skipped %llu of %u cells (scanned %llu, updates %llu, alpha0 %.3f), max diff %.4g\n",
                  (unsigned long long)c2.cells_skipped_ert, NT, (unsigned long long)c2.cells_scanned, (unsigned long long)c2.table_updates, a[4 * (20 * 40 + 20) + 3], mx);
    assert_true(c2.cells_skipped_ert > 0);
    /* The theory bounds a skipped cell's light by 1 - 0.9 = 0.1, a bound under which a wrong
     * skip (one tile row of the cell's box checked: 0.0123 measured) or a stale table passed.
     * One thread renders the same every run (the skip set depends on the cell order and the
     * update schedule only): measured 0.007629; 0.0095 leaves 25% for another compiler's float
     * contraction and fails that mutation. */
    assert_true(mx <= 0.0095);

    /* Workers: without ERT, 1 vs 4 workers (with and without DLB) differ only by the float
     * association of partial compositing (different segments merge on each worker): 1e-5 is
     * ~100 float32 ulps of values <= 1. With ERT 0.9, SHARE/DLB on/off only change which
     * hidden cells are skipped: a worker knows at most the terminations one thread knows
     * (its own lists and the shared table), so it skips no more; measured 0 to 0.007629 over
     * 200 runs (the most when sharing makes every table complete, as one thread's), so the
     * one-thread bound above holds them too. */
    float *c = calloc(40 * 40 * 4, sizeof *c);
    tet_counters pw[4];
    for (int mode = 0; mode < 4; mode++) {
        o.ert = 0; o.ert_threshold = 1.0f; o.workers = 4; o.share = mode & 1; o.dlb = (mode >> 1) & 1;
        assert_int_equal(tet_render_workers(&m, &cam, &tf, &o, c, &c1, pw, err, sizeof err), 0);
        double dmax = 0;
        for (int i = 0; i < 40 * 40 * 4; i++)
            dmax = fmax(dmax, fabs(a[i] - c[i]));
        assert_true(dmax < 1e-5);
        uint64_t sum = 0;
        for (int i = 0; i < 4; i++)
            sum += pw[i].cells_scanned;
        assert_int_equal(sum, c0.cells_scanned);
        o.ert = 1; o.ert_threshold = 0.9f;
        assert_int_equal(tet_render_workers(&m, &cam, &tf, &o, c, &c1, pw, err, sizeof err), 0);
        dmax = 0;
        for (int i = 0; i < 40 * 40 * 4; i++)
            dmax = fmax(dmax, fabs(a[i] - c[i]));
        print_message("4 workers share=%d dlb=%d: ERT 0.9 skipped %llu, max diff %.4g, scanned per worker %llu %llu %llu %llu\n",
                      o.share, o.dlb, (unsigned long long)c1.cells_skipped_ert, dmax,
                      (unsigned long long)pw[0].cells_scanned, (unsigned long long)pw[1].cells_scanned,
                      (unsigned long long)pw[2].cells_scanned, (unsigned long long)pw[3].cells_scanned);
        assert_true(dmax <= 0.0095);
    }
    o.workers = 1;
    free(c);
    free(a); free(b); free(pts); free(sc); free(tets);
}

/* volume.workers is documented up to 256 (the scene and the plugin allow it); the pool was
 * capped at 64 and failed the first frame of 65..256 (issue 28). 256 workers render the image of
 * one within the partial-compositing association bound (1e-5, as above); 257 are refused. */
static void test_many_workers(void **state)
{
    (void)state;
    enum { N = 3 };
    tet_mesh m;
    float *pts, *sc;
    uint32_t *tets;
    make_grid(N, &m, &pts, &sc, &tets);
    tet_camera cam; make_cam(&cam, 24, 24, 4.0f, 0.1f);
    tet_tf tf; make_tf(&tf, 4.0f);
    tet_options o; tet_options_default(&o); o.ert = 0;
    float *a = calloc(24 * 24 * 4, sizeof *a), *b = calloc(24 * 24 * 4, sizeof *b);
    char err[256];
    tet_counters c;
    o.workers = 1;
    assert_int_equal(tet_render(&m, &cam, &tf, &o, a, &c, err, sizeof err), 0);
    tet_pool *pool = NULL;
    assert_int_equal(tet_pool_create(TET_MAX_WORKERS, &pool, err, sizeof err), 0);
    assert_int_equal(tet_pool_workers(pool), 256);
    o.workers = 256;
    assert_int_equal(tet_render_pool(pool, &m, &cam, &tf, &o, b, &c, NULL, err, sizeof err), 0);
    double mx = 0;
    for (int i = 0; i < 24 * 24 * 4; i++)
        mx = fmax(mx, fabs(a[i] - b[i]));
    assert_true(mx < 1e-5);
    tet_pool_destroy(pool);
    assert_int_equal(tet_pool_create(TET_MAX_WORKERS + 1, &pool, err, sizeof err), TET_ERR_INVALID_ARGUMENT);
    free(a); free(b); free(pts); free(sc); free(tets);
}

/* Camera inside the cube, and the cube crossing the near plane: cells crossing the plane are
 * ray-clipped at the near plane (counted), nothing is NaN, and the opacity matches the
 * reference from the near plane on. NaN scalars skip the cell with a count. */
static void test_camera_inside_and_nan(void **state)
{
    (void)state;
    tet_mesh m; float pts[24], sc[8]; uint32_t tets[20];
    make_cube(&m, pts, sc, tets);
    tet_camera cam; make_cam(&cam, 16, 16, 0.5f, 0.05f); /* eye at z = 0.5, inside */
    tet_tf tf; make_tf(&tf, 1.0f);
    tet_options o; tet_options_default(&o);
    float img[16 * 16 * 4];
    double ref[16 * 16 * 4];
    char err[256];
    tet_counters cnt;
    assert_int_equal(tet_render(&m, &cam, &tf, &o, img, &cnt, err, sizeof err), 0);
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
    assert_int_equal(tet_render(&m, &cam, &tf, &o, img, &cnt, err, sizeof err), 0);
    assert_int_equal(cnt.cells_behind, 5);
    for (int i = 0; i < 16 * 16 * 4; i++)
        assert_true(img[i] == 0.0f);
    /* NaN scalar at one vertex: its cells are skipped and counted, the rest renders */
    sc[6] = NAN;
    make_cam(&cam, 16, 16, 4.0f, 0.1f);
    assert_int_equal(tet_render(&m, &cam, &tf, &o, img, &cnt, err, sizeof err), 0);
    assert_true(cnt.cells_nan >= 1);
    for (int i = 0; i < 16 * 16 * 4; i++)
        assert_false(isnan(img[i]));
}

/* Renders m without ERT and compares with the float64 reference; returns the max abs error and
 * stores the RMSE in *rmse. */
static double vs_reference(const tet_mesh *m, const tet_camera *cam, const tet_tf *tf,
                           double dist, double near, double tmax, int steps, double *rmse,
                           tet_counters *cnt)
{
    const int n = cam->width * cam->height * 4;
    float *img = calloc((size_t)n, sizeof *img);
    double *ref = calloc((size_t)n, sizeof *ref);
    tet_options o; tet_options_default(&o); o.ert = 0;
    char err[256];
    assert_int_equal(tet_render(m, cam, tf, &o, img, cnt, err, sizeof err), 0);
    reference_range(m, cam, tf, dist, near, tmax, steps, ref);
    double se = 0, mx = 0;
    for (int i = 0; i < n; i++) {
        assert_false(isnan(img[i]));
        double e = fabs(img[i] - ref[i]);
        se += e * e;
        if (e > mx) mx = e;
    }
    *rmse = sqrt(se / n);
    free(img);
    free(ref);
    return mx;
}

/* Three thin rods whose depth order is cyclic (rod i lies in front of rod i+1 where they cross,
 * rod 2 in front of rod 0): no global order of the cells is correct, so a renderer that
 * composited whole cells in any sorted order would get one crossing wrong. Each rod is one tet
 * spanned by a short edge across the rod at one end and a short edge in depth at the other; its
 * centre line rises in depth along the rod. Each rod has its own constant scalar (colour), so the
 * per-segment mid-scalar rule is exact and the only error is the reference's step (the rays
 * are marched over distance 2.4..3.6, which holds every rod, in 1500 steps: h <= 8e-4, optical
 * depth error per boundary <= tau h = 0.016): max 0.03 and RMSE 0.006 bound it, while one
 * crossing composited in the wrong order changes its pixels by ~0.3 (colours differ by 0.9,
 * alpha ~0.8). */
static void test_visibility_cycle(void **state)
{
    (void)state;
    const double r = 0.3, T = 2 * r * sqrt(3.0), k = 0.3, w = 0.2, dz = 0.08;
    float pts[12 * 3], sc[12];
    uint32_t tets[3 * 4];
    for (int i = 0; i < 3; i++) {
        double phi = 2.0943951 * i, nx = cos(phi), ny = sin(phi), dx = -ny, dy = nx;
        double cx = r * nx, cy = r * ny;
        double v[4][3] = {{cx - T * dx + w * nx, cy - T * dy + w * ny, -k * T},
                          {cx - T * dx - w * nx, cy - T * dy - w * ny, -k * T},
                          {cx + T * dx, cy + T * dy, k * T + dz},
                          {cx + T * dx, cy + T * dy, k * T - dz}};
        for (int j = 0; j < 4; j++) {
            for (int q = 0; q < 3; q++)
                pts[3 * (4 * i + j) + q] = (float)v[j][q];
            sc[4 * i + j] = 0.5f * i;
            tets[4 * i + j] = (uint32_t)(4 * i + j);
        }
    }
    /* the cycle is real: where rods i and i+1 cross (the triangle corner at distance 2r from
     * the centre), rod i's centre line is at depth +k r sqrt3 and rod i+1's at -k r sqrt3 */
    tet_mesh m = {0};
    m.point_count = 12; m.tet_count = 3; m.points = pts; m.tets = tets; m.scalar = sc;
    tet_camera cam; make_cam(&cam, 48, 48, 3.0f, 0.1f);
    tet_tf tf; make_tf(&tf, 20.0f);
    tf.tau_lo = tf.tau_hi = 20.0f; /* every rod equally dense; colour tells them apart */
    tet_counters cnt;
    float img[48 * 48 * 4];
    tet_options o; tet_options_default(&o); o.ert = 0;
    char err[256];
    assert_int_equal(tet_render(&m, &cam, &tf, &o, img, &cnt, err, sizeof err), 0);
    double *ref = calloc(48 * 48 * 4, sizeof *ref);
    reference_range(&m, &cam, &tf, 3.0, 2.4, 3.6, 1500, ref);
    double se = 0, mx = 0;
    for (int i = 0; i < 48 * 48 * 4; i++) {
        double e = fabs(img[i] - ref[i]);
        se += e * e;
        mx = fmax(mx, e);
    }
    double rmse = sqrt(se / (48 * 48 * 4));
    /* pixels where two rods overlap: segments beyond one per covered pixel (the rods are convex,
     * so each gives one segment per pixel) */
    unsigned covered = 0;
    for (int p = 0; p < 48 * 48; p++)
        covered += img[4 * p + 3] > 0;
    print_message("visibility cycle: rmse %.4g max %.4g (segments %llu, covered %u)\n", rmse, mx,
                  (unsigned long long)cnt.segments_made, covered);
    assert_int_equal(cnt.cells_scanned, 3);
    assert_true(cnt.segments_made >= covered + 3 * 4); /* >= 4 overlap pixels per crossing */
    /* the test can fail: whole cells composited in their sorted nearest-depth order (a
     * painter's order, what a renderer without per-pixel ordering would do) miss the reference
     * by far more than the bound at one of the crossings */
    float one[3][48 * 48 * 4];
    double nearest[3];
    for (int i = 0; i < 3; i++) {
        tet_mesh mi = m;
        mi.tets = &tets[4 * i];
        mi.tet_count = 1;
        assert_int_equal(tet_render(&mi, &cam, &tf, &o, one[i], &cnt, err, sizeof err), 0);
        nearest[i] = INFINITY;
        for (int j = 0; j < 4; j++)
            nearest[i] = fmin(nearest[i], 3.0 - pts[3 * (4 * i + j) + 2]);
    }
    int ord[3] = {0, 1, 2};
    for (int a = 0; a < 3; a++)
        for (int b = a + 1; b < 3; b++)
            if (nearest[ord[b]] < nearest[ord[a]]) { int t = ord[a]; ord[a] = ord[b]; ord[b] = t; }
    double painter_err = 0;
    for (int p = 0; p < 48 * 48; p++) {
        double acc[4] = {0, 0, 0, 0};
        for (int i = 0; i < 3; i++) {
            double t = 1 - acc[3];
            for (int c = 0; c < 4; c++)
                acc[c] += t * one[ord[i]][4 * p + c];
        }
        for (int c = 0; c < 4; c++)
            painter_err = fmax(painter_err, fabs(acc[c] - ref[4 * p + c]));
    }
    print_message("visibility cycle: painter's order of whole cells misses by %.3f\n", painter_err);
    assert_true(painter_err > 0.1);
    free(ref);
    assert_true(mx < 0.03);
    assert_true(rmse < 0.006);
}

/* Coincident vertices: a tet with two identical vertices has zero volume; it is skipped and
 * counted, draws nothing, and its neighbour renders as if alone. Two tets sharing a face exactly,
 * seen through the face and with the face edge-on, give the reference image (no seam: a pixel
 * on the shared face is neither dropped nor counted twice); the touching segments merge. */
static void test_coincident_vertices(void **state)
{
    (void)state;
    float pts[6 * 3] = {-0.8f, -0.8f, -0.8f, 0.9f, -0.7f, -0.6f, -0.6f, 0.9f, -0.7f,
                        -0.7f, -0.6f, 0.9f, 0.8f, 0.8f, 0.8f, 0.9f, -0.7f, -0.6f};
    float sc[6] = {0, 0.3f, 0.6f, 1.0f, 0.5f, 0.3f};
    uint32_t deg[4] = {0, 1, 2, 5}; /* vertices 1 and 5 coincide */
    tet_mesh m = {0};
    m.point_count = 6; m.tet_count = 1; m.points = pts; m.tets = deg; m.scalar = sc;
    tet_camera cam; make_cam(&cam, 24, 24, 4.0f, 0.1f);
    tet_tf tf; make_tf(&tf, 2.0f);
    tet_options o; tet_options_default(&o);
    float img[24 * 24 * 4];
    char err[256];
    tet_counters cnt;
    assert_int_equal(tet_render(&m, &cam, &tf, &o, img, &cnt, err, sizeof err), 0);
    assert_int_equal(cnt.cells_degenerate, 1);
    assert_int_equal(cnt.cells_scanned, 0);
    for (int i = 0; i < 24 * 24 * 4; i++)
        assert_true(img[i] == 0.0f);
    /* a real tet (0,1,2,3) next to the degenerate one: the degenerate one changes nothing */
    uint32_t two[8] = {0, 1, 2, 3, 0, 1, 2, 5};
    float alone[24 * 24 * 4];
    m.tets = two;
    m.tet_count = 1;
    assert_int_equal(tet_render(&m, &cam, &tf, &o, alone, &cnt, err, sizeof err), 0);
    m.tet_count = 2;
    assert_int_equal(tet_render(&m, &cam, &tf, &o, img, &cnt, err, sizeof err), 0);
    assert_int_equal(cnt.cells_degenerate, 1);
    assert_memory_equal(img, alone, sizeof img);
    /* shared face (1,2,3) between (0,1,2,3) and (4,1,3,2) (both positively oriented), the
     * scalar continuous across it. Same tolerance argument as the cube test (mid-scalar rule,
     * segments <= 2.5 long, scalar slope <= 0.4): max 0.05, RMSE 0.015; a dropped or doubled
     * face row would put 0.1..0.5 errors on a line of pixels. */
    uint32_t shared[8] = {0, 1, 2, 3, 4, 1, 3, 2};
    /* the cube test's transfer function and field, for which its bound holds */
    make_tf(&tf, 1.0f);
    for (int i = 0; i < 5; i++)
        sc[i] = (pts[3 * i] + pts[3 * i + 1] + pts[3 * i + 2] + 3.0f) / 6.0f;
    m.tets = shared;
    m.tet_count = 2;
    m.point_count = 5;
    double rmse, mx = vs_reference(&m, &cam, &tf, 4.0, 0.1, 6.0, 2000, &rmse, &cnt);
    print_message("shared face, through: rmse %.4g max %.4g merged %llu of %llu\n", rmse, mx,
                  (unsigned long long)cnt.segments_merged, (unsigned long long)cnt.segments_made);
    assert_true(cnt.segments_merged > 0);
    assert_true(mx < 0.05 && rmse < 0.015);
    /* edge-on: a shared face (0,1,2) in the plane y = 0, which contains the eye (0, 0, 4), so
     * the face projects to a line; with an odd image height that line is the middle pixel row,
     * whose rays run inside the face plane (each tet's segment there has zero or full length on
     * one side only: the row must not be dropped or doubled) */
    float flat[5 * 3] = {-0.9f, 0.0f, -0.9f, 0.8f, 0.0f, 0.0f, -0.8f, 0.0f, 0.5f,
                         0.0f, 0.7f, 0.0f, 0.1f, -0.8f, 0.2f};
    make_cam(&cam, 25, 25, 4.0f, 0.1f);
    m.points = flat;
    for (int i = 0; i < 5; i++)
        sc[i] = (flat[3 * i] + flat[3 * i + 1] + flat[3 * i + 2] + 3.0f) / 6.0f;
    uint32_t sh2[8] = {0, 1, 2, 3, 0, 2, 1, 4}; /* shared face (0,1,2) lies in y = 0 */
    m.tets = sh2;
    mx = vs_reference(&m, &cam, &tf, 4.0, 0.1, 6.0, 2000, &rmse, &cnt);
    print_message("shared face, edge-on: rmse %.4g max %.4g\n", rmse, mx);
    assert_true(mx < 0.05 && rmse < 0.015);
}

/* Opacity 0 everywhere gives an exactly empty image (and nothing for ERT to skip); a very high
 * extinction everywhere saturates the opacity to exactly 1 with no NaN or Inf, and ERT then
 * skips the cells behind the first layer (counted). */
static void test_opacity_extremes(void **state)
{
    (void)state;
    enum { N = 4 };
    tet_mesh m;
    float *pts, *sc;
    uint32_t *tets;
    make_grid(N, &m, &pts, &sc, &tets);
    tet_camera cam; make_cam(&cam, 24, 24, 4.0f, 0.1f);
    tet_tf tf; make_tf(&tf, 0.0f);
    tet_options o; tet_options_default(&o); o.tiles_d = 6; o.update_c = 50;
    float img[24 * 24 * 4];
    char err[256];
    tet_counters cnt;
    assert_int_equal(tet_render(&m, &cam, &tf, &o, img, &cnt, err, sizeof err), 0);
    assert_true(cnt.segments_made > 0);
    assert_int_equal(cnt.cells_skipped_ert, 0);
    for (int i = 0; i < 24 * 24 * 4; i++)
        assert_true(img[i] == 0.0f);
    tf.tau_lo = tf.tau_hi = 1e30f;
    assert_int_equal(tet_render(&m, &cam, &tf, &o, img, &cnt, err, sizeof err), 0);
    int covered = 0;
    for (int p = 0; p < 24 * 24; p++) {
        for (int c = 0; c < 4; c++)
            assert_true(isfinite(img[4 * p + c]));
        if (img[4 * p + 3] > 0) {
            covered++;
            assert_true(img[4 * p + 3] == 1.0f);
        }
    }
    print_message("tau 1e30: %d pixels covered, all opacity 1; ERT skipped %llu of %u\n", covered,
                  (unsigned long long)cnt.cells_skipped_ert, m.tet_count);
    assert_true(covered > 100);
    assert_true(cnt.cells_skipped_ert > 0);
    free(pts); free(sc); free(tets);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cube_vs_reference),
        cmocka_unit_test(test_ert_threshold),
        cmocka_unit_test(test_camera_inside_and_nan),
        cmocka_unit_test(test_many_workers),
        cmocka_unit_test(test_visibility_cycle),
        cmocka_unit_test(test_coincident_vertices),
        cmocka_unit_test(test_opacity_extremes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
