/* pass.h — the one way a pass begins, raster or compute (sokol style: a desc struct where zero
 * means default): its debug group, its GPU timer and its GL state in one call; std140 uniform
 * blocks uploaded once per frame, uniform locations resolved when a program is made, and the one
 * composite every effect ends with. Nothing here looks anything up by name on the frame path. */
#ifndef VOLFX_PASS_H
#define VOLFX_PASS_H

#include <stdbool.h>
#include "gpu/gpu.h"

typedef enum volfx_blend {
    VOLFX_BLEND_NONE = 0,    /* blending off */
    VOLFX_BLEND_ADD,         /* ONE, ONE */
    VOLFX_BLEND_OVER_PREMUL, /* ONE, ONE_MINUS_SRC_ALPHA: premultiplied colour over the target */
    VOLFX_BLEND_MAX,         /* equation MAX */
    VOLFX_BLEND_MIN,         /* equation MIN */
} volfx_blend;

typedef enum volfx_depth {
    VOLFX_DEPTH_NONE = 0,    /* no depth test, no depth write */
    VOLFX_DEPTH_TEST,        /* LESS test, no write */
    VOLFX_DEPTH_TEST_WRITE,  /* LESS test and write */
} volfx_depth;

typedef struct volfx_pass_desc {
    const char *name;        /* "effect.pass": debug group and GPU timer ("<name>.gpu_ms"); required */
    /* A compute pass (dispatches only), or a timed group of steps that each apply their own
     * state with volfx_pass_apply: begin leaves the framebuffer, viewport, clears, blend and depth
     * alone (a dispatch reads none of them), and every field below is ignored. What a dispatch
     * does read, the pass sets itself after begin: its program, its storage, uniform, image and
     * texture bindings (all inside the ranges gl_state.h saves and restores for the host; test
     * gl/gl_state binds hostile values on more), the dispatch-indirect buffer (unbound again
     * after), and the glMemoryBarrier its readers need after its writes. */
    bool compute;
    GLuint framebuffer;      /* 0 -> the default framebuffer */
    uint32_t width, height;  /* viewport; 0 -> the context's size */
    bool clear_color;        /* clear colour attachments to clear_rgba first */
    float clear_rgba[4];
    bool clear_depth;        /* clear depth to clear_depth_value (0 -> 1.0) first */
    float clear_depth_value;
    volfx_blend blend;
    volfx_depth depth;
} volfx_pass_desc;

/* Opens a timed, labelled pass (gpu.h's timer ring: its GPU ms reach the stats as
 * "<name>.gpu_ms") and, unless desc->compute, applies its framebuffer, viewport, clears, blend
 * and depth. Every pass of the plugin, raster or compute, begins here. */
void volfx_pass_begin(vfx_context *ctx, const volfx_pass_desc *desc);
/* Closes the innermost pass; leaves blending and depth testing off (the effect state rule). */
void volfx_pass_end(vfx_context *ctx);
/* Applies a desc's framebuffer, viewport, clears, blend and depth without opening a timed pass
 * (its name is not used): one draw among several inside a pass that volfx_pass_begin opened. */
void volfx_pass_apply(vfx_context *ctx, const volfx_pass_desc *desc);
/* Blending and depth testing off, depth writes on: the effect state rule, without closing a pass. */
void volfx_pass_reset(void);

/* A std140 uniform block: a buffer the effect fills from a C struct mirroring the GLSL block. */
typedef struct volfx_ubo {
    GLuint buffer;
    uint32_t bytes;
} volfx_ubo;

/* Makes a uniform buffer of `bytes` (a multiple of 16, as std140 pads); false with an error. */
bool volfx_ubo_create(vfx_context *ctx, volfx_ubo *ubo, uint32_t bytes, const char *label);
/* Uploads `bytes` (<= ubo->bytes) from data; once per frame per block. */
void volfx_ubo_update(const volfx_ubo *ubo, const void *data, uint32_t bytes);
/* Binds the block at `binding` (the GLSL `layout(std140, binding = N)`). */
void volfx_ubo_bind(const volfx_ubo *ubo, uint32_t binding);
/* Deletes the buffer; a zeroed ubo is allowed. */
void volfx_ubo_destroy(volfx_ubo *ubo);

/* Resolves n uniform names of prog into locs at program creation; a name the linker dropped
 * gets -1 (GL ignores it). Never call it on the frame path. */
void volfx_program_uniforms(GLuint prog, const char *const *names, GLint *locs, uint32_t n);

/* Draws `prog` (which uses common/fullscreen.vert) over the whole of the frame gate's framebuffer
 * (effect.h) with `blend`, timed as `name`, textures bound by the caller: the final pass of an
 * effect. */
struct volfx_frame_targets;
void volfx_composite_targets(vfx_context *ctx, const struct volfx_frame_targets *t, const char *name,
                             GLuint prog, volfx_blend blend);

#endif
