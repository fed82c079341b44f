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

/* Frames kept exactly at the start of a run, so a summary can drop up to this many warm-up
 * frames after the ring has rolled past them. */
#define RT_PROF_HEAD 256

struct rt_profiler {
    uint32_t max_frames;
    uint32_t frame;         /* frames ended */
    double frame_start;     /* ms */
    double *frame_ms;       /* ring of max_frames */
    double *frame_t0;       /* start time of each frame (trace) */
    double *values;         /* ring: max_frames x RT_PROFILER_MAX_SERIES, NAN when absent */
    double *starts;         /* span start offsets within the frame (trace) */
    double cursor;          /* CPU time of the current frame's spans laid end to end */
    series series[RT_PROFILER_MAX_SERIES];
    uint32_t series_count;
    /* Whole-run frame times in bounded memory (a game runs for hours): a log histogram of every
     * frame, the first RT_PROF_HEAD frames exactly (so warm-up frames can be dropped from it),
     * the sum and the max after the head. */
    uint32_t *hist;
    double head[RT_PROF_HEAD];
    double sum_ms, tail_max;
};

double rt_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/* Bucket b holds times in [lo r^b, lo r^(b+1)), r = 1.001: a percentile read from it is within
 * 0.05% of the exact one (the bucket's geometric centre), far below frame-time noise. */
#define RT_PROF_LO_MS 1e-3
#define RT_PROF_LOG_R 9.995003330835332e-4 /* ln 1.001 */
#define RT_PROF_BUCKETS 20736               /* 1e-3 ms .. ~1e6 ms */

static uint32_t bucket_of(double ms)
{
    if (!(ms > RT_PROF_LO_MS))
        return 0;
    double b = log(ms / RT_PROF_LO_MS) / RT_PROF_LOG_R;
    return b >= RT_PROF_BUCKETS - 1 ? RT_PROF_BUCKETS - 1 : (uint32_t)b;
}

static double bucket_centre(uint32_t b)
{
    return RT_PROF_LO_MS * exp(((double)b + 0.5) * RT_PROF_LOG_R);
}

rt_profiler *rt_profiler_create(uint32_t max_frames)
{
    if (max_frames == 0)
        max_frames = 1;
    rt_profiler *p = calloc(1, sizeof *p);
    if (!p)
        return NULL;
    p->max_frames = max_frames;
    p->frame_ms = calloc(max_frames, sizeof(double));
    p->frame_t0 = calloc(max_frames, sizeof(double));
    p->values = malloc((size_t)max_frames * RT_PROFILER_MAX_SERIES * sizeof(double));
    p->starts = malloc((size_t)max_frames * RT_PROFILER_MAX_SERIES * sizeof(double));
    p->hist = calloc(RT_PROF_BUCKETS, sizeof *p->hist);
    if (!p->frame_ms || !p->frame_t0 || !p->values || !p->starts || !p->hist) {
        rt_profiler_destroy(p);
        return NULL;
    }
    /* Every ring page is written now, not as the ring first fills: resident memory is then flat
     * from the first frame (calloc's lazy zero pages made RSS creep for max_frames frames). */
    for (size_t i = 0; i < (size_t)max_frames * RT_PROFILER_MAX_SERIES; ++i) {
        p->values[i] = NAN;
        p->starts[i] = NAN;
    }
    for (uint32_t i = 0; i < max_frames; ++i)
        p->frame_ms[i] = p->frame_t0[i] = NAN;
    for (uint32_t b = 0; b < RT_PROF_BUCKETS; b += 1024)
        p->hist[b] = 1; /* touch each page of the histogram, then clear it */
    memset(p->hist, 0, RT_PROF_BUCKETS * sizeof *p->hist);
    return p;
}

void rt_profiler_destroy(rt_profiler *p)
{
    if (!p)
        return;
    free(p->frame_ms);
    free(p->frame_t0);
    free(p->values);
    free(p->starts);
    free(p->hist);
    free(p);
}

static double *row(const rt_profiler *p, uint32_t frame)
{
    return &p->values[(size_t)(frame % p->max_frames) * RT_PROFILER_MAX_SERIES];
}

void rt_profiler_frame_begin(rt_profiler *p)
{
    if (!p)
        return;
    p->frame_start = rt_now_ms();
    p->cursor = 0;
    double *r = row(p, p->frame);
    for (int i = 0; i < RT_PROFILER_MAX_SERIES; ++i)
        r[i] = NAN;
}

double rt_profiler_frame_end(rt_profiler *p)
{
    if (!p)
        return 0;
    double ms = rt_now_ms() - p->frame_start;
    rt_profiler_frame_add(p, ms);
    return ms;
}

void rt_profiler_frame_add(rt_profiler *p, double ms)
{
    if (!p)
        return;
    if (!(ms >= 0) || isinf(ms))
        ms = 0; /* a clock step backwards or a broken clock: counted, not poisoning the sums */
    p->frame_ms[p->frame % p->max_frames] = ms;
    p->frame_t0[p->frame % p->max_frames] = p->frame_start;
    p->hist[bucket_of(ms)]++;
    p->sum_ms += ms;
    if (p->frame < RT_PROF_HEAD)
        p->head[p->frame] = ms;
    else if (ms > p->tail_max)
        p->tail_max = ms;
    p->frame++;
}

static int series_index(rt_profiler *p, const char *name, bool gpu)
{
    for (uint32_t i = 0; i < p->series_count; ++i)
        if (strcmp(p->series[i].name, name) == 0)
            return (int)i;
    if (p->series_count >= RT_PROFILER_MAX_SERIES)
        return -1;
    series *s = &p->series[p->series_count];
    snprintf(s->name, sizeof s->name, "%s", name);
    s->gpu = gpu;
    return (int)p->series_count++;
}

static void record(rt_profiler *p, const char *name, double ms, bool gpu)
{
    int i = series_index(p, name, gpu);
    if (i < 0)
        return;
    size_t at = (size_t)(p->frame % p->max_frames) * RT_PROFILER_MAX_SERIES + (size_t)i;
    p->values[at] = ms;
    if (!gpu) {
        p->starts[at] = p->cursor;
        p->cursor += ms;
    }
}

void rt_profiler_on_system(void *user, const char *name, rt_phase phase, double cpu_ms)
{
    (void)phase;
    if (user)
        record(user, name, cpu_ms, false);
}

void rt_profiler_cpu(rt_profiler *p, const char *name, double cpu_ms)
{
    if (p)
        record(p, name, cpu_ms, false);
}

void rt_profiler_gpu_stats(rt_profiler *p, const vfx_stats *stats)
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

static void summary_of_sorted(rt_frame_summary *s, double *sorted, uint32_t n)
{
    qsort(sorted, n, sizeof(double), cmp_double);
    double sum = 0;
    for (uint32_t i = 0; i < n; ++i)
        sum += sorted[i];
    s->frames = n;
    s->mean_ms = sum / n;
    s->mean_fps = sum > 0 ? 1000.0 * n / sum : 0;
    s->p50_ms = pct(sorted, n, 0.50);
    s->p95_ms = pct(sorted, n, 0.95);
    s->p99_ms = pct(sorted, n, 0.99);
    s->max_ms = sorted[n - 1];
}

/* Nearest-rank percentiles q[0..2] from the histogram less the head frames [0, skip). */
static int hist_pcts(const rt_profiler *p, uint32_t skip, uint32_t n, const double q[3],
                     double out[3])
{
    uint32_t *h = malloc(RT_PROF_BUCKETS * sizeof *h);
    if (!h)
        return -1;
    memcpy(h, p->hist, RT_PROF_BUCKETS * sizeof *h);
    for (uint32_t i = 0; i < skip; ++i)
        h[bucket_of(p->head[i])]--;
    uint64_t seen = 0;
    int k = 0;
    for (uint32_t b = 0; b < RT_PROF_BUCKETS && k < 3; ++b) {
        seen += h[b];
        while (k < 3) {
            double rank = ceil(q[k] * n);
            uint64_t want = rank < 1 ? 1 : (uint64_t)rank;
            if (seen < want)
                break;
            out[k++] = bucket_centre(b);
        }
    }
    free(h);
    return k == 3 ? 0 : -1;
}

rt_frame_summary rt_profiler_summary(const rt_profiler *p, uint32_t skip)
{
    rt_frame_summary s;
    memset(&s, 0, sizeof s);
    if (!p || p->frame <= skip)
        return s;
    uint32_t n = p->frame - skip;
    if (n <= p->max_frames) { /* every frame asked for is still in the ring: exact */
        double *sorted = malloc(n * sizeof(double));
        if (!sorted)
            return s;
        for (uint32_t i = 0; i < n; ++i)
            sorted[i] = p->frame_ms[(skip + i) % p->max_frames];
        summary_of_sorted(&s, sorted, n);
        free(sorted);
        return s;
    }
    /* Older frames live only in the histogram: a skip beyond the head is taken as the head. */
    if (skip > RT_PROF_HEAD)
        skip = RT_PROF_HEAD;
    n = p->frame - skip;
    double sum = p->sum_ms, mx = p->tail_max;
    for (uint32_t i = 0; i < skip; ++i)
        sum -= p->head[i];
    for (uint32_t i = skip; i < RT_PROF_HEAD; ++i)
        if (p->head[i] > mx)
            mx = p->head[i];
    static const double q[3] = {0.50, 0.95, 0.99};
    double v[3];
    if (hist_pcts(p, skip, n, q, v) != 0)
        return s;
    s.frames = n;
    s.mean_ms = sum / n;
    s.mean_fps = sum > 0 ? 1000.0 * n / sum : 0;
    s.p50_ms = fmin(v[0], mx);
    s.p95_ms = fmin(v[1], mx);
    s.p99_ms = fmin(v[2], mx);
    s.max_ms = mx;
    return s;
}

double rt_profiler_series_median(const rt_profiler *p, const char *name)
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
    double m = rt_median(v, n);
    free(v);
    return m;
}

double rt_median(double *v, uint32_t n)
{
    if (n == 0)
        return NAN;
    qsort(v, n, sizeof(double), cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

rt_frame_pcts rt_frame_percentiles(double *v, uint32_t n)
{
    rt_frame_pcts r = {NAN, NAN, NAN};
    if (n == 0)
        return r;
    r.p50 = rt_median(v, n); /* sorts */
    r.p95 = pct(v, n, 0.95);
    r.p99 = pct(v, n, 0.99);
    return r;
}

vfx_result rt_profiler_write_csv(const rt_profiler *p, const char *path)
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

vfx_result rt_profiler_write_trace(const rt_profiler *p, const char *path)
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
        const double *st = &p->starts[(size_t)(fr % p->max_frames) * RT_PROFILER_MAX_SERIES];
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
