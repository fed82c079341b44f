/* scene_spawn.h — a parsed scene (runtime/scene) spawned into the ECS world in one call: its
 * meshes (imported and uploaded: the GL context must be current), the water's particles and, for
 * a simulated tank, its SPH system with the paddle, the beams at t = 0, and the volume (generated
 * or read from its file) with its transfer table. The game calls rt_scene_spawn once per scene;
 * what the spawn made and owns (the simulation, the volume's arrays) is kept in rt_scene_spawned
 * and freed by rt_scene_despawn. Animation (beam keyframes, the volume's ripples) is the game's. */
#ifndef RT_SPAWN_SCENE_SPAWN_H
#define RT_SPAWN_SCENE_SPAWN_H

#include <stdbool.h>
#include <stdint.h>
#include <volfx/volfx.h>

#include "core/log.h"
#include "ecs/effects.h"
#include "ecs/particles.h"
#include "ecs/world.h"
#include "gfx/mesh_import.h"
#include "scene/scene.h"
#include "sim/sim_system.h"

#define RT_MESH_COMPONENT "vfx.mesh"           /* rt_mesh_component */
#define RT_TRANSFORM_COMPONENT "vfx.transform" /* float[16], column-major */

/* Component "vfx.mesh": a drawable mesh with its colour and model-space bounds; its transform
 * is the separate component "vfx.transform". */
typedef struct rt_mesh_component {
    rt_mesh_gpu gpu;
    float color[3];
    float bounds_min[3], bounds_max[3];
} rt_mesh_component;

typedef struct rt_mesh_components {
    rt_component mesh, transform;
} rt_mesh_components;

/* Registers "vfx.mesh" and "vfx.transform", or looks them up when already registered. */
vfx_result rt_mesh_components_register(rt_world *world, rt_mesh_components *out);
/* Uploads the mesh data (freed here whatever the result) and spawns its entity with the model
 * matrix (NULL: identity) and colour; `out` may be NULL. */
vfx_result rt_mesh_spawn(rt_world *world, const rt_mesh_components *mc, rt_mesh_data *data, const float model[16],
                         const float rgb[3], rt_entity *out);

/* Where the scene goes and what is left out. */
typedef struct rt_scene_spawn_desc {
    rt_world *world;
    const rt_particle_components *particles;
    const rt_effect_components *effects;
    const rt_mesh_components *meshes;
    const rt_logger *log;       /* warnings (a mesh file skipped, an empty particle file) and info */
    uint32_t effects_off;       /* VFX_EFFECT_BIT mask: those effects' content is not spawned */
    uint32_t max_beams;         /* beams spawned at most (the scene's count above it is capped) */
    float *joints;              /* bending beams' joints at t = 0, xyz triples, room for joint_cap */
    uint32_t joint_cap;
    /* the simulation's sim.* figures after each step (NULL: none) */
    void (*sim_stats)(void *user, const char *name, double value);
    void *sim_stats_user;
} rt_scene_spawn_desc;

/* What rt_scene_spawn made. The volume's view (in its entity) points into the arrays here. */
typedef struct rt_scene_spawned {
    uint32_t mesh_count, particle_count, beam_count;
    uint32_t joint_count;       /* joints written to desc.joints */
    rt_sim_system *sim;         /* the water's simulation (NULL: static or no water) */
    rt_entity volume;           /* the volume's entity (valid when has_volume) */
    bool has_volume;
    float *vol_points, *vol_scalar;
    uint32_t *vol_tets, vol_point_count, vol_tet_count;
    /* the scene's transfer function as the view's table (a constant is given twice) */
    float vol_transfer[RT_SCENE_MAX_TRANSFER * 4], vol_transfer_pos[RT_SCENE_MAX_TRANSFER];
    uint32_t vol_transfer_count;
} rt_scene_spawned;

/* Spawns the scene's content into desc->world in the scene's order (meshes, water, beams,
 * volume), out zeroed first. On an error (message in err, naming the scene key or file) what was
 * spawned stays in *out for rt_scene_despawn. A missing mesh file is a warning, not an error. */
vfx_result rt_scene_spawn(const rt_scene *scene, const rt_scene_spawn_desc *desc, rt_scene_spawned *out,
                          char *err, size_t errlen);
/* Despawns the volume's entity, destroys the simulation and frees the arrays (the world must not
 * run the simulation after this); the other entities stay in the world. NULL allowed. */
void rt_scene_despawn(rt_world *world, rt_scene_spawned *spawned);

#endif
