/* bench_sim_device.h — `volfx-bench sim --device gpu`: PBF on the CPU and on the GPU, side by side. */
#ifndef VFX_BENCH_SIM_DEVICE_H
#define VFX_BENCH_SIM_DEVICE_H

#include <stdint.h>

typedef struct bench_device_opts {
    uint32_t sizes[8];
    int nsizes;
    int frames;          /* 60 Hz frames per size, both solvers in turn */
    uint32_t iterations; /* PBF Jacobi iterations (0: the solver's 5) */
    uint32_t threads;    /* the CPU solver's threads (0: all cores) */
} bench_device_opts;

/* One JSON line per size: steps, wall and process CPU seconds and particle-steps per second of
 * each solver, the median per-frame ratio of wall times, the GL renderer; 0 on success. */
int bench_sim_device(const bench_device_opts *o);

#endif
