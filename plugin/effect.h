/* effect.h — what an effect implements (its ops table, registered in entry.c) and the targets
 * effects share during one render. */
#ifndef VOLFX_EFFECT_H
#define VOLFX_EFFECT_H

#include <stdbool.h>

#include "context.h"

/* Targets shared between effects during one render. Effects run in a fixed order:
 * water (writes water_dist), volume (over, clipped by scene depth and water), beams (additive,
 * integrated up to the nearer of scene and water). */
typedef struct volfx_frame_targets {
    unsigned scene_depth;  /* host depth texture (window depth [0,1]) */
    unsigned scene_color;  /* host colour texture */
    unsigned water_dist;   /* R32F distance along the view ray to water, -1 miss; 0 = no water */
    /* Made once per frame in entry.c from the frame view, so no effect multiplies or inverts. */
    float view_proj[16];     /* proj * view */
    float inv_view_proj[16]; /* window/NDC -> world */
    float inv_view[16];      /* eye space -> world */
    /* Version 2 fields (defaults when the host passed version 1). */
    double origin[3];        /* positions are relative to this */
    bool color_hdr;          /* framebuffer colour is float: write linear radiance */
    unsigned environment_cubemap; /* 0 -> procedural sky */
    /* Version 3: the view's id (0 for versions 1 and 2); effects key per-view state on it. */
    uint32_t view_id;
} volfx_frame_targets;

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
    /* Draws into frame->framebuffer. */
    vfx_result (*render)(vfx_context *ctx, void *state, const vfx_frame_view *frame,
                         volfx_frame_targets *targets);
    /* Copies the raw quantity of the last render, top row first. */
    vfx_result (*read_raw)(vfx_context *ctx, void *state, float *out, size_t count);
};

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
