/* The profiler's Chrome trace: fed stats shaped like the plugin's (totals in the order of the
 * passes' first runs, the water march loop's four passes with their depth, a pass of zero length
 * before another), the written JSON is read back and checked as Perfetto would lay it out: on
 * each thread every two slices are disjoint or one contains the other; each pass lies inside the
 * parent the plugin reported, after its previous sibling; GPU frames follow one another; names,
 * categories, process and thread names and counter tracks are there. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "core/file.h"
#include "profile/profiler.h"

/* Slack for the trace's %.3f microseconds. */
#define EPS_US 0.002

typedef struct xev {
    const char *name, *cat;
    int tid;
    double ts, dur;
} xev;

static void add_stat(vfx_stats *s, const char *name, double v)
{
    assert_true(strlen(name) < sizeof s->entries[0].name);
    memcpy(s->entries[s->count].name, name, strlen(name) + 1);
    s->entries[s->count++].value = v;
}

/* The stats of one GPU frame in the plugin's order: totals and the depths of nested passes (the
 * start column is where each pass begins when they are laid end to end). */
static void gpu_frame_stats(vfx_stats *s, double scale)
{
    static const struct {
        const char *pass;
        double start, ms;
        int depth;
    } passes[] = {
        {"water.init", 0, 1, 0},
        {"water.march", 1, 10, 0},
        {"water.pyramid", 1, 2, 1},   /* totals of four runs each, inside water.march */
        {"water.potential", 3, 4, 1},
        {"water.update", 7, 1, 1},
        {"water.skip", 8, 2.5, 1},
        {"water.refine", 11, 2, 0},
        {"volume.composite", 13, 0, 0}, /* zero length, next pass starts at the same time */
        {"beams.integrate", 13, 1, 0},
        {"beams.composite", 14, 0.5, 0},
    };
    char name[64];
    for (size_t i = 0; i < sizeof passes / sizeof passes[0]; ++i) {
        snprintf(name, sizeof name, "%s.gpu_ms", passes[i].pass);
        add_stat(s, name, passes[i].ms * scale);
        if (passes[i].depth) {
            snprintf(name, sizeof name, "%s.gpu_depth", passes[i].pass);
            add_stat(s, name, passes[i].depth);
        }
    }
    add_stat(s, "gpu.timer_lag_frames", 3);
    add_stat(s, "water.particles", 3000);
    add_stat(s, "water.pixels_sample_cap", 17);
    add_stat(s, "volume.cells_skipped_ert", 250);
    add_stat(s, "beams.count", 3); /* not a counter track */
}

static const xev *find_parent(const xev *ev, int n, const xev *child, const char *parent)
{
    for (int i = 0; i < n; ++i)
        if (ev[i].tid == child->tid && !strcmp(ev[i].name, parent) && ev[i].ts <= child->ts + EPS_US
            && child->ts + child->dur <= ev[i].ts + ev[i].dur + EPS_US)
            return &ev[i];
    return NULL;
}

static void test_trace_nested(void **state)
{
    (void)state;
    enum { FRAMES = 12 };
    rt_profiler *p = rt_profiler_create(64);
    assert_non_null(p);
    for (int f = 0; f < FRAMES; ++f) {
        rt_profiler_frame_begin(p);
        rt_profiler_cpu(p, "host.scene", 0.001);
        rt_profiler_cpu(p, "plugin.render", 0.002);
        vfx_stats st = {.type = VFX_TYPE_STATS};
        /* the GPU frame (14.5 ms scaled by 4) is longer than the CPU frame: GPU frames queue */
        if (f >= 3)
            gpu_frame_stats(&st, 4.0);
        rt_profiler_gpu_stats(p, &st);
        nanosleep(&(struct timespec){0, 2000000}, NULL); /* frames of real length, 2 ms */
        rt_profiler_frame_end(p);
    }
    char path[64];
    snprintf(path, sizeof path, "/tmp/volfx-trace-%d.json", (int)getpid());
    assert_int_equal(rt_profiler_write_trace(p, path, NULL, 0), VFX_OK);
    rt_profiler_destroy(p);
    size_t len;
    char *text = NULL, err[256];
    assert_int_equal(rt_read_file(path, 1 << 24, "16 MiB", &text, &len, err, sizeof err), VFX_OK);
    remove(path);
    cJSON *root = cJSON_Parse(text);
    free(text);
    assert_non_null(root);
    cJSON *events = cJSON_GetObjectItem(root, "traceEvents");
    assert_true(cJSON_IsArray(events));
    int n_ev = cJSON_GetArraySize(events), n = 0;
    xev *ev = calloc((size_t)n_ev, sizeof *ev);
    bool process_name = false, thread_cpu = false, thread_gpu = false;
    int counters[4] = {0};
    static const char *const counter_names[4] = {"fps", "particles", "water holes (rays at the sample cap)",
                                                 "volume cells skipped (ERT)"};
    cJSON *e;
    cJSON_ArrayForEach(e, events) {
        const char *ph = cJSON_GetStringValue(cJSON_GetObjectItem(e, "ph"));
        const char *name = cJSON_GetStringValue(cJSON_GetObjectItem(e, "name"));
        assert_non_null(ph);
        assert_non_null(name);
        if (!strcmp(ph, "M")) {
            cJSON *tid = cJSON_GetObjectItem(e, "tid");
            process_name |= !strcmp(name, "process_name");
            thread_cpu |= !strcmp(name, "thread_name") && tid && tid->valueint == 1;
            thread_gpu |= !strcmp(name, "thread_name") && tid && tid->valueint == 2;
        } else if (!strcmp(ph, "C")) {
            for (int c = 0; c < 4; ++c)
                counters[c] += !strcmp(name, counter_names[c]);
            assert_string_not_equal(name, "beams.count");
        } else {
            assert_string_equal(ph, "X");
            xev *x = &ev[n++];
            x->name = name;
            x->cat = cJSON_GetStringValue(cJSON_GetObjectItem(e, "cat"));
            x->tid = cJSON_GetObjectItem(e, "tid")->valueint;
            x->ts = cJSON_GetObjectItem(e, "ts")->valuedouble;
            x->dur = cJSON_GetObjectItem(e, "dur")->valuedouble;
            assert_non_null(x->cat);
            assert_null(strstr(name, ".gpu_ms"));
            assert_true(x->dur >= 0);
        }
    }
    assert_true(process_name && thread_cpu && thread_gpu);
    assert_int_equal(counters[0], FRAMES);
    for (int c = 1; c < 4; ++c)
        assert_int_equal(counters[c], FRAMES - 3);
    /* Perfetto's rule on one thread: two slices are disjoint or nested. */
    int overlaps = 0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            if (i == j || ev[i].tid != ev[j].tid)
                continue;
            const xev *a = &ev[i], *b = &ev[j];
            bool disjoint = a->ts + a->dur <= b->ts + EPS_US || b->ts + b->dur <= a->ts + EPS_US;
            bool a_in_b = b->ts <= a->ts + EPS_US && a->ts + a->dur <= b->ts + b->dur + EPS_US;
            bool b_in_a = a->ts <= b->ts + EPS_US && b->ts + b->dur <= a->ts + a->dur + EPS_US;
            if (!disjoint && !a_in_b && !b_in_a) {
                if (overlaps++ < 5)
                    print_error("overlap: %s [%.3f +%.3f] and %s [%.3f +%.3f]\n", a->name, a->ts,
                                a->dur, b->name, b->ts, b->dur);
            }
        }
    assert_int_equal(overlaps, 0);
    /* each pass inside the parent the plugin reported; every GPU slice inside a GPU frame */
    int gpu_frames = 0, loop_children = 0;
    double last_gpu_end = -1;
    for (int i = 0; i < n; ++i) {
        const xev *x = &ev[i];
        if (x->tid == 2 && !strncmp(x->name, "gpu frame ", 10)) {
            ++gpu_frames;
            assert_true(x->ts + EPS_US >= last_gpu_end); /* written in order, one after another */
            last_gpu_end = x->ts + x->dur;
            assert_true(fabs(x->dur - 14.5 * 4.0 * 1000.0) < EPS_US); /* first start to last end */
            continue;
        }
        if (x->tid == 2) {
            assert_string_equal(x->cat, "gpu");
            bool in_frame = false;
            for (int j = 0; j < n; ++j)
                in_frame |= ev[j].tid == 2 && !strncmp(ev[j].name, "gpu frame ", 10)
                            && ev[j].ts <= x->ts + EPS_US && x->ts + x->dur <= ev[j].ts + ev[j].dur + EPS_US;
            assert_true(in_frame);
            bool loop = !strcmp(x->name, "water.pyramid") || !strcmp(x->name, "water.potential")
                        || !strcmp(x->name, "water.update") || !strcmp(x->name, "water.skip");
            if (loop) {
                const xev *m = find_parent(ev, n, x, "water.march");
                assert_non_null(m);
                /* laid end to end from the start of water.march, in the plugin's order */
                double at = !strcmp(x->name, "water.pyramid") ? 1 : !strcmp(x->name, "water.potential") ? 3
                            : !strcmp(x->name, "water.update") ? 7 : 8;
                assert_true(fabs(x->ts - (m->ts + (at - 1) * 4.0 * 1000.0)) < EPS_US);
                assert_true(fabs(x->dur - 1000.0 * 4.0 * (!strcmp(x->name, "water.pyramid") ? 2 : !strcmp(x->name, "water.potential") ? 4 : !strcmp(x->name, "water.update") ? 1 : 2.5)) < EPS_US);
                ++loop_children;
            }
            /* top-level passes are inside no other pass */
            if (!loop) {
                static const char *const passes[] = {"water.init", "water.march", "water.refine", "volume.composite",
                                                     "beams.integrate", "beams.composite"};
                for (size_t k = 0; k < 6; ++k)
                    if (strcmp(passes[k], x->name) && x->dur > 0)
                        assert_null(find_parent(ev, n, x, passes[k]));
            }
        } else {
            assert_true(!strcmp(x->cat, "cpu") || !strcmp(x->cat, "frame"));
        }
    }
    assert_int_equal(gpu_frames, FRAMES - 3); /* stats from frame 3 on, each of a frame 3 back */
    assert_int_equal(loop_children, 4 * gpu_frames);
    free(ev);
    cJSON_Delete(root);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_trace_nested),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
