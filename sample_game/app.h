/* app.h — the sample host shared by volfx-game and volfx-bench: GL context, ECS world, host
 * renderer, the plugin behind its ABI, the profiler, and the scene's content. */
#ifndef VFX_APP_H
#define VFX_APP_H

#include <stdbool.h>
#include <stdint.h>
#include <volfx/volfx.h>

#include "ecs/particles.h"
#include "ecs/world.h"
#include "gfx/gl_context.h"
#include "gfx/mesh_import.h"
#include "gfx/renderer.h"
#include "host/plugin_host.h"
#include "profile/profiler.h"
#include "reference/reference.h"

#define VFX_APP_MAX_BEAMS 1024
#define VFX_APP_MAX_VOLUMES 4

typedef struct vfx_app_desc {
    vfx_gl_mode mode;
    uint32_t width, height;    /* 0 -> 640x360 */
    bool debug_gl;
    const char *plugin_path;   /* NULL -> the statically linked plugin */
    uint32_t profile_frames;   /* frames kept for CSV/trace; 0 -> 4096 */
    vfx_logger logger;
} vfx_app_desc;

/* Component "vfx.mesh": a drawable mesh with its colour and model-space bounds. The transform
 * is the separate component "vfx.transform" (float[16], column-major). */
typedef struct vfx_app_mesh {
    vfx_mesh_gpu gpu;
    float color[3];
    float bounds_min[3], bounds_max[3];
} vfx_app_mesh;

typedef struct vfx_app {
    vfx_app_desc desc;
    vfx_logger log;
    vfx_gl_context *gl;
    vfx_renderer *renderer;
    vfx_world *world;
    vfx_particle_components particles;
    vfx_plugin_host *plugin;
    const vfx_plugin_api *api;
    vfx_context *ctx;
    vfx_profiler *profiler;
    vfx_host_api host;
    vfx_ref_camera camera;
    float clear_color[3];
    vfx_component mesh_comp, transform_comp; /* scene meshes are entities of the world */
    uint32_t mesh_count;
    bool water_enabled;        /* particles are drawn as water when true */
    vfx_water_params water;
    vfx_beam beams[VFX_APP_MAX_BEAMS];
    uint32_t beam_count;
    vfx_beams_view beams_view; /* parameters; beams/count filled per call */
    vfx_volume_view volumes[VFX_APP_MAX_VOLUMES];
    uint32_t volume_count;
    double time;
    uint64_t frame;
} vfx_app;

/* Creates the context (window or headless), world, renderer and plugin. */
vfx_result vfx_app_create(const vfx_app_desc *desc, vfx_app **out);
/* Destroys everything in reverse order. NULL allowed. */
void vfx_app_destroy(vfx_app *app);
/* Imports a mesh file (Assimp) as an entity (mesh, transform); `out` may be NULL. */
vfx_result vfx_app_add_mesh_file(vfx_app *app, const char *path, const float model[16],
                                 const float rgb[3], vfx_entity *out);
/* Adds an axis-aligned box entity to the scene; `out` may be NULL. */
vfx_result vfx_app_add_box(vfx_app *app, const float min[3], const float max[3], const float rgb[3],
                           vfx_entity *out);
/* One frame: world systems (dt), plugin update, host scene, plugin render, present. */
vfx_result vfx_app_frame(vfx_app *app, float dt);
/* Writes the last frame's colour as a PNG. */
vfx_result vfx_app_screenshot(vfx_app *app, const char *path);
/* Writes an effect's raw quantity of the last frame as a PFM. */
vfx_result vfx_app_dump_raw(vfx_app *app, vfx_effect_kind effect, const char *path);
/* Sets the camera (and resizes the targets when the size changed). */
vfx_result vfx_app_set_camera(vfx_app *app, const vfx_ref_camera *cam);

#endif
