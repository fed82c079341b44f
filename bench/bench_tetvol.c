/* bench_tetvol.c — volfx-bench tetvol: the seed-002 cell-projection renderer on a loaded mesh
 * (--mesh FILE.vtu or a TetGen base, --scalar NAME) or a generated grid (--grid N), from a low-
 * and a high-overlap view: Table 1 (one worker, ERT off/on), the ERT threshold sweep against the
 * no-ERT image (RMSE, max, time), D and C sweeps (figs. 11-12), Table 2 (Base, ERT, ERT+SHARE,
 * ERT+DLB, ERT+DLB+SHARE at 2 and at --workers threads) with per-worker times and counts, and an
 * "image" line (camera, transfer function, wall time) with the image written by --out PREFIX for
 * the VTK comparison. Every time is the median of --reps runs after one dropped warm-up run.
 * One JSON line per configuration. */
#if !defined(_POSIX_C_SOURCE)
#define _POSIX_C_SOURCE 199309L
#endif
#include <math.h>
#include "core/args.h"
#include "core/file.h"
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "tet_clock.h"
#include "scene/volume_file.h"
#include "tet_render.h"
#include "tet_testmesh.h"

typedef struct view {
    const char *name;
    double eye[3], center[3], up[3];
    double fovy, nearp, farp;
} view;

static void norm3(double *v)
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int i = 0; i < 3; i++) v[i] /= l;
}

/* Camera looking along dir (from the eye towards the mesh) at the bounding box centre, placed so
 * the box's extent across the view fits the field of view at the box's near face. */
static void make_view(view *v, const char *name, const float bmin[3], const float bmax[3],
                      double dir[3])
{
    norm3(dir);
    double up[3] = {0, 0, 0};
    int k = 0; /* world axis least aligned with dir */
    for (int i = 1; i < 3; i++)
        if (fabs(dir[i]) < fabs(dir[k])) k = i;
    up[k] = 1;
    double c[3], half[3];
    for (int i = 0; i < 3; i++) {
        c[i] = 0.5 * ((double)bmin[i] + bmax[i]);
        half[i] = 0.5 * ((double)bmax[i] - bmin[i]);
    }
    /* extent of the box along the view and across it (max over the 8 corners) */
    double s[3] = {dir[1] * up[2] - dir[2] * up[1], dir[2] * up[0] - dir[0] * up[2], dir[0] * up[1] - dir[1] * up[0]};
    norm3(s);
    double u[3] = {s[1] * dir[2] - s[2] * dir[1], s[2] * dir[0] - s[0] * dir[2], s[0] * dir[1] - s[1] * dir[0]};
    double depth = 0, across = 0;
    for (int q = 0; q < 8; q++) {
        double p[3] = {q & 1 ? half[0] : -half[0], q & 2 ? half[1] : -half[1], q & 4 ? half[2] : -half[2]};
        double dd = fabs(p[0] * dir[0] + p[1] * dir[1] + p[2] * dir[2]);
        double ds = fabs(p[0] * s[0] + p[1] * s[1] + p[2] * s[2]);
        double du = fabs(p[0] * u[0] + p[1] * u[1] + p[2] * u[2]);
        if (dd > depth) depth = dd;
        if (ds > across) across = ds;
        if (du > across) across = du;
    }
    v->name = name;
    v->fovy = 0.8;
    double dist = depth + 1.05 * across / tan(0.5 * v->fovy);
    for (int i = 0; i < 3; i++) {
        v->center[i] = c[i];
        v->eye[i] = c[i] - dir[i] * dist;
        v->up[i] = u[i];
    }
    v->nearp = 0.05 * (dist - depth);
    v->farp = 2.0 * (dist + depth);
}

static void view_camera(const view *v, int w, int h, tet_camera *c)
{
    memset(c, 0, sizeof *c);
    c->width = w; c->height = h;
    double f[3] = {v->center[0] - v->eye[0], v->center[1] - v->eye[1], v->center[2] - v->eye[2]};
    norm3(f);
    double s[3] = {f[1] * v->up[2] - f[2] * v->up[1], f[2] * v->up[0] - f[0] * v->up[2], f[0] * v->up[1] - f[1] * v->up[0]};
    norm3(s);
    double u[3] = {s[1] * f[2] - s[2] * f[1], s[2] * f[0] - s[0] * f[2], s[0] * f[1] - s[1] * f[0]};
    for (int i = 0; i < 3; i++) {
        c->view[4 * i + 0] = (float)s[i];
        c->view[4 * i + 1] = (float)u[i];
        c->view[4 * i + 2] = (float)-f[i];
    }
    c->view[12] = (float)-(s[0] * v->eye[0] + s[1] * v->eye[1] + s[2] * v->eye[2]);
    c->view[13] = (float)-(u[0] * v->eye[0] + u[1] * v->eye[1] + u[2] * v->eye[2]);
    c->view[14] = (float)(f[0] * v->eye[0] + f[1] * v->eye[1] + f[2] * v->eye[2]);
    c->view[15] = 1;
    double ff = 1.0 / tan(0.5 * v->fovy);
    c->proj[0] = (float)(ff * h / w); c->proj[5] = (float)ff;
    c->proj[10] = (float)((v->farp + v->nearp) / (v->nearp - v->farp)); c->proj[11] = -1;
    c->proj[14] = (float)(2 * v->farp * v->nearp / (v->nearp - v->farp));
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

/* PFM (little endian, bottom row first, which is the renderer's row order): channel ch of the
 * RGBA image, or the three premultiplied colour channels when ch < 0. */
static int write_pfm(const char *path, const float *rgba, int w, int h, int ch)
{
    char err[1200];
    FILE *f = rt_open_output(path, "wb", err, sizeof err); /* never blocks on a FIFO */
    if (!f) {
        fprintf(stderr, "tetvol: %s\n", err);
        return -1;
    }
    int ok = fprintf(f, "%s\n%d %d\n-1.0\n", ch < 0 ? "PF" : "Pf", w, h) > 0;
    for (size_t i = 0; i < (size_t)w * h && ok; i++)
        ok = ch < 0 ? fwrite(&rgba[4 * i], sizeof(float), 3, f) == 3
                    : fwrite(&rgba[4 * i + ch], sizeof(float), 1, f) == 1;
    return (fclose(f) == 0 && ok) ? 0 : -1;
}

/* Writes PREFIX_VIEW<suffix>.rgb.pfm (premultiplied colour) and .alpha.pfm of an image. Returns
 * 0, or -1 with a message naming the file. */
static int write_pfm_pair(const char *prefix, const char *view, const char *suffix,
                          const float *rgba, int w, int h)
{
    char p1[1100], p2[1100];
    snprintf(p1, sizeof p1, "%s_%s%s.rgb.pfm", prefix, view, suffix);
    snprintf(p2, sizeof p2, "%s_%s%s.alpha.pfm", prefix, view, suffix);
    if (write_pfm(p1, rgba, w, h, -1) || write_pfm(p2, rgba, w, h, 3)) {
        fprintf(stderr, "bench tetvol: cannot write %s\n", p1);
        return -1;
    }
    return 0;
}

typedef struct run_result {
    double wall_ms, cpu_ms, t_sc_ms, t_update_ms, rmse, max;
    double wall_p95, wall_p99; /* nearest-rank over the timed runs ("frame_ms" in the JSON) */
    tet_counters c;
    tet_counters pw[64];
} run_result;

static int cmp_run(const void *a, const void *b)
{
    const run_result *x = a, *y = b;
    return (x->wall_ms > y->wall_ms) - (x->wall_ms < y->wall_ms);
}

static int cmp_d(const void *a, const void *b)
{
    const double *x = a, *y = b;
    return (*x > *y) - (*x < *y);
}

/* Runs one configuration reps + 1 times, drops the first (warm-up), and returns in *out the run
 * of median wall time, with t_sc and t_update replaced by their own medians. ref (or NULL) gives
 * rmse/max of each run against it. */
static int run_cfg(const tet_mesh *m, const tet_camera *cam, const tet_tf *tf,
                   const tet_options *o, float *img, const float *ref, int reps,
                   run_result *runs, run_result *out)
{
    char err[256];
    size_t n = (size_t)cam->width * cam->height * 4;
    for (int r = 0; r <= reps; r++) {
        run_result *rr = &runs[r > 0 ? r - 1 : 0];
        /* CPU time of the whole process (every worker thread): the figure that survives other
         * load */
        double t0 = tet_now_ms(), c0 = tet_clock_ms(CLOCK_PROCESS_CPUTIME_ID);
        if (tet_render_workers(m, cam, tf, o, img, &rr->c, rr->pw, err, sizeof err) != 0) {
            fprintf(stderr, "bench tetvol: %s\n", err);
            return -1;
        }
        rr->wall_ms = tet_now_ms() - t0;
        rr->cpu_ms = tet_clock_ms(CLOCK_PROCESS_CPUTIME_ID) - c0;
        rr->t_sc_ms = rr->c.t_sc_ms;
        rr->t_update_ms = rr->c.t_update_ms;
        rr->rmse = rr->max = 0;
        if (ref) diff(ref, img, n, &rr->rmse, &rr->max);
    }
    double sc[64], up[64], cp[64];
    for (int r = 0; r < reps; r++) {
        sc[r] = runs[r].t_sc_ms;
        up[r] = runs[r].t_update_ms;
        cp[r] = runs[r].cpu_ms;
    }
    qsort(sc, (size_t)reps, sizeof *sc, cmp_d);
    qsort(up, (size_t)reps, sizeof *up, cmp_d);
    qsort(cp, (size_t)reps, sizeof *cp, cmp_d);
    qsort(runs, (size_t)reps, sizeof *runs, cmp_run);
    *out = runs[reps / 2];
    out->wall_p95 = runs[(int)ceil(0.95 * reps) - 1].wall_ms;
    out->wall_p99 = runs[(int)ceil(0.99 * reps) - 1].wall_ms;
    out->t_sc_ms = sc[reps / 2];
    out->t_update_ms = up[reps / 2];
    out->cpu_ms = cp[reps / 2];
    return 0;
}

/* --only tf: the transfer-function integrators on this mesh and view, one worker, no ERT:
 * tables of 2, 5 and 64 points (a smooth map with a narrow spike), each by the exact split,
 * the pre-integrated lookup and the midpoint rule, interleaved rep by rep; median CPU ms and
 * the pieces integrated, and the error against the exact image (the exact method agrees with
 * the float64 ray march to ~1e-4 RMSE, tests/tetvol/test_tet_transfer.c). */
static int bench_tf(const tet_mesh *m, const tet_camera *cam, const tet_tf *base, int reps,
                    const char *mesh_name, const char *view_name)
{
    static tet_tf_point tabs[3][64];
    const int counts[3] = {2, 5, 64};
    for (int t = 0; t < 3; t++)
        for (int i = 0; i < counts[t]; i++) {
            double u = (double)i / (counts[t] - 1);
            if (t == 2 && (i == 38 || i == 39 || i == 40)) /* a spike of 1% of the range */
                u = 0.6 + 0.005 * (i - 39);
            else if (t == 2 && i > 40)
                u = 0.61 + 0.39 * (i - 41) / 22.0;
            else if (t == 2)
                u = 0.59 * i / 37.0;
            tet_tf_point *p = &tabs[t][i];
            p->s = (float)(base->smin + (base->smax - base->smin) * u);
            for (int c = 0; c < 3; c++)
                p->rgb[c] = (float)(base->color_lo[c] + (base->color_hi[c] - base->color_lo[c]) * u);
            p->tau = (float)(base->tau_lo + (base->tau_hi - base->tau_lo) * u);
            if (t == 1 && i == 2) /* a dip in the middle */
                p->tau *= 0.1f;
            if (t == 2 && i == 39) {
                p->rgb[0] = p->rgb[1] = p->rgb[2] = 1.0f;
                p->tau = 20 * base->tau_hi;
            }
        }
    const size_t n = (size_t)cam->width * cam->height * 4;
    float *ref = malloc(n * sizeof *ref), *img = malloc(n * sizeof *img);
    double *cpu = malloc((size_t)reps * 9 * sizeof *cpu);
    if (!ref || !img || !cpu) return -1;
    tet_options o;
    tet_options_default(&o);
    o.ert = 0;
    tet_pool *pool;
    char err[256];
    if (tet_pool_create(1, &pool, err, sizeof err) != TET_OK) return -1;
    double rmse[9] = {0}, mx[9] = {0};
    uint64_t pieces[9] = {0}, segs = 0;
    for (int r = 0; r <= reps; r++)
        for (int t = 0; t < 3; t++) {
            tet_tf tf = {.points = tabs[t], .count = counts[t], .method = TET_TF_EXACT};
            if (r == 0 && tet_render_pool(pool, m, cam, &tf, &o, ref, NULL, NULL, err, sizeof err) != TET_OK) goto fail;
            for (int k = 0; k < 3; k++) {
                tf.method = k;
                tet_counters c;
                double c0 = tet_clock_ms(CLOCK_PROCESS_CPUTIME_ID);
                if (tet_render_pool(pool, m, cam, &tf, &o, img, &c, NULL, err, sizeof err) != TET_OK) goto fail;
                if (r > 0) cpu[(size_t)(r - 1) * 9 + t * 3 + k] = tet_clock_ms(CLOCK_PROCESS_CPUTIME_ID) - c0;
                if (r == 0) {
                    diff(ref, img, n, &rmse[t * 3 + k], &mx[t * 3 + k]);
                    pieces[t * 3 + k] = c.tf_pieces;
                    segs = c.segments_made;
                }
            }
        }
    static const char *const mname[3] = {"exact", "preintegrated", "midpoint"};
    for (int t = 0; t < 3; t++)
        for (int k = 0; k < 3; k++) {
            double v[64];
            for (int r = 0; r < reps; r++) v[r] = cpu[(size_t)r * 9 + t * 3 + k];
            qsort(v, (size_t)reps, sizeof *v, cmp_d);
            printf("{\"effect\":\"tetvol\",\"mesh\":\"%s\",\"view\":\"%s\",\"test\":\"tf\",\"points\":%d,\"method\":\"%s\","
                   "\"cpu_ms\":%.2f,\"segments\":%llu,\"pieces\":%llu,\"rmse_vs_exact\":%.3g,\"max_vs_exact\":%.3g}\n",
                   mesh_name, view_name, counts[t], mname[k], v[reps / 2], (unsigned long long)segs,
                   (unsigned long long)pieces[t * 3 + k], rmse[t * 3 + k], mx[t * 3 + k]);
        }
    tet_pool_destroy(pool);
    free(ref); free(img); free(cpu);
    return 0;
fail:
    fprintf(stderr, "bench tetvol tf: %s\n", err);
    tet_pool_destroy(pool);
    free(ref); free(img); free(cpu);
    return -1;
}

/* --only threads: 1 against 2 workers of persistent pools (created once, as in the plugin),
 * interleaved rep by rep, no ERT and ERT+SHARE+DLB at 0.9: median wall and process CPU ms,
 * and where the second worker's time goes (scan, table updates, waiting at the end of the
 * scan, the composite, the serial set-up on the caller). */
static int bench_threads(const tet_mesh *m, const tet_camera *cam, const tet_tf *tf, int reps,
                         const char *mesh_name, const char *view_name)
{
    const size_t n = (size_t)cam->width * cam->height * 4;
    float *img = malloc(n * sizeof *img);
    tet_pool *pools[2];
    char err[256];
    if (!img || tet_pool_create(1, &pools[0], err, sizeof err) != TET_OK || tet_pool_create(2, &pools[1], err, sizeof err) != TET_OK)
        return -1;
    for (int cfg = 0; cfg < 2; cfg++) {
        tet_options o;
        tet_options_default(&o);
        o.ert = cfg;
        double wall[2][64], cpu[2][64];
        tet_counters pw[2][64][2], tot[2][64];
        for (int r = 0; r <= reps; r++)
            for (int p = 0; p < 2; p++) {
                tet_counters c, w[2];
                double t0 = tet_now_ms(), c0 = tet_clock_ms(CLOCK_PROCESS_CPUTIME_ID);
                if (tet_render_pool(pools[p], m, cam, tf, &o, img, &c, w, err, sizeof err) != TET_OK) {
                    fprintf(stderr, "bench tetvol threads: %s\n", err);
                    return -1;
                }
                if (r == 0) continue; /* warm-up */
                wall[p][r - 1] = tet_now_ms() - t0;
                cpu[p][r - 1] = tet_clock_ms(CLOCK_PROCESS_CPUTIME_ID) - c0;
                tot[p][r - 1] = c;
                pw[p][r - 1][0] = w[0];
                pw[p][r - 1][1] = p ? w[1] : w[0];
            }
        double ws[2][64], cs[2][64];
        memcpy(ws, wall, sizeof ws);
        memcpy(cs, cpu, sizeof cs);
        for (int p = 0; p < 2; p++) {
            qsort(ws[p], (size_t)reps, sizeof(double), cmp_d);
            qsort(cs[p], (size_t)reps, sizeof(double), cmp_d);
        }
        /* the breakdown of the 2-worker run of median wall time */
        int med = 0;
        for (int r = 0; r < reps; r++)
            if (wall[1][r] == ws[1][reps / 2]) med = r;
        const tet_counters *T = &tot[1][med];
        printf("{\"effect\":\"tetvol\",\"mesh\":\"%s\",\"view\":\"%s\",\"test\":\"threads\",\"ert\":%d,\"reps\":%d,"
               "\"wall_ms_1\":%.2f,\"wall_ms_2\":%.2f,\"speedup_wall\":%.3f,\"cpu_ms_1\":%.2f,\"cpu_ms_2\":%.2f,"
               "\"setup_ms\":%.2f,\"composite_ms\":%.2f,\"workers\":[",
               mesh_name, view_name, cfg, reps, ws[0][reps / 2], ws[1][reps / 2], ws[1][reps / 2] > 0 ? ws[0][reps / 2] / ws[1][reps / 2] : 0,
               cs[0][reps / 2], cs[1][reps / 2], T->t_setup_ms, T->t_composite_ms);
        for (int k = 0; k < 2; k++) {
            const tet_counters *c = &pw[1][med][k];
            printf("%s{\"scan_ms\":%.2f,\"update_ms\":%.2f,\"wait_ms\":%.2f,\"cpu_ms\":%.2f,\"cells\":%llu,\"skipped\":%llu}",
                   k ? "," : "", c->t_sc_ms, c->t_update_ms, c->t_wait_ms, c->cpu_ms,
                   (unsigned long long)c->cells_scanned, (unsigned long long)c->cells_skipped_ert);
        }
        /* what 2 idle cores would give: the 1-worker frame's CPU over the busier worker's CPU
         * in the 2-worker frame (each phase is split evenly, so the busier worker's CPU is the
         * frame's critical path on idle cores), medians over the reps */
        double bound[64];
        for (int r = 0; r < reps; r++) {
            double mw = fmax(pw[1][r][0].cpu_ms, pw[1][r][1].cpu_ms);
            bound[r] = mw > 0 ? cpu[0][r] / mw : 0;
        }
        qsort(bound, (size_t)reps, sizeof(double), cmp_d);
        const tet_counters *one = &tot[0][med];
        printf("],\"speedup_cpu_bound\":%.3f,\"one_worker\":{", bound[reps / 2]);
        printf("\"setup_ms\":%.2f,\"scan_ms\":%.2f,\"update_ms\":%.2f,\"composite_ms\":%.2f},\"threads_started\":%d}\n",
               one->t_setup_ms, one->t_sc_ms, one->t_update_ms, one->t_composite_ms, tet_pool_threads(pools[1]));
        fflush(stdout);
    }
    tet_pool_destroy(pools[0]);
    tet_pool_destroy(pools[1]);
    free(img);
    return 0;
}

static int has(const char *list, const char *item)
{
    size_t l = strlen(item);
    for (const char *p = list; (p = strstr(p, item)) != NULL; p += l)
        if ((p == list || p[-1] == ',') && (p[l] == 0 || p[l] == ','))
            return 1;
    return !strcmp(list, "all");
}

static void usage(void)
{
    fputs("volfx-bench tetvol [--mesh FILE.vtu|TETGEN_BASE] [--scalar NAME] [--grid N] [--size PX]\n"
          "  [--view across,axis] [--only table1,ert,D,C,table2,image|tf|threads] [--workers N] [--reps R]\n"
          "  [--tau T] [--out PREFIX] [--c-nopartial-max C] [--json]\n"
          "--tau: optical depth through the mesh's thinnest box extent at the top of the transfer\n"
          "function (default 4). --out writes PREFIX_<view>.rgb.pfm (premultiplied) and .alpha.pfm\n"
          "of the no-ERT image. Output is JSON lines (--json is accepted for symmetry).\n", stderr);
}

int bench_tetvol(int argc, char **argv)
{
    int n = 24, w = 300, h = 300, maxw = 8, reps = 5, cnp_max = 100;
    float tau = 4.0f;
    const char *mesh_path = NULL, *scalar = NULL, *views_opt = "across,axis", *only = "all";
    const char *out_prefix = NULL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--json")) continue;
        if (!strcmp(a, "--help")) { usage(); return 0; }
        if (!v) { fprintf(stderr, "bench tetvol: %s needs a value\n", a); usage(); return 2; }
        i++;
        char e[200];
        uint32_t u = 0;
        double d = 0;
#define U32(lo, hi, dst) do { if (!rt_arg_u32(a, v, lo, hi, &u, e, sizeof e)) goto bad; dst = (int)u; } while (0)
        if (!strcmp(a, "--grid")) U32(1, 200, n);
        else if (!strcmp(a, "--size")) { U32(1, 4096, w); h = w; }
        else if (!strcmp(a, "--tau")) { if (!rt_arg_double(a, v, 1e-6, 1e6, &d, e, sizeof e)) goto bad; tau = (float)d; }
        else if (!strcmp(a, "--workers")) U32(1, 64, maxw);
        else if (!strcmp(a, "--reps")) U32(1, 63, reps);
        else if (!strcmp(a, "--mesh")) mesh_path = v;
        else if (!strcmp(a, "--scalar")) scalar = v;
        else if (!strcmp(a, "--view")) views_opt = v;
        else if (!strcmp(a, "--only")) only = v;
        else if (!strcmp(a, "--out")) out_prefix = v;
        else if (!strcmp(a, "--c-nopartial-max")) U32(1, 1000000, cnp_max);
        else { fprintf(stderr, "bench tetvol: unknown option '%s'\n", a); usage(); return 2; }
#undef U32
        continue;
    bad:
        fprintf(stderr, "bench tetvol: %s\n", e);
        return 2;
    }
    tet_mesh m;
    char err[256];
    const char *mesh_name = "grid";
    if (mesh_path) {
        size_t l = strlen(mesh_path);
        int r;
        if (l > 4 && !strcmp(mesh_path + l - 4, ".vtu")) {
            r = rt_volume_load_vtu(mesh_path, scalar ? scalar : "Velocity", &m, err, sizeof err);
        } else {
            char base[1024];
            snprintf(base, sizeof base, "%s", mesh_path);
            l = strlen(base);
            if (l > 5 && (!strcmp(base + l - 5, ".node") || !strcmp(base + l - 4, ".ele")))
                base[!strcmp(base + l - 4, ".ele") ? l - 4 : l - 5] = 0;
            r = rt_volume_load_tetgen(base, scalar ? scalar : "attr0", &m, err, sizeof err);
        }
        if (r != 0) { fprintf(stderr, "bench tetvol: %s\n", err); return 1; }
        const char *sl = strrchr(mesh_path, '/');
        mesh_name = sl ? sl + 1 : mesh_path;
    } else if (ref_testmesh_grid(n, &m) != 0) {
        fprintf(stderr, "bench tetvol: out of memory\n");
        return 1;
    }
    float bmin[3] = {INFINITY, INFINITY, INFINITY}, bmax[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < m.point_count; i++)
        for (int r = 0; r < 3; r++) {
            float x = m.points[3 * i + r];
            if (x < bmin[r]) bmin[r] = x;
            if (x > bmax[r]) bmax[r] = x;
        }
    int lo = 0, hi = 0;
    for (int r = 1; r < 3; r++) {
        if (bmax[r] - bmin[r] < bmax[lo] - bmin[lo]) lo = r;
        if (bmax[r] - bmin[r] > bmax[hi] - bmin[hi]) hi = r;
    }
    if (lo == hi) hi = (lo + 2) % 3;
    /* low overlap: along the thinnest box axis ("across" a pipe); high overlap: along the
     * longest ("down the axis"); both tilted slightly so no face is exactly edge-on. A cube grid
     * (all extents equal) looks along z and along its diagonal. */
    view views[2];
    double d0[3] = {0, 0, 0}, d1[3] = {0, 0, 0};
    d0[lo] = 1; d0[(lo + 1) % 3] = 0.15; d0[(lo + 2) % 3] = 0.1;
    d1[hi] = 1; d1[(hi + 1) % 3] = 0.1; d1[(hi + 2) % 3] = 0.15;
    if (!mesh_path) { d1[0] = d1[1] = d1[2] = 1; }
    make_view(&views[0], "across", bmin, bmax, d0);
    make_view(&views[1], "axis", bmin, bmax, d1);

    float thin = bmax[lo] - bmin[lo];
    float tau_hi = tau / thin;
    if (!(thin > 0) || !isfinite(tau_hi)) { /* a flat mesh wrote "inf" into the JSON */
        fprintf(stderr, "bench tetvol: %s is flat (extent %g along %c): tau/thinnest extent is not finite\n",
                mesh_name, (double)thin, "xyz"[lo]);
        tet_mesh_free(&m);
        return 1;
    }
    tet_tf tf = {.smin = m.scalar_min, .smax = m.scalar_max, .tau_lo = 0.2f * tau_hi, .tau_hi = tau_hi,
                 .color_lo = {0.1f, 0.3f, 1.0f}, .color_hi = {1.0f, 0.6f, 0.1f}};
    size_t npx = (size_t)w * h * 4;
    float *ref = malloc(npx * sizeof *ref), *img = malloc(npx * sizeof *img);
    run_result *runs = malloc(64 * sizeof *runs), *res = malloc(sizeof *res);
    if (!ref || !img || !runs || !res) return 1;
    printf("{\"effect\":\"tetvol\",\"test\":\"mesh\",\"mesh\":\"%s\",\"scalar\":\"%s\",\"points\":%u,\"tets\":%u,"
           "\"bbox\":[%g,%g,%g,%g,%g,%g],\"width\":%d,\"height\":%d,\"reps\":%d,"
           "\"tf\":{\"smin\":%.9g,\"smax\":%.9g,\"tau_lo\":%.9g,\"tau_hi\":%.9g,\"color_lo\":[%g,%g,%g],\"color_hi\":[%g,%g,%g]}}\n",
           mesh_name, m.scalar_name, m.point_count, m.tet_count, bmin[0], bmin[1], bmin[2], bmax[0],
           bmax[1], bmax[2], w, h, reps, tf.smin, tf.smax, tf.tau_lo, tf.tau_hi, tf.color_lo[0],
           tf.color_lo[1], tf.color_lo[2], tf.color_hi[0], tf.color_hi[1], tf.color_hi[2]);
#define HEAD "{\"effect\":\"tetvol\",\"mesh\":\"%s\",\"tets\":%u,\"view\":\"%s\","
#define HARGS mesh_name, m.tet_count, vw->name
    int rc = 0;
    for (int vi = 0; vi < 2 && rc == 0; vi++) {
        const view *vw = &views[vi];
        if (!has(views_opt, vw->name) && strcmp(views_opt, "all") != 0)
            continue;
        tet_camera cam;
        view_camera(vw, w, h, &cam);
        tet_options o; tet_options_default(&o);
        o.ert = 0; o.workers = 1;
        /* the no-ERT one-worker image is the reference of every error figure */
        if ((rc = run_cfg(&m, &cam, &tf, &o, ref, NULL, reps, runs, res)) != 0) break;
        run_result base = *res;
        double asum = 0, cov = 0, opaque = 0;
        for (size_t p = 0; p < (size_t)w * h; p++) {
            float a = ref[4 * p + 3];
            if (a > 0) { cov++; asum += a; }
            if (a >= 0.9f) opaque++;
        }
        if (has(only, "image")) {
            printf(HEAD "\"test\":\"image\",\"width\":%d,\"height\":%d,\"eye\":[%.9g,%.9g,%.9g],"
                   "\"center\":[%.9g,%.9g,%.9g],\"up\":[%.9g,%.9g,%.9g],\"fovy_deg\":%.9g,\"near\":%.9g,\"far\":%.9g,"
                   "\"wall_ms\":%.2f,\"frame_ms\":{\"p50\":%.2f,\"p95\":%.2f,\"p99\":%.2f},\"cpu_ms\":%.2f,\"t_sc_ms\":%.2f,\"t_composite_ms\":%.2f,\"covered\":%.0f,\"mean_alpha_covered\":%.4f,"
                   "\"pixels_alpha_ge_0.9\":%.0f,\"cells_scanned\":%llu,\"segments\":%llu}\n",
                   HARGS, w, h, vw->eye[0], vw->eye[1], vw->eye[2], vw->center[0], vw->center[1],
                   vw->center[2], vw->up[0], vw->up[1], vw->up[2], vw->fovy * 57.29577951308232, vw->nearp,
                   vw->farp, base.wall_ms, base.wall_ms, base.wall_p95, base.wall_p99, base.cpu_ms, base.t_sc_ms, base.c.t_composite_ms, cov,
                   cov > 0 ? asum / cov : 0.0, opaque, (unsigned long long)base.c.cells_scanned,
                   (unsigned long long)base.c.segments_made);
            if (out_prefix && write_pfm_pair(out_prefix, vw->name, "", ref, w, h) != 0) {
                rc = 1;
                break;
            }
            /* the fast setting: every core, ERT 0.99 with sharing and load balancing */
            o.ert = 1; o.ert_threshold = 0.99f; o.workers = 2; o.share = o.dlb = 1;
            if ((rc = run_cfg(&m, &cam, &tf, &o, img, ref, reps, runs, res)) != 0) break;
            printf(HEAD "\"test\":\"image_fast\",\"workers\":2,\"threshold\":0.99,\"wall_ms\":%.2f,\"frame_ms\":{\"p50\":%.2f,\"p95\":%.2f,\"p99\":%.2f},\"cpu_ms\":%.2f,"
                   "\"N_skipped\":%llu,\"rmse_vs_no_ert\":%.3g,\"max_vs_no_ert\":%.3g}\n",
                   HARGS, res->wall_ms, res->wall_ms, res->wall_p95, res->wall_p99, res->cpu_ms, (unsigned long long)res->c.cells_skipped_ert, res->rmse, res->max);
            if (out_prefix && write_pfm_pair(out_prefix, vw->name, "_fast", img, w, h) != 0) {
                rc = 1;
                break;
            }
            tet_options_default(&o);
            o.ert = 0; o.workers = 1;
        }
        if (strcmp(only, "all") && has(only, "tf") && (rc = bench_tf(&m, &cam, &tf, reps, mesh_name, vw->name)) != 0)
            break;
        if (strcmp(only, "all") && has(only, "threads") &&
            (rc = bench_threads(&m, &cam, &tf, reps, mesh_name, vw->name)) != 0)
            break;
        if (has(only, "table1")) {
            for (int e = 0; e < 2; e++) {
                o.ert = e; o.ert_threshold = 0.9f;
                if (e && (rc = run_cfg(&m, &cam, &tf, &o, img, ref, reps, runs, res)) != 0) break;
                const run_result *r = e ? res : &base;
                printf(HEAD "\"test\":\"table1\",\"ert\":%d,\"threshold\":0.9,\"D\":%d,\"C\":%d,\"wall_ms\":%.2f,\"frame_ms\":{\"p50\":%.2f,\"p95\":%.2f,\"p99\":%.2f},\"cpu_ms\":%.2f,"
                       "\"t_sc_ms\":%.2f,\"t_update_ms\":%.2f,\"t_composite_ms\":%.2f,\"N_skipped\":%llu,"
                       "\"cells_scanned\":%llu,\"segments\":%llu,\"merged\":%llu,\"updates\":%llu,\"rmse\":%.3g,\"max\":%.3g}\n",
                       HARGS, e, o.tiles_d, o.update_c, r->wall_ms, r->wall_ms, r->wall_p95, r->wall_p99, r->cpu_ms, r->t_sc_ms, r->t_update_ms,
                       r->c.t_composite_ms, (unsigned long long)r->c.cells_skipped_ert,
                       (unsigned long long)r->c.cells_scanned, (unsigned long long)r->c.segments_made,
                       (unsigned long long)r->c.segments_merged, (unsigned long long)r->c.table_updates,
                       r->rmse, r->max);
            }
            if (rc) break;
        }
        if (has(only, "ert")) {
            const float thr[4] = {0.9f, 0.95f, 0.99f, 1.0f};
            for (int i = 0; i < 4 && rc == 0; i++) {
                o.ert = 1; o.ert_threshold = thr[i];
                if ((rc = run_cfg(&m, &cam, &tf, &o, img, ref, reps, runs, res)) != 0) break;
                printf(HEAD "\"test\":\"ert_threshold\",\"threshold\":%.2f,\"D\":%d,\"C\":%d,\"wall_ms\":%.2f,\"frame_ms\":{\"p50\":%.2f,\"p95\":%.2f,\"p99\":%.2f},\"cpu_ms\":%.2f,"
                       "\"t_sc_ms\":%.2f,\"t_update_ms\":%.2f,\"no_ert_wall_ms\":%.2f,\"no_ert_cpu_ms\":%.2f,\"N_skipped\":%llu,\"rmse\":%.3g,\"max\":%.3g}\n",
                       HARGS, thr[i], o.tiles_d, o.update_c, res->wall_ms, res->wall_ms, res->wall_p95, res->wall_p99, res->cpu_ms, res->t_sc_ms,
                       res->t_update_ms, base.wall_ms, base.cpu_ms, (unsigned long long)res->c.cells_skipped_ert,
                       res->rmse, res->max);
            }
        }
        o.ert = 1; o.ert_threshold = 0.9f;
        if (has(only, "D")) {
            const int Ds[6] = {5, 10, 20, 40, 80, 150};
            for (int i = 0; i < 6 && rc == 0; i++) {
                o.tiles_d = Ds[i];
                if ((rc = run_cfg(&m, &cam, &tf, &o, img, ref, reps, runs, res)) != 0) break;
                printf(HEAD "\"test\":\"D_sweep\",\"D\":%d,\"C\":%d,\"wall_ms\":%.2f,\"frame_ms\":{\"p50\":%.2f,\"p95\":%.2f,\"p99\":%.2f},\"cpu_ms\":%.2f,\"t_sc_ms\":%.2f,"
                       "\"t_update_ms\":%.2f,\"updates\":%llu,\"N_skipped\":%llu,\"rmse\":%.3g}\n",
                       HARGS, o.tiles_d, o.update_c, res->wall_ms, res->wall_ms, res->wall_p95, res->wall_p99, res->cpu_ms, res->t_sc_ms, res->t_update_ms,
                       (unsigned long long)res->c.table_updates,
                       (unsigned long long)res->c.cells_skipped_ert, res->rmse);
            }
            o.tiles_d = 20;
        }
        if (has(only, "C")) {
            const int Cs[5] = {1, 10, 100, 1000, 10000};
            /* without partial compositing each update walks whole lists: C is capped at
             * --c-nopartial-max and one run is timed (after the warm-up), or the sweep would take
             * minutes per point */
            for (int pc = 1; pc >= 0 && rc == 0; pc--)
                for (int i = 0; i < 5 && (pc || Cs[i] <= cnp_max) && rc == 0; i++) {
                    o.update_c = Cs[i]; o.partial_composite = pc;
                    int rp = pc ? reps : 1;
                    if ((rc = run_cfg(&m, &cam, &tf, &o, img, ref, rp, runs, res)) != 0) break;
                    printf(HEAD "\"test\":\"C_sweep\",\"partial\":%d,\"D\":%d,\"C\":%d,\"reps\":%d,\"wall_ms\":%.2f,\"frame_ms\":{\"p50\":%.2f,\"p95\":%.2f,\"p99\":%.2f},\"cpu_ms\":%.2f,"
                           "\"t_sc_ms\":%.2f,\"t_update_ms\":%.2f,\"updates\":%llu,\"N_skipped\":%llu,\"segments_in_lists\":%llu}\n",
                           HARGS, pc, o.tiles_d, o.update_c, rp, res->wall_ms, res->wall_ms, res->wall_p95, res->wall_p99, res->cpu_ms, res->t_sc_ms,
                           res->t_update_ms, (unsigned long long)res->c.table_updates,
                           (unsigned long long)res->c.cells_skipped_ert,
                           (unsigned long long)(res->c.segments_made - res->c.segments_merged));
                }
            o.update_c = 100; o.partial_composite = 1;
        }
        if (has(only, "table2")) {
            const char *names[5] = {"Base", "ERT", "ERT+SHARE", "ERT+DLB", "ERT+DLB+SHARE"};
            const int cfg[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1, 0, 1}, {1, 1, 1}};
            int wcounts[2] = {2, maxw};
            for (int wc = 0; wc < (maxw != 2 ? 2 : 1) && rc == 0; wc++)
                for (int i = 0; i < 5 && rc == 0; i++) {
                    int nw = wcounts[wc];
                    o.workers = nw; o.ert = cfg[i][0]; o.share = cfg[i][1]; o.dlb = cfg[i][2];
                    if ((rc = run_cfg(&m, &cam, &tf, &o, img, ref, reps, runs, res)) != 0) break;
                    double sum = 0, tmax = 0, csum = 0, cmax = 0, csum_cpu = 0, cmax_cpu = 0;
                    printf(HEAD "\"test\":\"table2\",\"config\":\"%s\",\"workers\":%d,\"wall_ms\":%.2f,\"frame_ms\":{\"p50\":%.2f,\"p95\":%.2f,\"p99\":%.2f},\"cpu_ms\":%.2f,\"rmse\":%.3g,\"max\":%.3g,\"per_worker\":[",
                           HARGS, names[i], nw, res->wall_ms, res->wall_ms, res->wall_p95, res->wall_p99, res->cpu_ms, res->rmse, res->max);
                    for (int k = 0; k < nw; k++) {
                        const tet_counters *p = &res->pw[k];
                        double t = p->t_sc_ms + p->t_update_ms;
                        csum_cpu += p->cpu_ms;
                        if (p->cpu_ms > cmax_cpu) cmax_cpu = p->cpu_ms;
                        double work = (double)p->cells_scanned;
                        sum += t; if (t > tmax) tmax = t;
                        csum += work; if (work > cmax) cmax = work;
                        printf("%s{\"ms\":%.1f,\"cpu_ms\":%.1f,\"cells\":%llu,\"skipped\":%llu,\"segments\":%llu,\"merged\":%llu}", k ? "," : "", t, p->cpu_ms,
                               (unsigned long long)p->cells_scanned, (unsigned long long)p->cells_skipped_ert,
                               (unsigned long long)p->segments_made, (unsigned long long)p->segments_merged);
                    }
                    printf("],\"t_worker_max_ms\":%.2f,\"cpu_worker_max_ms\":%.2f,\"imbalance_cpu\":%.3f,\"imbalance_time\":%.3f,\"imbalance_cells\":%.3f,"
                           "\"N_skipped\":%llu,\"cells_scanned\":%llu,\"segments\":%llu,\"t_composite_ms\":%.2f}\n",
                           tmax, cmax_cpu, csum_cpu > 0 ? cmax_cpu / (csum_cpu / nw) : 0.0,
                           sum > 0 ? tmax / (sum / nw) : 0.0, csum > 0 ? cmax / (csum / nw) : 0.0,
                           (unsigned long long)res->c.cells_skipped_ert,
                           (unsigned long long)res->c.cells_scanned,
                           (unsigned long long)res->c.segments_made, res->c.t_composite_ms);
                }
            o.workers = 1;
        }
        fflush(stdout);
    }
    free(ref); free(img); free(runs); free(res);
    if (mesh_path) tet_mesh_free(&m);
    else { free(m.points); free(m.scalar); free(m.tets); }
    return rc ? 1 : 0;
}
