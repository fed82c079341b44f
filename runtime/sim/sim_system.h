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


#endif
