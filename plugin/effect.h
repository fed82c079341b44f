/* effect.h — what an effect implements (its ops table, registered in entry.c) and the targets
 * effects share during one render. */
#ifndef VOLFX_EFFECT_H
#define VOLFX_EFFECT_H

#include <stdbool.h>

#include "context.h"

/* The frame gate (plugin/frame_check.c): what effects read of the camera, computed once a frame
 * from the checked frame view, and the targets effects share during one render. Effects run in
 * a fixed order: water (writes water_dist), volume (over, clipped by scene depth and water),
 * beams (additive, integrated up to the nearer of scene and water). Effects read the frame
 * through this alone (render() is given no frame view); none multiplies or inverts these
 * matrices (docs/architecture.md "Frame gate"). */
typedef struct volfx_frame_targets {
    unsigned scene_depth;  /* host depth texture (window depth [0,1]); a far-depth one for 0 */
    unsigned host_depth;   /* scene_depth when the host gave depth (a depth texture or a chained
                            * vfx_frame_depth), 0 when scene_depth is the far-depth stand-in: the
                            * water then binds none and tells its shaders it has no depth */
    unsigned scene_color;  /* host colour texture */
    unsigned water_dist;   /* R32F distance along the view ray to water, -1 miss; 0 = no water */
    float view_proj[16];     /* proj * view */
    float inv_view_proj[16]; /* window/NDC -> position */
    float inv_view[16];      /* eye space -> position */
    double origin[3];        /* positions are relative to this */
    bool color_hdr;          /* framebuffer colour is float: write linear radiance */
    unsigned environment_cubemap; /* 0 -> procedural sky */
    /* the view's id; effects key per-view state on it */
    uint32_t view_id;
    /* The rest of the camera (frame gate, issue 23). */
    unsigned framebuffer;    /* where effects draw their result: the host's, or the layer's */
    unsigned layer_texture;  /* the host's effects layer (RGBA16F, premultiplied); 0 -> none */
    uint32_t width, height;
    uint32_t effects;        /* VFX_EFFECT_BIT mask drawn this frame (the host's 0 -> all) */
    float view[16], proj[16];        /* the host's, checked finite */
    float eye[3];                    /* the host's eye (relative to origin) */
    double view_eye[3];              /* -R^T t of the view matrix, in double */
    float near_plane, far_plane;     /* checked against proj; filled from it when the host gave 0, 0
                                      * (far FLT_MAX for an infinite projection) */
    float fov_y;                     /* radians, [0, pi) */
    float cam_view_proj[16];         /* camera-relative: proj * view without its translation */
    float inv_cam_view_proj[16];     /* window/NDC -> direction from the eye */
    bool depth_convert;              /* the host's depth is rewritten in the standard convention */
    double depth_host[4], depth_std[2]; /* its parameters (shaders/common/depth_convert.frag) */
    bool output_srgb;                /* framebuffer's colour attachment 0 is sRGB-encoded: the
                                      * frame gate turns GL_FRAMEBUFFER_SRGB on for the frame */
    /* The beams' prepare step (before the water's shading): their light in front of the water
     * surface (or of the scene where no water), RGBA16F linear, a = white cores, flares and sparks
     * included; and their light behind the water surface (0: no water this frame). 0, 0 when the
     * beams draw nothing. */
    unsigned beams_light, beams_behind;
} volfx_frame_targets;

/* The shared std140 block of the frame gate (shaders/common/frame.glsl, `VolfxFrame`): uploaded
 * once a frame and bound at this uniform block binding before any effect renders; effects keep
 * it bound (they bind their own blocks at other indices: beams 3, water 4, volume 0). */
#define VOLFX_FRAME_BINDING 6u
typedef struct volfx_frame_block {
    float view_proj[16], inv_view_proj[16], cam_view_proj[16], inv_cam_view_proj[16];
    float view[16], proj[16], inv_view[16];
    float eye_fov[4];        /* eye xyz, fov_y */
    float planes_size[4];    /* near, far, width, height */
    float origin_hdr[4];     /* origin xyz (float), 1 when HDR */
    uint32_t flags[4];       /* cubemap given, view id, effects mask, 0 */
} volfx_frame_block;

struct volfx_effect_ops {
    const char *name;
    vfx_effect_kind kind;
    /* True when the host's world holds this effect now (asks the host api; allocates nothing). */
    bool (*present)(vfx_context *ctx);
    /* Makes the effect's state: programs, buffers. Called the first frame it is present. */
    vfx_result (*create)(vfx_context *ctx, void **state);
    /* Frees every GL object and allocation of the state. */
    void (*destroy)(vfx_context *ctx, void *state);
    /* Reallocates size-dependent targets. */
    vfx_result (*resize)(vfx_context *ctx, void *state, uint32_t width, uint32_t height);
    /* Pulls host data (uploads columns, meshes). */
    vfx_result (*update)(vfx_context *ctx, void *state, double time, float dt);
    /* Optional: the part of a frame other effects read (the beams' light, split at the water's
     * surface), into the effect's own targets, published in targets. Runs once a render for each
     * drawn effect, before the water's shading (volfx_effects_prepare), and always before render. */
    vfx_result (*prepare)(vfx_context *ctx, void *state, volfx_frame_targets *targets);
    /* Draws into targets->framebuffer, reading the camera and the host's textures from targets
     * alone (the frame gate's). */
    vfx_result (*render)(vfx_context *ctx, void *state, volfx_frame_targets *targets);
    /* Copies the raw quantity of the last render, top row first. */
    vfx_result (*read_raw)(vfx_context *ctx, void *state, float *out, size_t count);
};

/* Runs the prepare step of every effect drawn this render that has one and has not run it yet
 * (entry.c): the water calls it between its surface and its shading, so that the shading sees
 * the beams' light; entry.c calls it before each render for the rest. */
vfx_result volfx_effects_prepare(vfx_context *ctx, volfx_frame_targets *targets);

#if VFX_WITH_WATER
extern const volfx_effect_ops volfx_water_ops;
#endif
#if VFX_WITH_BEAMS
extern const volfx_effect_ops volfx_beams_ops;
#endif
#if VFX_WITH_TETVOL
extern const volfx_effect_ops volfx_volume_ops;
#endif

#endif
