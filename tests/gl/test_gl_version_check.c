/* The plugin's own "needs GL 4.5" check (volfx_gpu_create), run through the real plugin on a
 * context below 4.5 (issue 28: only the runtime's refusal to make such a context was tested, so
 * deleting the plugin's check passed). The test runner sets MESA_GL_VERSION_OVERRIDE=3.3; this
 * test makes an EGL context itself (surfaceless, no version asked for), so that the plugin, not
 * the runtime, is the one that meets GL 3.3. Not Mesa, or no such context: skip (77). */
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <volfx/volfx.h>

#include "test_util.h"

static void *proc(void *user, const char *name)
{
    (void)user;
    return (void *)eglGetProcAddress(name);
}

int main(void)
{
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    if (!client || !strstr(client, "EGL_MESA_platform_surfaceless") || !get_display) {
        fprintf(stderr, "no EGL surfaceless platform: skipping\n");
        return VFX_TEST_SKIP;
    }
    EGLDisplay d = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    EGLint major, minor;
    if (d == EGL_NO_DISPLAY || !eglInitialize(d, &major, &minor) || !eglBindAPI(EGL_OPENGL_API)) {
        fprintf(stderr, "no EGL display: skipping\n");
        return VFX_TEST_SKIP;
    }
    EGLContext c = eglCreateContext(d, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, (const EGLint[]){EGL_NONE});
    if (c == EGL_NO_CONTEXT || !eglMakeCurrent(d, EGL_NO_SURFACE, EGL_NO_SURFACE, c)) {
        fprintf(stderr, "no GL context (EGL error 0x%x): skipping\n", eglGetError());
        return VFX_TEST_SKIP;
    }
    typedef const unsigned char *(*get_string_fn)(unsigned);
    get_string_fn get_string = (get_string_fn)eglGetProcAddress("glGetString");
    const char *version = get_string ? (const char *)get_string(0x1F02 /* GL_VERSION */) : NULL;
    if (!version || version[0] >= '4') {
        fprintf(stderr, "the driver gave GL %s (MESA_GL_VERSION_OVERRIDE ignored): skipping\n", version ? version : "?");
        return VFX_TEST_SKIP;
    }
    test_log log = {0};
    vfx_context_desc host = {.type = VFX_TYPE_CONTEXT_DESC, .gl_get_proc_address = proc,
                         .user = &log, .log = test_vfx_log_fn};
    vfx_plugin_api api = {.type = VFX_TYPE_PLUGIN_API};
    if (vfx_plugin_entry(VFX_ABI_VERSION, NULL, &api) != VFX_OK) {
        fprintf(stderr, "vfx_plugin_entry failed\n");
        return 1;
    }
    vfx_context *ctx = NULL;
    vfx_result r = api.create(&host, &ctx);
    int ok = r == VFX_ERR_GL_UNSUPPORTED && ctx == NULL && strstr(log.last, "needs desktop GL 4.5") && log.last_id == VFX_LOG_ID_GL_VERSION
             && strstr(log.last, version);
    fprintf(ok ? stdout : stderr, "GL %s: create gave %d, ctx %p: %s\n", version, r, (void *)ctx, log.last);
    if (ctx)
        api.destroy(ctx);
    eglMakeCurrent(d, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(d, c);
    return ok ? 0 : 1;
}
