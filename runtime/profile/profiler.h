/* profiler.h — frame profiler: CPU ms per system (from the world's hook), GPU ms per pass
 * (from the plugin's stats, read from a timestamp ring that never stalls), frame times with
 * mean fps and p50/p95/p99, per-frame CSV and Chrome trace-event JSON (Perfetto opens it). */
#ifndef VFX_PROFILER_H
#define VFX_PROFILER_H

#include <stdint.h>
#include <stdio.h>
#include <volfx/volfx.h>
#include "ecs/world.h"

#define VFX_PROFILER_MAX_SERIES 48

typedef struct vfx_profiler vfx_profiler;

typedef struct vfx_frame_summary {
    uint32_t frames;
    double mean_fps;
    double mean_ms, p50_ms, p95_ms, p99_ms, max_ms;
} vfx_frame_summary;

/* Keeps up to max_frames frames (older frames roll off the CSV/trace, not the summary); memory
 * is fixed at creation, however long the run. */
vfx_profiler *vfx_profiler_create(uint32_t max_frames);
/* NULL allowed. */
void vfx_profiler_destroy(vfx_profiler *p);
/* Marks the start of a frame. */
void vfx_profiler_frame_begin(vfx_profiler *p);
/* Marks the end of a frame; returns its wall time in ms. */
double vfx_profiler_frame_end(vfx_profiler *p);
/* Records a finished frame of the given wall time, as frame_end does (replays and tests);
 * NaN, Inf or negative times count as 0. */
void vfx_profiler_frame_add(vfx_profiler *p, double ms);
/* Records a CPU span of the current frame (matches vfx_world_desc.on_system_done). */
void vfx_profiler_on_system(void *profiler, const char *name, vfx_phase phase, double cpu_ms);
/* Records a CPU span by name with its own timing (for host work outside systems). */
void vfx_profiler_cpu(vfx_profiler *p, const char *name, double cpu_ms);
/* Records every "*.gpu_ms" entry of the plugin's stats for the current frame. */
void vfx_profiler_gpu_stats(vfx_profiler *p, const vfx_stats *stats);
/* Summary over frames [skip, end): skip drops warm-up frames. Exact while those frames are all
 * in the ring of max_frames; beyond, from a bounded histogram (percentiles within 0.05%, mean and
 * max exact) with skip capped at 256. */
vfx_frame_summary vfx_profiler_summary(const vfx_profiler *p, uint32_t skip);
/* Median of a named series over kept frames (NAN when never recorded). */
double vfx_profiler_series_median(const vfx_profiler *p, const char *name);
/* Writes frame,frame_ms,<series...> one row per kept frame. */
vfx_result vfx_profiler_write_csv(const vfx_profiler *p, const char *path);
/* Writes Chrome trace-event JSON (complete events "ph":"X", pid 1, tid 1 CPU, tid 2 GPU). */
vfx_result vfx_profiler_write_trace(const vfx_profiler *p, const char *path);
/* Median of v[0..n) (sorts v in place); NAN when n is 0. */
double vfx_median(double *v, uint32_t n);
/* Frame-time percentiles for benchmark JSON ("frame_ms":{"p50","p95","p99"}). */
typedef struct vfx_frame_pcts {
    double p50, p95, p99;
} vfx_frame_pcts;
/* Median (as vfx_median) and nearest-rank p95/p99 of v[0..n) (sorts v in place); NAN when n is 0. */
vfx_frame_pcts vfx_frame_percentiles(double *v, uint32_t n);
/* Monotonic clock in ms. */
double vfx_now_ms(void);

#endif
