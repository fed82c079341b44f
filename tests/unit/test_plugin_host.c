#define _POSIX_C_SOURCE 200809L /* mkdtemp, mkfifo */
/* Plugin loading: the real plugin loads; a wrong ABI version, a missing entry symbol, a
 * table of another version and a missing file are refused with messages naming what. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <sys/stat.h>

#include "host/plugin_host.h"
#include "test_util.h"

static const char *g_plugin, *g_nosym, *g_badver;

static vfx_context_desc host_with(test_log *log)
{
    return (vfx_context_desc){.type = VFX_TYPE_CONTEXT_DESC, .gl_get_proc_address = test_gl_proc,
                          .user = log, .log = test_vfx_log_fn};
}

static void test_good_plugin(void **state)
{
    (void)state;
    test_log log = {0};
    vfx_context_desc host = host_with(&log);
    rt_logger lg = {test_log_fn, &log};
    rt_plugin_host *h = NULL;
    assert_int_equal(rt_plugin_host_load(g_plugin, &host, &lg, &h), VFX_OK);
    const vfx_plugin_api *api = rt_plugin_host_api(h);
    assert_int_equal(api->type, VFX_TYPE_PLUGIN_API);
    assert_non_null(api->get_lights);
    assert_non_null(api->resolve_defaults);
    assert_string_equal(api->name, "volfx");
    assert_non_null(api->create);
    assert_non_null(api->render);
    rt_plugin_host_unload(h);
    /* the static entry is the same code */
    assert_int_equal(rt_plugin_host_load_static(vfx_plugin_entry, &host, &lg, &h), VFX_OK);
    rt_plugin_host_unload(h);
}

static void test_wrong_abi_refused(void **state)
{
    (void)state;
    test_log log = {0};
    vfx_context_desc host = host_with(&log);
    rt_logger lg = {test_log_fn, &log};
    rt_plugin_host *h = NULL;
    assert_int_equal(rt_plugin_host_load_as(g_plugin, VFX_ABI_VERSION + 1, &host, &lg, &h), VFX_ERR_ABI);
    assert_null(h);
    /* the plugin's own message names both versions */
    char want[96];
    snprintf(want, sizeof want, "host ABI version %u, plugin ABI version %u", VFX_ABI_VERSION + 1, VFX_ABI_VERSION);
    assert_true(log.errors >= 2); /* plugin's message + host's */
    assert_non_null(strstr(log.last, "host ABI 3")); /* the host's own line: VFX_ABI_VERSION + 1 */
    vfx_plugin_api api = {.type = VFX_TYPE_PLUGIN_API};
    test_log log2 = {0};
    vfx_context_desc host2 = host_with(&log2);
    assert_int_equal(vfx_plugin_entry(VFX_ABI_VERSION + 1, &host2, &api), VFX_ERR_ABI);
    assert_non_null(strstr(log2.last, want));
    assert_int_equal(log2.last_id, VFX_LOG_ID_ABI_VERSION);
    assert_string_equal(vfx_log_id_name(log2.last_id), "ABI_VERSION"); /* the header-only name */
    assert_null(vfx_log_id_name((vfx_log_id)100000)); /* an id of a newer plugin: no name */
    /* a host table of another type is refused too, and left as it was */
    vfx_plugin_api other = {.type = VFX_TYPE_STATS};
    assert_int_equal(vfx_plugin_entry(VFX_ABI_VERSION, &host2, &other), VFX_ERR_ABI);
    assert_int_equal(log2.last_id, VFX_LOG_ID_STRUCT_TYPE);
    assert_null(other.create);
}

/* ABI 1's host description as an ABI 1 host lays it out (size, version, user, loader, a logger
 * without ids, ...): what such a host passes to vfx_plugin_entry. */
typedef struct abi1_host {
    uint32_t size, version;
    void *user;
    void *(*gl_get_proc_address)(void *user, const char *name);
    void (*log)(void *user, vfx_log_level level, const char *message);
    void *rest[9]; /* alloc, free and the data callbacks */
} abi1_host;

typedef struct abi1_api { /* ABI 1's vfx_plugin_api head: size, version, then pointers */
    uint32_t size, version;
    void *rest[16];
} abi1_api;

static void test_abi1_host_refused(void **state)
{
    (void)state;
    test_log log = {0};
    abi1_host old = {.size = sizeof old, .version = 1, .user = &log, .gl_get_proc_address = test_gl_proc,
                     .log = test_log_fn};
    abi1_api out = {.size = sizeof out, .version = 1};
    abi1_api before = out;
    /* the call an ABI 1 host makes, through the entry's type as it finds it with dlsym */
    vfx_plugin_entry_fn entry = vfx_plugin_entry;
    assert_int_equal(entry(1, (const vfx_context_desc *)(const void *)&old, (vfx_plugin_api *)(void *)&out),
                     VFX_ERR_ABI);
    assert_int_equal(log.errors, 1);
    assert_non_null(strstr(log.last, "host ABI version 1, plugin ABI version 2"));
    assert_memory_equal(&out, &before, sizeof out); /* nothing written into the old table */
    /* an ABI 1 header with a size too small for its logger: no call through it */
    test_log log2 = {0};
    abi1_host tiny = {.size = 8, .version = 1, .user = &log2, .log = test_log_fn};
    assert_int_equal(entry(1, (const vfx_context_desc *)(const void *)&tiny, NULL), VFX_ERR_ABI);
    assert_int_equal(log2.errors, 0);
    assert_int_equal(entry(1, NULL, NULL), VFX_ERR_ABI);
}

static void test_missing_symbol(void **state)
{
    (void)state;
    test_log log = {0};
    vfx_context_desc host = host_with(&log);
    rt_logger lg = {test_log_fn, &log};
    rt_plugin_host *h = NULL;
    assert_int_equal(rt_plugin_host_load(g_nosym, &host, &lg, &h), VFX_ERR_NOT_FOUND);
    assert_null(h);
    assert_non_null(strstr(log.last, "vfx_plugin_entry"));
}

static void test_table_version_refused(void **state)
{
    (void)state;
    test_log log = {0};
    vfx_context_desc host = host_with(&log);
    rt_logger lg = {test_log_fn, &log};
    rt_plugin_host *h = NULL;
    assert_int_equal(rt_plugin_host_load(g_badver, &host, &lg, &h), VFX_ERR_ABI);
    assert_non_null(strstr(log.last, "function table of type 99"));
}

static void test_missing_file(void **state)
{
    (void)state;
    test_log log = {0};
    vfx_context_desc host = host_with(&log);
    rt_logger lg = {test_log_fn, &log};
    rt_plugin_host *h = NULL;
    assert_int_equal(rt_plugin_host_load("/nonexistent/libvolfx.so", &host, &lg, &h), VFX_ERR_IO);
    assert_non_null(strstr(log.last, "/nonexistent/libvolfx.so"));
}

/* issue 18: a plugin path that is a FIFO blocked forever in dlopen's open(); a directory gave
 * only the loader's "cannot read file data". Both refused by stat first, naming what they are. */
static void test_special_file_plugin(void **state)
{
    (void)state;
    test_log log = {0};
    vfx_context_desc host = host_with(&log);
    rt_logger lg = {test_log_fn, &log};
    rt_plugin_host *h = NULL;
    char dir[] = "/tmp/vfx_plug_XXXXXX", fifo[64];
    assert_non_null(mkdtemp(dir));
    snprintf(fifo, sizeof fifo, "%s/libvolfx.so.1", dir);
    assert_int_equal(mkfifo(fifo, 0600), 0);
    alarm(30);
    assert_int_equal(rt_plugin_host_load(fifo, &host, &lg, &h), VFX_ERR_IO);
    assert_non_null(strstr(log.last, "is a FIFO"));
    alarm(0);
    assert_int_equal(rt_plugin_host_load(dir, &host, &lg, &h), VFX_ERR_IO);
    assert_non_null(strstr(log.last, "is a directory"));
    unlink(fifo);
    rmdir(dir);
    /* issue 28: "" is named as an empty path (dlopen("") opened the game itself, and the error
     * was its missing vfx_plugin_entry symbol) */
    log.last[0] = 0;
    assert_int_equal(rt_plugin_host_load("", &host, &lg, &h), VFX_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(log.last, "plugin path is empty"));
    assert_null(strstr(log.last, "symbol"));
    assert_null(h);
}

static void test_create_refuses_bad_host(void **state)
{
    (void)state;
    vfx_plugin_api api = {.type = VFX_TYPE_PLUGIN_API};
    assert_int_equal(vfx_plugin_entry(VFX_ABI_VERSION, NULL, &api), VFX_OK);
    vfx_context *ctx = NULL;
    test_log log = {0};
    vfx_context_desc host = host_with(&log);
    host.type = VFX_TYPE_FRAME_VIEW; /* a struct of another type */
    assert_int_equal(api.create(&host, &ctx), VFX_ERR_ABI);
    assert_null(ctx);
    assert_int_equal(api.create(NULL, &ctx), VFX_ERR_ABI);
}

/* vfx_plugin_info chained into the table (docs/abi.md "Extensions an older plugin would
 * misread"): the entry fills the minor version and the types it reads, 13 (vfx_frame_depth) among
 * them and none past the last it knows; the rest of the chain is left to the host. */
static void test_plugin_info(void **state)
{
    (void)state;
    typedef struct other { vfx_struct_type type; void *next; } other;
    vfx_plugin_info info = {.type = VFX_TYPE_PLUGIN_INFO};
    other o = {(vfx_struct_type)0x7000beef, &info};
    vfx_plugin_api api = {.type = VFX_TYPE_PLUGIN_API, .next = &o};
    assert_int_equal(vfx_plugin_entry(VFX_ABI_VERSION, NULL, &api), VFX_OK);
    assert_ptr_equal(api.next, &o);
    assert_ptr_equal(o.next, &info);
    assert_null(info.next);
    assert_int_equal(info.abi_minor, VFX_ABI_MINOR);
    assert_int_equal(info.type_count, 64);
    assert_true(info.known_types & (1ull << VFX_TYPE_FRAME_DEPTH));
    assert_true(info.known_types & (1ull << VFX_TYPE_GL_STATE_DESC));
    assert_false(info.known_types & (1ull << VFX_TYPE_NONE));
    assert_true(info.known_types & (1ull << VFX_TYPE_WATER_FOAM));
    assert_false(info.known_types & (1ull << (VFX_TYPE_WATER_FOAM + 1)));
    /* without it the table is filled as before */
    vfx_plugin_api plain = {.type = VFX_TYPE_PLUGIN_API};
    assert_int_equal(vfx_plugin_entry(VFX_ABI_VERSION, NULL, &plain), VFX_OK);
    assert_null(plain.next);
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: test_plugin_host PLUGIN NOSYM BADVER\n");
        return 2;
    }
    g_plugin = argv[1], g_nosym = argv[2], g_badver = argv[3];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_good_plugin),
        cmocka_unit_test(test_plugin_info),
        cmocka_unit_test(test_wrong_abi_refused),
        cmocka_unit_test(test_abi1_host_refused),
        cmocka_unit_test(test_missing_symbol),
        cmocka_unit_test(test_table_version_refused),
        cmocka_unit_test(test_missing_file),
        cmocka_unit_test(test_special_file_plugin),
        cmocka_unit_test(test_create_refuses_bad_host),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
