/* gpu.h — plugin-side GL helpers: embedded-shader program cache with file:line errors,
 * non-stalling timestamp ring per pass, debug groups and labels, a fullscreen triangle. */
#ifndef VOLFX_GPU_H
#define VOLFX_GPU_H

#include "gpu/gl.h"
#include "context.h"

/* Makes the helper state; needs a current GL 4.5 context (checked, VFX_ERR_GL_UNSUPPORTED). */
vfx_result volfx_gpu_create(vfx_context *ctx, volfx_gpu **out);
/* Deletes every program, query and VAO it made. */
void volfx_gpu_destroy(vfx_context *ctx, volfx_gpu *gpu);

/* Returns a linked program from embedded shaders (paths relative to shaders/, e.g.
 * "common/fullscreen.vert"); `defines` is inserted after #version (may be NULL). Programs are
 * cached by (paths, defines). 0 on failure, with an error naming file:line. A source may
 * `#include "common/x.glsl"` (one level, expanded with #line so errors keep file:line). */
GLuint volfx_gpu_program(vfx_context *ctx, const char *vert, const char *frag, const char *defines);
/* Keeps program binaries in `dir` from now on (gpu/program_cache.h); NULL or "" switches it
 * off. Programs already linked stay as they are. */
vfx_result volfx_gpu_set_program_cache(vfx_context *ctx, const char *dir);
/* Same for a compute shader. */
GLuint volfx_gpu_compute(vfx_context *ctx, const char *comp, const char *defines);
/* Location of a uniform of a program made by volfx_gpu_program/compute, from the table read
 * when it was linked (no GL call); -1 when the program has no such active uniform. */
GLint volfx_gpu_uniform(vfx_context *ctx, GLuint prog, const char *name);

/* The timer under volfx_pass_begin/end (gpu/pass.h), which every pass calls instead: a debug
 * group (RenderDoc shows it) and a timestamp pair. Names are "effect.pass", e.g.
 * "water.potential"; the GPU ms of the pass reach the stats as "<name>.gpu_ms"
 * gpu.timer_lag_frames frames later, without stalling (passes of one name in a frame summed; the
 * stats in the order of the first runs), and for a pass opened inside others "<name>.gpu_depth",
 * how many were open. */
void volfx_gpu_timer_begin(vfx_context *ctx, const char *name);
/* Closes the innermost open timer. */
void volfx_gpu_timer_end(vfx_context *ctx);
/* Called once per frame by the plugin: collects finished timer results. */
void volfx_gpu_frame_end(vfx_context *ctx);

/* Draws one fullscreen triangle (bind a program using common/fullscreen.vert first). */
void volfx_gpu_fullscreen(vfx_context *ctx);
/* Reads a w x h float texture of comps components (format GL_RED/GL_RGBA...) into out with the
 * top row first (GL's rows are bottom first): every component (w*h*comps floats) when channel < 0,
 * else that one component (w*h floats). VFX_ERR_OUT_OF_MEMORY when the staging copy fails. */
vfx_result volfx_gpu_read_top_first(vfx_context *ctx, GLuint tex, GLenum format, uint32_t comps,
                                  int channel, uint32_t w, uint32_t h, float *out);
/* How many GL commands create resolves through the host's gl_get_proc_address (the generated
 * table's size; tests count the lookups against it). */
unsigned volfx_gl_command_count(void);
/* A labelled storage buffer of `bytes`, updatable with glNamedBufferSubData. */
GLuint volfx_gpu_storage(GLsizeiptr bytes, const char *label);
/* Labels a GL object for debuggers (no-op without KHR_debug). */
void volfx_gpu_label(GLenum kind, GLuint object, const char *label);
/* Returns a GL error as a string, or NULL when glGetError() is GL_NO_ERROR. */
const char *volfx_gpu_error_string(void);
/* VFX_OK when the render target framebuffer fb (what, w x h, just made) is complete. Reads the GL
 * error first: GL_OUT_OF_MEMORY fails with VFX_ERR_OUT_OF_MEMORY naming it (the framebuffer's
 * incompleteness is its symptom), any other incompleteness or error with VFX_ERR_GL. */
vfx_result volfx_gpu_check_target(vfx_context *ctx, GLuint fb, const char *what, uint32_t w, uint32_t h);

/* Compiles and links from source strings (used by volfx_gpu_program; tests call it directly).
 * `names` give the file name of each stage for error messages. */
GLuint volfx_gpu_link_sources(vfx_context *ctx, int stage_count, const GLenum *stages,
                            const char *const *sources, const char *const *names);
#endif
