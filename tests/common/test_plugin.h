/* test_plugin.h — a libvolfx context for the tests that drive the plugin directly on the headless
 * GL context of test_gl_or_skip. Header-only: the GL tests that include test_util.h alone link no
 * plugin. The group runner is there where <cmocka.h> is included before this header. */
#ifndef VFX_TEST_PLUGIN_H
#define VFX_TEST_PLUGIN_H

#include "test_util.h"

/* A plugin context on the current GL context logging through test_vfx_log_fn; NULL when the entry
 * or create fails. *api_out is set on success and lives until the process ends. */
static inline vfx_context *test_plugin_open(const vfx_plugin_api **api_out)
{
    static test_log log;
    static vfx_context_desc host;
    static vfx_plugin_api api;
    host = (vfx_context_desc){.type = VFX_TYPE_CONTEXT_DESC, .gl_get_proc_address = test_gl_proc, .user = &log,
                              .log = test_vfx_log_fn};
    api.type = VFX_TYPE_PLUGIN_API;
    vfx_context *ctx = NULL;
    if (vfx_plugin_entry(VFX_ABI_VERSION, NULL, &api) != VFX_OK || api.create(&host, &ctx) != VFX_OK)
        return NULL;
    *api_out = &api;
    return ctx;
}

#ifdef cmocka_run_group_tests
/* Runs a cmocka group with *ctx and *api open (test_plugin_open) on a headless GL context, exiting
 * 77 when there is none; destroys both after. Returns cmocka's result, or 1 when the plugin
 * could not be opened. */
static inline int test_plugin_run_group_(const char *name, const struct CMUnitTest *tests, size_t n,
                                         vfx_context **ctx, const vfx_plugin_api **api)
{
    rt_gl_context *gl = test_gl_or_skip();
    *ctx = test_plugin_open(api);
    int rc = *ctx ? _cmocka_run_group_tests(name, tests, n, NULL, NULL) : 1;
    if (*ctx)
        (*api)->destroy(*ctx);
    rt_gl_context_destroy(gl);
    return rc;
}
#define test_plugin_run_group(tests, ctx, api) \
    test_plugin_run_group_(#tests, tests, sizeof(tests) / sizeof((tests)[0]), ctx, api)
#endif

#endif
