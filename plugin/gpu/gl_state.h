/* gl_state.h — the GL state contract with the host (docs/integration.md, "GL state contract").
 * On entry to every API call that touches GL the plugin saves the host's bindings and state it
 * may change (volfx_gl_state_save), then sets the baseline every pass depends on
 * (volfx_gl_state_baseline); on return it puts the saved state back (volfx_gl_state_restore).
 * Passes then set only what they vary (framebuffer, viewport, blend, depth: gpu/pass.h).
 *
 * The limits below are what the plugin's shaders and passes use (checked by tests/gl's
 * hostile-state test, which binds something on every one of them and on more). */
#ifndef VOLFX_GL_STATE_H
#define VOLFX_GL_STATE_H

#include <stdbool.h>
#include "gpu/gl.h"

#define VOLFX_GL_TEXTURE_UNITS 10  /* units 0..9: sampler2D/samplerCube bindings of the shaders (8: the water reads the beams behind it, 9: its foam layer) */
#define VOLFX_GL_UBO_BINDINGS 8    /* uniform blocks at bindings 0..7 */
#define VOLFX_GL_SSBO_BINDINGS 16  /* storage blocks at bindings 0..15 */
#define VOLFX_GL_IMAGE_UNITS 8     /* image units 0..7 */
#define VOLFX_GL_DRAW_BUFFERS 8    /* per-draw-buffer blend and colour mask, indices 0..7 */

typedef struct volfx_gl_range { GLint name; GLint64 start, size; } volfx_gl_range;
typedef struct volfx_gl_image { GLint name, level, layered, layer, access, format; } volfx_gl_image;
typedef struct volfx_gl_blend_i {
    GLint src_rgb, dst_rgb, src_alpha, dst_alpha, eq_rgb, eq_alpha;
    GLboolean enabled, mask[4];
} volfx_gl_blend_i;

/* Everything the plugin may change, as the host left it. */
typedef struct volfx_gl_saved {
    GLint draw_fb, read_fb, renderbuffer, program, vao;
    GLint array_buf, draw_indirect, dispatch_indirect, pack_buf, unpack_buf, uniform_buf, storage_buf;
    GLint active_texture;
    GLint tex_2d[VOLFX_GL_TEXTURE_UNITS], tex_cube[VOLFX_GL_TEXTURE_UNITS], sampler[VOLFX_GL_TEXTURE_UNITS];
    volfx_gl_range ubo[VOLFX_GL_UBO_BINDINGS], ssbo[VOLFX_GL_SSBO_BINDINGS];
    volfx_gl_image image[VOLFX_GL_IMAGE_UNITS];
    GLint viewport[4];
    GLdouble depth_range[2];
    GLint depth_func, polygon_mode, clip_origin, clip_depth;
    GLboolean depth_mask;
    GLint draw_buffers; /* how many entries of blend[] are saved: min(GL_MAX_DRAW_BUFFERS, 8) */
    volfx_gl_blend_i blend[VOLFX_GL_DRAW_BUFFERS];
    GLint pack[7], unpack[7]; /* the pixel-store values of volfx_gl_pixel_store's order */
    GLint stencil[2][7];      /* front, back: func, ref, value mask, fail, depth fail, depth pass, write mask */
    uint32_t enables;         /* bit i: the i-th capability of the enables table was on */
    bool compat;              /* a compatibility profile: GL_ALPHA_TEST is saved as well */
    bool alpha_test;
} volfx_gl_saved;

/* Reads every binding and state of volfx_gl_saved from the current context (GL queries only). */
void volfx_gl_state_save(volfx_gl_saved *s, bool compat);
/* Puts back what volfx_gl_state_save read. */
void volfx_gl_state_restore(const volfx_gl_saved *s);
/* Sets the state every pass assumes: no culling, scissor, stencil, colour logic op, rasterizer
 * discard, depth clamp, polygon offset, alpha-to-coverage, sample mask or primitive restart;
 * filled polygons; all colour and the depth write masks on; depth range 0..1; default clip
 * control; sRGB encoding off (the frame gate turns it on for an sRGB output framebuffer);
 * blending and depth test off; no sampler objects on the units the plugin uses; default pixel store and no pixel
 * buffers bound. `compat` also turns off GL_ALPHA_TEST. */
void volfx_gl_state_baseline(bool compat);

#endif
