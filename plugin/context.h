/* context.h — the plugin's context and the services every part of it uses through it: logging,
 * errors, allocation through the host api, per-frame counters (context.c). Effects add effect.h. */
#ifndef VOLFX_PLUGIN_INTERNAL_H
#define VOLFX_PLUGIN_INTERNAL_H

#include <stdarg.h>
#include <stdbool.h>
#include <volfx/volfx.h>

#include "gpu/gl_state.h"

typedef struct volfx_gpu volfx_gpu;
typedef struct volfx_scan volfx_scan;
typedef struct volfx_lab_hooks volfx_lab_hooks; /* lab_hooks.h */
struct volfx_gl_table; /* gpu/volfx_gl.h, generated: the GL commands, resolved at create */
typedef struct volfx_effect_ops volfx_effect_ops;

/* Knobs that only tests and benchmarks set (through this header: hosts of the shared library
 * cannot reach them). Zero is the production behaviour. */
typedef struct volfx_debug_knobs {
    bool sync_counters;        /* GPU counters of this frame, waited for (a stall); otherwise
                                  effects report those of the last frame the GPU finished */
    uint32_t water_buffer_cap; /* particles per water position buffer; 0 -> the GL limit */
    uint32_t water_max_tiles;  /* TILE's tile count limit; 0 -> the scan's 2^20 - 1 */
    uint64_t water_storage_cap; /* bytes per TILE storage block; 0 -> GL_MAX_SHADER_STORAGE_BLOCK_SIZE */
} volfx_debug_knobs;

/* The engine's own depth (docs/integration.md, "The engine's own depth"): this frame's
 * vfx_frame_depth as the frame gate read it. Zero is the standard: depth_texture holds window
 * depth of proj under GL_NEGATIVE_ONE_TO_ONE, rows bottom first. */
typedef struct volfx_frame_depth {
    unsigned depth_renderbuffer; /* a depth renderbuffer of the frame's size, read instead of depth_texture */
    unsigned depth_framebuffer;  /* or a framebuffer whose depth attachment is read (renderbuffer or texture) */
    bool flip_y;                 /* colour and depth rows are stored top first, and the output is expected so */
    bool zero_to_one;            /* the depth was written under glClipControl(.., GL_ZERO_TO_ONE) */
    bool chained;                /* the host chained one: a reversed proj is then read as reversed-Z */
} volfx_frame_depth;

/* The frame gate's depth objects (frame_check.c): a same-format copy of a renderbuffer's depth,
 * and the depth converted to the standard convention. */
typedef struct volfx_depth_targets {
    unsigned src_fbo;            /* the host's renderbuffer attached, to blit from */
    unsigned copy_tex, copy_fbo; /* the blit's target, of the host's depth format */
    int copy_format;
    unsigned std_tex, std_fbo;   /* DEPTH_COMPONENT32F, the standard convention */
    uint32_t w, h;               /* size of copy_tex and std_tex */
} volfx_depth_targets;

struct vfx_context {
    vfx_context_desc host;      /* copy of the host's description (next cleared: not kept) */
    volfx_gpu *gpu;               /* program cache, timers, fullscreen VAO */
    volfx_scan *scan;             /* the GPU prefix sum's programs and block sums (gpu/scan.h), made on first use */
    struct volfx_gl_table *gl;    /* every GL command, through host.gl_get_proc_address */
    uint32_t width, height;
    void *effect_state[VFX_EFFECT_COUNT];
    uint32_t rendered;          /* VFX_EFFECT_BIT of effects rendered since their creation (read_raw) */
    uint32_t prepared;          /* VFX_EFFECT_BIT of effects whose prepare step ran this render */
    const volfx_effect_ops *effect_ops[VFX_EFFECT_COUNT];
    vfx_stats stats;            /* counters of the frame being made */
    vfx_stats last_stats;       /* counters of the last finished frame */
    char last_error[512];
    vfx_log_id last_error_id;   /* the id of last_error */
    unsigned water_dist_tex;    /* shared target owned by the context */
    unsigned no_depth_tex;      /* far depth for a frame view without depth_texture (frame_check.c) */
    uint32_t no_depth_w, no_depth_h;
    unsigned frame_block;       /* GL uniform buffer of the frame gate's VolfxFrame block */
    unsigned layer_fbo;         /* framebuffer the effects layer is attached to (frame_check.c) */
    volfx_debug_knobs debug;
    /* the laboratory's functions (lab_hooks.h): NULL in the product; volfx_lab_attach fills it */
    const volfx_lab_hooks *lab;
    /* the GL state contract (gpu/gl_state.h): the host's state saved on entry to the outermost
     * API call that touches GL (gl_calls counts the nesting: warm_up calls render, render
     * resize), put back on its return unless the host said it resets its own state */
    volfx_gl_saved gl_saved;
    uint32_t gl_calls;
    bool gl_compat;             /* the context is a compatibility profile */
    bool gl_skip_restore;       /* vfx_gl_state_desc.skip_restore: the host resets its own state, no save, no restore */
    volfx_frame_depth frame_depth; /* this frame's vfx_frame_depth (zero: the standard depth) */
    volfx_depth_targets depth;
};

/* Logs through the host logger, printf-style, with the message's stable id (VFX_LOG_ID_LIST:
 * add one there for a new kind of message). */
void volfx_log(vfx_context *ctx, vfx_log_level level, vfx_log_id id, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* Records an error (last_error and its id + log at ERROR) and returns `code` for
 * `return volfx_fail(...)`. */
vfx_result volfx_fail(vfx_context *ctx, vfx_result code, vfx_log_id id, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* The host's struct at `p` has `want` as its type; otherwise fails ctx (VFX_ERR_ABI,
 * VFX_LOG_ID_STRUCT_TYPE) naming `what` (the struct and where) and both types. */
vfx_result volfx_check_type(vfx_context *ctx, const void *p, vfx_struct_type want, const char *what);
/* The first struct of `type` in the chain at `next` (at most 64 entries walked), or NULL. */
const void *volfx_chain_find(const void *next, vfx_struct_type type);
/* Allocates through the host allocator; zeroed; NULL on failure (error recorded). */
void *volfx_alloc(vfx_context *ctx, size_t size);
/* Frees what volfx_alloc returned; NULL allowed. */
void volfx_free(vfx_context *ctx, void *ptr);
/* Sets a named counter of the current frame (adds an entry or overwrites it). */
void volfx_stat_set(vfx_context *ctx, const char *name, double value);
/* True when the current frame already has a counter of this name. */
bool volfx_stat_has(const vfx_context *ctx, const char *name);
/* Adds to a named counter of the current frame. */
void volfx_stat_add(vfx_context *ctx, const char *name, double value);
/* Column-major 4x4 inverse in double (false when singular or not finite): what cglm lacks. */
bool volfx_mat4_invert(const float m[16], float out[16]);
/* out = a * b, column-major (cglm's glm_mat4_mul; out may alias a or b). */
void volfx_mat4_mul(const float a[16], const float b[16], float out[16]);

#endif
