/* sph_gpu.h — the Position Based Fluids solver in GL 4.5 compute shaders (shaders/sim/pbf_*.comp),
 * the GPU twin of the CPU PBF solver (sph_pbf.c): the same parameters, walls, colliders (box,
 * sphere, plane, moving paddles), Chebyshev-accelerated Jacobi iterations, speed cap, XSPH
 * viscosity, wall friction, settle and impulse. docs/simulation-gpu.md.
 *
 * The CPU solver it is made from (rt_sph, solver PBF) keeps the parameters, the colliders and
 * the clock; the particles are copied once into GL buffers at creation and stay there: each step
 * predicts, sorts the particles by cell (a counting sort on a uniform grid of H/2: count, prefix
 * scan, scatter), runs the iterations and updates the velocities without a CPU copy. The state
 * feeds a renderer as GL buffer columns (rt_sph_gpu_columns). Figures that need the CPU (max
 * speed, compression, energies) come back through a ring of 3 small persistently mapped slots
 * behind fences: with sync_stats false a step's report carries the newest finished frame's
 * figures (1-3 frames late) and never waits for the GPU unless it is 3 frames behind.
 *
 * Not supported (refused at creation, naming the feature): mesh colliders, emitters, vorticity
 * confinement, the warm-start experiment. Needs a current GL 4.5 context on every call; not
 * thread-safe. No global state. */
#ifndef RT_SIM_SPH_GPU_H
#define RT_SIM_SPH_GPU_H

#include "sim/sph.h"

typedef struct rt_sph_gpu rt_sph_gpu;

typedef struct rt_sph_gpu_desc {
    /* every step waits for its own figures (tests, benches; the settle always does) */
    bool sync_stats;
} rt_sph_gpu_desc;

/* Compiles the compute programs and copies sim's particles into GL buffers. sim (solver PBF)
 * keeps the parameters, colliders and clock and must outlive the GPU solver; its own columns
 * are not stepped. VFX_ERR_UNSUPPORTED names a feature the GPU solver lacks; VFX_ERR_GL a
 * program or buffer that could not be made. NULL desc: defaults. */
vfx_result rt_sph_gpu_create(rt_sph *sim, const rt_sph_gpu_desc *desc, rt_sph_gpu **out, char *err, size_t errlen);
/* Deletes the programs, buffers and fences. NULL allowed. */
void rt_sph_gpu_destroy(rt_sph_gpu *g);
/* Advances by frame_dt as rt_sph_step does for PBF (the step count from the newest known max
 * speed). The report's state figures are this step's with sync_stats, else the newest finished
 * frame's. VFX_ERR_NUMERIC when particles went non-finite (they are then
 * held at their predicted positions, at rest, as on the CPU). */
vfx_result rt_sph_gpu_step(rt_sph_gpu *g, float frame_dt, rt_sph_report *rep, char *err, size_t errlen);
/* rt_sph_settle on the GPU (the same defaults, damping and stopping rule; waits for each step). */
vfx_result rt_sph_gpu_settle(rt_sph_gpu *g, const rt_sph_settle_desc *desc, rt_sph_settle_report *rep, char *err,
                             size_t errlen);
/* rt_sph_impulse on the GPU buffers (the count of particles changed is not known here). */
void rt_sph_gpu_impulse(rt_sph_gpu *g, const float centre[3], const float dir[3], float radius, float speed);
/* The state as GL buffer columns for vfx_particle_view (positions and velocities, 16 bytes a
 * particle, in the solver's cell order); valid until the next step. */
void rt_sph_gpu_columns(const rt_sph_gpu *g, vfx_gpu_column *pos, vfx_gpu_column *vel, uint32_t *count);
/* Copies the state back (waits for the GPU; tests and benches): each non-NULL array gets count
 * values, in the solver's cell order; id says which input particle a row is. */
vfx_result rt_sph_gpu_download(rt_sph_gpu *g, float *x, float *y, float *z, float *vx, float *vy, float *vz,
                               float *density, uint32_t *id, char *err, size_t errlen);
/* GL buffer bytes the solver holds. */
size_t rt_sph_gpu_memory_bytes(const rt_sph_gpu *g);
/* True when the current context's GL_RENDERER names a software rasteriser (llvmpipe, softpipe,
 * swrast): water.simulation.device "auto" then picks the CPU solver. */
bool rt_sph_gpu_software_renderer(void);

#endif
