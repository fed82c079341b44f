/* The profiler's whole-run summary in bounded memory against exact sorted statistics of the same
 * frame times (the independent reference: a plain sort with the nearest-rank rule). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "profile/profiler.h"

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double nearest_rank(const double *sorted, uint32_t n, double q)
{
    double r = ceil(q * n);
    uint32_t i = r < 1 ? 0 : (uint32_t)r - 1;
    return sorted[i < n ? i : n - 1];
}

/* Frame times with a heavy tail and a slow warm-up, from a fixed LCG (no global state). */
static double frame_time(uint32_t i, uint64_t *rng)
{
    *rng = *rng * 6364136223846793005ull + 1442695040888963407ull;
    double u = (double)(*rng >> 11) / 9007199254740992.0;
    double ms = 8.0 + 4.0 * u + (u > 0.99 ? 60.0 * u : 0.0);
    return i < 20 ? ms + 500.0 : ms;
}

static void check_against_sort(uint32_t ring, uint32_t frames, uint32_t skip, double rel)
{
    rt_profiler *p = rt_profiler_create(ring);
    assert_non_null(p);
    double *t = malloc(frames * sizeof *t);
    uint64_t rng = 12345;
    for (uint32_t i = 0; i < frames; ++i) {
        t[i] = frame_time(i, &rng);
        rt_profiler_frame_add(p, t[i]);
    }
    rt_frame_summary s = rt_profiler_summary(p, skip);
    uint32_t n = frames - skip;
    double sum = 0;
    for (uint32_t i = skip; i < frames; ++i)
        sum += t[i];
    qsort(t + skip, n, sizeof *t, cmp);
    assert_int_equal(s.frames, n);
    assert_true(fabs(s.mean_ms - sum / n) <= 1e-9 * sum / n);
    assert_true(s.max_ms == t[frames - 1]);
    const double q[3] = {0.50, 0.95, 0.99}, got[3] = {s.p50_ms, s.p95_ms, s.p99_ms};
    for (int k = 0; k < 3; ++k) {
        double want = nearest_rank(t + skip, n, q[k]);
        assert_true(fabs(got[k] - want) <= rel * want);
    }
    free(t);
    rt_profiler_destroy(p);
}

/* Inside the ring the summary is exact (rel 0). */
static void test_exact_in_ring(void **s)
{
    (void)s;
    check_against_sort(4096, 3000, 5, 0.0);
}

/* Past the ring: histogram buckets of ratio 1.001 put a percentile within 0.05% of the exact one
 * (the bucket's geometric centre is at most sqrt(1.001) - 1 = 5.0e-4 away); mean and max exact;
 * the slow warm-up frames (500 ms) are dropped exactly. */
static void test_histogram_past_ring(void **s)
{
    (void)s;
    check_against_sort(64, 100000, 20, 5.0005e-4);
    check_against_sort(64, 5000, 0, 5.0005e-4);
}

/* A skip beyond the exact head falls back to the head's 256 frames (documented): counts say so. */
static void test_skip_capped(void **s)
{
    (void)s;
    rt_profiler *p = rt_profiler_create(16);
    for (int i = 0; i < 1000; ++i)
        rt_profiler_frame_add(p, 10.0);
    rt_frame_summary r = rt_profiler_summary(p, 600);
    assert_int_equal(r.frames, 1000 - 256);
    assert_true(fabs(r.p50_ms - 10.0) <= 5.0005e-4 * 10.0);
    /* bad times count as 0, never NaN in the sums */
    rt_profiler_frame_add(p, NAN);
    rt_profiler_frame_add(p, -3.0);
    r = rt_profiler_summary(p, 0);
    assert_int_equal(r.frames, 1002);
    assert_false(isnan(r.mean_ms));
    rt_profiler_destroy(p);
}

/* The CSV puts each frame's GPU times in that frame's row: the plugin reports frame f's pass
 * times in frame f + lag's stats (gpu.timer_lag_frames = lag), so row r must hold what frame
 * r + lag reported, and the last lag rows (timers not yet arrived) stay empty; CPU series stay in
 * the row they were recorded in. */
static void test_csv_gpu_rows(void **s)
{
    (void)s;
    enum { FRAMES = 8, LAG = 3 };
    rt_profiler *p = rt_profiler_create(64);
    for (int f = 0; f < FRAMES; ++f) {
        vfx_stats st = {.type = VFX_TYPE_STATS};
        snprintf(st.entries[st.count].name, sizeof st.entries[0].name, "gpu.timer_lag_frames");
        st.entries[st.count++].value = LAG;
        if (f >= LAG) { /* the timers of frame f - LAG have arrived */
            snprintf(st.entries[st.count].name, sizeof st.entries[0].name, "water.march.gpu_ms");
            st.entries[st.count++].value = 100.0 + (f - LAG);
        }
        rt_profiler_cpu(p, "sim", (double)f);
        rt_profiler_gpu_stats(p, &st);
        rt_profiler_frame_add(p, 16.0);
    }
    char path[] = "/tmp/vfx_test_csv_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    assert_int_equal(rt_profiler_write_csv(p, path, NULL, 0), VFX_OK);
    FILE *f = fopen(path, "r");
    char line[512];
    assert_non_null(fgets(line, sizeof line, f));
    assert_string_equal(line, "frame,frame_ms,sim,water.march.gpu_ms\n");
    for (int r = 0; r < FRAMES; ++r) {
        assert_non_null(fgets(line, sizeof line, f));
        char want[128];
        if (r + LAG < FRAMES)
            snprintf(want, sizeof want, "%d,16.0000,%.4f,%.4f\n", r, (double)r, 100.0 + r);
        else
            snprintf(want, sizeof want, "%d,16.0000,%.4f,\n", r, (double)r);
        assert_string_equal(line, want);
    }
    fclose(f);
    unlink(path);
    rt_profiler_destroy(p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_exact_in_ring),
        cmocka_unit_test(test_histogram_past_ring),
        cmocka_unit_test(test_skip_capped),
        cmocka_unit_test(test_csv_gpu_rows),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
