/* plugin_internal.h — what the effects inside the plugin share: the context, the effect ops
 * table, logging/errors/allocation through the host api, and per-frame stats. */
#ifndef VOLFX_PLUGIN_INTERNAL_H
#define VOLFX_PLUGIN_INTERNAL_H

#include <stdarg.h>
#include <stdbool.h>
#include <volfx/volfx.h>

typedef struct volfx_gpu volfx_gpu;

/* Targets shared between effects during one render. Effects run in a fixed order:
 * water (writes water_dist), volume (over, clipped by scene depth and water), beams (additive,
 * integrated up to the nearer of scene and water). */
typedef struct volfx_frame_targets {
    unsigned scene_depth;  /* host depth texture (window depth [0,1]) */
    unsigned scene_color;  /* host colour texture */
    unsigned water_dist;   /* R32F distance along the view ray to water, -1 miss; 0 = no water */
    float inv_view_proj[16];
} volfx_frame_targets;

typedef struct volfx_effect_ops {
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
} volfx_effect_ops;

#if VFX_WITH_WATER
extern const volfx_effect_ops volfx_water_ops;
#endif
#if VFX_WITH_BEAMS
extern const volfx_effect_ops volfx_beams_ops;
#endif
#if VFX_WITH_TETVOL
extern const volfx_effect_ops volfx_volume_ops;
#endif

/* Knobs that only tests and benchmarks set (through this header: hosts of the shared library
 * cannot reach them). Zero is the production behaviour. */
typedef struct volfx_debug_knobs {
    bool sync_counters;        /* GPU counters of this frame, waited for (a stall); otherwise
                                  effects report those of the last frame the GPU finished */
    uint32_t water_buffer_cap; /* particles per water position buffer; 0 -> the GL limit */
} volfx_debug_knobs;

struct vfx_context {
    vfx_host_api host;          /* copy of the host's table */
    volfx_gpu *gpu;               /* program cache, timers, fullscreen VAO */
    uint32_t width, height;
    void *effect_state[VFX_EFFECT_COUNT];
    const volfx_effect_ops *effect_ops[VFX_EFFECT_COUNT];
    vfx_stats stats;            /* counters of the frame being made */
    vfx_stats last_stats;       /* counters of the last finished frame */
    char last_error[512];
    unsigned water_dist_tex;    /* shared target owned by the context */
    volfx_debug_knobs debug;
};

/* Logs through the host logger, printf-style. */
void volfx_log(vfx_context *ctx, vfx_log_level level, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* Records an error (last_error + log at ERROR) and returns `code` for `return volfx_fail(...)`. */
vfx_result volfx_fail(vfx_context *ctx, vfx_result code, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* Allocates through the host allocator; zeroed; NULL on failure (error recorded). */
void *volfx_alloc(vfx_context *ctx, size_t size);
/* Frees what volfx_alloc returned; NULL allowed. */
void volfx_free(vfx_context *ctx, void *ptr);
/* Sets a named counter of the current frame (adds an entry or overwrites it). */
void volfx_stat_set(vfx_context *ctx, const char *name, double value);
/* Adds to a named counter of the current frame. */
void volfx_stat_add(vfx_context *ctx, const char *name, double value);
/* Column-major 4x4 inverse (false when singular or not finite). */
bool volfx_mat4_invert(const float m[16], float out[16]);
/* out = a * b, column-major. */
void volfx_mat4_mul(const float a[16], const float b[16], float out[16]);

#endif
