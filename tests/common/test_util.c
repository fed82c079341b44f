/* test_util.c — see test_util.h. */
#include "test_util.h"

#include <epoxy/egl.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

const char *test_shared_data_or_skip(const char *rel, char *buf, unsigned buflen)
{
    const char *dir = getenv("VFX_SHARED_DATA");
    if (!dir)
        dir = "../shared/data";
    snprintf(buf, buflen, "%s/%s", dir, rel);
    FILE *f = fopen(buf, "rb");
    if (!f) {
        fprintf(stderr, "shared data %s absent: skipping\n", buf);
        exit(VFX_TEST_SKIP);
    }
    fclose(f);
    return buf;
}

void test_log_fn(void *user, vfx_log_level level, const char *message)
{
    test_log *l = user;
    snprintf(l->last, sizeof l->last, "%s", message);
    if (level == VFX_LOG_ERROR)
        l->errors++;
    else if (level == VFX_LOG_WARN)
        l->warnings++;
}

void *test_gl_proc(void *user, const char *name)
{
    (void)user;
    return (void *)eglGetProcAddress(name);
}
