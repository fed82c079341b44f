/* app.h — the sample host shared by volfx-game and volfx-bench: GL context, ECS world, host
 * renderer, the plugin behind its ABI, the profiler, and the scene's content. */
#ifndef GAME_APP_H
#define GAME_APP_H

#include <stdbool.h>
#include <stdint.h>
#include <volfx/volfx.h>

#include "ecs/effects.h"
#include "ecs/particles.h"
#include "ecs/world.h"
#include "gfx/camera.h"
#include "gfx/gl_context.h"
#include "gfx/mesh_import.h"
#include "gfx/renderer.h"
#include "host/plugin_host.h"
#include "profile/profiler.h"
#include "spawn/scene_spawn.h"

#include "gpu_particles.h"

#define GAME_APP_MAX_BEAMS 1024  /* beams a scene may spawn */
#define GAME_APP_MAX_JOINTS 4096

typedef struct game_app_desc {
    rt_gl_mode mode;
    uint32_t width, height;    /* 0 -> 640x360 */
    bool debug_gl;
    bool gl_compat;            /* headless: a GL 4.5 compatibility-profile context (default core) */
    const char *plugin_path;   /* NULL -> the statically linked plugin */
    const char *program_cache; /* the plugin keeps its program binaries here (NULL: off) */
    uint32_t profile_frames;   /* frames kept for CSV/trace; 0 -> 4096 */
    bool ldr;                  /* 8-bit output without tone mapping; default: HDR (RGBA16F, ACES) */
    float exposure;            /* HDR tone-map exposure; 0 -> 1 */
    bool gpu_particles;        /* hand the particles as one GL buffer (gpu_pos / gpu_vel), not CPU arrays */
    bool effects_layer;        /* the plugin renders into an RGBA16F layer the host composites itself */
    rt_logger logger;
} game_app_desc;

typedef struct game_app {
    game_app_desc desc;
    rt_logger log;
    rt_gl_context *gl;
    rt_renderer *renderer;
    rt_world *world;
    rt_particle_components particles;
    rt_effect_components effects; /* beams and volumes are entities ("vfx.beam", "vfx.volume") */
    rt_plugin_host *plugin;
    const vfx_plugin_api *api;
    vfx_context *ctx;
    rt_profiler *profiler;
    vfx_context_desc host;
    rt_camera camera;
    float clear_color[3];
    rt_renderer_environment environment; /* sky, sun and fog (zero: clear colour) */
    rt_mesh_components meshes; /* meshes are entities of the world ("vfx.mesh", "vfx.transform") */
    bool water_enabled;        /* particles are drawn as water when true */
    /* where beams struck the water, as of the last frame's get_lights (vfx_impact_events) */
#define GAME_APP_MAX_IMPACTS 16
    vfx_impact_event impacts[GAME_APP_MAX_IMPACTS];
    uint32_t impact_count;
    /* every field (kernel: method TILE's; the others get isotropic); its next is set per call */
    vfx_water_params water;
    vfx_water_foam water_foam; /* chained when the scene sets anything in water.foam */
    vfx_beams_view beams_view; /* parameters; beams/count/joints filled per call from the entities */
    /* chained after the beams view the game hands the plugin (NULL: none): tests and benches
     * chain their lab structs here; the game itself knows none */
    const void *beams_next;
    float joints[GAME_APP_MAX_JOINTS][3]; /* bending beams' joints (vfx_beam.joint_first) */
    uint32_t joint_count;
    double time;
    double origin[3];          /* large worlds: what every position the game holds is relative to
                                  (the scene's "origin"), handed to the plugin in frame view 2 */
    uint64_t frame;
    /* particle chunk views of this frame (host_particle_chunk_count fills them; a world
     * change since then clears chunks_valid) */
    vfx_particle_view *chunks;
    uint32_t chunk_count, chunk_cap;
    bool chunks_valid;
    game_gpu_particles gpu;    /* desc.gpu_particles: the GL buffer the chunks name */
    /* game_app_set_particle_source: a simulation holding the particles in GL buffers */
    bool (*particle_source)(void *user, vfx_particle_view *out);
    void *particle_source_user;
} game_app;

/* The water's particles from `source` from now on instead of the world's particle table: one chunk
 * of GL buffer columns (a GPU simulation's state, handed over with no CPU copy); source returns
 * false while it has none. NULL: the world's table again. */
void game_app_set_particle_source(game_app *app, bool (*source)(void *user, vfx_particle_view *out), void *user);

/* Sets the world around the meshes: the procedural sky (or the clear colour), the sun's
 * direction (towards it) and fog per metre. VFX_ERR_GL when the sky's shader fails. */
vfx_result game_app_set_environment(game_app *app, bool sky, const float sun_dir[3], float fog);
/* Creates the context (window or headless), world, renderer and plugin. */
vfx_result game_app_create(const game_app_desc *desc, game_app **out);
/* Destroys everything in reverse order. NULL allowed. */
void game_app_destroy(game_app *app);
/* Imports a mesh file (Assimp) as an entity (mesh, transform); `out` may be NULL. */
vfx_result game_app_add_mesh_file(game_app *app, const char *path, const float model[16],
                                 const float rgb[3], rt_entity *out);
/* Adds an axis-aligned box entity to the scene; `out` may be NULL. */
vfx_result game_app_add_box(game_app *app, const float min[3], const float max[3], const float rgb[3],
                           rt_entity *out);
/* Spawns n beam entities (component "vfx.beam"), copies of beams (NULL: zeroed, of type
 * VFX_TYPE_BEAM, to be filled through game_app_beams); they reach the plugin with beams_view's
 * parameters. */
vfx_result game_app_add_beams(game_app *app, const vfx_beam *beams, uint32_t n);
/* The beams as one array to read or edit in place (keep each one's type), their number in
 * *count (NULL, 0: none). Valid until the next structural change of the world. */
vfx_beam *game_app_beams(game_app *app, uint32_t *count);
/* Despawns every beam entity. */
void game_app_clear_beams(game_app *app);
/* Spawns a volume entity (component "vfx.volume") with a copy of the view; its arrays stay the
 * caller's and must outlive the entity. `out` may be NULL. */
vfx_result game_app_add_volume(game_app *app, const vfx_volume_view *view, rt_entity *out);
/* The volume entity's view, to edit in place (bump revision when its data changed); NULL for
 * a stale id. Valid until the next structural change of the world. */
vfx_volume_view *game_app_volume(game_app *app, rt_entity e);
/* Number of volume entities. */
uint32_t game_app_volume_count(game_app *app);
/* Despawns an entity (mesh, beam or volume); VFX_ERR_NOT_FOUND for a stale id. */
vfx_result game_app_remove(game_app *app, rt_entity e);
/* One frame: world systems (dt), plugin update, host scene, plugin render, present. */
vfx_result game_app_frame(game_app *app, float dt);
/* Writes the last frame's colour as a PNG. */
vfx_result game_app_screenshot(game_app *app, const char *path);
/* Writes an effect's raw quantity of the last frame as a PFM. */
vfx_result game_app_dump_raw(game_app *app, vfx_effect_kind effect, const char *path);
/* Sets the camera (and resizes the targets when the size changed); VFX_ERR_INVALID_ARGUMENT,
 * logged naming the field, for a camera rt_camera_check refuses. */
vfx_result game_app_set_camera(game_app *app, const rt_camera *cam);

#endif
