/* profiler.h — frame profiler: CPU ms per system (from the world's hook), GPU ms per pass
 * (from the plugin's stats, read from a timestamp ring that never stalls), frame times with
 * mean fps and p50/p95/p99, per-frame CSV and Chrome trace-event JSON (Perfetto opens it). */
#ifndef RT_PROFILER_H
#define RT_PROFILER_H

#include <stdint.h>
#include <stdio.h>
#include <volfx/volfx.h>
#include "ecs/world.h"

#define RT_PROFILER_MAX_SERIES 48

typedef struct rt_profiler rt_profiler;

typedef struct rt_frame_summary {
    uint32_t frames;
    double mean_fps;
    double mean_ms, p50_ms, p95_ms, p99_ms, max_ms;
} rt_frame_summary;

/* Keeps up to max_frames frames (older frames roll off the CSV/trace, not the summary); memory
 * is fixed at creation, however long the run. */
rt_profiler *rt_profiler_create(uint32_t max_frames);
/* NULL allowed. */
void rt_profiler_destroy(rt_profiler *p);
/* Marks the start of a frame. */
void rt_profiler_frame_begin(rt_profiler *p);
/* Marks the end of a frame; returns its wall time in ms. */
double rt_profiler_frame_end(rt_profiler *p);
/* Records a finished frame of the given wall time, as frame_end does (replays and tests);
 * NaN, Inf or negative times count as 0. */
void rt_profiler_frame_add(rt_profiler *p, double ms);
/* Records a CPU span of the current frame (matches rt_world_desc.on_system_done). */
void rt_profiler_on_system(void *profiler, const char *name, rt_phase phase, double cpu_ms);
/* Records a CPU span by name with its own timing (for host work outside systems). */
void rt_profiler_cpu(rt_profiler *p, const char *name, double cpu_ms);
/* Records a counter series of the current frame by name (host figures such as sim.*; in the CSV
 * and the series medians, not a trace track). p is an rt_profiler (void: a stats sink). */
void rt_profiler_counter(void *p, const char *name, double value);
/* Records the plugin's stats for the current frame: every "<pass>.gpu_ms" (a GPU series, in the
 * stats' order) with its "<pass>.gpu_depth", gpu.timer_lag_frames, and the counters drawn as
 * counter tracks (water.particles, water.pixels_sample_cap, volume.cells_skipped_ert). */
void rt_profiler_gpu_stats(rt_profiler *p, const vfx_stats *stats);
/* Summary over frames [skip, end): skip drops warm-up frames. Exact while those frames are all
 * in the ring of max_frames; beyond, from a bounded histogram (percentiles within 0.05%, mean and
 * max exact) with skip capped at 256. */
rt_frame_summary rt_profiler_summary(const rt_profiler *p, uint32_t skip);
/* Median of a named series over kept frames (NAN when never recorded). */
double rt_profiler_series_median(const rt_profiler *p, const char *name);
/* Writes frame,frame_ms,<series...> one row per kept frame (CPU and GPU series in ms, the
 * counter series as counts). Each row holds its own frame's GPU times (recorded
 * gpu.timer_lag_frames frames later); the last lag rows' GPU cells are empty. */
vfx_result rt_profiler_write_csv(const rt_profiler *p, const char *path, char *err, size_t errlen);
/* Writes Chrome trace-event JSON for Perfetto/chrome://tracing: process and thread names, a
 * "frame N" slice per frame on the CPU thread (tid 1) with the CPU spans nested inside it at
 * their measured starts, a "gpu frame N" slice per frame on the GPU thread (tid 2) starting when
 * that frame's plugin.render issued it (or when the GPU finished the frame before) with the
 * passes laid end to end inside their parent by the plugin's order and depth (names without
 * ".gpu_ms"; a repeated pass as one slice of its total), categories frame/cpu/gpu/counter, and
 * counter tracks fps, particles, water holes, volume cells skipped. Both writers open the path
 * with rt_open_output (never blocking on a FIFO) and name it in err on failure. */
vfx_result rt_profiler_write_trace(const rt_profiler *p, const char *path, char *err, size_t errlen);
/* Median of v[0..n) (sorts v in place); NAN when n is 0. */
double rt_median(double *v, uint32_t n);
/* Frame-time percentiles for benchmark JSON ("frame_ms":{"p50","p95","p99"}). */
typedef struct rt_frame_pcts {
    double p50, p95, p99;
} rt_frame_pcts;
/* Median (as rt_median) and nearest-rank p95/p99 of v[0..n) (sorts v in place); NAN when n is 0. */
rt_frame_pcts rt_frame_percentiles(double *v, uint32_t n);
/* Monotonic clock in ms. */
double rt_now_ms(void);
/* The calling thread's CPU time in ms (CLOCK_THREAD_CPUTIME_ID): with LP_NUM_THREADS=0 llvmpipe
 * does its work on the calling thread, so a call's CPU cost, whatever else loads the machine. */
double rt_thread_cpu_ms(void);

#endif
