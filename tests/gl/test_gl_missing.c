/* Missing GL feature: with Mesa told to offer only GL 3.3 (MESA_GL_VERSION_OVERRIDE, set by the
 * test runner), making the context fails with VFX_ERR_GL_UNSUPPORTED and says what is missing. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gfx/gl_context.h"
#include "test_util.h"

int main(void)
{
    test_log log = {0};
    rt_gl_context *gl = NULL;
    rt_gl_context_desc d = {.mode = RT_GL_HEADLESS, .logger = {test_log_fn, &log}};
    vfx_result r = rt_gl_context_create(&d, &gl);
    const char *renderer = getenv("MESA_GL_VERSION_OVERRIDE");
    if (r == VFX_OK) {
        /* not Mesa (the override is ignored): nothing to check here */
        fprintf(stderr, "driver ignored MESA_GL_VERSION_OVERRIDE=%s: skipping\n", renderer ? renderer : "");
        rt_gl_context_destroy(gl);
        return 77;
    }
    if (r != VFX_ERR_GL_UNSUPPORTED || gl != NULL || !strstr(log.last, "4.5")) {
        fprintf(stderr, "expected GL_UNSUPPORTED naming 4.5, got %d: %s\n", r, log.last);
        return 1;
    }
    printf("refused as expected: %s\n", log.last);
    return 0;
}
