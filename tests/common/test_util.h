/* test_util.h — shared helpers for tests: a headless GL context or a clean skip (exit 77).
 * test_util.c (GL-free, test_util_dep) and test_gl.c (test_gl_dep, links the GL runtime). */
#ifndef TEST_UTIL_H
#define TEST_UTIL_H

#include "gfx/gl_context.h"

#define VFX_TEST_SKIP 77

/* Makes a headless GL 4.5 context, or exits the process with 77 (skip) when none can be made. */
rt_gl_context *test_gl_or_skip(void);
/* Path of the shared test data file `rel` (under VFX_SHARED_DATA), or exits 77 when absent. */
const char *test_shared_data_or_skip(const char *rel, char *buf, unsigned buflen);
/* vfx_context_desc.gl_get_proc_address for the headless context of test_gl_or_skip (eglGetProcAddress;
 * user unused). */
void *test_gl_proc(void *user, const char *name);
/* A logger for tests that records the last message, so tests can assert on error text. */
typedef struct test_log {
    char last[1024];
    int errors, warnings;
    vfx_log_id last_id; /* the id of last (test_vfx_log_fn) */
} test_log;
void test_log_fn(void *user, vfx_log_level level, const char *message);
/* The same as the plugin's log callback (vfx_context_desc.log): also keeps the id in last_id. */
void test_vfx_log_fn(void *user, vfx_log_level level, vfx_log_id id, const char *message);
/* True when the plugin's last error on ctx has the id `want` and, unless `part` is NULL, contains
 * `part` (text checks only where the text is the point: the field or value it names); prints
 * what it got otherwise. */
bool test_last_error_is(const vfx_plugin_api *api, vfx_context *ctx, vfx_log_id want, const char *part);
/* The same for the last message a test_log recorded through test_vfx_log_fn. */
bool test_log_is(const test_log *log, vfx_log_id want, const char *part);

#endif
