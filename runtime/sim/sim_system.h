/* sim_system.h — the SPH solver as an ECS system: "vfx.sim.sph" in the simulate phase reads
 * and writes the particle components of runtime/ecs/particles.h.
 *
 * The world is the source of truth: every frame the system imports all entities that have
 * position, velocity and density (in query order), steps the solver by the frame dt, and
 * writes position, velocity and density back to the same rows. So the game may spawn,
 * despawn or move particles between frames. Particles made by the solver's emitters are
 * spawned as new particle entities after the step. */
#ifndef VFX_SIM_SYSTEM_H
#define VFX_SIM_SYSTEM_H

#include "ecs/particles.h"
#include "ecs/world.h"
#include "sim/sph.h"

typedef struct vfx_sim_system vfx_sim_system;

/* Registers (or looks up) the particle components, creates the solver (NULL desc = defaults)
 * and adds the system to the world. Destroy the system only after the world is destroyed or
 * will not run again (the world keeps a pointer to it). */
vfx_result vfx_sim_system_create(vfx_world *world, const vfx_sph_desc *desc, vfx_sim_system **out,
                                 char *err, size_t err_len);
/* Frees the solver and the system's buffers. NULL allowed. */
void vfx_sim_system_destroy(vfx_sim_system *sys);
/* The solver (add colliders and emitters through it; particles come from the world). */
vfx_sph *vfx_sim_system_solver(vfx_sim_system *sys);
/* Report of the last step (zeroed before the first). */
const vfx_sph_report *vfx_sim_system_report(const vfx_sim_system *sys);
/* Last error message of the system or its solver ("" when none). */
const char *vfx_sim_system_last_error(const vfx_sim_system *sys);

#endif
