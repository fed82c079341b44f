/* test_gl.c — see test_util.h: the headless GL context helpers. */
#include "test_util.h"

#include <epoxy/egl.h>

#include <stdio.h>
#include <stdlib.h>

rt_gl_context *test_gl_or_skip(void)
{
    rt_gl_context *gl = NULL;
    rt_gl_context_desc d = {.mode = RT_GL_HEADLESS, .width = 64, .height = 64};
    if (rt_gl_context_create(&d, &gl) != VFX_OK) {
        fprintf(stderr, "no headless GL 4.5 context: skipping\n");
        exit(VFX_TEST_SKIP);
    }
    return gl;
}

void *test_gl_proc(void *user, const char *name)
{
    (void)user;
    return (void *)eglGetProcAddress(name);
}
