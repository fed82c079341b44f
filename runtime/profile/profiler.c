/* profiler.c — fixed table of named series x frames; no allocation per frame. */
#include "profile/profiler.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct series {
    char name[48];
    bool gpu;
} series;

struct vfx_profiler {
    uint32_t max_frames;
    uint32_t frame;         /* frames ended */
    double frame_start;     /* ms */
    double *frame_ms;       /* ring of max_frames */
    double *frame_t0;       /* start time of each frame (trace) */
    double *values;         /* ring: max_frames x VFX_PROFILER_MAX_SERIES, NAN when absent */
    double *starts;         /* span start offsets within the frame (trace) */
    double cursor;          /* CPU time of the current frame's spans laid end to end */
    series series[VFX_PROFILER_MAX_SERIES];
    uint32_t series_count;
    double *all_frame_ms;   /* every frame, for the summary */
    uint32_t all_count, all_cap;
};

double vfx_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

vfx_profiler *vfx_profiler_create(uint32_t max_frames)
{
    if (max_frames == 0)
        max_frames = 1;
    vfx_profiler *p = calloc(1, sizeof *p);
    if (!p)
        return NULL;
    p->max_frames = max_frames;
    p->frame_ms = calloc(max_frames, sizeof(double));
    p->frame_t0 = calloc(max_frames, sizeof(double));
    p->values = malloc((size_t)max_frames * VFX_PROFILER_MAX_SERIES * sizeof(double));
    p->starts = calloc((size_t)max_frames * VFX_PROFILER_MAX_SERIES, sizeof(double));
    if (!p->frame_ms || !p->frame_t0 || !p->values || !p->starts) {
        vfx_profiler_destroy(p);
        return NULL;
    }
    for (size_t i = 0; i < (size_t)max_frames * VFX_PROFILER_MAX_SERIES; ++i)
        p->values[i] = NAN;
    return p;
}

void vfx_profiler_destroy(vfx_profiler *p)
{
    if (!p)
        return;
    free(p->frame_ms);
    free(p->frame_t0);
    free(p->values);
    free(p->starts);
    free(p->all_frame_ms);
    free(p);
}

static double *row(const vfx_profiler *p, uint32_t frame)
{
    return &p->values[(size_t)(frame % p->max_frames) * VFX_PROFILER_MAX_SERIES];
}

void vfx_profiler_frame_begin(vfx_profiler *p)
{
    if (!p)
        return;
    p->frame_start = vfx_now_ms();
    p->cursor = 0;
    double *r = row(p, p->frame);
    for (int i = 0; i < VFX_PROFILER_MAX_SERIES; ++i)
        r[i] = NAN;
}

double vfx_profiler_frame_end(vfx_profiler *p)
{
    if (!p)
        return 0;
    double ms = vfx_now_ms() - p->frame_start;
    p->frame_ms[p->frame % p->max_frames] = ms;
    p->frame_t0[p->frame % p->max_frames] = p->frame_start;
    if (p->all_count == p->all_cap) {
        uint32_t cap = p->all_cap ? p->all_cap * 2 : 256;
        double *n = realloc(p->all_frame_ms, cap * sizeof(double));
        if (n) {
            p->all_frame_ms = n;
            p->all_cap = cap;
        }
    }
    if (p->all_count < p->all_cap)
        p->all_frame_ms[p->all_count++] = ms;
    p->frame++;
    return ms;
}

static int series_index(vfx_profiler *p, const char *name, bool gpu)
{
    for (uint32_t i = 0; i < p->series_count; ++i)
        if (strcmp(p->series[i].name, name) == 0)
            return (int)i;
    if (p->series_count >= VFX_PROFILER_MAX_SERIES)
        return -1;
    series *s = &p->series[p->series_count];
    snprintf(s->name, sizeof s->name, "%s", name);
    s->gpu = gpu;
    return (int)p->series_count++;
}

static void record(vfx_profiler *p, const char *name, double ms, bool gpu)
{
    int i = series_index(p, name, gpu);
    if (i < 0)
        return;
    size_t at = (size_t)(p->frame % p->max_frames) * VFX_PROFILER_MAX_SERIES + (size_t)i;
    p->values[at] = ms;
    if (!gpu) {
        p->starts[at] = p->cursor;
        p->cursor += ms;
    }
}

void vfx_profiler_on_system(void *user, const char *name, vfx_phase phase, double cpu_ms)
{
    (void)phase;
    if (user)
        record(user, name, cpu_ms, false);
}

void vfx_profiler_cpu(vfx_profiler *p, const char *name, double cpu_ms)
{
    if (p)
        record(p, name, cpu_ms, false);
}

void vfx_profiler_gpu_stats(vfx_profiler *p, const vfx_stats *stats)
{
    if (!p || !stats)
        return;
    for (uint32_t i = 0; i < stats->count && i < VFX_STATS_MAX; ++i) {
        const char *n = stats->entries[i].name;
        size_t len = strnlen(n, sizeof stats->entries[i].name);
        if (len > 7 && strcmp(n + len - 7, ".gpu_ms") == 0)
            record(p, n, stats->entries[i].value, true);
    }
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Nearest-rank percentile of a sorted array. */
static double pct(const double *s, uint32_t n, double q)
{
    if (n == 0)
        return NAN;
    double rank = ceil(q * n);
    uint32_t i = rank < 1 ? 0 : (uint32_t)rank - 1;
    return s[i < n ? i : n - 1];
}

vfx_frame_summary vfx_profiler_summary(const vfx_profiler *p, uint32_t skip)
{
    vfx_frame_summary s;
    memset(&s, 0, sizeof s);
    if (!p || p->all_count <= skip)
        return s;
    uint32_t n = p->all_count - skip;
    double *sorted = malloc(n * sizeof(double));
    if (!sorted)
        return s;
    memcpy(sorted, p->all_frame_ms + skip, n * sizeof(double));
    qsort(sorted, n, sizeof(double), cmp_double);
    double sum = 0;
    for (uint32_t i = 0; i < n; ++i)
        sum += sorted[i];
    s.frames = n;
    s.mean_ms = sum / n;
    s.mean_fps = sum > 0 ? 1000.0 * n / sum : 0;
    s.p50_ms = pct(sorted, n, 0.50);
    s.p95_ms = pct(sorted, n, 0.95);
    s.p99_ms = pct(sorted, n, 0.99);
    s.max_ms = sorted[n - 1];
    free(sorted);
    return s;
}

double vfx_profiler_series_median(const vfx_profiler *p, const char *name)
{
    if (!p)
        return NAN;
    int idx = -1;
    for (uint32_t i = 0; i < p->series_count; ++i)
        if (strcmp(p->series[i].name, name) == 0)
            idx = (int)i;
    if (idx < 0)
        return NAN;
    uint32_t kept = p->frame < p->max_frames ? p->frame : p->max_frames;
    double *v = malloc((kept ? kept : 1) * sizeof(double));
    if (!v)
        return NAN;
    uint32_t n = 0;
    for (uint32_t f = p->frame - kept; f < p->frame; ++f) {
        double x = row(p, f)[idx];
        if (!isnan(x))
            v[n++] = x;
    }
    double m = vfx_median(v, n);
    free(v);
    return m;
}

double vfx_median(double *v, uint32_t n)
{
    if (n == 0)
        return NAN;
    qsort(v, n, sizeof(double), cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

vfx_result vfx_profiler_write_csv(const vfx_profiler *p, const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return VFX_ERR_IO;
    fprintf(f, "frame,frame_ms");
    for (uint32_t i = 0; i < p->series_count; ++i)
        fprintf(f, ",%s", p->series[i].name);
    fprintf(f, "\n");
    uint32_t kept = p->frame < p->max_frames ? p->frame : p->max_frames;
    for (uint32_t fr = p->frame - kept; fr < p->frame; ++fr) {
        fprintf(f, "%u,%.4f", fr, p->frame_ms[fr % p->max_frames]);
        const double *r = row(p, fr);
        for (uint32_t i = 0; i < p->series_count; ++i)
            isnan(r[i]) ? fprintf(f, ",") : fprintf(f, ",%.4f", r[i]);
        fprintf(f, "\n");
    }
    return fclose(f) == 0 ? VFX_OK : VFX_ERR_IO;
}

vfx_result vfx_profiler_write_trace(const vfx_profiler *p, const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return VFX_ERR_IO;
    fprintf(f, "{\"traceEvents\":[\n");
    fprintf(f, "{\"name\":\"thread_name\",\"ph\":\"M\",\"pid\":1,\"tid\":1,\"args\":{\"name\":\"CPU\"}},\n");
    fprintf(f, "{\"name\":\"thread_name\",\"ph\":\"M\",\"pid\":1,\"tid\":2,\"args\":{\"name\":\"GPU\"}}");
    uint32_t kept = p->frame < p->max_frames ? p->frame : p->max_frames;
    double origin = kept ? p->frame_t0[(p->frame - kept) % p->max_frames] : 0;
    for (uint32_t fr = p->frame - kept; fr < p->frame; ++fr) {
        double t0 = (p->frame_t0[fr % p->max_frames] - origin) * 1000.0; /* us */
        fprintf(f, ",\n{\"name\":\"frame %u\",\"ph\":\"X\",\"pid\":1,\"tid\":1,\"ts\":%.3f,\"dur\":%.3f}",
                fr, t0, p->frame_ms[fr % p->max_frames] * 1000.0);
        const double *r = row(p, fr);
        const double *st = &p->starts[(size_t)(fr % p->max_frames) * VFX_PROFILER_MAX_SERIES];
        double gpu_cursor = 0;
        for (uint32_t i = 0; i < p->series_count; ++i) {
            if (isnan(r[i]))
                continue;
            /* GPU passes are laid end to end: their absolute start times are not read back. */
            double start = p->series[i].gpu ? gpu_cursor : st[i];
            if (p->series[i].gpu)
                gpu_cursor += r[i];
            fprintf(f, ",\n{\"name\":\"%s\",\"ph\":\"X\",\"pid\":1,\"tid\":%d,\"ts\":%.3f,\"dur\":%.3f}",
                    p->series[i].name, p->series[i].gpu ? 2 : 1, t0 + start * 1000.0, r[i] * 1000.0);
        }
    }
    fprintf(f, "\n]}\n");
    return fclose(f) == 0 ? VFX_OK : VFX_ERR_IO;
}
