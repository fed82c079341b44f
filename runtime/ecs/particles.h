/* particles.h — the particle components shared by the simulation (writer) and the plugin
 * (reader, through vfx_particle_view). Names are the contract; every field is float32 and
 * stored as its own contiguous column:
 *   "vfx.particle.position" 3 fields x[], y[], z[]
 *   "vfx.particle.velocity" 3 fields x[], y[], z[]
 *   "vfx.particle.density"  1 field
 *   "vfx.particle.radius"   1 field, optional (scale of the kernel radius h) */
#ifndef RT_ECS_PARTICLES_H
#define RT_ECS_PARTICLES_H

#include "ecs/world.h"

#define RT_PARTICLE_POSITION "vfx.particle.position"
#define RT_PARTICLE_VELOCITY "vfx.particle.velocity"
#define RT_PARTICLE_DENSITY "vfx.particle.density"
#define RT_PARTICLE_RADIUS "vfx.particle.radius"

typedef struct rt_particle_components {
    rt_component position, velocity, density, radius;
} rt_particle_components;

/* Registers the four particle components, or looks them up when already registered. */
vfx_result rt_particles_register(rt_world *world, rt_particle_components *out);
/* Spawns n particles (position, velocity, density; radius when with_radius) at the given
 * positions (each array n long; NULL -> zero), velocity 0 and density 0. Refuses NaN/Inf
 * positions, naming the first bad index. */
vfx_result rt_particles_spawn(rt_world *world, const rt_particle_components *pc, uint32_t n,
                               const float *x, const float *y, const float *z, bool with_radius);

#endif
