/* gl_context.h — a GL 4.5 core context: a GLFW window, or headless EGL (Mesa's surfaceless
 * platform, or the EGL device platform on NVIDIA), chosen at run time. */
#ifndef VFX_GL_CONTEXT_H
#define VFX_GL_CONTEXT_H

#include <stdbool.h>
#include <stdint.h>
#include "core/log.h"

typedef enum vfx_gl_mode {
    VFX_GL_AUTO = 0,     /* a window when a display is there, else headless */
    VFX_GL_WINDOW = 1,   /* GLFW window, GL 4.5 core */
    VFX_GL_HEADLESS = 2, /* EGL, no surface: render into framebuffer objects */
} vfx_gl_mode;

typedef struct vfx_gl_context_desc {
    vfx_gl_mode mode;
    uint32_t width, height; /* window size; 0 -> 1280x720 */
    const char *title;      /* window title; NULL -> "volfx" */
    bool debug;             /* GL debug output to the logger (KHR_debug) */
    bool vsync;
    vfx_logger logger;
} vfx_gl_context_desc;

typedef struct vfx_gl_context vfx_gl_context;

/* Creates the context and makes it current; checks GL >= 4.5 and the extensions volfx needs,
 * failing with VFX_ERR_GL_UNSUPPORTED and a message naming what is missing. */
vfx_result vfx_gl_context_create(const vfx_gl_context_desc *desc, vfx_gl_context **out);
/* Destroys the context (and its window). NULL allowed. */
void vfx_gl_context_destroy(vfx_gl_context *ctx);
/* True when this context has a window (false when headless). */
bool vfx_gl_context_has_window(const vfx_gl_context *ctx);
/* The GLFW window (GLFWwindow*) or NULL when headless. */
void *vfx_gl_context_window(vfx_gl_context *ctx);
/* Presents the back buffer (window) or does nothing (headless). */
void vfx_gl_context_swap(vfx_gl_context *ctx);
/* True when the user asked to close the window (always false headless). */
bool vfx_gl_context_should_close(vfx_gl_context *ctx);
/* GL_RENDERER string, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)". */
const char *vfx_gl_context_renderer(const vfx_gl_context *ctx);
/* Proc loader matching vfx_host_api.gl_get_proc_address (user = the vfx_gl_context). */
void *vfx_gl_context_get_proc(void *user, const char *name);
/* The window's framebuffer size (headless: the desc size). */
void vfx_gl_context_size(vfx_gl_context *ctx, uint32_t *width, uint32_t *height);

#endif
