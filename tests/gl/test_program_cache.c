/* The program binary cache (plugin/gpu/program_cache.c) through the plugin api version 2: a
 * program compiled once is written to the host's folder and loaded from it by the next context;
 * an entry that is corrupt (payload bytes flipped), truncated, made by another driver, or whose
 * checksum agrees but whose binary the driver refuses is never used: the program is rebuilt
 * from source (it links and draws), the entry is rewritten and the next context loads it again.
 * The counters are the stats gpu.program_cache_loaded / _stored / _rejected. A corrupt header
 * version or source hash is rebuilt too. test_hostile_names plants what another user of a
 * shared folder could: a symbolic link or a FIFO under the entry's name and under the name the
 * cache's temporary file once had (<entry>.<pid>.tmp): nothing is written through a link, no
 * call blocks (an alarm fails the test), each is a warning naming the path, and the program
 * still links. Skips (77) when the driver offers no binary format (Mesa with its shader cache
 * disabled). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "debug.h"
#include "gpu/program_cache.h"
#include "test_util.h"

static char g_dir[] = "/tmp/vfx_progcache_XXXXXX";
static char g_entry[4096];

static const vfx_plugin_api *api2(void)
{
    static vfx_plugin_api api;
    api.type = VFX_TYPE_PLUGIN_API;
    assert_int_equal(vfx_plugin_entry(VFX_ABI_VERSION, NULL, &api), VFX_OK);
    assert_int_equal(api.type, VFX_TYPE_PLUGIN_API);
    assert_non_null(api.set_program_cache);
    assert_non_null(api.warm_up);
    return &api;
}

/* A fresh context with the cache on, one program asked for; returns the cache's counts. */
static volfx_program_cache_counts one_program(test_log *log)
{
    const vfx_plugin_api *a = api2();
    vfx_context_desc host = {.type = VFX_TYPE_CONTEXT_DESC, .gl_get_proc_address = test_gl_proc,
                         .user = log, .log = test_vfx_log_fn};
    vfx_context *ctx;
    assert_int_equal(a->create(&host, &ctx), VFX_OK);
    assert_int_equal(a->set_program_cache(ctx, g_dir), VFX_OK);
    GLuint p = volfx_gpu_program(ctx, "common/fullscreen.vert", "beams/composite.frag", NULL);
    assert_int_not_equal(p, 0);
    GLint linked = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &linked);
    assert_true(linked);
    volfx_gpu_frame_end(ctx); /* the counts reach the frame's stats */
    const vfx_stats st = ctx->stats;
    volfx_program_cache_counts c = {0};
    for (uint32_t i = 0; i < st.count; ++i) {
        if (!strcmp(st.entries[i].name, "gpu.program_cache_loaded")) c.loaded = (uint32_t)st.entries[i].value;
        if (!strcmp(st.entries[i].name, "gpu.program_cache_stored")) c.stored = (uint32_t)st.entries[i].value;
        if (!strcmp(st.entries[i].name, "gpu.program_cache_rejected")) c.rejected = (uint32_t)st.entries[i].value;
    }
    a->destroy(ctx);
    return c;
}

static long file_size(const char *p)
{
    FILE *f = fopen(p, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fclose(f);
    return n;
}

/* Rewrites bytes [at, at + n) of the entry with `with` (NULL: flips them). */
static void patch(long at, const void *with, size_t n)
{
    FILE *f = fopen(g_entry, "r+b");
    assert_non_null(f);
    unsigned char b[64];
    assert_true(n <= sizeof b);
    fseek(f, at, SEEK_SET);
    assert_int_equal(fread(b, 1, n, f), n);
    for (size_t i = 0; i < n; ++i)
        b[i] = with ? ((const unsigned char *)with)[i] : (unsigned char)~b[i];
    fseek(f, at, SEEK_SET);
    assert_int_equal(fwrite(b, 1, n, f), n);
    fclose(f);
}

static void find_entry(void)
{
    DIR *d = opendir(g_dir);
    assert_non_null(d);
    int n = 0;
    for (struct dirent *e; (e = readdir(d));)
        if (strstr(e->d_name, ".bin")) {
            snprintf(g_entry, sizeof g_entry, "%s/%s", g_dir, e->d_name);
            ++n;
        }
    closedir(d);
    assert_int_equal(n, 1); /* one program, one file, no temporary left behind */
}

/* Each bad entry: rejected, rebuilt (the program still links), rewritten, then loaded again. */
static void expect_rebuilt(test_log *log, const char *what)
{
    volfx_program_cache_counts c = one_program(log);
    printf("%s: loaded %u stored %u rejected %u\n", what, c.loaded, c.stored, c.rejected);
    assert_int_equal(c.rejected, 1);
    assert_int_equal(c.loaded, 0);
    assert_int_equal(c.stored, 1);
    c = one_program(log);
    assert_int_equal(c.loaded, 1);
    assert_int_equal(c.rejected, 0);
}

/* The last warning, whatever came after it. */
typedef struct warn_log {
    test_log base;
    char warning[1024];
    vfx_log_id warning_id;
} warn_log;

static void warn_log_fn(void *user, vfx_log_level level, vfx_log_id id, const char *message)
{
    warn_log *w = user;
    test_vfx_log_fn(&w->base, level, id, message);
    if (level == VFX_LOG_WARN)
        snprintf(w->warning, sizeof w->warning, "%s", message), w->warning_id = id;
}

static void test_cache(void **state)
{
    (void)state;
    test_log log = {0};
    volfx_program_cache_counts c = one_program(&log); /* cold: compiled and stored */
    assert_int_equal(c.loaded, 0);
    assert_int_equal(c.stored, 1);
    find_entry();
    c = one_program(&log); /* warm: loaded, nothing written */
    assert_int_equal(c.loaded, 1);
    assert_int_equal(c.stored, 0);
    long n = file_size(g_entry);
    assert_true(n > 48 + 16);
    patch(n - 8, NULL, 8); /* payload bytes flipped: the checksum catches it */
    expect_rebuilt(&log, "payload corrupted");
    assert_int_equal(truncate(g_entry, n / 2), 0); /* truncated */
    expect_rebuilt(&log, "truncated");
    patch(16, "\x01\x02\x03\x04\x05\x06\x07\x08", 8); /* another driver's hash */
    expect_rebuilt(&log, "foreign driver");
    patch(0, "NOTVOLFX", 8); /* not ours at all */
    expect_rebuilt(&log, "bad magic");
    patch(8, "\x02\x00\x00\x00", 4); /* another header version */
    expect_rebuilt(&log, "header version");
    patch(24, NULL, 8); /* the source hash flipped: the entry's name still matches */
    expect_rebuilt(&log, "source hash");
    /* the payload garbled with its checksum made to agree: only the driver can refuse it */
    n = file_size(g_entry);
    FILE *f = fopen(g_entry, "rb");
    unsigned char *b = malloc((size_t)n);
    assert_int_equal(fread(b, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    for (long i = 48; i < n; ++i)
        b[i] = (unsigned char)(b[i] * 31u + 7u);
    uint64_t h = 14695981039346656037ull;
    for (long i = 48; i < n; ++i)
        h = (h ^ b[i]) * 1099511628211ull;
    patch(40, &h, 8);
    f = fopen(g_entry, "r+b");
    fseek(f, 48, SEEK_SET);
    fwrite(b + 48, 1, (size_t)(n - 48), f);
    fclose(f);
    free(b);
    expect_rebuilt(&log, "garbled with a matching checksum");
    assert_int_equal(log.errors, 0);
}

static const char victim_text[] = "not the cache's to write\n";

static void read_victim(const char *path, char *out, size_t cap)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    size_t n = fread(out, 1, cap - 1, f);
    out[n] = 0;
    fclose(f);
}

/* One context with `name` planted as `kind` ('l': a link to a file outside the folder, 'f': a
 * FIFO), the entry itself removed first unless `name` is the entry: stored, never loaded, and
 * the file outside unchanged. */
static void hostile(const char *name, char kind, const char *victim, bool is_entry)
{
    if (!is_entry)
        remove(g_entry);
    else
        remove(name);
    if (kind == 'l')
        assert_int_equal(symlink(victim, name), 0);
    else
        assert_int_equal(mkfifo(name, 0644), 0);
    warn_log log = {0};
    alarm(60); /* a blocking open fails the test instead of hanging it */
    const vfx_plugin_api *a = api2();
    vfx_context_desc host = {.type = VFX_TYPE_CONTEXT_DESC, .gl_get_proc_address = test_gl_proc,
                         .user = &log, .log = warn_log_fn};
    vfx_context *ctx;
    assert_int_equal(a->create(&host, &ctx), VFX_OK);
    assert_int_equal(a->set_program_cache(ctx, g_dir), VFX_OK);
    GLuint p = volfx_gpu_program(ctx, "common/fullscreen.vert", "beams/composite.frag", NULL);
    assert_int_not_equal(p, 0); /* the render goes on: the program is built from source */
    GLint linked = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &linked);
    assert_true(linked);
    a->destroy(ctx);
    alarm(0);
    char got[256];
    read_victim(victim, got, sizeof got);
    printf("%s %s: victim \"%.40s\", last warning: %s\n", kind == 'l' ? "link" : "FIFO", is_entry ? "entry" : "temp name",
           got, log.warning);
    assert_string_equal(got, victim_text); /* nothing written through the link */
    struct stat st;
    assert_int_equal(lstat(g_entry, &st), 0);
    assert_true(S_ISREG(st.st_mode)); /* the entry was written, in the folder */
    if (is_entry) {
        assert_int_equal(log.base.warnings, 1); /* the planted entry is named, and rebuilt */
        assert_non_null(strstr(log.warning, g_entry + strlen(g_dir) + 1));
        assert_int_equal(log.warning_id, VFX_LOG_ID_PROGRAM_CACHE_ENTRY);
        assert_non_null(strstr(log.warning, kind == 'l' ? "symbolic link" : "not a regular file"));
    } else {
        assert_int_equal(log.base.warnings, 0);
        remove(name);
    }
    assert_int_equal(log.base.errors, 0);
}

static void test_hostile_names(void **state)
{
    (void)state;
    char victim[] = "/tmp/vfx_progcache_victim_XXXXXX";
    int fd = mkstemp(victim);
    assert_true(fd >= 0);
    assert_int_equal(write(fd, victim_text, sizeof victim_text - 1), (ssize_t)(sizeof victim_text - 1));
    close(fd);
    if (!g_entry[0]) { /* run alone: make the entry first */
        test_log log = {0};
        one_program(&log);
        find_entry();
    }
    char old_tmp[4200];
    snprintf(old_tmp, sizeof old_tmp, "%s.%ld.tmp", g_entry, (long)getpid());
    hostile(old_tmp, 'l', victim, false);
    hostile(old_tmp, 'f', victim, false);
    hostile(g_entry, 'l', victim, true);
    hostile(g_entry, 'f', victim, true);
    find_entry(); /* one entry, no temporary left behind */
    remove(victim);
}

int main(void)
{
    rt_gl_context *gl = test_gl_or_skip();
    GLint formats = 0;
    glGetIntegerv(GL_NUM_PROGRAM_BINARY_FORMATS, &formats);
    if (formats <= 0) {
        printf("the driver offers no program binary format: skipping\n");
        rt_gl_context_destroy(gl);
        return VFX_TEST_SKIP;
    }
    if (!mkdtemp(g_dir)) {
        rt_gl_context_destroy(gl);
        return 1;
    }
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_cache), cmocka_unit_test(test_hostile_names)};
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    if (g_entry[0])
        remove(g_entry);
    rmdir(g_dir);
    rt_gl_context_destroy(gl);
    return rc;
}
