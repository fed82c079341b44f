/* bench_beams.c — `volfx-bench beams`: the thesis' comparison (its 4.3) of the closed form
 * against ray marching with 8..120 samples, error against run time, on the CPU in float32
 * (the GL path is bench_beams_gpu.c). One JSON object per configuration.
 *
 * Error is measured against the float64 closed form, which tests/beams/test_beam_field.c
 * checks against the adaptive quadrature of the raw density (max 2.7e-10 relative); running the
 * quadrature per pixel would take minutes per image. Metrics over pixels whose H is above
 * 1e-6 of the image maximum (the criterion): max and mean relative error, how many are
 * above 1e-5, the max where the float32 inputs allow 1e-5 (cond < 1e-5 H), and the
 * max of error / (1e-5 H + cond), cond = ref_beams_cond_abs at 2 ulps (what float32 inputs
 * allow; docs/beams.md). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "lab/beam_field_d.h"
#include "lab/beam_field_f.h"
#include "beams_ref.h"

typedef struct bench_scene {
    volfx_beam_d beams[10];
    uint32_t count;
    float eye[3];
    uint32_t width, height;
} bench_scene;

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/* Pinhole camera at eye looking down -z, 60 degrees vertical field of view. */
static void pixel_ray(const bench_scene *s, uint32_t x, uint32_t y, double v[3])
{
    double t = tan(0.5 * 60.0 * 3.14159265358979 / 180.0);
    double a = (double)s->width / s->height;
    v[0] = (2.0 * (x + 0.5) / s->width - 1.0) * t * a;
    v[1] = (1.0 - 2.0 * (y + 0.5) / s->height) * t;
    v[2] = -1.0;
    double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; ++k)
        v[k] /= n;
}

/* Beam sets as in the thesis' figures: beams fired across the view, a = b. */
static void make_scene(bench_scene *s, uint32_t beams, uint32_t size)
{
    memset(s, 0, sizeof *s);
    s->count = beams;
    s->width = s->height = size;
    s->eye[2] = 6.0f;
    for (uint32_t i = 0; i < beams; ++i) {
        double ang = 2.0 * 3.14159265358979 * i / (beams > 0 ? beams : 1);
        vfx_beam b = {.type = VFX_TYPE_BEAM,
                      .head = {(float)(1.2 * cos(ang)), (float)(1.2 * sin(ang)), (float)(-0.5 * (i % 3))},
                      .length = 2.5f, .dir = {(float)-cos(ang + 0.6), (float)-sin(ang + 0.6), 0.2f},
                      .radius = 0.6f, .a = 0.3f, .b = 0.3f};
        char err[256];
        volfx_beam_validate(&b, &s->beams[i], err, sizeof err);
    }
}

/* Ray marching baseline: midpoint rule with n samples over the part of the ray inside the
 * beams' bounding spheres (centre of the segment, radius L/2 + R), float32. */
static float march(const bench_scene *s, const float o[3], const float v[3], float far, int n)
{
    float lo = far, hi = 0.0f;
    for (uint32_t i = 0; i < s->count; ++i) {
        const volfx_beam_d *b = &s->beams[i];
        float c[3], rad = (float)(0.5 * b->length + b->radius);
        for (int k = 0; k < 3; ++k)
            c[k] = (float)(b->head[k] + 0.5 * b->length * b->dir[k]) - o[k];
        float tc = c[0] * v[0] + c[1] * v[1] + c[2] * v[2];
        float d2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2] - tc * tc;
        if (d2 >= rad * rad)
            continue;
        float h = sqrtf(rad * rad - d2);
        if (tc - h < lo) lo = tc - h;
        if (tc + h > hi) hi = tc + h;
    }
    if (lo < 0.0f) lo = 0.0f;
    if (hi > far) hi = far;
    if (!(hi > lo))
        return 0.0f;
    float dt = (hi - lo) / (float)n, sum = 0.0f;
    for (int j = 0; j < n; ++j) {
        float t = lo + (j + 0.5f) * dt;
        double p[3] = {o[0] + t * v[0], o[1] + t * v[1], o[2] + t * v[2]};
        for (uint32_t i = 0; i < s->count; ++i)
            sum += (float)volfx_beam_density_d(&s->beams[i], p);
    }
    return sum * dt;
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int bench_beams_gpu(int argc, char **argv);
int bench_beams_panel(int argc, char **argv);

int bench_beams(int argc, char **argv)
{
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--gpu"))
            return bench_beams_gpu(argc, argv);
        if (!strcmp(argv[i], "--panel"))
            return bench_beams_panel(argc, argv);
    }
    int reps = 5;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--reps") && i + 1 < argc) reps = atoi(argv[++i]);
        else if (strcmp(argv[i], "--json") != 0) {
            fprintf(stderr, "volfx-bench beams: unknown option '%s' (options: --reps N, --json)\n", argv[i]);
            return 2;
        }
    }
    if (reps < 1 || reps > 100) {
        fprintf(stderr, "volfx-bench beams: --reps must be 1..100\n");
        return 2;
    }
    static const uint32_t sets[] = {1, 5, 10}, sizes[] = {256, 512};
    static const int samples[] = {0, 8, 16, 32, 64, 120}; /* 0 = closed form */
    const float far = 50.0f;
    for (size_t si = 0; si < 2; ++si) {
        for (size_t bi = 0; bi < 3; ++bi) {
            bench_scene s;
            make_scene(&s, sets[bi], sizes[si]);
            size_t np = (size_t)s.width * s.height;
            double *ref = malloc(np * sizeof *ref);
            float *img = malloc(np * sizeof *img);
            double *times = malloc((size_t)reps * sizeof *times);
            double *cond = malloc(np * sizeof *cond);
            if (!ref || !img || !times || !cond) {
                free(ref); free(img); free(times); free(cond);
                fprintf(stderr, "volfx-bench beams: out of memory\n");
                return 1;
            }
            double od[3] = {s.eye[0], s.eye[1], s.eye[2]}, hmax = 0.0;
            for (uint32_t y = 0; y < s.height; ++y)
                for (uint32_t x = 0; x < s.width; ++x) {
                    double v[3], h = 0.0;
                    pixel_ray(&s, x, y, v);
                    for (uint32_t i = 0; i < s.count; ++i)
                        h += volfx_beam_integral_d(&s.beams[i], od, v, 0.0, far);
                    ref[(size_t)y * s.width + x] = h;
                    /* what the float32 inputs allow (2-ulp moves of the ray and the heads) */
                    cond[(size_t)y * s.width + x] = ref_beams_cond_abs(s.beams, s.count, od, v, 0.0, far, 2.0);
                    if (h > hmax) hmax = h;
                }
            for (size_t mi = 0; mi < sizeof samples / sizeof samples[0]; ++mi) {
                int n = samples[mi];
                for (int r = 0; r < reps; ++r) {
                    double t0 = now_ms();
                    for (uint32_t y = 0; y < s.height; ++y)
                        for (uint32_t x = 0; x < s.width; ++x) {
                            double vd[3];
                            pixel_ray(&s, x, y, vd);
                            float v[3] = {(float)vd[0], (float)vd[1], (float)vd[2]}, h = 0.0f;
                            if (n == 0)
                                for (uint32_t i = 0; i < s.count; ++i)
                                    h += volfx_beam_integral_f(&s.beams[i], s.eye, v, 0.0f, far);
                            else
                                h = march(&s, s.eye, v, far, n);
                            img[(size_t)y * s.width + x] = h;
                        }
                    times[r] = now_ms() - t0;
                }
                qsort(times, (size_t)reps, sizeof *times, cmp_d);
                double emax = 0.0, esum = 0.0, emax_wc = 0.0, ratio = 0.0;
                size_t counted = 0, above = 0;
                for (size_t p = 0; p < np; ++p) {
                    if (ref[p] <= 1e-6 * hmax)
                        continue;
                    double e = fabs(img[p] - ref[p]) / ref[p];
                    if (e > emax) emax = e;
                    if (cond[p] < 1e-5 * ref[p] && e > emax_wc) emax_wc = e;
                    ratio = fmax(ratio, e * ref[p] / (1e-5 * ref[p] + cond[p]));
                    above += e > 1e-5;
                    esum += e;
                    counted++;
                }
                printf("{\"effect\":\"beams\",\"device\":\"cpu-float32-1-thread\",\"method\":\"%s\","
                       "\"samples\":%d,\"beams\":%u,\"width\":%u,\"height\":%u,\"reps\":%d,"
                       "\"frame_ms\":{\"p50\":%.3f,\"p95\":%.3f,\"p99\":%.3f,\"min\":%.3f,\"max\":%.3f},"
                       "\"error_vs_f64_closed_form\":{\"max_rel\":%.3g,\"mean_rel\":%.3g,\"pixels\":%zu,"
                       "\"above_1e-5\":%zu,\"max_rel_where_cond_below_1e-5\":%.3g,\"max_err_over_1e-5_plus_cond\":%.3g}}\n",
                       n == 0 ? "closed_form" : "ray_march", n, s.count, s.width, s.height, reps,
                       times[reps / 2], times[(size_t)ceil(0.95 * reps) - 1], times[(size_t)ceil(0.99 * reps) - 1],
                       times[0], times[reps - 1], emax,
                       counted ? esum / counted : 0.0, counted, above, emax_wc, ratio);
                fflush(stdout);
            }
            free(ref); free(img); free(times); free(cond);
        }
    }
    return 0;
}
