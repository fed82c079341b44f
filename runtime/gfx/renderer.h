/* renderer.h — the host's own drawing: opaque meshes into a scene target (colour + depth
 * textures the plugin reads), copied into the output target the plugin draws into, then shown
 * or read back. */
#ifndef RT_RENDERER_H
#define RT_RENDERER_H

#include <stdbool.h>
#include <stdint.h>
#include <volfx/volfx.h>
#include "core/log.h"
#include "gfx/mesh_import.h"

typedef struct rt_renderer rt_renderer;

/* Compiles the host shaders; needs a current GL 4.5 context. */
vfx_result rt_renderer_create(const rt_logger *logger, rt_renderer **out);
/* Frees every GL object. NULL allowed. */
void rt_renderer_destroy(rt_renderer *r);
/* (Re)allocates the targets at width x height (1..16384). */
vfx_result rt_renderer_resize(rt_renderer *r, uint32_t width, uint32_t height);
/* Clears the scene target and sets the camera (column-major view and projection). */
void rt_renderer_begin_scene(rt_renderer *r, const float view[16], const float proj[16],
                              const float clear_rgb[3]);
/* The world around the meshes. Zeroed (the default): a clear colour behind lit, checkered
 * meshes. With `sky`: the procedural dusk sky of shaders/common/sky.glsl behind everything
 * (the water reflects the same sky), stone-tiled meshes lit by the sun at sun_dir (towards the
 * sun) and the sky, fog of fog_density per metre towards the horizon seen from eye. */
typedef struct rt_renderer_environment {
    bool sky;
    float sun_dir[3];
    float fog_density;
    float eye[3];
} rt_renderer_environment;

/* Sets the environment for the frames that follow (the eye moves with the camera: call it when
 * the camera moves). VFX_ERR_GL when the sky's shader cannot be made. */
vfx_result rt_renderer_set_environment(rt_renderer *r, const rt_renderer_environment *env);
/* The world position the meshes' model matrices are relative to (a scene's origin): their
 * stone and checker patterns are laid out in world space, so they stay put whatever the origin. */
void rt_renderer_set_origin(rt_renderer *r, const double origin[3]);
/* Lights the meshes drawn from now on with the plugin's lights (get_lights of plugin api 3:
 * points and isotropic line segments on Lambertian meshes, closed-form irradiance), on top of
 * the sun and sky. At most RT_RENDERER_MAX_LIGHTS are kept (the first ones); n = 0 clears them.
 * VFX_ERR_ABI for a light of a kind this renderer does not know (none is kept then). */
#define RT_RENDERER_MAX_LIGHTS 32
vfx_result rt_renderer_set_lights(rt_renderer *r, const vfx_light *lights, uint32_t n);
/* The irradiance below which a light is left out of a mesh's draw: a Lambertian surface of
 * albedo <= 1 gets under 1/512 of display white from it (half an 8-bit step). */
#define RT_RENDERER_LIGHT_CUTOFF (3.14159265f / 512.f)
/* Squared distance from a light (its point or segment) past which its irradiance bound is below
 * RT_RENDERER_LIGHT_CUTOFF (no further than its radius for a point, which mesh.frag cuts at). */
float rt_renderer_light_reach2(const vfx_light *l);
/* Writes to keep[] the indices (ascending) of the lights that can light some point of the world
 * box lo..hi (relative to the origin, like the lights), i.e. whose reach meets the box; returns
 * how many. Conservative: a light left out adds under the cutoff anywhere in the box. */
uint32_t rt_renderer_lights_near_box(const vfx_light *lights, uint32_t n, const float lo[3],
                                     const float hi[3], uint32_t *keep);
/* Draws a mesh with a model matrix and a colour into the scene target, lit by every light. */
void rt_renderer_draw_mesh(rt_renderer *r, const rt_mesh_gpu *mesh, const float model[16],
                            const float rgb[3]);
/* Same, for a mesh whose model-space bounding box is lo..hi: only the lights that reach its
 * world box (rt_renderer_lights_near_box) go to the draw, so a far mesh pays for none. */
void rt_renderer_draw_mesh_bounded(rt_renderer *r, const rt_mesh_gpu *mesh, const float model[16],
                                   const float rgb[3], const float lo[3], const float hi[3]);
/* The targets of a finished scene: the output framebuffer effects draw into, and the scene's
 * colour and depth textures they sample (never attached to the output: no feedback loop). */
typedef struct rt_renderer_targets {
    unsigned output_framebuffer, scene_color, scene_depth;
    uint32_t width, height;
    bool color_hdr; /* colour targets are RGBA16F linear radiance (rt_renderer_set_hdr) */
} rt_renderer_targets;

/* The targets as rt_renderer_end_scene reports them, without drawing (tests read them back). */
void rt_renderer_get_targets(const rt_renderer *r, rt_renderer_targets *out);
/* Copies scene colour and depth into the output target and says where they are. */
void rt_renderer_end_scene(rt_renderer *r, rt_renderer_targets *out);
/* HDR mode on or off (off at creation): colour targets RGBA16F holding linear radiance,
 * tone-mapped (ACES fit, times `exposure`, 0 -> 1) for read-back and presenting. Remakes the
 * targets at the current size. */
vfx_result rt_renderer_set_hdr(rt_renderer *r, bool hdr, float exposure);
/* Reads the output colour, RGBA8 (tone-mapped in HDR mode), top row first (width*height*4 bytes). */
vfx_result rt_renderer_read_rgba(rt_renderer *r, uint8_t *rgba);
/* The effects layer texture (RGBA16F, the targets' size; remade when the size changed) a host
 * hands the plugin as frame view layer_texture instead of drawing into its output. */
vfx_result rt_renderer_layer(rt_renderer *r, unsigned *out);
/* Composites the effects layer over the output: out = layer.rgb + out * (1 - layer.a). Call after
 * the plugin's render, with the layer rt_renderer_layer gave. */
void rt_renderer_composite_layer(rt_renderer *r);
/* Blits the output to the default framebuffer of the current window. */
void rt_renderer_present(rt_renderer *r, uint32_t window_w, uint32_t window_h);

#endif
