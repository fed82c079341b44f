/* gl_context.c — GLFW window or headless EGL context, GL 4.5 core.
 * Headless order: a real GPU on the EGL device platform (NVIDIA), else Mesa's surfaceless
 * platform (llvmpipe in CI), else any device (Mesa's software device). VFX_EGL_PLATFORM=
 * device|surfaceless forces one. With libepoxy we include <epoxy/egl.h> (not <EGL/egl.h>:
 * their headers clash) and call the EXT entry point. */
#include "gfx/gl_context.h"

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct rt_gl_context {
    rt_gl_context_desc desc;
    GLFWwindow *window;
    EGLDisplay egl_display;
    EGLContext egl_context;
    uint32_t width, height;
    char renderer[256];
    char platform[32];
};

static void APIENTRY debug_cb(GLenum source, GLenum type, GLuint id, GLenum severity,
                              GLsizei length, const GLchar *message, const void *user)
{
    (void)source; (void)length;
    const rt_gl_context *c = user;
    if (severity == GL_DEBUG_SEVERITY_NOTIFICATION)
        return;
    vfx_log_level lvl = severity == GL_DEBUG_SEVERITY_HIGH || type == GL_DEBUG_TYPE_ERROR
                            ? VFX_LOG_ERROR : VFX_LOG_WARN;
    rt_logf(&c->desc.logger, lvl, "GL debug (id %u): %s", id, message);
}

static bool egl_has(const char *exts, const char *name)
{
    if (!exts)
        return false;
    size_t n = strlen(name);
    for (const char *p = exts; (p = strstr(p, name)); p += n)
        if ((p == exts || p[-1] == ' ') && (p[n] == ' ' || p[n] == 0))
            return true;
    return false;
}

static EGLDisplay egl_open_device(bool want_hardware)
{
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!egl_has(client, "EGL_EXT_platform_device") || !egl_has(client, "EGL_EXT_device_enumeration"))
        return EGL_NO_DISPLAY;
    EGLDeviceEXT devs[16];
    EGLint n = 0;
    if (!eglQueryDevicesEXT(16, devs, &n))
        return EGL_NO_DISPLAY;
    for (EGLint i = 0; i < n; ++i) {
        const char *dext = eglQueryDeviceStringEXT(devs[i], EGL_EXTENSIONS);
        bool software = egl_has(dext, "EGL_MESA_device_software");
        if (want_hardware == software)
            continue;
        EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devs[i], NULL);
        if (d != EGL_NO_DISPLAY)
            return d;
    }
    return EGL_NO_DISPLAY;
}

typedef struct egl_try {
    const char *name;
    EGLDisplay d;
} egl_try;

static vfx_result make_headless(rt_gl_context *c)
{
    const char *force = getenv("VFX_EGL_PLATFORM");
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!client) {
        rt_logf(&c->desc.logger, VFX_LOG_ERROR,
                 "headless GL: EGL client extensions unavailable (no EGL 1.5 / libglvnd?)");
        return VFX_ERR_GL_UNSUPPORTED;
    }
    egl_try tries[3];
    int nt = 0;
    bool allow_device = !force || strcmp(force, "device") == 0;
    bool allow_surfaceless = !force || strcmp(force, "surfaceless") == 0;
    if (allow_device)
        tries[nt++] = (egl_try){"device", egl_open_device(true)};
    if (allow_surfaceless && egl_has(client, "EGL_MESA_platform_surfaceless"))
        tries[nt++] = (egl_try){"surfaceless",
            eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL)};
    if (allow_device)
        tries[nt++] = (egl_try){"device-software", egl_open_device(false)};
    const EGLint attrs[] = {
        EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5, EGL_CONTEXT_OPENGL_PROFILE_MASK,
        c->desc.compat_profile ? EGL_CONTEXT_OPENGL_COMPATIBILITY_PROFILE_BIT : EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
        EGL_NONE};
    /* Leak checking only (VFX_EGL_KEEP_DRIVER): eglTerminate unloads Mesa's driver, after
     * which LeakSanitizer cannot name the driver's own allocations to suppress them. */
    const bool keep_driver = getenv("VFX_EGL_KEEP_DRIVER") != NULL;
    for (int i = 0; i < nt; ++i) {
        EGLDisplay d = tries[i].d;
        EGLint major, minor;
        if (d == EGL_NO_DISPLAY || !eglInitialize(d, &major, &minor))
            continue;
        const char *dext = eglQueryString(d, EGL_EXTENSIONS);
        if (!egl_has(dext, "EGL_KHR_no_config_context") || !egl_has(dext, "EGL_KHR_surfaceless_context")
            || !eglBindAPI(EGL_OPENGL_API)) {
            rt_logf(&c->desc.logger, VFX_LOG_WARN,
                     "headless GL: EGL %s display lacks no-config/surfaceless contexts", tries[i].name);
            if (!keep_driver)
                eglTerminate(d);
            continue;
        }
        EGLint dbg[16];
        memcpy(dbg, attrs, sizeof attrs);
        if (c->desc.debug) {
            int k = (int)(sizeof attrs / sizeof attrs[0]) - 1;
            dbg[k++] = EGL_CONTEXT_OPENGL_DEBUG;
            dbg[k++] = EGL_TRUE;
            dbg[k] = EGL_NONE;
        }
        EGLContext ctx = eglCreateContext(d, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, dbg);
        if (ctx == EGL_NO_CONTEXT) {
            rt_logf(&c->desc.logger, VFX_LOG_WARN,
                     "headless GL: EGL %s display gives no GL 4.5 core context (EGL error 0x%x)",
                     tries[i].name, eglGetError());
            if (!keep_driver)
                eglTerminate(d);
            continue;
        }
        if (!eglMakeCurrent(d, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
            eglDestroyContext(d, ctx);
            if (!keep_driver)
                eglTerminate(d);
            continue;
        }
        c->egl_display = d;
        c->egl_context = ctx;
        snprintf(c->platform, sizeof c->platform, "egl-%s", tries[i].name);
        return VFX_OK;
    }
    rt_logf(&c->desc.logger, VFX_LOG_ERROR,
             "headless GL: no EGL platform gave a GL 4.5 core context (tried %d%s%s)", nt,
             force ? ", VFX_EGL_PLATFORM=" : "", force ? force : "");
    return VFX_ERR_GL_UNSUPPORTED;
}

static vfx_result make_window(rt_gl_context *c)
{
    if (!glfwInit()) {
        rt_logf(&c->desc.logger, VFX_LOG_ERROR, "window GL: glfwInit failed (no display?)");
        return VFX_ERR_GL_UNSUPPORTED;
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_OPENGL_DEBUG_CONTEXT, c->desc.debug ? GLFW_TRUE : GLFW_FALSE);
    c->window = glfwCreateWindow((int)c->width, (int)c->height,
                                 c->desc.title ? c->desc.title : "volfx", NULL, NULL);
    if (!c->window) {
        const char *msg = NULL;
        glfwGetError(&msg);
        rt_logf(&c->desc.logger, VFX_LOG_ERROR, "window GL: no GL 4.5 core window: %s",
                 msg ? msg : "unknown GLFW error");
        glfwTerminate();
        return VFX_ERR_GL_UNSUPPORTED;
    }
    glfwMakeContextCurrent(c->window);
    glfwSwapInterval(c->desc.vsync ? 1 : 0);
    snprintf(c->platform, sizeof c->platform, "glfw");
    return VFX_OK;
}

/* Checks what every effect relies on; names what is missing. */
static vfx_result check_caps(rt_gl_context *c)
{
    int ver = epoxy_gl_version();
    if (ver < 45) {
        rt_logf(&c->desc.logger, VFX_LOG_ERROR,
                 "GL 4.5 core is required, the driver gives %d.%d (%s)", ver / 10, ver % 10,
                 (const char *)glGetString(GL_VERSION));
        return VFX_ERR_GL_UNSUPPORTED;
    }
    GLint ssbo = 0, frag_ssbo = 0;
    glGetIntegerv(GL_MAX_SHADER_STORAGE_BUFFER_BINDINGS, &ssbo);
    glGetIntegerv(GL_MAX_FRAGMENT_SHADER_STORAGE_BLOCKS, &frag_ssbo);
    if (ssbo < 8 || frag_ssbo < 4) {
        rt_logf(&c->desc.logger, VFX_LOG_ERROR,
                 "GL: need >= 8 shader storage bindings and >= 4 in fragment shaders, have %d/%d",
                 ssbo, frag_ssbo);
        return VFX_ERR_GL_UNSUPPORTED;
    }
    return VFX_OK;
}

vfx_result rt_gl_context_create(const rt_gl_context_desc *desc, rt_gl_context **out)
{
    if (!out)
        return VFX_ERR_INVALID_ARGUMENT;
    *out = NULL;
    rt_gl_context *c = calloc(1, sizeof *c);
    if (!c)
        return VFX_ERR_OUT_OF_MEMORY;
    if (desc)
        c->desc = *desc;
    c->width = c->desc.width ? c->desc.width : 1280;
    c->height = c->desc.height ? c->desc.height : 720;
    rt_gl_mode mode = c->desc.mode;
    if (mode == RT_GL_AUTO) {
        const char *x = getenv("DISPLAY"), *wl = getenv("WAYLAND_DISPLAY");
        mode = ((x && *x) || (wl && *wl)) ? RT_GL_WINDOW : RT_GL_HEADLESS;
    }
    vfx_result r = mode == RT_GL_WINDOW ? make_window(c) : make_headless(c);
    if (r == VFX_OK)
        r = check_caps(c);
    if (r != VFX_OK) {
        rt_gl_context_destroy(c);
        return r;
    }
    snprintf(c->renderer, sizeof c->renderer, "%s", (const char *)glGetString(GL_RENDERER));
    if (c->desc.debug && epoxy_has_gl_extension("GL_KHR_debug")) {
        glEnable(GL_DEBUG_OUTPUT);
        glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
        glDebugMessageCallback(debug_cb, c);
    }
    rt_logf(&c->desc.logger, VFX_LOG_INFO, "GL context: %s, %s, via %s", c->renderer,
             (const char *)glGetString(GL_VERSION), c->platform);
    *out = c;
    return VFX_OK;
}

void rt_gl_context_destroy(rt_gl_context *c)
{
    if (!c)
        return;
    if (c->window) {
        glfwDestroyWindow(c->window);
        glfwTerminate();
    }
    if (c->egl_display != EGL_NO_DISPLAY && c->egl_display) {
        eglMakeCurrent(c->egl_display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        if (c->egl_context)
            eglDestroyContext(c->egl_display, c->egl_context);
        /* Leak checking only: eglTerminate unloads Mesa's driver, after which LeakSanitizer
         * cannot name the driver's own leaks to suppress them (tests/lsan-gl.supp). */
        if (!getenv("VFX_EGL_KEEP_DRIVER"))
            eglTerminate(c->egl_display);
    }
    free(c);
}

bool rt_gl_context_has_window(const rt_gl_context *c) { return c && c->window; }
void *rt_gl_context_window(rt_gl_context *c) { return c ? c->window : NULL; }
const char *rt_gl_context_renderer(const rt_gl_context *c) { return c ? c->renderer : ""; }

void rt_gl_context_swap(rt_gl_context *c)
{
    if (c && c->window) {
        glfwSwapBuffers(c->window);
        glfwPollEvents();
    }
}

bool rt_gl_context_should_close(rt_gl_context *c)
{
    return c && c->window && glfwWindowShouldClose(c->window);
}

void *rt_gl_context_get_proc(void *user, const char *name)
{
    rt_gl_context *c = user;
    if (c && c->window)
        return (void *)glfwGetProcAddress(name);
    return (void *)eglGetProcAddress(name);
}

void rt_gl_context_size(rt_gl_context *c, uint32_t *w, uint32_t *h)
{
    if (c && c->window) {
        int fw, fh;
        glfwGetFramebufferSize(c->window, &fw, &fh);
        c->width = (uint32_t)(fw > 0 ? fw : 1);
        c->height = (uint32_t)(fh > 0 ? fh : 1);
    }
    if (w) *w = c ? c->width : 0;
    if (h) *h = c ? c->height : 0;
}
