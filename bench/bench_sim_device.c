/* bench_sim_device.c — `volfx-bench sim --device gpu`: the PBF solver on the CPU (sph_pbf.c) and
 * on the GPU (sph_gpu.c) beside each other, particle-steps per second at each size. */
#include "bench_sim_device.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "gfx/gl_context.h"
#include "sim/sph.h"
#include "sim/sph_gpu.h"

static double dev_wall_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double dev_cpu_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int dev_cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* A block of n particles (dx = 2 cm) in the corner of a tank three times as long (bench_size's
 * dam break), PBF with the given iterations (0: the default 5). */
static rt_sph *dev_block(uint32_t n_target, uint32_t iterations, uint32_t threads, char *err, size_t errlen)
{
    uint32_t kx = (uint32_t)floor(cbrt((double)n_target) + 1e-9);
    while (kx > 1 && n_target % (kx * kx) != 0)
        kx--;
    uint32_t ky = n_target / (kx * kx);
    const float dx = 0.02f;
    float bx = (float)kx * dx, by = (float)ky * dx, bz = (float)kx * dx;
    rt_sph_desc d = {.spacing = dx, .domain_min = {0, 0, 0}, .domain_max = {3.f * bx, 1.2f * by, bz},
                      .solver = RT_SPH_SOLVER_PBF, .pbf_iterations = iterations, .threads = threads};
    rt_sph *s = NULL;
    if (rt_sph_create(&d, &s, err, errlen))
        return NULL;
    float lo[3] = {0, 0, 0}, hi[3] = {bx, by, bz};
    if (rt_sph_add_block(s, lo, hi, NULL, err, errlen)) {
        rt_sph_destroy(s);
        return NULL;
    }
    return s;
}

/* One size: both solvers from the same block, stepped frame by frame in turn (the load of other
 * processes falls on both alike); the GPU waits for its own figures every frame, so its time is
 * the whole frame's work. */
static int dev_size(const bench_device_opts *o, uint32_t n, const char *renderer)
{
    char err[512];
    rt_sph *sc = dev_block(n, o->iterations, o->threads, err, sizeof err);
    rt_sph *sg = sc ? dev_block(n, o->iterations, o->threads, err, sizeof err) : NULL;
    rt_sph_gpu *g = NULL;
    rt_sph_gpu_desc gd = {.sync_stats = true};
    if (!sc || !sg || rt_sph_gpu_create(sg, &gd, &g, err, sizeof err)) {
        fprintf(stderr, "volfx-bench sim --device: %s\n", err);
        rt_sph_destroy(sc), rt_sph_destroy(sg);
        return 1;
    }
    const int F = o->frames;
    double *ratio = calloc((size_t)F, sizeof *ratio);
    double wall[2] = {0, 0}, cpu[2] = {0, 0};
    uint64_t steps[2] = {0, 0};
    uint32_t iters = rt_sph_params(sc)->pbf_iterations;
    int rc = 0;
    for (int f = -1; f < F && !rc && ratio; ++f) { /* frame -1: untimed (first-use allocations) */
        double fw[2];
        for (int k = 0; k < 2 && !rc; ++k) {
            rt_sph_report r;
            double w0 = dev_wall_s(), c0 = dev_cpu_s();
            rc = k ? rt_sph_gpu_step(g, 1.f / 60.f, &r, err, sizeof err) : rt_sph_step(sc, 1.f / 60.f, &r, err, sizeof err);
            fw[k] = dev_wall_s() - w0;
            if (f < 0)
                continue;
            wall[k] += fw[k], cpu[k] += dev_cpu_s() - c0;
            steps[k] += r.substeps;
        }
        if (f >= 0)
            ratio[f] = fw[1] / fw[0];
    }
    if (rc || !ratio) {
        fprintf(stderr, "volfx-bench sim --device: %u particles: %s\n", n, ratio ? err : "out of memory");
        rc = 1;
    } else {
        qsort(ratio, (size_t)F, sizeof *ratio, dev_cmp);
        printf("{\"bench\":\"sim_device\",\"particles\":%u,\"iterations\":%u,\"frames\":%d,\"threads\":%u,"
               "\"cpu\":{\"steps\":%llu,\"wall_s\":%.4f,\"process_cpu_s\":%.4f,\"particle_steps_per_s\":%.4g},"
               "\"gpu\":{\"steps\":%llu,\"wall_s\":%.4f,\"process_cpu_s\":%.4f,\"particle_steps_per_s\":%.4g,"
               "\"buffer_bytes\":%zu},\"gpu_wall_over_cpu_median\":%.3f,\"gl_renderer\":\"%s\"}\n",
               n, iters, F, rt_sph_thread_count(sc), (unsigned long long)steps[0], wall[0], cpu[0],
               (double)n * steps[0] / wall[0], (unsigned long long)steps[1], wall[1], cpu[1],
               (double)n * steps[1] / wall[1], rt_sph_gpu_memory_bytes(g), ratio[F / 2], renderer);
        fflush(stdout);
    }
    free(ratio);
    rt_sph_gpu_destroy(g);
    rt_sph_destroy(sc), rt_sph_destroy(sg);
    return rc;
}

int bench_sim_device(const bench_device_opts *o)
{
    rt_gl_context *gl = NULL;
    rt_gl_context_desc cd = {.mode = RT_GL_HEADLESS, .width = 64, .height = 64};
    if (rt_gl_context_create(&cd, &gl) != VFX_OK) {
        fprintf(stderr, "volfx-bench sim --device gpu: no headless GL 4.5 context\n");
        return 1;
    }
    int rc = 0;
    for (int k = 0; k < o->nsizes && !rc; ++k)
        rc = dev_size(o, o->sizes[k], rt_gl_context_renderer(gl));
    rt_gl_context_destroy(gl);
    return rc;
}
