/* test_util.c — see test_util.h: the GL-free helpers (shared data, log capture); the GL ones are
 * in test_gl.c, so GL-free tests link no GL. */
#include "test_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

void test_vfx_log_fn(void *user, vfx_log_level level, vfx_log_id id, const char *message)
{
    ((test_log *)user)->last_id = id;
    test_log_fn(user, level, message);
}

static bool message_is(const char *text, vfx_log_id id, vfx_log_id want, const char *part)
{
    bool ok = id == want && (!part || strstr(text, part));
    if (!ok) {
        const char *got = vfx_log_id_name(id), *need = vfx_log_id_name(want);
        fprintf(stderr, "message id %s (%d), want %s (%d)%s%s%s: \"%s\"\n", got ? got : "?", (int)id,
                need ? need : "?", (int)want, part ? ", naming \"" : "", part ? part : "", part ? "\"" : "", text);
    }
    return ok;
}

bool test_last_error_is(const vfx_plugin_api *api, vfx_context *ctx, vfx_log_id want, const char *part)
{
    vfx_log_id id = VFX_LOG_ID_NONE;
    const char *text = api->last_error(ctx, &id);
    return message_is(text ? text : "(null)", id, want, part);
}

bool test_log_is(const test_log *log, vfx_log_id want, const char *part)
{
    return message_is(log->last, log->last_id, want, part);
}
