/* gl_context.h — a GL 4.5 core context: a GLFW window, or headless EGL (Mesa's surfaceless
 * platform, or the EGL device platform on NVIDIA), chosen at run time. */
#ifndef RT_GL_CONTEXT_H
#define RT_GL_CONTEXT_H

#include <stdbool.h>
#include <stdint.h>
#include "core/log.h"

typedef enum rt_gl_mode {
    RT_GL_AUTO = 0,     /* a window when a display is there, else headless */
    RT_GL_WINDOW = 1,   /* GLFW window, GL 4.5 core */
    RT_GL_HEADLESS = 2, /* EGL, no surface: render into framebuffer objects */
} rt_gl_mode;

typedef struct rt_gl_context_desc {
    rt_gl_mode mode;
    uint32_t width, height; /* window size; 0 -> 1280x720 */
    const char *title;      /* window title; NULL -> "volfx" */
    bool debug;             /* GL debug output to the logger (KHR_debug) */
    bool vsync;
    bool compat_profile;    /* headless: a 4.5 compatibility-profile context instead of core
                               (what OGRE's GLX code makes; tests run the plugin in both) */
    rt_logger logger;
} rt_gl_context_desc;

typedef struct rt_gl_context rt_gl_context;

/* Creates the context and makes it current; checks GL >= 4.5 and the extensions volfx needs,
 * failing with VFX_ERR_GL_UNSUPPORTED and a message naming what is missing. */
vfx_result rt_gl_context_create(const rt_gl_context_desc *desc, rt_gl_context **out);
/* Destroys the context (and its window). NULL allowed. */
void rt_gl_context_destroy(rt_gl_context *ctx);
/* True when this context has a window (false when headless). */
bool rt_gl_context_has_window(const rt_gl_context *ctx);
/* The GLFW window (GLFWwindow*) or NULL when headless. */
void *rt_gl_context_window(rt_gl_context *ctx);
/* Presents the back buffer (window) or does nothing (headless). */
void rt_gl_context_swap(rt_gl_context *ctx);
/* True when the user asked to close the window (always false headless). */
bool rt_gl_context_should_close(rt_gl_context *ctx);
/* GL_RENDERER string, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)". */
const char *rt_gl_context_renderer(const rt_gl_context *ctx);
/* Proc loader matching vfx_context_desc.gl_get_proc_address (user = the rt_gl_context). */
void *rt_gl_context_get_proc(void *user, const char *name);
/* The window's framebuffer size (headless: the desc size). */
void rt_gl_context_size(rt_gl_context *ctx, uint32_t *width, uint32_t *height);

#endif
