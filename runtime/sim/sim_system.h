/* sim_system.h — the SPH solver as an ECS system: "vfx.sim.sph" in the simulate phase reads
 * and writes the particle components of runtime/ecs/particles.h.
 *
 * The world is the source of truth and the only copy: the solver steps the columns of the
 * table holding position, velocity and density in place (rt_sph_bind), sorting its rows by grid
 * cell (rt_world_table_permute: rows move, follow particles by entity) and appending the
 * particles its emitters make as new entities of that table. The game may spawn, despawn or
 * edit particles between frames: edited values are the solver's at once; a change of the
 * table's revision (structural change, or a write by another system) makes the system bind
 * again (values checked, neighbour lists rebuilt). The particles must all be in one table
 * (VFX_ERR_UNSUPPORTED otherwise). A failed run returns its code to rt_world_run_phase and
 * leaves its message, naming the particle or table, in rt_world_last_error. */
#ifndef RT_SIM_SYSTEM_H
#define RT_SIM_SYSTEM_H

#include "core/log.h"
#include "ecs/particles.h"
#include "ecs/world.h"
#include "sim/sph.h"

typedef struct rt_sim_system rt_sim_system;

/* Registers (or looks up) the particle components, creates the solver (NULL desc = defaults)
 * and adds the system to the world. Destroy the system only after the world is destroyed or
 * will not run again (the world keeps a pointer to it). */
vfx_result rt_sim_system_create(rt_world *world, const rt_sph_desc *desc, rt_sim_system **out,
                                 char *err, size_t err_len);
/* Frees the solver (the world keeps the particles). NULL allowed. */
void rt_sim_system_destroy(rt_sim_system *sys);
/* The solver (add colliders and emitters through it; particles come from the world). */
rt_sph *rt_sim_system_solver(rt_sim_system *sys);
/* Report of the last step (zeroed before the first). */
const rt_sph_report *rt_sim_system_report(const rt_sim_system *sys);
/* The simulation clock: from now on each run adds the frame's dt to an accumulator and steps
 * the solver by whole steps of step_dt (at most max_steps a frame; time beyond that is dropped
 * and counted, so a slow frame never makes the next slower), so simulated time follows the
 * frame clock. step_dt 0 (the default) steps once by the frame's dt. */
vfx_result rt_sim_system_set_clock(rt_sim_system *sys, float step_dt, uint32_t max_steps);
/* Per-frame figures of the last run (the stats docs/stats.md lists as sim.*). */
typedef struct rt_sim_stats {
    uint32_t steps;          /* solver steps (PBF steps, WCSPH substeps) this frame */
    uint32_t iterations;     /* PBF Jacobi iterations this frame (0 for WCSPH) */
    double realtime_factor;  /* simulated seconds this frame / wall seconds the solver took */
    double simulated_s;      /* simulated seconds this frame */
    double dropped_s;        /* frame time the clock dropped (max_steps reached), total */
    float max_speed;         /* [m/s], end of the frame */
    float density_error;     /* mean max(0, rho/rho0 - 1), end of the frame */
    uint32_t settle_steps;   /* rt_sph_settle steps run before this frame's steps (0 but once) */
    double settle_cpu_s;     /* their process CPU seconds */
    uint32_t device;         /* 0 the CPU solver, else the device's id (1 GPU) */
} rt_sim_stats;
/* The next run settles the particles before its first step (rt_sph_settle, desc NULL: its
 * defaults), once: a fluid block placed in a scene then starts in the solver's equilibrium at
 * rest. A progress line every desc->progress_every steps and a summary go to log (NULL: stderr);
 * desc's own progress callback is not used. The steps are counted in the stats (settle_steps). */
vfx_result rt_sim_system_settle_next(rt_sim_system *sys, const rt_sph_settle_desc *desc, const rt_logger *log);
/* Names what the fluid came from (e.g. "scene water.simulation") in every failure message:
 * "vfx.sim.sph (NAME): ...". NULL or "": none. origin (NULL: 0) is added to the solver's
 * coordinates where a message gives a position, so they read as the scene wrote them. */
vfx_result rt_sim_system_set_label(rt_sim_system *sys, const char *name, const double origin[3]);
/* From now on the first solver step (of a run, or of the settle before frame 0) that takes more
 * than `seconds` of wall time is said once, as a warning through log (NULL: the logger already
 * set, else stderr) naming the particle count, the spacing and the tank. 0 turns it off (the
 * default); the sample game sets 0.5 s. */
vfx_result rt_sim_system_warn_slow(rt_sim_system *sys, double seconds, const rt_logger *log);
/* The last run's figures (zero before the first). */
const rt_sim_stats *rt_sim_system_stats(const rt_sim_system *sys);
/* A solver that steps the particles somewhere else than the CPU columns (sim_gpu.h: the GPU PBF
 * solver). At the system's first run, after it bound the table, start is handed the CPU solver
 * (its parameters, colliders and the bound particles); from then on the settle, the steps and
 * rt_sim_system_impulse go through the device, the table is not bound again and its rows keep
 * the state of that first run. destroy is called with the system's. */
typedef struct rt_sim_device {
    void *user;
    uint32_t id; /* the stat sim.device (0 is the CPU solver; 1 the GPU) */
    vfx_result (*start)(void *user, rt_sph *sph, char *err, size_t errlen);
    vfx_result (*step)(void *user, float dt, rt_sph_report *rep, char *err, size_t errlen);
    vfx_result (*settle)(void *user, const rt_sph_settle_desc *d, rt_sph_settle_report *rep, char *err,
                         size_t errlen);
    void (*impulse)(void *user, const float centre[3], const float dir[3], float radius, float speed);
    void (*destroy)(void *user);
} rt_sim_device;
/* Sets the device (copied); VFX_ERR_INVALID_ARGUMENT once the system has run or a callback is NULL. */
vfx_result rt_sim_system_set_device(rt_sim_system *sys, const rt_sim_device *dev);
/* rt_sph_impulse on whatever steps the particles: the particles changed, or 1 on a device (its count
 * stays on the GPU). */
uint32_t rt_sim_system_impulse(rt_sim_system *sys, const float centre[3], const float dir[3], float radius,
                               float speed);
/* Called at the end of every run with each sim.* figure (e.g. rt_profiler_counter); NULL: none. */
void rt_sim_system_set_stats_sink(rt_sim_system *sys, void (*sink)(void *user, const char *name, double value),
                                  void *user);


#endif
