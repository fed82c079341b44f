/* Headless GL on the real driver (llvmpipe in CI): render and read back, timestamp queries
 * through the plugin's pass timers, shader errors as file:line, plugin lifecycle with nothing
 * in the world (no effect state, no pass, no stat). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <epoxy/gl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app.h"
#include "gpu/gpu.h"
#include "gpu/pass.h"
#include "shader_text.h"
#include "debug.h"
#include "camera_ref.h"
#include "test_util.h"

static rt_gl_context *g_gl;

static vfx_context_desc empty_host(test_log *log)
{
    return (vfx_context_desc){.type = VFX_TYPE_CONTEXT_DESC, .gl_get_proc_address = test_gl_proc,
                          .user = log, .log = test_vfx_log_fn};
}

static const vfx_plugin_api *plugin_api(void)
{
    static vfx_plugin_api api; /* test-local table; the plugin itself holds no globals */
    api.type = VFX_TYPE_PLUGIN_API;
    assert_int_equal(vfx_plugin_entry(VFX_ABI_VERSION, NULL, &api), VFX_OK);
    return &api;
}

static void test_render_readback(void **state)
{
    (void)state;
    rt_renderer *r;
    rt_logger lg = {0};
    assert_int_equal(rt_renderer_create(&lg, &r), VFX_OK);
    assert_int_equal(rt_renderer_resize(r, 64, 48), VFX_OK);
    ref_camera cam = {{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.8, 64, 48, 0.1, 100};
    float view[16], proj[16];
    ref_camera_matrices(&cam, view, proj);
    rt_mesh_data box;
    assert_int_equal(rt_mesh_make_box((float[3]){-1, -1, -1}, (float[3]){1, 1, 1}, &box), VFX_OK);
    rt_mesh_gpu gpu;
    assert_int_equal(rt_mesh_upload(&box, &gpu), VFX_OK);
    rt_mesh_data_free(&box);
    static const float clear[3] = {0, 0, 1}, red[3] = {1, 0, 0};
    static const float id[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    rt_renderer_begin_scene(r, view, proj, clear);
    rt_renderer_draw_mesh(r, &gpu, id, red);
    rt_renderer_targets fv;
    rt_renderer_end_scene(r, &fv);
    assert_int_equal(fv.width, 64);
    assert_int_not_equal(fv.scene_depth, 0);
    uint8_t *px = malloc(64 * 48 * 4);
    assert_int_equal(rt_renderer_read_rgba(r, px), VFX_OK);
    const uint8_t *centre = px + (24 * 64 + 32) * 4, *corner = px;
    assert_true(centre[0] > 60 && centre[2] < 10);   /* the box, lit red */
    assert_true(corner[2] == 255 && corner[0] == 0); /* the clear colour */
    /* the depth the plugin will read: the box front face at z = 1 is 4 units from the eye */
    float *depth = malloc(64 * 48 * sizeof(float));
    glGetTextureImage(fv.scene_depth, 0, GL_DEPTH_COMPONENT, GL_FLOAT, 64 * 48 * 4, depth);
    double n = 0.1, f = 100, d = depth[24 * 64 + 32];
    double z_eye = 2.0 * n * f / (f + n - (2.0 * d - 1.0) * (f - n));
    assert_true(fabs(z_eye - 4.0) < 1e-3); /* depth32F keeps this to ~1e-5 relative */
    free(depth);
    free(px);
    rt_mesh_gpu_destroy(&gpu);
    rt_renderer_destroy(r);
    assert_int_equal(glGetError(), GL_NO_ERROR);
}

static void test_timestamps_and_empty_world(void **state)
{
    (void)state;
    test_log log = {0};
    vfx_context_desc host = empty_host(&log);
    const vfx_plugin_api *api = plugin_api();
    vfx_context *ctx;
    assert_int_equal(api->create(&host, &ctx), VFX_OK);
    vfx_frame_view fv = {.type = VFX_TYPE_FRAME_VIEW, .width = 32, .height = 32};
    ref_camera cam = {{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.8, 32, 32, 0.1, 100};
    ref_camera_matrices(&cam, fv.view, fv.proj);
    vfx_stats st = {.type = VFX_TYPE_STATS};
    /* nothing in the world: no effect state is made, no pass runs, no stat appears */
    for (int i = 0; i < 6; ++i) {
        assert_int_equal(api->update(ctx, i / 60.0, 1.f / 60.f), VFX_OK);
        assert_int_equal(api->render(ctx, &fv), VFX_OK);
    }
    for (int k = 0; k < VFX_EFFECT_COUNT; ++k)
        assert_null(ctx->effect_state[k]);
    assert_int_equal(api->get_stats(ctx, &st), VFX_OK);
    assert_int_equal(st.count, 0);
    float raw[32 * 32];
    assert_int_not_equal(api->read_raw(ctx, VFX_EFFECT_BEAMS, raw, 32 * 32), VFX_OK);
    /* a timed pass: its GPU ms reach the stats a few frames later, without a stall */
    GLuint fbo, tex;
    glCreateTextures(GL_TEXTURE_2D, 1, &tex);
    glTextureStorage2D(tex, 1, GL_RGBA8, 256, 256);
    glCreateFramebuffers(1, &fbo);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, tex, 0);
    bool seen = false;
    for (int frame = 0; frame < 12 && !seen; ++frame) {
        ctx->stats.count = 0;
        volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "test.clear", .framebuffer = fbo, .width = 256,
                                                 .height = 256, .clear_color = true,
                                                 .clear_rgba = {0.1f * frame, 0, 0, 1}});
        volfx_pass_end(ctx);
        glFinish();
        volfx_gpu_frame_end(ctx);
        for (uint32_t i = 0; i < ctx->stats.count; ++i)
            if (!strcmp(ctx->stats.entries[i].name, "test.clear.gpu_ms")) {
                seen = true;
                assert_true(ctx->stats.entries[i].value >= 0 && ctx->stats.entries[i].value < 1000);
            }
    }
    assert_true(seen);
    /* more counters than the stats hold: the first VFX_STATS_MAX are given, the rest counted */
    ctx->stats.count = 0;
    ctx->stats.dropped = 0;
    for (int i = 0; i < VFX_STATS_MAX + 3; ++i) {
        char name[32];
        snprintf(name, sizeof name, "test.c%d", i);
        volfx_stat_set(ctx, name, i);
    }
    ctx->last_stats = ctx->stats;
    static vfx_stats v2;
    v2 = (vfx_stats){.type = VFX_TYPE_STATS};
    assert_int_equal(api->get_stats(ctx, &v2), VFX_OK);
    assert_int_equal(v2.count, VFX_STATS_MAX);
    assert_int_equal(v2.dropped, 3);
    assert_string_equal(v2.entries[VFX_STATS_MAX - 1].name, "test.c511");
    assert_true(v2.entries[VFX_STATS_MAX - 1].value == VFX_STATS_MAX - 1);
    v2.type = VFX_TYPE_LIGHTS; /* a struct of another type is refused, naming it */
    assert_int_equal(api->get_stats(ctx, &v2), VFX_ERR_ABI);
    vfx_log_id id = VFX_LOG_ID_NONE;
    assert_non_null(strstr(api->last_error(ctx, &id), "vfx_stats has type 9, need 8"));
    assert_int_equal(id, VFX_LOG_ID_STRUCT_TYPE);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &tex);
    /* bad frames are refused with a message, not drawn */
    fv.proj[5] = NAN;
    assert_int_equal(api->render(ctx, &fv), VFX_ERR_INVALID_ARGUMENT);
    assert_true(test_last_error_is(api, ctx, VFX_LOG_ID_FRAME_VIEW, "camera matrix element"));
    fv.proj[5] = 1;
    fv.type = (vfx_struct_type)9;
    assert_int_equal(api->render(ctx, &fv), VFX_ERR_ABI);
    assert_int_equal(api->resize(ctx, 0, 10), VFX_ERR_INVALID_ARGUMENT);
    assert_true(test_last_error_is(api, ctx, VFX_LOG_ID_RESIZE_RANGE, "0x10"));
    api->destroy(ctx);
}

static void test_shader_error_names_file_line(void **state)
{
    (void)state;
    test_log log = {0};
    vfx_context_desc host = empty_host(&log);
    const vfx_plugin_api *api = plugin_api();
    vfx_context *ctx;
    assert_int_equal(api->create(&host, &ctx), VFX_OK);
    char src[256];
    int idx = volfx_shader_index(&volfx_plugin_shaders, "common/depth.glsl");
    assert_true(idx >= 0);
    /* line 3 of the named file has the error */
    snprintf(src, sizeof src, "#version 450 core\n#line %ld\nvoid f() {}\n\nvoid main() { undefined_thing = 1; }\n",
             volfx_shader_line_base(idx) + 1);
    const char *srcs[1] = {src}, *names[1] = {"common/depth.glsl"};
    GLenum stage = GL_FRAGMENT_SHADER;
    assert_int_equal(volfx_gpu_link_sources(ctx, 1, &stage, srcs, names), 0);
    assert_true(test_last_error_is(api, ctx, VFX_LOG_ID_SHADER_COMPILE, "common/depth.glsl:3:"));
    /* an error inside an included file names that file: the integrate shader compiled with a
     * define that breaks the included beam_field.glsl is reported at beam_field.glsl */
    assert_int_equal(volfx_gpu_program(ctx, "common/fullscreen.vert", "beams/integrate.frag",
                                     "#define fma undefined_fma"), 0);
    assert_true(test_last_error_is(api, ctx, VFX_LOG_ID_SHADER_COMPILE, "beams/beam_field.glsl:"));
    /* a shader that is not embedded is named */
    assert_int_equal(volfx_gpu_program(ctx, "common/fullscreen.vert", "nope/none.frag", NULL), 0);
    assert_true(test_last_error_is(api, ctx, VFX_LOG_ID_SHADER_COMPILE, "nope/none.frag"));
    /* the host's shaders are not the plugin's */
    assert_int_equal(volfx_gpu_program(ctx, "host/mesh.vert", "host/mesh.frag", NULL), 0);
    assert_true(test_last_error_is(api, ctx, VFX_LOG_ID_SHADER_COMPILE, "host/mesh.vert"));
    /* the real embedded program links, and is cached */
    GLuint p0 = volfx_gpu_program(ctx, "common/fullscreen.vert", "beams/composite.frag", NULL);
    assert_int_not_equal(p0, 0);
    assert_int_equal(volfx_gpu_program(ctx, "common/fullscreen.vert", "beams/composite.frag", NULL), p0);
    /* define sets that differ only far into the string are different programs */
    char d1[400], d2[400];
    memset(d1, 0, sizeof d1);
    strcpy(d1, "// ");
    memset(d1 + 3, 'x', 330);
    memcpy(d2, d1, sizeof d1);
    strcat(d1, "\n#define VARIANT 1");
    strcat(d2, "\n#define VARIANT 2");
    GLuint p1 = volfx_gpu_program(ctx, "common/fullscreen.vert", "beams/composite.frag", d1);
    GLuint p2 = volfx_gpu_program(ctx, "common/fullscreen.vert", "beams/composite.frag", d2);
    assert_true(p1 != 0 && p2 != 0 && p1 != p2 && p1 != p0);
    api->destroy(ctx);
}

static void test_lifecycle_many(void **state)
{
    (void)state;
    test_log log = {0};
    vfx_context_desc host = empty_host(&log);
    const vfx_plugin_api *api = plugin_api();
    /* create, resize, destroy and re-create; run under valgrind/LSan this proves no leak */
    for (int i = 0; i < 1000; ++i) {
        vfx_context *ctx;
        assert_int_equal(api->create(&host, &ctx), VFX_OK);
        assert_int_equal(api->resize(ctx, 64 + (uint32_t)i % 7, 32), VFX_OK);
        api->destroy(ctx);
    }
    assert_int_equal(log.errors, 0);
    assert_int_equal(glGetError(), GL_NO_ERROR);
}

static void test_app_frame(void **state)
{
    (void)state;
    /* the full host path: world, scene, plugin, screenshot */
    rt_gl_context_destroy(g_gl);
    g_gl = NULL;
    test_log log = {0};
    game_app_desc d = {.mode = RT_GL_HEADLESS, .width = 48, .height = 32, .logger = {test_log_fn, &log}};
    game_app *app;
    assert_int_equal(game_app_create(&d, &app), VFX_OK);
    assert_int_equal(game_app_add_box(app, (float[3]){-1, -1, -1}, (float[3]){1, 1, 1}, (float[3]){0, 1, 0}, NULL), VFX_OK);
    for (int i = 0; i < 3; ++i)
        assert_int_equal(game_app_frame(app, 1.f / 60.f), VFX_OK);
    assert_int_equal(game_app_screenshot(app, "app_frame.png"), VFX_OK);
    FILE *f = fopen("app_frame.png", "rb");
    assert_non_null(f);
    fclose(f);
    rt_frame_summary s = rt_profiler_summary(app->profiler, 0);
    assert_int_equal(s.frames, 3);
    assert_true(s.p50_ms > 0 && s.p99_ms >= s.p50_ms);
    assert_int_equal(game_app_dump_raw(app, VFX_EFFECT_WATER, "none.pfm") == VFX_OK, 0);
    game_app_destroy(app);
}

int main(void)
{
    g_gl = test_gl_or_skip();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_render_readback),
        cmocka_unit_test(test_timestamps_and_empty_world),
        cmocka_unit_test(test_shader_error_names_file_line),
        cmocka_unit_test(test_lifecycle_many),
        cmocka_unit_test(test_app_frame),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    rt_gl_context_destroy(g_gl);
    return rc;
}
