/* bench_sim_pool.h — `volfx-bench sim --pool N`: the default scene's pool in each solver. */
#ifndef VFX_BENCH_SIM_POOL_H
#define VFX_BENCH_SIM_POOL_H

#include <stdbool.h>
#include <stdint.h>

/* Zero in a field means the solver's (or the scene's) default. */
typedef struct bench_pool_opts {
    uint32_t n;           /* particles asked for (the block fills the scene's fluid box) */
    int frames;           /* 60 Hz frames */
    bool no_paddle;
    uint32_t threads;
    unsigned solvers;     /* bit 0 WCSPH, 1 PBF, 2 PBF recomputing its pair terms, 3 PBF with 6 plain
                           * Jacobi iterations at eps 0.2 D0 (the old default) */
    uint32_t pbf_steps;   /* steps per 1/60 s */
    uint32_t pbf_iters;
    float pbf_relax;
    float pbf_rho;        /* Chebyshev rho; < 0: plain Jacobi for every PBF solver */
    float pbf_xsph;
    float ramp_s;         /* paddle ramp; < 0: one period (the scene's default) */
    uint32_t settle;      /* rt_sph_settle's steps at most before frame 0 */
    bool settle_qs;       /* its quasi-static variant */
} bench_pool_opts;

/* Runs the pool and prints one JSON object per solver; 0 on success. */
int bench_sim_pool(const bench_pool_opts *o);

#endif
