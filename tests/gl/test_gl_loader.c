/* The plugin's GL loader: every GL command it calls comes through the host's
 * gl_get_proc_address. A counting loader sees each of the generated table's commands asked for
 * exactly once, at create, and nothing after (three frames of water, beams and a volume ask for
 * none);
 * a loader that lacks one command gets create refused with that command's name; a host api
 * without a loader is refused at create. The shared library's dynamic symbols are checked by
 * tests/unit/check_exports.sh (no GL, EGL or libepoxy symbol or library). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <epoxy/egl.h>
#include <epoxy/gl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "debug.h"
#include "test_util.h"

typedef struct counting {
    test_log log;
    unsigned lookups, distinct;
    char names[256][48];
    const char *hide; /* answer NULL for this one */
} counting;

static void *count_proc(void *user, const char *name)
{
    counting *c = user;
    c->lookups++;
    bool seen = false;
    for (unsigned i = 0; i < c->distinct; ++i)
        seen |= strcmp(c->names[i], name) == 0;
    if (!seen && c->distinct < 256)
        snprintf(c->names[c->distinct++], sizeof c->names[0], "%s", name);
    if (c->hide && strcmp(c->hide, name) == 0)
        return NULL;
    return (void *)eglGetProcAddress(name);
}

static void counting_log(void *user, vfx_log_level level, vfx_log_id id, const char *message)
{
    test_vfx_log_fn(&((counting *)user)->log, level, id, message);
}

static const vfx_plugin_api *plugin_api(void)
{
    static vfx_plugin_api api; /* test-local table */
    api.type = VFX_TYPE_PLUGIN_API;
    assert_int_equal(vfx_plugin_entry(VFX_ABI_VERSION, NULL, &api), VFX_OK);
    return &api;
}

/* What the lookups are for: a block of water, a beam and a tet cube drawn for three frames. */
static float px[512], py[512], pz[512];
static const vfx_beam beam = {.type = VFX_TYPE_BEAM, .head = {-2, 1.2f, 0}, .dir = {1, 0, 0}, .length = 4, .radius = 1, .a = 0.5f,
                              .b = 0.5f, .eps = 0.05f};
static float points[24], scalar[8];
static const uint32_t tets[20] = {0, 1, 2, 4, 1, 2, 3, 7, 1, 4, 5, 7, 2, 4, 6, 7, 1, 2, 4, 7};
static uint32_t one(void *user) { (void)user; return 1; }
static vfx_result chunk(void *user, uint32_t i, vfx_particle_view *v)
{
    (void)user, (void)i;
    v->count = 512, v->pos[0] = px, v->pos[1] = py, v->pos[2] = pz;
    return VFX_OK;
}
static vfx_result beams(void *user, vfx_beams_view *v) { (void)user; v->count = 1, v->beams = &beam; return VFX_OK; }
static vfx_result volume(void *user, uint32_t i, vfx_volume_view *v)
{
    (void)user, (void)i;
    v->point_count = 8, v->tet_count = 5, v->points = points, v->tets = tets, v->scalar = scalar;
    v->revision = 1;
    return VFX_OK;
}

static void test_counted_once_at_create(void **state)
{
    (void)state;
    static counting c;
    memset(&c, 0, sizeof c);
    for (int i = 0; i < 512; ++i)
        px[i] = -0.6f + 0.15f * (i % 8), py[i] = -0.6f + 0.15f * (i / 8 % 8), pz[i] = -0.6f + 0.15f * (i / 64);
    for (int i = 0; i < 8; ++i) {
        points[3 * i] = 1.0f + 0.8f * (i & 1), points[3 * i + 1] = -0.4f + 0.8f * (i >> 1 & 1);
        points[3 * i + 2] = -0.4f + 0.8f * (i >> 2 & 1), scalar[i] = (float)(i & 1);
    }
    const vfx_plugin_api *api = plugin_api();
    vfx_context_desc host = {.type = VFX_TYPE_CONTEXT_DESC, .user = &c,
                         .gl_get_proc_address = count_proc, .log = counting_log, .particle_chunk_count = one,
                         .particle_chunk = chunk, .beams = beams, .volume_count = one, .volume = volume};
    vfx_context *ctx;
    assert_int_equal(api->create(&host, &ctx), VFX_OK);
    /* one lookup per command of the generated table, each name once, every one a GL name */
    assert_int_equal(c.lookups, volfx_gl_command_count());
    assert_int_equal(c.distinct, c.lookups);
    for (unsigned i = 0; i < c.distinct; ++i)
        assert_true(strncmp(c.names[i], "gl", 2) == 0);
    enum { W = 64, H = 48 };
    GLuint col, dep, out, fbo;
    glCreateTextures(GL_TEXTURE_2D, 1, &col);
    glTextureStorage2D(col, 1, GL_RGBA8, W, H);
    glCreateTextures(GL_TEXTURE_2D, 1, &dep);
    glTextureStorage2D(dep, 1, GL_DEPTH_COMPONENT32F, W, H);
    glClearTexImage(dep, 0, GL_DEPTH_COMPONENT, GL_FLOAT, (const float[1]){1});
    glCreateTextures(GL_TEXTURE_2D, 1, &out);
    glTextureStorage2D(out, 1, GL_RGBA8, W, H);
    glCreateFramebuffers(1, &fbo);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, out, 0);
    float f = 1.732f, n = 0.1f, fa = 50.f;
    vfx_frame_view fv = {.type = VFX_TYPE_FRAME_VIEW, .framebuffer = fbo,
                         .color_texture = col, .depth_texture = dep, .width = W, .height = H,
                         .view = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -4, 1},
                         .proj = {f * H / W, 0, 0, 0, 0, f, 0, 0, 0, 0, -(fa + n) / (fa - n), -1, 0, 0, -2 * fa * n / (fa - n), 0},
                         .eye = {0, 0, 4}, .near_plane = n, .far_plane = fa, .fov_y = 1.0472f};
    for (int frame = 0; frame < 3; ++frame) {
        assert_int_equal(api->update(ctx, frame / 60.0, 1 / 60.f), VFX_OK);
        assert_int_equal(api->render(ctx, &fv), VFX_OK);
    }
    static float raw[W * H];
    int drawn = 0;
    for (int k = 0; k < VFX_EFFECT_COUNT; ++k) /* every built effect drew: its code ran */
        if (api->read_raw(ctx, (vfx_effect_kind)k, raw, W * H) == VFX_OK) {
            int lit = 0;
            for (int i = 0; i < W * H; ++i)
                lit += raw[i] > 0;
            drawn += lit > 0;
        }
    assert_int_equal(drawn, __builtin_popcount(api->effects_built));
    assert_int_equal(c.lookups, volfx_gl_command_count()); /* nothing resolved lazily */
    api->destroy(ctx);
    glDeleteFramebuffers(1, &fbo);
    GLuint t[3] = {col, dep, out};
    glDeleteTextures(3, t);
}

static void test_missing_command_named(void **state)
{
    (void)state;
    static const char *const hide[] = {"glDispatchCompute", "glCreateTextures", "glQueryCounter"};
    for (size_t i = 0; i < sizeof hide / sizeof hide[0]; ++i) {
        static counting c;
        memset(&c, 0, sizeof c);
        c.hide = hide[i];
        const vfx_plugin_api *api = plugin_api();
        vfx_context_desc host = {.type = VFX_TYPE_CONTEXT_DESC, .user = &c,
                             .gl_get_proc_address = count_proc, .log = counting_log};
        vfx_context *ctx = (vfx_context *)&c;
        assert_int_equal(api->create(&host, &ctx), VFX_ERR_GL_UNSUPPORTED);
        assert_null(ctx);
        assert_true(test_log_is(&c.log, VFX_LOG_ID_GL_COMMAND_MISSING, hide[i]));
    }
}

static void test_no_loader_refused(void **state)
{
    (void)state;
    test_log log = {0};
    const vfx_plugin_api *api = plugin_api();
    vfx_context_desc host = {.type = VFX_TYPE_CONTEXT_DESC, .user = &log, .log = test_vfx_log_fn};
    vfx_context *ctx = (vfx_context *)&log;
    assert_int_equal(api->create(&host, &ctx), VFX_ERR_INVALID_ARGUMENT);
    assert_null(ctx);
    assert_true(test_log_is(&log, VFX_LOG_ID_CONTEXT_DESC, "gl_get_proc_address"));
}

int main(void)
{
    rt_gl_context *gl = test_gl_or_skip();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_counted_once_at_create),
        cmocka_unit_test(test_missing_command_named),
        cmocka_unit_test(test_no_loader_refused),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    rt_gl_context_destroy(gl);
    return rc;
}
