/* bench_sim.c — `volfx-bench sim`: SPH throughput (particle-steps/s and neighbour
 * interactions/s) at several particle counts and thread counts, and `--dam-break`: the surge
 * front against Martin & Moyce (1952). One JSON object per line. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#if defined(__has_include)
#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#endif
#endif
#ifndef CALLGRIND_START_INSTRUMENTATION
#define CALLGRIND_START_INSTRUMENTATION
#endif

#include "profile/profiler.h"
#include "sim/sph.h"
#include "bench_sim_device.h"
#include "bench_sim_pool.h"

int bench_sim(int argc, char **argv);

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void cpu_model(char *out, size_t len)
{
    snprintf(out, len, "unknown");
    FILE *f = fopen("/proc/cpuinfo", "r");
    if (!f)
        return;
    char line[512];
    while (fgets(line, sizeof line, f)) {
        if (strncmp(line, "model name", 10) == 0) {
            char *c = strchr(line, ':');
            if (c) {
                c += 2;
                c[strcspn(c, "\n\"\\")] = 0;
                snprintf(out, len, "%s", c);
            }
            break;
        }
    }
    fclose(f);
}

/* The timed call, out of line so that `valgrind --tool=callgrind --toggle-collect=bench_timed_step`
 * counts the timed substeps only (not the warm-up or the setup). */
__attribute__((noinline)) vfx_result bench_timed_step(rt_sph *s, rt_sph_report *r, char *err, size_t errlen);
__attribute__((noinline)) vfx_result bench_timed_step(rt_sph *s, rt_sph_report *r, char *err, size_t errlen)
{
    return rt_sph_step(s, 1.f, r, err, errlen);
}

typedef struct bench_opts {
    int substeps, reps;
    double warmup_s;  /* simulated seconds of the collapse before timing */
    float skin[4];    /* desc.neighbor_skin per Verlet solver set (0 = the solver's default) */
    int nskin;
    bool rebuild, verlet;
} bench_opts;

/* Block of n particles (dx = 2 cm) in the corner of a tank three times as long: a dam break.
 * It first collapses for `warmup_s` simulated seconds in one solver (untimed), so that the
 * timed substeps are of a moving fluid (a block at rest would almost never rebuild its Verlet
 * lists and flatter them); that state is copied into one solver per method (rebuild every
 * substep, Verlet lists) and thread count, all stepped in turn within each repetition (so the
 * load other processes put on a shared machine falls on every configuration alike). Ratios
 * (threads, methods) are medians of the per-repetition ratios. */
#define BENCH_MAX_T 8
#define BENCH_MAX_S (5 * BENCH_MAX_T)
static int bench_size(uint32_t n_target, const uint32_t *threads, int nthreads, const bench_opts *o,
                      const char *cpu)
{
    const int substeps = o->substeps, reps = o->reps;
    /* block of exactly n_target particles: kx = kz, the largest divisor pair with kx <= cbrt */
    uint32_t kx = (uint32_t)floor(cbrt((double)n_target) + 1e-9);
    while (kx > 1 && n_target % (kx * kx) != 0)
        kx--;
    uint32_t ky = n_target / (kx * kx);
    const float dx = 0.02f;
    float bx = (float)kx * dx, by = (float)ky * dx, bz = (float)kx * dx;
    rt_sph_desc base = {.spacing = dx, .domain_min = {0, 0, 0}, .domain_max = {3.f * bx, 1.2f * by, bz},
                         .neighbor_skin = o->skin[0]};
    char err[256];
    /* warm-up: the collapse, on all the threads asked for */
    rt_sph *w = NULL;
    rt_sph_desc dw = base;
    dw.threads = threads[nthreads - 1];
    dw.max_substeps = 100000000;
    if (rt_sph_create(&dw, &w, err, sizeof err)) {
        fprintf(stderr, "volfx-bench sim: %s\n", err);
        return 1;
    }
    float lo[3] = {0, 0, 0}, hi[3] = {bx, by, bz};
    uint32_t n = 0;
    rt_sph_report wr = {0};
    double tw = now_s();
    if (rt_sph_add_block(w, lo, hi, &n, err, sizeof err) ||
        (o->warmup_s > 0.0 && rt_sph_step(w, (float)o->warmup_s, &wr, err, sizeof err))) {
        fprintf(stderr, "volfx-bench sim: warm-up: %s\n", err);
        rt_sph_destroy(w);
        return 1;
    }
    tw = now_s() - tw;
    rt_sph_columns wc = rt_sph_get_columns(w);
    int nsol = 0;
    rt_sph *s[BENCH_MAX_S] = {0};
    bool rebuild_of[BENCH_MAX_S];
    uint32_t thr_of[BENCH_MAX_S];
    int set_of[BENCH_MAX_S], tidx_of[BENCH_MAX_S]; /* solver set (method, skin), thread index */
    double *ps[BENCH_MAX_S] = {0}, *is[BENCH_MAX_S] = {0}, *ms[BENCH_MAX_S] = {0};
    double *rt[BENCH_MAX_S] = {0}, *rm[BENCH_MAX_S] = {0};
    uint64_t sub_sum[BENCH_MAX_S] = {0}, reb_sum[BENCH_MAX_S] = {0}, skin_sum[BENCH_MAX_S] = {0};
    rt_sph_report r[BENCH_MAX_S];
    int rc = 0;
    for (int m = 0; m < 1 + o->nskin && !rc; ++m) {
        if ((m == 0 && !o->rebuild) || (m > 0 && !o->verlet))
            continue;
        for (int t = 0; t < nthreads && !rc; ++t) {
            rt_sph_desc d = base;
            d.threads = threads[t];
            d.max_substeps = (uint32_t)substeps;
            d.flags = m == 0 ? RT_SPH_REBUILD_EVERY_SUBSTEP : 0;
            d.neighbor_skin = o->skin[m > 0 ? m - 1 : 0];
            int k = nsol++;
            rebuild_of[k] = m == 0;
            set_of[k] = m, tidx_of[k] = t;
            if (rt_sph_create(&d, &s[k], err, sizeof err)) {
                fprintf(stderr, "volfx-bench sim: %s\n", err);
                rc = 1;
                break;
            }
            thr_of[k] = rt_sph_thread_count(s[k]);
            if (rt_sph_add_particles(s[k], wc.count, wc.x, wc.y, wc.z, wc.vx, wc.vy, wc.vz, err, sizeof err)) {
                fprintf(stderr, "volfx-bench sim: %s\n", err);
                rc = 1;
                break;
            }
            rt_sph_step(s[k], 1.f, &r[k], NULL, 0); /* untimed: pages touched, lists built */
            ps[k] = calloc((size_t)reps, sizeof *ps[k]);
            is[k] = calloc((size_t)reps, sizeof *is[k]);
            ms[k] = calloc((size_t)reps, sizeof *ms[k]);
            rt[k] = calloc((size_t)reps, sizeof *rt[k]);
            rm[k] = calloc((size_t)reps, sizeof *rm[k]);
            if (!ps[k] || !is[k] || !ms[k] || !rt[k] || !rm[k])
                rc = 1;
        }
    }
    /* a no-op natively; under `valgrind --tool=callgrind --instr-atstart=no` the warm-up runs
     * uninstrumented (fast) and counting starts here */
    CALLGRIND_START_INSTRUMENTATION;
    for (int i = 0; i < reps && !rc; ++i) {
        for (int k = 0; k < nsol && !rc; ++k) {
            double t0 = now_s();
            /* frame_dt 1 s and a substep cap: exactly `substeps` substeps + one closing density pass */
            vfx_result e = bench_timed_step(s[k], &r[k], err, sizeof err);
            double dt = now_s() - t0;
            if (e) {
                fprintf(stderr, "volfx-bench sim: %s\n", err);
                rc = 1;
                break;
            }
            ps[k][i] = (double)n * r[k].substeps / dt;
            is[k][i] = 2.0 * (double)r[k].neighbor_pairs / dt; /* density + force pass */
            ms[k][i] = 1e3 * dt / r[k].substeps;
            sub_sum[k] += r[k].substeps;
            reb_sum[k] += r[k].neighbor_rebuilds;
            skin_sum[k] += r[k].skin_pairs;
        }
        for (int k = 0; k < nsol && !rc; ++k) {
            int first = k, same = k; /* 1st thread count of the same set; rebuild, same threads */
            for (int q = 0; q < nsol; ++q) {
                if (set_of[q] == set_of[k] && tidx_of[q] == 0)
                    first = q;
                if (set_of[q] == 0 && tidx_of[q] == tidx_of[k])
                    same = q;
            }
            rt[k][i] = ps[k][i] / ps[first][i];
            rm[k][i] = ps[k][i] / ps[same][i];
        }
    }
    double load[3] = {0, 0, 0};
    FILE *la = fopen("/proc/loadavg", "r");
    if (la) {
        if (fscanf(la, "%lf %lf %lf", &load[0], &load[1], &load[2]) != 3)
            load[0] = load[1] = load[2] = -1.0;
        fclose(la);
    }
    for (int k = 0; k < nsol && !rc; ++k) {
        double p = rt_median(ps[k], (uint32_t)reps), in = rt_median(is[k], (uint32_t)reps);
        double m = rt_median(ms[k], (uint32_t)reps), q = rt_median(rt[k], (uint32_t)reps);
        double qm = rt_median(rm[k], (uint32_t)reps);
        uint32_t tc = thr_of[k];
        printf("{\"effect\":\"sim\",\"particles\":%u,\"threads\":%u,\"substeps_per_rep\":%d,\"reps\":%d,"
               "\"particle_steps_per_s\":%.0f,\"particle_steps_per_s_per_thread\":%.0f,"
               "\"neighbour_interactions_per_s\":%.0f,\"ms_per_substep\":%.3f,"
               "\"neighbours_per_particle\":%.1f,\"memory_mb\":%.1f,\"ratio_to_first\":%.3f,\"cpu\":\"%s\","
               "\"method\":\"%s\",\"skin_over_H\":%.3f,\"ratio_to_rebuild\":%.3f,"
               "\"rebuilds_per_substep\":%.4f,\"mean_skin_list\":%.1f,\"warmup_s\":%.3f,"
               "\"warmup_substeps\":%u,\"warmup_wall_s\":%.1f,\"max_speed_after_warmup\":%.3f,"
               "\"loadavg\":[%.2f,%.2f,%.2f]}\n",
               n, tc, substeps, reps, p, p / tc, in, m,
               r[k].substeps ? (double)r[k].neighbor_pairs / r[k].substeps / n : 0.0,
               rt_sph_memory_bytes(s[k]) / 1048576.0, q, cpu, rebuild_of[k] ? "rebuild" : "verlet",
               rt_sph_params(s[k])->neighbor_skin, qm,
               sub_sum[k] ? (double)reb_sum[k] / (double)sub_sum[k] : 0.0,
               sub_sum[k] ? (double)skin_sum[k] / (double)sub_sum[k] / n : 0.0, o->warmup_s,
               wr.substeps, tw, wr.max_speed, load[0], load[1], load[2]);
    }
    for (int k = 0; k < nsol; ++k) {
        free(ps[k]), free(is[k]), free(ms[k]), free(rt[k]), free(rm[k]);
        rt_sph_destroy(s[k]);
    }
    rt_sph_destroy(w);
    return rc;
}

/* Martin & Moyce (1952), n^2 = 2 (column height 2a), a = 2.25 in, read from their Fig. 3
 * (digitised values as published in PySPH's examples/db_exp_data.py): T = t sqrt(2g/a),
 * Z = surge front x / a. */
static const double mm_T[] = {0.832, 1.219, 1.997, 2.547, 3.345, 4.034, 4.418, 5.091, 5.685};
static const double mm_Z[] = {1.217, 1.474, 2.292, 2.995, 4.134, 4.944, 5.881, 6.980, 7.945};

/* The surge front: the largest x where the fluid volume fraction on the floor
 * (rt_sph_volume_fraction: sum_j (m/rho0) W_poly6 over the fluid share of the kernel)
 * reaches 1/2, sampled every dx/20 at the first layer's height (dx/2) and mid-depth. 1/2 is
 * where a kernel-smoothed step from fluid to air crosses: the edge of the continuum the
 * particles stand for (a flat block's edge lies half a spacing beyond its last particle
 * centres), while a particle thrown ahead alone (fraction < 0.3) is spray, not the surge. */
static double surge_front(rt_sph *s, float dx)
{
    rt_sph_columns c = rt_sph_get_columns(s);
    const rt_sph_desc *p = rt_sph_params(s);
    double xmax = 0.0;
    for (uint32_t i = 0; i < c.count; ++i)
        xmax = c.x[i] > xmax ? c.x[i] : xmax;
    float q[3] = {0.f, p->domain_min[1] + 0.5f * dx, 0.5f * (p->domain_min[2] + p->domain_max[2])};
    for (double x = xmax + rt_sph_support(s); x > p->domain_min[0]; x -= dx / 20.0) {
        q[0] = (float)x;
        if (rt_sph_volume_fraction(s, q) >= 0.5f)
            return x;
    }
    return 0.0;
}

static double cpu_now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* pbf_iters, pbf_rho, pbf_relax: PBF's iterations, Chebyshev rho and relaxation (0: the defaults;
 * rho < 0: plain Jacobi) */
static int dam_break(int res, uint32_t threads, double t_max, double settle_s, uint32_t no_slip,
                     uint32_t solver, uint32_t pbf_iters, float pbf_rho, float pbf_relax, const char *cpu)
{
    const double a = 0.05715, g = 9.81;
    float dx = (float)(a / res);
    rt_sph_desc d = {.spacing = dx, .domain_min = {0, 0, 0},
                      .domain_max = {(float)(10 * a), (float)(2.5 * a), 4 * dx},
                      .threads = threads, .max_substeps = 1000000, .no_slip_faces = no_slip,
                      .solver = solver & 255u,
                      .flags = ((solver & 256u) ? RT_SPH_PBF_RECOMPUTE : 0u) | (pbf_rho < 0.f ? RT_SPH_PBF_NO_CHEBYSHEV : 0u),
                      .pbf_iterations = pbf_iters, .pbf_chebyshev_rho = pbf_rho > 0.f ? pbf_rho : 0.f,
                      .pbf_relaxation = pbf_relax};
    rt_sph *s;
    char err[256];
    if (rt_sph_create(&d, &s, err, sizeof err)) {
        fprintf(stderr, "volfx-bench sim: %s\n", err);
        return 1;
    }
    float lo[3] = {0, 0, 0}, hi[3] = {(float)a, (float)(2 * a), 4 * dx};
    uint32_t n;
    double t0 = now_s();
    if (settle_s > 0.0) {
        /* The experiment's column stood at rest behind a gate: settle it behind a wall at x = a
         * (a tank a wide, same EOS) so it starts hydrostatic, then release it at rest. A fresh
         * lattice is uncompressed (p = 0 everywhere): released as it is, it first falls and
         * bounces on its own compression, a pressure overshoot the experiment did not have. */
        rt_sph_desc dg = d;
        dg.domain_max[0] = (float)a;
        dg.sound_speed = rt_sph_params(s)->sound_speed;
        dg.stiffness = 0.f;
        rt_sph *gs;
        if (rt_sph_create(&dg, &gs, err, sizeof err)) {
            fprintf(stderr, "volfx-bench sim: %s\n", err);
            rt_sph_destroy(s);
            return 1;
        }
        rt_sph_add_block(gs, lo, hi, &n, NULL, 0);
        rt_sph_report r;
        if (rt_sph_step(gs, (float)settle_s, &r, err, sizeof err)) {
            fprintf(stderr, "volfx-bench sim: settling: %s\n", err);
            rt_sph_destroy(gs);
            rt_sph_destroy(s);
            return 1;
        }
        printf("{\"effect\":\"sim\",\"case\":\"dam_break_settle\",\"a_over_dx\":%d,\"settle_s\":%.3f,"
               "\"kinetic_energy_J\":%.3g,\"max_speed\":%.4f,\"max_density_error\":%.4f}\n",
               res, settle_s, r.kinetic_energy, r.max_speed, r.max_density_error);
        rt_sph_columns c = rt_sph_get_columns(gs);
        rt_sph_add_particles(s, c.count, c.x, c.y, c.z, NULL, NULL, NULL, NULL, 0); /* released at rest */
        rt_sph_destroy(gs);
    } else {
        rt_sph_add_block(s, lo, hi, &n, NULL, 0);
    }
    double Ts = sqrt(2 * g / a), worst = 0.0, c0 = cpu_now_s(), err_sum = 0.0;
    uint64_t substeps = 0;
    int rc = 0, used = 0;
    for (size_t k = 0; k < sizeof mm_T / sizeof mm_T[0]; ++k) {
        if (mm_T[k] > t_max)
            break;
        rt_sph_report r;
        if (rt_sph_step(s, (float)(mm_T[k] / Ts - rt_sph_time(s)), &r, err, sizeof err)) {
            fprintf(stderr, "volfx-bench sim: %s\n", err);
            rc = 1;
            break;
        }
        substeps += r.substeps;
        err_sum += r.mean_density_error;
        double front = surge_front(s, dx);
        double Z = front / a, e = (Z - mm_Z[k]) / mm_Z[k];
        worst = fabs(e) > worst ? fabs(e) : worst;
        used++;
        printf("{\"effect\":\"sim\",\"case\":\"dam_break\",\"solver\":\"%s\",\"a_over_dx\":%d,\"settle_s\":%.2f,\"no_slip\":%u,\"particles\":%u,\"T\":%.3f,"
               "\"Z\":%.4f,\"Z_martin_moyce\":%.3f,\"error_pct\":%.2f,\"max_density_error\":%.4f,\"mean_density_error\":%.5f}\n",
               (solver & 256u) ? "pbf-recompute" : solver ? "pbf" : "wcsph", res, settle_s, no_slip, n, mm_T[k], Z, mm_Z[k], 100.0 * e,
               r.max_density_error, r.mean_density_error);
    }
    double sim_s = rt_sph_time(s) > 0 ? rt_sph_time(s) : 1.0;
    printf("{\"effect\":\"sim\",\"case\":\"dam_break_summary\",\"solver\":\"%s\",\"a_over_dx\":%d,\"settle_s\":%.2f,\"no_slip\":%u,\"particles\":%u,"
           "\"points\":%d,\"max_abs_error_pct\":%.2f,\"substeps\":%llu,\"wall_s\":%.2f,"
           "\"cpu_s_per_simulated_s\":%.3f,\"mean_density_error_at_points\":%.5f,\"cpu\":\"%s\"}\n",
           (solver & 256u) ? "pbf-recompute" : solver ? "pbf" : "wcsph", res, settle_s, no_slip, n, used, 100.0 * worst, (unsigned long long)substeps,
           now_s() - t0, (cpu_now_s() - c0) / sim_s, used ? err_sum / used : 0.0, cpu);
    rt_sph_destroy(s);
    return rc;
}

static int parse_list(const char *s, uint32_t *out, int max)
{
    int n = 0;
    while (*s && n < max) {
        char *end;
        unsigned long v = strtoul(s, &end, 10);
        if (end == s || v == 0 || v > (1ul << 27))
            return -1;
        out[n++] = (uint32_t)v;
        s = *end == ',' ? end + 1 : end;
        if (*end && *end != ',')
            return -1;
    }
    return n;
}

/* `sim --device gpu [--sizes L] [--frames F] [--iterations I] [--threads T]` (bench_sim_device.c) */
static int bench_sim_device_args(int argc, char **argv, int from)
{
    bench_device_opts o = {.sizes = {16384, 65536, 262144}, .nsizes = 3, .frames = 10, .threads = 2};
    bool bad = from + 1 >= argc || strcmp(argv[from + 1], "gpu") != 0;
    for (int k = from + 2; k < argc && !bad; ++k) {
        const bool more = k + 1 < argc;
        if (!strcmp(argv[k], "--sizes") && more)
            bad = (o.nsizes = parse_list(argv[++k], o.sizes, 8)) <= 0;
        else if (!strcmp(argv[k], "--frames") && more)
            o.frames = atoi(argv[++k]);
        else if (!strcmp(argv[k], "--iterations") && more)
            o.iterations = (uint32_t)atoi(argv[++k]);
        else if (!strcmp(argv[k], "--threads") && more)
            o.threads = (uint32_t)atoi(argv[++k]);
        else if (strcmp(argv[k], "--json") != 0)
            bad = true;
    }
    if (bad || o.frames < 1 || o.frames > 100000 || o.iterations > 1000 || o.threads > 64) {
        fprintf(stderr, "volfx-bench sim --device gpu [--sizes 16384,65536,262144] [--frames 10 (1..100000)]\n"
                        "                 [--iterations I (PBF Jacobi iterations, 0..1000; 0 = 5)] [--threads 2 "
                        "(the CPU solver's; 0 = all cores)]\n");
        return 2;
    }
    return bench_sim_device(&o);
}

int bench_sim(int argc, char **argv)
{
    for (int i = 1; i < argc; ++i)
        if (!strcmp(argv[i], "--device"))
            return bench_sim_device_args(argc, argv, i);
    uint32_t sizes[8] = {4096, 16384, 65536}, threads[8] = {1, 2};
    int nsizes = 3, nthreads = 2, substeps = 20, reps = 5, res = 20;
    bool dam = false;
    bench_opts bo = {.warmup_s = 0.2, .nskin = 1, .rebuild = true, .verlet = true};
    double t_max = 6.0, settle_s = 0.0;
    uint32_t no_slip = 0, solver = RT_SPH_SOLVER_WCSPH, dam_iters = 0;
    float dam_rho = 0.f, dam_relax = 0.f;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--sizes") && i + 1 < argc) {
            if ((nsizes = parse_list(argv[++i], sizes, 8)) <= 0) {
                fprintf(stderr, "volfx-bench sim: --sizes wants a comma list of counts 1..2^27\n");
                return 2;
            }
        } else if (!strcmp(argv[i], "--threads") && i + 1 < argc) {
            if ((nthreads = parse_list(argv[++i], threads, 8)) <= 0) {
                fprintf(stderr, "volfx-bench sim: --threads wants a comma list\n");
                return 2;
            }
        } else if (!strcmp(argv[i], "--substeps") && i + 1 < argc) {
            substeps = atoi(argv[++i]);
        } else if (!strcmp(argv[i], "--reps") && i + 1 < argc) {
            reps = atoi(argv[++i]);
        } else if (!strcmp(argv[i], "--warmup-s") && i + 1 < argc) {
            bo.warmup_s = atof(argv[++i]);
        } else if (!strcmp(argv[i], "--skin") && i + 1 < argc) {
            /* a comma list: one set of Verlet solvers per skin, all stepped in the same run */
            char *v = argv[++i], *end;
            bo.nskin = 0;
            while (*v && bo.nskin < 4) {
                bo.skin[bo.nskin++] = strtof(v, &end);
                if (end == v || (*end && *end != ',')) {
                    fprintf(stderr, "volfx-bench sim: --skin wants a comma list of fractions of H\n");
                    return 2;
                }
                v = *end ? end + 1 : end;
            }
        } else if (!strcmp(argv[i], "--methods") && i + 1 < argc) {
            const char *v = argv[++i];
            bo.rebuild = strstr(v, "rebuild") != NULL;
            bo.verlet = strstr(v, "verlet") != NULL;
            if (!bo.rebuild && !bo.verlet) {
                fprintf(stderr, "volfx-bench sim: --methods wants rebuild, verlet or rebuild,verlet\n");
                return 2;
            }
        } else if (!strcmp(argv[i], "--pool") && i + 1 < argc) {
            /* the default scene's pool in WCSPH and PBF (bench_sim_pool.c) */
            bench_pool_opts po = {.n = (uint32_t)atoi(argv[++i]), .frames = 60, .threads = 2u, .solvers = 3u,
                                  .ramp_s = -1.f};
            bool bad = false;
            for (int k = i + 1; k < argc && !bad; ++k) {
                const bool more = k + 1 < argc;
                if (!strcmp(argv[k], "--frames") && more)
                    po.frames = atoi(argv[++k]);
                else if (!strcmp(argv[k], "--no-paddle"))
                    po.no_paddle = true;
                else if (!strcmp(argv[k], "--solver") && more) {
                    /* a comma list, all stepped in turn every frame */
                    char list[128];
                    snprintf(list, sizeof list, "%s", argv[++k]);
                    po.solvers = 0u;
                    for (char *t = strtok(list, ","); t; t = strtok(NULL, ","))
                        po.solvers |= !strcmp(t, "wcsph") ? 1u : !strcmp(t, "pbf") ? 2u : !strcmp(t, "pbf-recompute") ? 4u
                                      : !strcmp(t, "pbf-jacobi") ? 8u : 1u << 8;
                    if (po.solvers >> 8)
                        po.solvers = 0u;
                } else if (!strcmp(argv[k], "--threads") && more)
                    po.threads = (unsigned)atoi(argv[++k]);
                else if (!strcmp(argv[k], "--pbf-steps") && more)
                    po.pbf_steps = (unsigned)atoi(argv[++k]);
                else if (!strcmp(argv[k], "--pbf-iterations") && more)
                    po.pbf_iters = (unsigned)atoi(argv[++k]);
                else if (!strcmp(argv[k], "--pbf-relaxation") && more)
                    po.pbf_relax = (float)atof(argv[++k]);
                else if (!strcmp(argv[k], "--pbf-chebyshev") && more)
                    po.pbf_rho = (float)atof(argv[++k]);
                else if (!strcmp(argv[k], "--paddle-ramp") && more)
                    po.ramp_s = (float)atof(argv[++k]);
                else if (!strcmp(argv[k], "--settle") && more) {
                    int v = atoi(argv[++k]);
                    bad = v < 0 || v > 100000;
                    po.settle = (uint32_t)(v > 0 ? v : 0);
                } else if (!strcmp(argv[k], "--settle-quasi-static"))
                    po.settle_qs = true;
                else if (!strcmp(argv[k], "--pbf-xsph") && more)
                    po.pbf_xsph = (float)atof(argv[++k]);
                else if (strcmp(argv[k], "--json") != 0) {
                    fprintf(stderr, "volfx-bench sim --pool: unknown option '%s'\n", argv[k]);
                    bad = true;
                }
            }
            if (bad || po.n < 1 || po.frames < 1 || !po.solvers || po.threads < 1 || po.threads > 64 ||
                !(po.ramp_s >= 0.f || po.ramp_s == -1.f) || !(po.pbf_xsph >= 0.f && po.pbf_xsph <= 1.f) ||
                !(po.pbf_rho < 1.f) || !(po.pbf_relax >= 0.f)) {
                fprintf(stderr, "volfx-bench sim --pool N [--frames F] [--no-paddle] [--solver a comma list of wcsph, "
                        "pbf, pbf-recompute, pbf-jacobi (6 plain Jacobi iterations at eps 0.2 D0, the old default) (default wcsph,pbf)]\n"
                        "                      [--threads 1..64 (2)] [--pbf-steps S (per 1/60 s)] [--pbf-iterations I] "
                        "[--pbf-relaxation R] [--pbf-chebyshev RHO (< 0: plain Jacobi)]\n"
                        "                      [--paddle-ramp S (0: none; default one period)]\n"
                        "                      [--settle N (rt_sph_settle before frame 0, at most N steps; 0: none)] [--settle-quasi-static]\n"
                        "                      [--pbf-xsph C]\n");
                return 2;
            }
            return bench_sim_pool(&po);
        } else if (!strcmp(argv[i], "--dam-break")) {
            dam = true;
        } else if (!strcmp(argv[i], "--res") && i + 1 < argc) {
            res = atoi(argv[++i]);
        } else if (!strcmp(argv[i], "--t-max") && i + 1 < argc) {
            t_max = atof(argv[++i]);
        } else if (!strcmp(argv[i], "--settle") && i + 1 < argc) {
            settle_s = atof(argv[++i]);
        } else if (!strcmp(argv[i], "--solver") && i + 1 < argc) {
            const char *v = argv[++i];
            if (strcmp(v, "wcsph") && strcmp(v, "pbf") && strcmp(v, "pbf-recompute")) {
                fprintf(stderr, "volfx-bench sim: --solver is wcsph, pbf or pbf-recompute, not '%s'\n", v);
                return 2;
            }
            /* pbf-recompute: PBF with RT_SPH_PBF_RECOMPUTE (bit 8 here, the flag in dam_break) */
            solver = !strcmp(v, "wcsph") ? RT_SPH_SOLVER_WCSPH : !strcmp(v, "pbf") ? RT_SPH_SOLVER_PBF : RT_SPH_SOLVER_PBF | 256u;
        } else if (!strcmp(argv[i], "--pbf-iterations") && i + 1 < argc) {
            dam_iters = (uint32_t)atoi(argv[++i]);
        } else if (!strcmp(argv[i], "--pbf-relaxation") && i + 1 < argc) {
            dam_relax = (float)atof(argv[++i]);
        } else if (!strcmp(argv[i], "--pbf-chebyshev") && i + 1 < argc) {
            dam_rho = (float)atof(argv[++i]); /* < 0: plain Jacobi */
        } else if (!strcmp(argv[i], "--no-slip")) {
            /* the experiment's solid walls: the floor and the back wall behind the column */
            no_slip = RT_SPH_FACE_Y_MIN | RT_SPH_FACE_X_MIN;
        } else if (!strcmp(argv[i], "--help")) {
            puts("volfx-bench sim [--sizes 4096,16384,65536] [--threads 1,2] [--substeps 20] [--reps 5]\n"
                 "volfx-bench sim --device gpu [--sizes 16384,65536,262144] [--frames 10] [--iterations I] [--threads 2]\n"
                 "                (PBF on the CPU and in compute shaders side by side: particle-steps/s)\n"
                 "                [--warmup-s 0.2 (simulated s of the collapse before timing)]\n"
                 "                [--methods rebuild,verlet] [--skin 0 (neighbor_skin / H, up to 4 in a comma\n"
                 "                list, one set of Verlet solvers each; 0 = default)]\n"
                 "volfx-bench sim --dam-break [--res 20 (a/dx)] [--t-max 6 (last T)] [--threads 2]\n"
                 "                            [--settle 0 (s at rest behind a gate first; 0 = release a fresh lattice)]\n"
                 "                            [--no-slip (wall-law friction on the floor and back wall)]\n"
                 "                            [--solver wcsph|pbf|pbf-recompute] [--pbf-iterations I (PBF; 0 = 5)]\n"
                 "                            [--pbf-chebyshev R (PBF's rho; 0 = 0.7, < 0 = plain Jacobi)] [--pbf-relaxation E]");
            return 0;
        } else if (strcmp(argv[i], "--json") != 0) {
            fprintf(stderr, "volfx-bench sim: unknown option '%s'\n", argv[i]);
            return 2;
        }
    }
    if (substeps < 1 || substeps > 100000 || reps < 1 || reps > 1000 || res < 4 || res > 200 ||
        !(settle_s >= 0.0 && settle_s <= 10.0) || !(bo.warmup_s >= 0.0 && bo.warmup_s <= 10.0) ||
        !(bo.skin[0] >= 0.f && bo.skin[0] <= 1.f && bo.skin[1] >= 0.f && bo.skin[1] <= 1.f &&
          bo.skin[2] >= 0.f && bo.skin[2] <= 1.f && bo.skin[3] >= 0.f && bo.skin[3] <= 1.f)) {
        fprintf(stderr, "volfx-bench sim: need 1..100000 substeps, 1..1000 reps, 4..200 res, 0..10 s settle, "
                "0..10 s warm-up, skin 0..1\n");
        return 2;
    }
    char cpu[256];
    cpu_model(cpu, sizeof cpu);
    if (dam)
        return dam_break(res, threads[nthreads - 1], t_max, settle_s, no_slip, solver, dam_iters, dam_rho, dam_relax, cpu);
    bo.substeps = substeps;
    bo.reps = reps;
    for (int k = 0; k < nsizes; ++k)
        if (bench_size(sizes[k], threads, nthreads, &bo, cpu))
            return 1;
    return 0;
}
