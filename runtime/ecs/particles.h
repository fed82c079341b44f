/* particles.h — the particle components shared by the simulation (writer) and the plugin
 * (reader, through vfx_particle_view). Names are the contract; every field is float32 and
 * stored as its own contiguous column:
 *   "vfx.particle.position" 3 fields x[], y[], z[]
 *   "vfx.particle.velocity" 3 fields x[], y[], z[]
 *   "vfx.particle.density"  1 field
 *   "vfx.particle.radius"   1 field, optional (scale of the kernel radius h) */
#ifndef VFX_ECS_PARTICLES_H
#define VFX_ECS_PARTICLES_H

#include "ecs/world.h"

#define VFX_PARTICLE_POSITION "vfx.particle.position"
#define VFX_PARTICLE_VELOCITY "vfx.particle.velocity"
#define VFX_PARTICLE_DENSITY "vfx.particle.density"
#define VFX_PARTICLE_RADIUS "vfx.particle.radius"

typedef struct vfx_particle_components {
    vfx_component position, velocity, density, radius;
} vfx_particle_components;

/* Registers the four particle components, or looks them up when already registered. */
vfx_result vfx_particles_register(vfx_world *world, vfx_particle_components *out);
/* Spawns n particles (position, velocity, density; radius when with_radius) at the given
 * positions (each array n long; NULL -> zero), velocity 0 and density 0. Refuses NaN/Inf
 * positions, naming the first bad index. */
vfx_result vfx_particles_spawn(vfx_world *world, const vfx_particle_components *pc, uint32_t n,
                               const float *x, const float *y, const float *z, bool with_radius);

#endif
