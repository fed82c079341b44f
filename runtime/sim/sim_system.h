/* sim_system.h — the SPH solver as an ECS system: "vfx.sim.sph" in the simulate phase reads
 * and writes the particle components of runtime/ecs/particles.h.
 *
 * The world is the source of truth: every frame the system imports all entities that have
 * position, velocity and density (in query order), steps the solver by the frame dt, and
 * writes position, velocity and density back to the same rows. So the game may spawn,
 * despawn or move particles between frames. Particles made by the solver's emitters are
 * spawned as new particle entities after the step. */
#ifndef RT_SIM_SYSTEM_H
#define RT_SIM_SYSTEM_H

#include "ecs/particles.h"
#include "ecs/world.h"
#include "sim/sph.h"

typedef struct rt_sim_system rt_sim_system;

/* Registers (or looks up) the particle components, creates the solver (NULL desc = defaults)
 * and adds the system to the world. Destroy the system only after the world is destroyed or
 * will not run again (the world keeps a pointer to it). */
vfx_result rt_sim_system_create(rt_world *world, const rt_sph_desc *desc, rt_sim_system **out,
                                 char *err, size_t err_len);
/* Frees the solver and the system's buffers. NULL allowed. */
void rt_sim_system_destroy(rt_sim_system *sys);
/* The solver (add colliders and emitters through it; particles come from the world). */
rt_sph *rt_sim_system_solver(rt_sim_system *sys);
/* Report of the last step (zeroed before the first). */
const rt_sph_report *rt_sim_system_report(const rt_sim_system *sys);
/* Last error message of the system or its solver ("" when none). */
const char *rt_sim_system_last_error(const rt_sim_system *sys);

#endif
