/* profiler.c — fixed table of named series x frames; no allocation per frame. */
#define _GNU_SOURCE /* program_invocation_short_name: the trace's process name */
#include "profile/profiler.h"
#include "core/file.h"

#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef enum series_kind { SERIES_CPU, SERIES_GPU, SERIES_COUNTER } series_kind;

typedef struct series {
    char name[48];
    series_kind kind;
    int depth; /* GPU: passes open around this one (the plugin's <pass>.gpu_depth; 0 absent) */
} series;

/* Plugin counters drawn as counter tracks in the trace (with fps from the frame times). */
static const struct {
    const char *stat, *track;
} counter_tracks[] = {
    {"water.particles", "particles"},
    {"water.pixels_sample_cap", "water holes (rays at the sample cap)"},
    {"volume.cells_skipped_ert", "volume cells skipped (ERT)"},
};
#define N_COUNTER_TRACKS (sizeof counter_tracks / sizeof counter_tracks[0])

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
    double *starts;         /* CPU spans: start in ms after the frame's start; NAN when absent */
    uint8_t *order;         /* ring: the order in which each series was recorded in its frame
                               (the plugin's stats come in pass submission order) */
    uint8_t recorded;       /* series recorded in the current frame */
    uint32_t gpu_lag;       /* gpu.timer_lag_frames: GPU times arrive this many frames late */
    series series[RT_PROFILER_MAX_SERIES];
    uint32_t series_count;
    /* Whole-run frame times in bounded memory (a game runs for hours): a log histogram of every
     * frame, the first RT_PROF_HEAD frames exactly (so warm-up frames can be dropped from it),
     * the sum and the max after the head. */
    uint32_t *hist;
    double head[RT_PROF_HEAD];
    double sum_ms, tail_max;
};

double rt_thread_cpu_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

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
    p->order = calloc((size_t)max_frames * RT_PROFILER_MAX_SERIES, 1);
    if (!p->frame_ms || !p->frame_t0 || !p->values || !p->starts || !p->hist || !p->order) {
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
    free(p->order);
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
    double *r = row(p, p->frame);
    double *st = &p->starts[(size_t)(p->frame % p->max_frames) * RT_PROFILER_MAX_SERIES];
    for (int i = 0; i < RT_PROFILER_MAX_SERIES; ++i)
        r[i] = st[i] = NAN;
    p->recorded = 0;
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

static int series_index(rt_profiler *p, const char *name, size_t len, series_kind kind)
{
    for (uint32_t i = 0; i < p->series_count; ++i)
        if (strncmp(p->series[i].name, name, len) == 0 && p->series[i].name[len] == 0)
            return (int)i;
    if (p->series_count >= RT_PROFILER_MAX_SERIES || len >= sizeof p->series[0].name)
        return -1;
    series *s = &p->series[p->series_count];
    memcpy(s->name, name, len);
    s->name[len] = 0;
    s->kind = kind;
    return (int)p->series_count++;
}

/* The ring index of series i in the current frame; notes the order it was first recorded in. */
static size_t at_of(rt_profiler *p, int i)
{
    size_t at = (size_t)(p->frame % p->max_frames) * RT_PROFILER_MAX_SERIES + (size_t)i;
    if (isnan(p->values[at]) && isnan(p->starts[at]))
        p->order[at] = p->recorded++;
    return at;
}

static void record(rt_profiler *p, const char *name, double ms, series_kind kind)
{
    int i = series_index(p, name, strlen(name), kind);
    if (i < 0)
        return;
    size_t at = at_of(p, i);
    p->values[at] = ms;
    if (kind == SERIES_CPU) {
        /* Called as the span ends: it began ms ago. Nested spans (a RENDER-phase system inside
         * plugin.render) then lie inside their parent in the trace. */
        double start = rt_now_ms() - p->frame_start - ms;
        p->starts[at] = start > 0 ? start : 0;
    }
}

void rt_profiler_on_system(void *user, const char *name, rt_phase phase, double cpu_ms)
{
    (void)phase;
    if (user)
        record(user, name, cpu_ms, SERIES_CPU);
}

void rt_profiler_cpu(rt_profiler *p, const char *name, double cpu_ms)
{
    if (p)
        record(p, name, cpu_ms, SERIES_CPU);
}

void rt_profiler_counter(void *p, const char *name, double value)
{
    if (p && name)
        record(p, name, value, SERIES_COUNTER);
}

void rt_profiler_gpu_stats(rt_profiler *p, const vfx_stats *stats)
{
    if (!p || !stats)
        return;
    const uint32_t cap = VFX_STATS_MAX;
    for (uint32_t i = 0; i < stats->count && i < cap; ++i) {
        const char *n = stats->entries[i].name;
        double v = stats->entries[i].value;
        size_t len = strnlen(n, sizeof stats->entries[i].name);
        if (len == sizeof stats->entries[i].name)
            continue; /* not terminated: not a name we know */
        if (len > 7 && strcmp(n + len - 7, ".gpu_ms") == 0) {
            int k = series_index(p, n, len, SERIES_GPU);
            if (k >= 0)
                p->values[at_of(p, k)] = v;
        } else if (len > 10 && strcmp(n + len - 10, ".gpu_depth") == 0) {
            char dur[48]; /* the depth of the series "<pass>.gpu_ms" */
            int w = snprintf(dur, sizeof dur, "%.*s.gpu_ms", (int)(len - 10), n);
            int k = w > 0 && (size_t)w < sizeof dur ? series_index(p, dur, (size_t)w, SERIES_GPU) : -1;
            if (k >= 0)
                p->series[k].depth = v >= 0 && v < 15 ? (int)v : 0;
        } else if (strcmp(n, "gpu.timer_lag_frames") == 0) {
            p->gpu_lag = v >= 0 && v < 64 ? (uint32_t)v : 0;
        } else {
            for (size_t c = 0; c < N_COUNTER_TRACKS; ++c)
                if (strcmp(n, counter_tracks[c].stat) == 0)
                    record(p, n, v, SERIES_COUNTER);
        }
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

vfx_result rt_profiler_write_csv(const rt_profiler *p, const char *path, char *err, size_t errlen)
{
    FILE *f = rt_open_output(path, "w", err, errlen);
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
        /* A frame's GPU times arrive gpu_lag frames later (the plugin's timestamp ring): they
         * were recorded in row fr + gpu_lag and are written here, in their own frame's row. The
         * last gpu_lag frames' timers had not arrived when the run ended: empty cells. */
        const double *g = fr + p->gpu_lag < p->frame ? row(p, fr + p->gpu_lag) : NULL;
        for (uint32_t i = 0; i < p->series_count; ++i) {
            double v = p->series[i].kind == SERIES_GPU ? (g ? g[i] : NAN) : r[i];
            isnan(v) ? fprintf(f, ",") : fprintf(f, ",%.4f", v);
        }
        fprintf(f, "\n");
    }
    if (fclose(f) != 0) {
        snprintf(err, errlen, "write to %s failed", path);
        return VFX_ERR_IO;
    }
    return VFX_OK;
}

/* One slice of a track as the trace will show it. */
typedef struct slice {
    double start, dur; /* ms after the frame's (or GPU frame's) start */
    uint32_t series;
    uint32_t order;    /* recording order: of two slices starting together, the first opened
                          is the parent (GPU passes all start at 0: their order is the stats') */
    int depth;         /* GPU passes: nesting depth the plugin reported; -1 (CPU spans): the
                          parent is the innermost slice still open at the start */
} slice;

static int cmp_slice(const void *a, const void *b)
{
    const slice *x = a, *y = b;
    if (x->start != y->start)
        return (x->start > y->start) - (x->start < y->start);
    return (x->order > y->order) - (x->order < y->order);
}

/* Clock readings in ms: a span that starts where the last ended may read a hair before it. */
#define NEST_EPS_MS 1e-6

/* Makes the slices of one track properly nested: sorted by start (then recording order), each
 * slice lies inside its parent (for a GPU pass the last pass one level up, by the plugin's
 * depth; for a CPU span the innermost slice still open at its start) and no earlier than the end
 * of its previous sibling, clamped into the parent. GPU passes come as totals without start
 * times (a pass run several times in a frame, like the water march loop's four, as one total),
 * so they are laid end to end inside their parent in the plugin's order. Returns the end of the
 * last slice. */
static double nest_slices(slice *s, uint32_t n, double frame_end)
{
    qsort(s, n, sizeof *s, cmp_slice);
    struct open {
        double start, end, cursor; /* cursor: end of the last child placed */
    } stack[16];
    int depth = 0;
    stack[0] = (struct open){0, frame_end, 0};
    double last = 0;
    for (uint32_t i = 0; i < n; ++i) {
        if (s[i].depth >= 0) {
            if (s[i].depth < depth)
                depth = s[i].depth;
        } else {
            while (depth > 0 && s[i].start >= stack[depth].end - NEST_EPS_MS)
                --depth;
        }
        struct open *parent = &stack[depth];
        double start = fmax(s[i].start, parent->cursor);
        double room = parent->end - parent->start;
        double dur = fmin(s[i].dur, room);
        if (start + dur > parent->end)
            start = parent->end - dur;
        if (start < parent->start)
            start = parent->start;
        s[i].start = start;
        s[i].dur = dur;
        parent->cursor = start + dur;
        if (start + dur > last)
            last = start + dur;
        if (depth + 1 < (int)(sizeof stack / sizeof stack[0]))
            stack[++depth] = (struct open){start, start + dur, start};
    }
    return last;
}

/* The trace name of a series: a GPU pass without the stat's ".gpu_ms" suffix. */
static int trace_name_len(const series *s)
{
    size_t len = strlen(s->name);
    return (int)(s->kind == SERIES_GPU && len > 7 ? len - 7 : len);
}

vfx_result rt_profiler_write_trace(const rt_profiler *p, const char *path, char *err, size_t errlen)
{
    FILE *f = rt_open_output(path, "w", err, errlen);
    if (!f)
        return VFX_ERR_IO;
    fprintf(f, "{\"displayTimeUnit\":\"ms\",\"traceEvents\":[\n");
    fprintf(f, "{\"name\":\"process_name\",\"ph\":\"M\",\"pid\":1,\"args\":{\"name\":\"%s\"}},\n",
            program_invocation_short_name);
    fprintf(f, "{\"name\":\"thread_name\",\"ph\":\"M\",\"pid\":1,\"tid\":1,\"args\":{\"name\":\"CPU (frame thread)\"}},\n");
    fprintf(f, "{\"name\":\"thread_name\",\"ph\":\"M\",\"pid\":1,\"tid\":2,\"args\":{\"name\":\"GPU (volfx passes)\"}},\n");
    fprintf(f, "{\"name\":\"thread_sort_index\",\"ph\":\"M\",\"pid\":1,\"tid\":1,\"args\":{\"sort_index\":1}},\n");
    fprintf(f, "{\"name\":\"thread_sort_index\",\"ph\":\"M\",\"pid\":1,\"tid\":2,\"args\":{\"sort_index\":2}}");
    uint32_t kept = p->frame < p->max_frames ? p->frame : p->max_frames;
    double origin = kept ? p->frame_t0[(p->frame - kept) % p->max_frames] : 0;
    int render = -1; /* GPU work of a frame is issued in its plugin.render */
    for (uint32_t i = 0; i < p->series_count; ++i)
        if (p->series[i].kind == SERIES_CPU && strcmp(p->series[i].name, "plugin.render") == 0)
            render = (int)i;
    slice sl[RT_PROFILER_MAX_SERIES];
    double gpu_free = -INFINITY; /* the GPU runs one frame after another */
    for (uint32_t fr = p->frame - kept; fr < p->frame; ++fr) {
        double t0 = (p->frame_t0[fr % p->max_frames] - origin) * 1000.0; /* us */
        double fms = p->frame_ms[fr % p->max_frames];
        fprintf(f, ",\n{\"name\":\"frame %u\",\"cat\":\"frame\",\"ph\":\"X\",\"pid\":1,\"tid\":1,\"ts\":%.3f,\"dur\":%.3f}",
                fr, t0, fms * 1000.0);
        fprintf(f, ",\n{\"name\":\"fps\",\"cat\":\"counter\",\"ph\":\"C\",\"pid\":1,\"ts\":%.3f,\"args\":{\"fps\":%.3f}}",
                t0, fms > 0 ? 1000.0 / fms : 0.0);
        const double *r = row(p, fr);
        const double *st = &p->starts[(size_t)(fr % p->max_frames) * RT_PROFILER_MAX_SERIES];
        const uint8_t *ord = &p->order[(size_t)(fr % p->max_frames) * RT_PROFILER_MAX_SERIES];
        uint32_t n = 0;
        for (uint32_t i = 0; i < p->series_count; ++i)
            if (p->series[i].kind == SERIES_CPU && !isnan(r[i]))
                sl[n++] = (slice){isnan(st[i]) ? 0 : st[i], r[i], i, ord[i], -1};
        nest_slices(sl, n, fms);
        for (uint32_t k = 0; k < n; ++k)
            fprintf(f, ",\n{\"name\":\"%s\",\"cat\":\"cpu\",\"ph\":\"X\",\"pid\":1,\"tid\":1,\"ts\":%.3f,\"dur\":%.3f}",
                    p->series[sl[k].series].name, t0 + sl[k].start * 1000.0, sl[k].dur * 1000.0);
        for (size_t c = 0; c < N_COUNTER_TRACKS; ++c)
            for (uint32_t i = 0; i < p->series_count; ++i)
                if (p->series[i].kind == SERIES_COUNTER && !isnan(r[i])
                    && strcmp(p->series[i].name, counter_tracks[c].stat) == 0)
                    fprintf(f, ",\n{\"name\":\"%s\",\"cat\":\"counter\",\"ph\":\"C\",\"pid\":1,\"ts\":%.3f,\"args\":{\"value\":%.17g}}",
                            counter_tracks[c].track, t0, r[i]);
        /* GPU times recorded in this frame belong to the frame gpu_lag frames back: drawn from
         * that frame's plugin.render (when the commands were issued), or later if the GPU was
         * still busy with the frame before; the frame lasts as long as its outermost passes. */
        if (fr < p->frame - kept + p->gpu_lag)
            continue;
        uint32_t issued = fr - p->gpu_lag;
        const double *ist = &p->starts[(size_t)(issued % p->max_frames) * RT_PROFILER_MAX_SERIES];
        double at = (p->frame_t0[issued % p->max_frames] - origin)
                    + (render >= 0 && !isnan(ist[render]) ? ist[render] : 0);
        n = 0;
        double span = 0;
        for (uint32_t i = 0; i < p->series_count; ++i) {
            if (p->series[i].kind != SERIES_GPU || isnan(r[i]))
                continue;
            sl[n++] = (slice){0, r[i], i, ord[i], p->series[i].depth};
            if (p->series[i].depth == 0)
                span += r[i];
        }
        if (n == 0)
            continue;
        at = fmax(at, gpu_free);
        span = nest_slices(sl, n, span);
        gpu_free = at + span;
        fprintf(f, ",\n{\"name\":\"gpu frame %u\",\"cat\":\"frame\",\"ph\":\"X\",\"pid\":1,\"tid\":2,\"ts\":%.3f,\"dur\":%.3f}",
                issued, at * 1000.0, span * 1000.0);
        for (uint32_t k = 0; k < n; ++k) {
            const series *se = &p->series[sl[k].series];
            fprintf(f, ",\n{\"name\":\"%.*s\",\"cat\":\"gpu\",\"ph\":\"X\",\"pid\":1,\"tid\":2,\"ts\":%.3f,\"dur\":%.3f,\"args\":{\"gpu_ms\":%.4f}}",
                    trace_name_len(se), se->name, (at + sl[k].start) * 1000.0, sl[k].dur * 1000.0, r[sl[k].series]);
        }
    }
    fprintf(f, "\n]}\n");
    if (fclose(f) != 0) {
        snprintf(err, errlen, "write to %s failed", path);
        return VFX_ERR_IO;
    }
    return VFX_OK;
}
