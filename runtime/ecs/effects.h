/* effects.h — the beam and volume components: what the host hands the plugin as beams and
 * tetrahedral volumes, one entity each. Names are the contract:
 *   "vfx.beam"   vfx_beam (of type VFX_TYPE_BEAM); beam
 *                entities carry only this component, so they share one table and its column
 *                is the contiguous array a beams view points at (no copy)
 *   "vfx.volume" vfx_volume_view (its arrays are owned by whoever spawned it) */
#ifndef RT_ECS_EFFECTS_H
#define RT_ECS_EFFECTS_H

#include "ecs/world.h"

#define RT_EFFECT_BEAM "vfx.beam"
#define RT_EFFECT_VOLUME "vfx.volume"

typedef struct rt_effect_components {
    rt_component beam, volume;
} rt_effect_components;

/* Registers the beam and volume components, or looks them up when already registered. */
vfx_result rt_effects_register(rt_world *world, rt_effect_components *out);
/* Spawns n beam entities, copies of beams (NULL: zeroed); their ids into out_ids when not NULL. */
vfx_result rt_beams_spawn(rt_world *world, const rt_effect_components *ec, uint32_t n,
                          const vfx_beam *beams, rt_entity *out_ids);
/* The beams as one array (the beam table's column) and their number in *count; NULL and 0
 * when there are none. Valid until the next structural change of the world. */
vfx_beam *rt_beams_column(rt_world *world, const rt_effect_components *ec, uint32_t *count);

#endif
