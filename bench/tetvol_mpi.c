/* tetvol_mpi.c — volfx-tetvol-mpi: the seed-002 renderer across MPI ranks (tet_mpi.c) on a
 * .vtu / TetGen mesh or a generated grid, in the paper's configurations (Base, ERT, ERT+SHARE,
 * ERT+DLB, ERT+SHARE+DLB, DLB). Rank 0 prints one JSON line per configuration: median wall
 * time over --repeat renders, per-rank scan times and counts of the last render, imbalance
 * (max/mean), binary-swap bytes, and the image difference against the one-process renderer.
 * Usage: mpirun -np P volfx-tetvol-mpi [--vtu PATH [--field NAME] | --tetgen BASE [--field
 *        attrK] | --grid N] [--size S] [--view A|B|Z] [--tau T] [--repeat R] [--modes a,b,..]
 *        [--threshold X] [--tiles-d D] [--update-c C] [--ppm OUT] (OUT: the last image) */
#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include <mpi.h>

#include "core/args.h"
#include "core/file.h"
#include "scene/volume_file.h"
#include "tet_mpi.h"
#include "tet_render.h"
#include "tet_testmesh.h"

/* Frames the mesh's bounding sphere: view = T(0,0,-dist) Rx(pitch) Ry(yaw) T(-centre). */
static void camera(tet_camera *c, const tet_mesh *m, int w, int h, float yaw,
                   float pitch, float *radius)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < m->point_count; i++)
        for (int r = 0; r < 3; r++) {
            lo[r] = fmin(lo[r], m->points[3 * i + r]);
            hi[r] = fmax(hi[r], m->points[3 * i + r]);
        }
    double ctr[3], rad = 0;
    for (int r = 0; r < 3; r++) {
        ctr[r] = 0.5 * (lo[r] + hi[r]);
        rad += 0.25 * (hi[r] - lo[r]) * (hi[r] - lo[r]);
    }
    rad = sqrt(rad);
    *radius = (float)rad;
    const float fov = 0.8f;
    float dist = (float)(rad / sin(0.5 * fov) * 1.05);
    ref_testmesh_orbit(c, w, h, yaw, pitch, 1.0f / tanf(0.5f * fov), dist * 0.01f, dist * 4);
    const float *R = c->view; /* the rotation's columns at 0, 4, 8 */
    for (int r = 0; r < 3; r++)
        c->view[12 + r] = -(float)(R[r] * ctr[0] + R[4 + r] * ctr[1] + R[8 + r] * ctr[2]);
    c->view[14] -= dist;
}

/* A barrier that sleeps while waiting: MPI_Barrier spins, and with more ranks than cores the
 * spinning ranks would slow the one-process reference render on rank 0. */
static void barrier_polite(void)
{
    MPI_Request rq;
    int flag = 0;
    MPI_Ibarrier(MPI_COMM_WORLD, &rq);
    for (MPI_Test(&rq, &flag, MPI_STATUS_IGNORE); !flag; MPI_Test(&rq, &flag, MPI_STATUS_IGNORE)) {
        struct timespec ts = {0, 200000};
        nanosleep(&ts, NULL);
    }
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

typedef struct mode {
    const char *name;
    int ert, share, dlb;
} mode;

static const mode modes[] = {
    {"base", 0, 0, 0},      {"dlb", 0, 0, 1},     {"ert", 1, 0, 0},
    {"ert_share", 1, 1, 0}, {"ert_dlb", 1, 0, 1}, {"ert_share_dlb", 1, 1, 1},
};

static bool arg_int(const char *opt, const char *v, uint32_t lo, uint32_t hi, int *out, char *e, size_t n)
{
    uint32_t u = 0;
    bool ok = rt_arg_u32(opt, v, lo, hi, &u, e, n);
    if (ok) *out = (int)u;
    return ok;
}

static bool arg_float(const char *opt, const char *v, double lo, double hi, float *out, char *e, size_t n)
{
    double d = 0;
    bool ok = rt_arg_double(opt, v, lo, hi, &d, e, n);
    if (ok) *out = (float)d;
    return ok;
}

/* Every comma-separated entry of --modes must name a mode (an unknown one rendered nothing and
 * exited 0). */
static bool check_modes(const char *list, char *e, size_t n)
{
    for (const char *p = list;;) {
        const char *c = strchr(p, ',');
        size_t len = c ? (size_t)(c - p) : strlen(p);
        bool found = false;
        for (size_t k = 0; k < sizeof modes / sizeof modes[0]; k++)
            found |= strlen(modes[k].name) == len && !strncmp(p, modes[k].name, len);
        if (!found) {
            snprintf(e, n, "--modes: unknown mode '%.*s' (known: base, dlb, ert, ert_share, ert_dlb, "
                     "ert_share_dlb)", (int)len, p);
            return false;
        }
        if (!c)
            return true;
        p = c + 1;
    }
}

static void print_array_u(const char *key, const tet_mpi_stats *all, int P, size_t off)
{
    printf(",\"%s\":[", key);
    for (int r = 0; r < P; r++)
        printf("%s%llu", r ? "," : "",
               (unsigned long long)*(const uint64_t *)((const char *)&all[r] + off));
    printf("]");
}

static void print_array_d(const char *key, const tet_mpi_stats *all, int P, size_t off)
{
    printf(",\"%s\":[", key);
    for (int r = 0; r < P; r++)
        printf("%s%.1f", r ? "," : "", *(const double *)((const char *)&all[r] + off));
    printf("]");
}

static double imbalance(const tet_mpi_stats *all, int P, size_t off, int is_double)
{
    double mx = 0, sum = 0;
    for (int r = 0; r < P; r++) {
        const char *p = (const char *)&all[r] + off;
        double v = is_double ? *(const double *)p : (double)*(const uint64_t *)p;
        mx = fmax(mx, v);
        sum += v;
    }
    return sum > 0 ? mx / (sum / P) : 1.0;
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    int rank, P;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &P);
    const char *ppm = NULL, *vtu = NULL, *tetgen = NULL, *field = NULL, *view = "A", *mode_list = NULL;
    int grid = 30, size = 300, repeat = 3, tiles_d = 20, update_c = 100;
    float tau = 4.0f, threshold = 0.9f;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v) {
            if (rank == 0)
                fprintf(stderr, "volfx-tetvol-mpi: option %s needs a value\n", a);
            MPI_Finalize();
            return 2;
        }
        i++;
        char e[200] = "";
        bool ok = true;
        if (!strcmp(a, "--vtu")) vtu = v;
        else if (!strcmp(a, "--tetgen")) tetgen = v;
        else if (!strcmp(a, "--field")) field = v;
        else if (!strcmp(a, "--ppm")) ppm = v;
        else if (!strcmp(a, "--grid")) ok = arg_int(a, v, 1, 200, &grid, e, sizeof e);
        else if (!strcmp(a, "--size")) ok = arg_int(a, v, 1, 4096, &size, e, sizeof e);
        else if (!strcmp(a, "--view")) view = v;
        else if (!strcmp(a, "--tau")) ok = arg_float(a, v, 1e-6, 1e6, &tau, e, sizeof e);
        else if (!strcmp(a, "--repeat")) ok = arg_int(a, v, 1, 100, &repeat, e, sizeof e);
        else if (!strcmp(a, "--modes")) ok = check_modes(v, e, sizeof e), mode_list = v;
        else if (!strcmp(a, "--threshold")) ok = arg_float(a, v, 1e-6, 1, &threshold, e, sizeof e);
        else if (!strcmp(a, "--tiles-d")) ok = arg_int(a, v, 1, 1000, &tiles_d, e, sizeof e);
        else if (!strcmp(a, "--update-c")) ok = arg_int(a, v, 1, 1000000, &update_c, e, sizeof e);
        else {
            if (rank == 0)
                fprintf(stderr, "volfx-tetvol-mpi: unknown option %s\n", a);
            MPI_Finalize();
            return 2;
        }
        if (!ok) {
            if (rank == 0)
                fprintf(stderr, "volfx-tetvol-mpi: %s\n", e);
            MPI_Finalize();
            return 2;
        }
    }
    if (grid < 1 || grid > 200 || size < 1 || size > 4096 || repeat < 1 || repeat > 100 ||
        !(threshold > 0 && threshold <= 1) || tiles_d < 1 || tiles_d > 1000 || update_c < 1 ||
        (strcmp(view, "A") && strcmp(view, "B") && strcmp(view, "Z"))) {
        if (rank == 0)
            fprintf(stderr, "volfx-tetvol-mpi: --grid 1..200, --size 1..4096, --repeat 1..100, "
                            "--threshold (0,1], --tiles-d 1..1000, --update-c >= 1, --view A|B|Z\n");
        MPI_Finalize();
        return 2;
    }
    /* every rank loads the mesh itself (the paper's nodes hold their data where the
     * simulation left it; here each rank holds it all so that work can move as key ranges) */
    tet_mesh m;
    char err[256] = "";
    int rc = 0;
    const char *src = "grid";
    if (vtu) {
        src = vtu;
        rc = rt_volume_load_vtu(vtu, field ? field : "Velocity", &m, err, sizeof err);
    } else if (tetgen) {
        src = tetgen;
        rc = rt_volume_load_tetgen(tetgen, field ? field : "attr0", &m, err, sizeof err);
    } else if (ref_testmesh_grid(grid, &m) != 0) {
        rc = VFX_ERR_OUT_OF_MEMORY;
        snprintf(err, sizeof err, "out of memory for a %d^3 grid", grid);
    }
    int worst = rc;
    MPI_Allreduce(&rc, &worst, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (worst != 0) {
        if (rc != 0)
            fprintf(stderr, "volfx-tetvol-mpi: rank %d: %s\n", rank, err);
        MPI_Finalize();
        return 1;
    }
    tet_camera cam;
    float radius;
    /* A: from the side (across z), Z: down the z axis (the pipe's axis: long rays, many
     * cells per pixel), B: along the bounding box diagonal */
    if (!strcmp(view, "A"))
        camera(&cam, &m, size, size, 1.5708f, 0.0f, &radius);
    else if (!strcmp(view, "Z"))
        camera(&cam, &m, size, size, 0.0f, 0.0f, &radius);
    else
        camera(&cam, &m, size, size, 0.785f, 0.6155f, &radius);
    /* extinction per world unit scaled by the mesh's size: tau is the optical depth across
     * one bounding radius at the top of the scalar range */
    tet_tf tf = {.smin = m.scalar_min, .smax = m.scalar_max, .tau_lo = 0.1f * tau / radius,
                 .tau_hi = tau / radius, .color_lo = {0.1f, 0.3f, 1.0f}, .color_hi = {1.0f, 0.6f, 0.1f}};
    const size_t n4 = (size_t)size * size * 4;
    float *img = rank == 0 ? malloc(n4 * sizeof *img) : NULL;
    float *ref = rank == 0 ? malloc(n4 * sizeof *ref) : NULL;
    tet_mpi_stats *all = rank == 0 ? calloc((size_t)P, sizeof *all) : NULL;
    double *times = malloc((size_t)repeat * sizeof *times);
    if ((rank == 0 && (!img || !ref || !all)) || !times) {
        fprintf(stderr, "volfx-tetvol-mpi: out of memory for %dx%d images\n", size, size);
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    tet_mpi *ctx;
    if (tet_mpi_create(MPI_COMM_WORLD, &ctx, err, sizeof err) != 0) {
        fprintf(stderr, "volfx-tetvol-mpi: %s\n", err);
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    tet_options o;
    tet_options_default(&o);
    o.tiles_d = tiles_d;
    o.update_c = update_c;
    /* the one-process image every configuration is compared with */
    double t_one = 0;
    if (rank == 0) {
        tet_counters c;
        o.ert = 0;
        o.ert_threshold = 1.0f; /* the partial-compositing stop of the no-ERT runs below */
        double t0 = MPI_Wtime();
        if (tet_render(&m, &cam, &tf, &o, ref, &c, err, sizeof err) != 0) {
            fprintf(stderr, "volfx-tetvol-mpi: %s\n", err);
            MPI_Abort(MPI_COMM_WORLD, 1);
        }
        t_one = (MPI_Wtime() - t0) * 1e3;
        char host[64] = "";
        gethostname(host, sizeof host - 1);
        printf("{\"effect\":\"tetvol_mpi\",\"test\":\"setup\",\"mesh\":\"%s\",\"field\":\"%s\","
               "\"tets\":%u,\"points\":%u,\"size\":%d,\"view\":\"%s\",\"ranks\":%d,\"cores\":%ld,"
               "\"host\":\"%s\",\"threshold\":%.2f,\"D\":%d,\"C\":%d,\"one_process_ms\":%.1f,"
               "\"one_process_scanned\":%llu}\n",
               src, m.scalar_name[0] ? m.scalar_name : "grid", m.tet_count, m.point_count, size,
               view, P, sysconf(_SC_NPROCESSORS_ONLN), host, threshold, tiles_d, update_c, t_one,
               (unsigned long long)c.cells_scanned);
        fflush(stdout);
    }
    for (size_t mi = 0; mi < sizeof modes / sizeof modes[0]; mi++) {
        const mode *md = &modes[mi];
        if (mode_list) {
            /* exact match of one comma-separated entry */
            const char *p = mode_list;
            size_t n = strlen(md->name);
            int found = 0;
            while (*p) {
                const char *e = strchr(p, ',');
                size_t len = e ? (size_t)(e - p) : strlen(p);
                if (len == n && !strncmp(p, md->name, n))
                    found = 1;
                p += len + (e ? 1 : 0);
            }
            if (!found)
                continue;
        }
        o.ert = md->ert;
        o.ert_threshold = md->ert ? threshold : 1.0f;
        o.share = md->share;
        o.dlb = md->dlb;
        for (int r = 0; r < repeat; r++) {
            barrier_polite();
            double t0 = MPI_Wtime();
            rc = tet_mpi_render(ctx, &m, &cam, &tf, &o, img, NULL, all, err, sizeof err);
            double t = (MPI_Wtime() - t0) * 1e3, tmax = t;
            MPI_Reduce(&t, &tmax, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
            if (rc != 0) {
                if (rank == 0)
                    fprintf(stderr, "volfx-tetvol-mpi: %s\n", err);
                tet_mpi_destroy(ctx);
                MPI_Finalize();
                return 1;
            }
            times[r] = tmax;
        }
        if (rank != 0)
            continue;
        qsort(times, (size_t)repeat, sizeof *times, cmp_double);
        double se = 0, mx = 0;
        for (size_t i = 0; i < n4; i++) {
            double e = fabs((double)img[i] - ref[i]);
            se += e * e;
            mx = fmax(mx, e);
        }
        uint64_t scanned = 0, skipped = 0, moved = 0, bytes = 0;
        for (int r = 0; r < P; r++) {
            scanned += all[r].cnt.cells_scanned;
            skipped += all[r].cnt.cells_skipped_ert;
            moved += all[r].cells_taken;
            bytes += all[r].bytes_sent;
        }
        printf("{\"effect\":\"tetvol_mpi\",\"test\":\"mode\",\"mode\":\"%s\",\"ranks\":%d,"
               "\"view\":\"%s\",\"median_ms\":%.1f,\"min_ms\":%.1f,\"max_ms\":%.1f,\"repeat\":%d,"
               "\"cells_scanned\":%llu,\"cells_skipped_ert\":%llu,\"keys_moved\":%llu,"
               "\"swap_bytes\":%llu,\"imbalance_t_sc\":%.2f,\"imbalance_cpu\":%.2f,"
               "\"imbalance_scanned\":%.2f,"
               "\"max_vs_one_process\":%.3g,\"rmse_vs_one_process\":%.3g",
               md->name, P, view, times[repeat / 2], times[0], times[repeat - 1], repeat,
               (unsigned long long)scanned, (unsigned long long)skipped,
               (unsigned long long)moved, (unsigned long long)bytes,
               imbalance(all, P, offsetof(tet_mpi_stats, cnt.t_sc_ms), 1),
               imbalance(all, P, offsetof(tet_mpi_stats, t_phase1_cpu_ms), 1),
               imbalance(all, P, offsetof(tet_mpi_stats, cnt.cells_scanned), 0), mx,
               sqrt(se / n4));
        print_array_d("t_sc_ms", all, P, offsetof(tet_mpi_stats, cnt.t_sc_ms));
        print_array_d("t_setup_ms", all, P, offsetof(tet_mpi_stats, t_setup_ms));
        print_array_d("t_phase1_ms", all, P, offsetof(tet_mpi_stats, t_phase1_ms));
        print_array_d("t_export_ms", all, P, offsetof(tet_mpi_stats, t_export_ms));
        print_array_d("t_phase1_cpu_ms", all, P, offsetof(tet_mpi_stats, t_phase1_cpu_ms));
        print_array_d("t_comm_ms", all, P, offsetof(tet_mpi_stats, t_comm_ms));
        print_array_d("t_idle_ms", all, P, offsetof(tet_mpi_stats, t_idle_ms));
        print_array_u("polls", all, P, offsetof(tet_mpi_stats, polls));
        print_array_d("t_swap_ms", all, P, offsetof(tet_mpi_stats, t_swap_ms));
        print_array_d("t_gather_ms", all, P, offsetof(tet_mpi_stats, t_gather_ms));
        print_array_u("scanned", all, P, offsetof(tet_mpi_stats, cnt.cells_scanned));
        print_array_u("keys_done", all, P, offsetof(tet_mpi_stats, keys_done));
        print_array_u("taken", all, P, offsetof(tet_mpi_stats, cells_taken));
        print_array_u("segments_made", all, P, offsetof(tet_mpi_stats, cnt.segments_made));
        print_array_u("segments_local", all, P, offsetof(tet_mpi_stats, segments_local));
        print_array_u("segments_final", all, P, offsetof(tet_mpi_stats, segments_final));
        print_array_u("swap_bytes_rank", all, P, offsetof(tet_mpi_stats, bytes_sent));
        print_array_u("shares", all, P, offsetof(tet_mpi_stats, share_rounds));
        print_array_u("reductions", all, P, offsetof(tet_mpi_stats, reductions));
        printf("}\n");
        fflush(stdout);
    }
    if (rank == 0 && ppm) {
        /* premultiplied colour over black, rows flipped (row 0 is the bottom) */
        char perr[1200];
        FILE *f = rt_open_output(ppm, "wb", perr, sizeof perr); /* never blocks on a FIFO */
        if (!f) {
            fprintf(stderr, "volfx-tetvol-mpi: --ppm: %s\n", perr);
        } else {
            fprintf(f, "P6\n%d %d\n255\n", size, size);
            for (int y = size - 1; y >= 0; y--)
                for (int x = 0; x < size; x++)
                    for (int k = 0; k < 3; k++) {
                        float c = img[4 * ((size_t)y * size + x) + k];
                        fputc((int)(255.0f * (c < 0 ? 0 : c > 1 ? 1 : c) + 0.5f), f);
                    }
            fclose(f);
        }
    }
    tet_mpi_destroy(ctx);
    free(img);
    free(ref);
    free(all);
    free(times);
    if (vtu || tetgen)
        tet_mesh_free(&m);
    else {
        free(m.points);
        free(m.scalar);
        free(m.tets);
    }
    MPI_Finalize();
    return 0;
}
