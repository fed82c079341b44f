/* bench_tetvol.c — volfx-bench tetvol: the seed-002 cell-projection renderer on a generated
 * tetrahedral grid (N^3 cubes x 5 tets, scalar = smooth field): ERT threshold sweep against the
 * no-ERT image (RMSE, max, time), D and C sweeps, and worker configurations (Base, ERT,
 * ERT+SHARE, ERT+DLB, ERT+DLB+SHARE) with per-worker times and counts. One JSON line each. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tetvol/tet_render.h"

static const uint32_t cube5[20] = {0, 1, 3, 4, 1, 2, 3, 6, 1, 4, 5, 6, 3, 4, 6, 7, 1, 3, 4, 6};

static int make_grid(int n, vfx_tet_mesh *m)
{
    uint32_t np = (uint32_t)((n + 1) * (n + 1) * (n + 1)), nt = (uint32_t)(n * n * n * 5);
    memset(m, 0, sizeof *m);
    m->points = malloc((size_t)np * 3 * sizeof(float));
    m->scalar = malloc((size_t)np * sizeof(float));
    m->tets = malloc((size_t)nt * 4 * sizeof(uint32_t));
    if (!m->points || !m->scalar || !m->tets)
        return -1;
    for (int k = 0, i = 0; k <= n; k++)
        for (int j = 0; j <= n; j++)
            for (int l = 0; l <= n; l++, i++) {
                float x = -1 + 2.0f * l / n, y = -1 + 2.0f * j / n, z = -1 + 2.0f * k / n;
                m->points[3 * i] = x; m->points[3 * i + 1] = y; m->points[3 * i + 2] = z;
                m->scalar[i] = 0.5f + 0.5f * sinf(3 * x) * cosf(2 * y) * cosf(1.5f * z);
            }
    uint32_t t = 0;
    for (int k = 0; k < n; k++)
        for (int j = 0; j < n; j++)
            for (int l = 0; l < n; l++) {
                uint32_t c[8];
                for (int q = 0; q < 8; q++)
                    c[q] = (uint32_t)((k + (q >> 2 & 1)) * (n + 1) * (n + 1) + (j + (q >> 1 & 1)) * (n + 1) + l + (q & 1));
                uint32_t o8[8] = {c[0], c[1], c[3], c[2], c[4], c[5], c[7], c[6]};
                static const uint32_t mirror[8] = {1, 0, 3, 2, 5, 4, 7, 6};
                int flip = (l + j + k) & 1;
                for (int q = 0; q < 20; q++)
                    m->tets[(size_t)t * 4 + q] = o8[flip ? mirror[cube5[q]] : cube5[q]];
                t += 5;
            }
    m->point_count = np;
    m->tet_count = nt;
    m->scalar_min = 0; m->scalar_max = 1;
    return 0;
}

/* view A looks face-on along z; view B along the cube diagonal (longer rays, more cells per
 * pixel: the higher-overlap view). */
static void camera(vfx_tet_camera *c, int w, int h, float yaw, float pitch, float dist)
{
    memset(c, 0, sizeof *c);
    c->width = w; c->height = h;
    float cy = cosf(yaw), sy = sinf(yaw), cp = cosf(pitch), sp = sinf(pitch);
    float R[9] = {cy, sp * sy, -cp * sy, 0, cp, sp, sy, -sp * cy, cp * cy};
    for (int col = 0; col < 3; col++)
        for (int r = 0; r < 3; r++)
            c->view[col * 4 + r] = R[col * 3 + r];
    c->view[14] = -dist; c->view[15] = 1;
    float f = 1.0f / tanf(0.5f * 0.8f), nearp = 0.05f, farp = 100;
    c->proj[0] = f * h / (float)w; c->proj[5] = f;
    c->proj[10] = (farp + nearp) / (nearp - farp); c->proj[11] = -1;
    c->proj[14] = 2 * farp * nearp / (nearp - farp);
}

static void diff(const float *a, const float *b, size_t n, double *rmse, double *mx)
{
    double se = 0, m = 0;
    for (size_t i = 0; i < n; i++) {
        double e = fabs((double)a[i] - b[i]);
        se += e * e;
        if (e > m) m = e;
    }
    *rmse = sqrt(se / n); *mx = m;
}

int vfx_bench_tetvol(int argc, char **argv)
{
    int n = 40, w = 300, h = 300, maxw = 8;
    float tau = 4.0f;
    for (int i = 1; i + 1 < argc; i++) {
        if (!strcmp(argv[i], "--grid")) n = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--size")) w = h = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--tau")) tau = (float)atof(argv[++i]);
        else if (!strcmp(argv[i], "--workers")) maxw = atoi(argv[++i]);
    }
    if (n < 1 || n > 200 || w < 1 || w > 4096 || maxw < 1 || maxw > 64) {
        fprintf(stderr, "bench tetvol: --grid 1..200, --size 1..4096, --workers 1..64\n");
        return 2;
    }
    vfx_tet_mesh m;
    if (make_grid(n, &m) != 0) { fprintf(stderr, "bench tetvol: out of memory\n"); return 1; }
    vfx_tet_tf tf = {0, 1, 0.1f * tau, tau, {0.1f, 0.3f, 1.0f}, {1.0f, 0.6f, 0.1f}};
    size_t npx = (size_t)w * h * 4;
    float *ref = malloc(npx * sizeof *ref), *img = malloc(npx * sizeof *img);
    vfx_tet_counters *pw = calloc((size_t)maxw, sizeof *pw);
    char err[256];
    if (!ref || !img || !pw) return 1;
    const char *views[2] = {"A_side", "B_diagonal"};
    for (int v = 0; v < 2; v++) {
        vfx_tet_camera cam;
        if (v == 0) camera(&cam, w, h, 0.0f, 0.0f, 4.5f);
        else camera(&cam, w, h, 0.785f, 0.6155f, 4.5f);
        vfx_tet_options o; vfx_tet_options_default(&o);
        vfx_tet_counters c;
        o.ert = 0;
        if (vfx_tet_render_workers(&m, &cam, &tf, &o, ref, &c, pw, err)) { fprintf(stderr, "%s\n", err); return 1; }
        double base_ms = c.t_sc_ms + c.t_update_ms;
        printf("{\"effect\":\"tetvol\",\"test\":\"table1\",\"view\":\"%s\",\"tets\":%u,\"width\":%d,\"height\":%d,\"ert\":0,\"t_sc_ms\":%.1f,\"t_composite_ms\":%.1f,\"cells_scanned\":%llu,\"segments\":%llu}\n",
               views[v], m.tet_count, w, h, c.t_sc_ms, c.t_composite_ms,
               (unsigned long long)c.cells_scanned, (unsigned long long)c.segments_made);
        const float thr[4] = {0.9f, 0.95f, 0.99f, 1.0f};
        for (int i = 0; i < 4; i++) {
            o.ert = 1; o.ert_threshold = thr[i];
            vfx_tet_render_workers(&m, &cam, &tf, &o, img, &c, pw, err);
            double r, mx; diff(ref, img, npx, &r, &mx);
            printf("{\"effect\":\"tetvol\",\"test\":\"ert_threshold\",\"view\":\"%s\",\"threshold\":%.2f,\"D\":%d,\"C\":%d,\"t_sc_ms\":%.1f,\"t_update_ms\":%.1f,\"speedup_vs_no_ert\":%.2f,\"N_skipped\":%llu,\"rmse\":%.3g,\"max\":%.3g}\n",
                   views[v], thr[i], o.tiles_d, o.update_c, c.t_sc_ms, c.t_update_ms,
                   base_ms / (c.t_sc_ms + c.t_update_ms), (unsigned long long)c.cells_skipped_ert, r, mx);
        }
        o.ert_threshold = 0.9f;
        const int Ds[5] = {5, 10, 20, 40, 80};
        for (int i = 0; i < 5; i++) {
            o.tiles_d = Ds[i];
            vfx_tet_render_workers(&m, &cam, &tf, &o, img, &c, pw, err);
            printf("{\"effect\":\"tetvol\",\"test\":\"D_sweep\",\"view\":\"%s\",\"D\":%d,\"C\":%d,\"t_sc_ms\":%.1f,\"t_update_ms\":%.1f,\"updates\":%llu,\"N_skipped\":%llu}\n",
                   views[v], o.tiles_d, o.update_c, c.t_sc_ms, c.t_update_ms,
                   (unsigned long long)c.table_updates, (unsigned long long)c.cells_skipped_ert);
        }
        o.tiles_d = 20;
        const int Cs[5] = {1, 10, 100, 1000, 10000};
        for (int pc = 0; pc < 2; pc++)
            for (int i = 0; i < 5; i++) {
                o.update_c = Cs[i]; o.partial_composite = pc;
                vfx_tet_render_workers(&m, &cam, &tf, &o, img, &c, pw, err);
                printf("{\"effect\":\"tetvol\",\"test\":\"C_sweep\",\"view\":\"%s\",\"partial\":%d,\"D\":20,\"C\":%d,\"t_sc_ms\":%.1f,\"t_update_ms\":%.1f,\"N_skipped\":%llu}\n",
                       views[v], pc, o.update_c, c.t_sc_ms, c.t_update_ms, (unsigned long long)c.cells_skipped_ert);
            }
        o.update_c = 100; o.partial_composite = 1;
        const char *names[5] = {"Base", "ERT", "ERT+SHARE", "ERT+DLB", "ERT+DLB+SHARE"};
        const int cfg[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1, 0, 1}, {1, 1, 1}};
        for (int i = 0; i < 5; i++) {
            o.workers = maxw; o.ert = cfg[i][0]; o.share = cfg[i][1]; o.dlb = cfg[i][2];
            vfx_tet_render_workers(&m, &cam, &tf, &o, img, &c, pw, err);
            double r, mx; diff(ref, img, npx, &r, &mx);
            double sum = 0, tmax = 0;
            printf("{\"effect\":\"tetvol\",\"test\":\"table2\",\"view\":\"%s\",\"config\":\"%s\",\"workers\":%d,\"rmse\":%.3g,\"per_worker\":[",
                   views[v], names[i], maxw, r);
            for (int k = 0; k < maxw; k++) {
                double t = pw[k].t_sc_ms + pw[k].t_update_ms;
                sum += t; if (t > tmax) tmax = t;
                printf("%s{\"ms\":%.1f,\"cells\":%llu,\"segments\":%llu}", k ? "," : "", t,
                       (unsigned long long)pw[k].cells_scanned, (unsigned long long)pw[k].segments_made);
            }
            printf("],\"t_sc_max_ms\":%.1f,\"imbalance_max_over_mean\":%.2f,\"N_skipped\":%llu,\"t_composite_ms\":%.1f}\n",
                   tmax, tmax / (sum / maxw), (unsigned long long)c.cells_skipped_ert, c.t_composite_ms);
        }
        o.workers = 1;
    }
    free(ref); free(img); free(pw);
    free(m.points); free(m.scalar); free(m.tets);
    return 0;
}
