/* test_frame_check.c — issue 18, defects 7 and 8: what the plugin checks at the ABI. Host
 * callback pairs at create and update; every frame-view field: texture names, targets, formats
 * and sizes (GL queries), the framebuffer, near/far against the projection, the effects mask;
 * depth_texture 0 drawing as "nothing occludes" (the beams vanished before); read_raw and
 * get_stats with NULL writing their own error instead of leaving a stale one; the frame gate's
 * VolfxFrame block against float64 references (issue 23). */
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

#include "camera_ref.h"
#include "debug.h"
#include "gpu/gpu.h"
#include "test_util.h"

#define W 32
#define H 32

static rt_gl_context *g_gl;

static vfx_result one_beam(void *user, vfx_beams_view *out)
{
    (void)user;
    static const vfx_beam b = {.type = VFX_TYPE_BEAM, .head = {-1, 0, 0}, .length = 2, .dir = {1, 0, 0}, .radius = 0.6f,
                               .a = 0.5f, .b = 0.5f, .eps = 0.05f, .color = {1, 1, 1, 1}};
    *out = (vfx_beams_view){.type = VFX_TYPE_BEAMS_VIEW, .count = 1, .beams = &b};
    return VFX_OK;
}
static uint32_t one_chunk(void *user) { (void)user; return 1; }
static const float k_px[4] = {0, 0.1f, 0.2f, 0.3f}, k_py[4] = {0}, k_pz[4] = {0};
static vfx_result four_particles(void *user, uint32_t c, vfx_particle_view *out)
{
    (void)user, (void)c;
    *out = (vfx_particle_view){.type = VFX_TYPE_PARTICLE_VIEW, .count = 4,
                               .pos = {k_px, k_py, k_pz}};
    return VFX_OK;
}
static vfx_result params_v99(void *user, vfx_water_params *out)
{
    (void)user;
    out->type = (vfx_struct_type)99; /* a struct of a type this plugin cannot know */
    return VFX_OK;
}
/* A chained struct of a type the plugin does not know (a later ABI's): skipped. */
typedef struct future_ext {
    vfx_struct_type type;
    const void *next;
    float anything[8];
} future_ext;
static const future_ext k_future = {(vfx_struct_type)0x7000abcd, NULL, {1, 2, 3}};
static vfx_result params_future_chain(void *user, vfx_water_params *out)
{
    (void)user;
    out->next = &k_future;
    out->h = 0.5f;
    return VFX_OK;
}
/* GPU-resident columns: reserved in ABI 1.0, refused until the plugin reads them. */
static vfx_result gpu_particles(void *user, uint32_t c, vfx_particle_view *out)
{
    (void)user, (void)c;
    *out = (vfx_particle_view){.type = VFX_TYPE_PARTICLE_VIEW, .count = 4, .gpu_pos = {.buffer = 5000, .stride = 12}};
    return VFX_OK;
}
static vfx_result gpu_kernel(void *user, uint32_t c, vfx_particle_view *out)
{
    static const float xyz[4] = {0, 0, 0, 0};
    (void)user, (void)c;
    *out = (vfx_particle_view){.type = VFX_TYPE_PARTICLE_VIEW, .count = 4, .pos = {xyz, xyz, xyz},
                               .gpu_kernel = {.buffer = 5000, .stride = 24}};
    return VFX_OK;
}
static uint32_t one_volume(void *user) { (void)user; return 1; }
static void host_free(void *user, void *p) { (void)user; free(p); }

static const vfx_plugin_api *plugin_api(void)
{
    static vfx_plugin_api api;
    api.type = VFX_TYPE_PLUGIN_API;
    assert_int_equal(vfx_plugin_entry(VFX_ABI_VERSION, NULL, &api), VFX_OK);
    return &api;
}

static vfx_context_desc beams_host(test_log *log)
{
    return (vfx_context_desc){.type = VFX_TYPE_CONTEXT_DESC, .gl_get_proc_address = test_gl_proc, .user = log,
                          .log = test_vfx_log_fn, .beams = one_beam};
}

typedef struct fixture {
    GLuint color, depth, far_depth, out_tex, fbo, small, cube;
    vfx_frame_view fv;
} fixture;

static void make_fixture(fixture *f)
{
    glCreateTextures(GL_TEXTURE_2D, 1, &f->color);
    glTextureStorage2D(f->color, 1, GL_RGBA8, W, H);
    glCreateTextures(GL_TEXTURE_2D, 1, &f->depth);
    glTextureStorage2D(f->depth, 1, GL_DEPTH_COMPONENT32F, W, H);
    const float one = 1.0f;
    glClearTexImage(f->depth, 0, GL_DEPTH_COMPONENT, GL_FLOAT, &one);
    glCreateTextures(GL_TEXTURE_2D, 1, &f->small);
    glTextureStorage2D(f->small, 1, GL_DEPTH_COMPONENT32F, W / 2, H / 2);
    glCreateTextures(GL_TEXTURE_CUBE_MAP, 1, &f->cube);
    glTextureStorage2D(f->cube, 1, GL_RGBA8, 8, 8);
    glCreateTextures(GL_TEXTURE_2D, 1, &f->out_tex);
    glTextureStorage2D(f->out_tex, 1, GL_RGBA8, W, H);
    glCreateFramebuffers(1, &f->fbo);
    glNamedFramebufferTexture(f->fbo, GL_COLOR_ATTACHMENT0, f->out_tex, 0);
    ref_camera cam = {{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.8, W, H, 0.1, 100};
    f->fv = (vfx_frame_view){.type = VFX_TYPE_FRAME_VIEW,
                             .framebuffer = f->fbo, .color_texture = f->color, .depth_texture = f->depth,
                             .width = W, .height = H, .eye = {0, 0, 5}, .near_plane = 0.1f,
                             .far_plane = 100.0f, .fov_y = 0.8f};
    ref_camera_matrices(&cam, f->fv.view, f->fv.proj);
}

static void free_fixture(fixture *f)
{
    GLuint t[] = {f->color, f->depth, f->small, f->cube, f->out_tex};
    glDeleteTextures(5, t);
    glDeleteFramebuffers(1, &f->fbo);
}

static double max_h(const vfx_plugin_api *api, vfx_context *ctx)
{
    static float h[W * H];
    assert_int_equal(api->read_raw(ctx, VFX_EFFECT_BEAMS, h, W * H), VFX_OK);
    double m = 0;
    for (int i = 0; i < W * H; ++i)
        m = h[i] > m ? h[i] : m;
    return m;
}

/* Renders fv and expects `code` and a message containing `part` (NULL: expect VFX_OK). */
static void expect(const vfx_plugin_api *api, vfx_context *ctx, const vfx_frame_view *fv, vfx_result code,
                   const char *part)
{
    vfx_result r = api->render(ctx, fv);
    const char *msg = api->last_error(ctx, NULL);
    if (r != code || (part && !strstr(msg, part)))
        fail_msg("render: got %d \"%s\", want %d containing \"%s\"", r, msg, code, part ? part : "");
    assert_int_equal(glGetError(), GL_NO_ERROR); /* the checks leave no GL error behind */
}

/* A context over the beams host (its messages in *log), updated once, and the fixture's frame. */
static vfx_context *open_beams(test_log *log, fixture *f)
{
    vfx_context_desc host = beams_host(log);
    vfx_context *ctx;
    assert_int_equal(plugin_api()->create(&host, &ctx), VFX_OK);
    assert_int_equal(plugin_api()->update(ctx, 0.0, 0.0f), VFX_OK);
    make_fixture(f);
    return ctx;
}

static void test_frame_fields(void **state)
{
    (void)state;
    test_log log = {0};
    fixture f;
    vfx_context *ctx = open_beams(&log, &f);
    const vfx_plugin_api *api = plugin_api();
    /* read_raw before any render (issue 28: VFX_OK with nothing rendered) */
    static float early[W * H];
    assert_int_equal(api->read_raw(ctx, VFX_EFFECT_BEAMS, early, W * H), VFX_ERR_NOT_FOUND);
    assert_true(test_last_error_is(api, ctx, VFX_LOG_ID_EFFECT_NOT_RENDERED, "read_raw: effect beams"));
    expect(api, ctx, &f.fv, VFX_OK, NULL);
    double h_ref = max_h(api, ctx);
    assert_true(h_ref > 0.1); /* the beam is in view */
    vfx_frame_view v = f.fv;
    /* depth_texture 0: no host depth, nothing occludes; the beams drew nothing before */
    v.depth_texture = 0;
    expect(api, ctx, &v, VFX_OK, NULL);
    assert_true(fabs(max_h(api, ctx) - h_ref) <= 1e-6 * h_ref);
    v = f.fv;
    v.depth_texture = f.color; /* a colour format as depth */
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "depth_texture");
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "not a depth format");
    v = f.fv;
    v.color_texture = f.depth;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "color_texture");
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "not a colour format");
    v = f.fv;
    v.depth_texture = 4242;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "frame view depth_texture 4242 is not a texture name");
    v = f.fv;
    v.depth_texture = f.small;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "depth_texture");
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "is 16x16, the frame view 32x32");
    v = f.fv;
    v.color_texture = f.cube;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "is a GL_TEXTURE_CUBE_MAP texture, need a GL_TEXTURE_2D texture");
    /* a frame view four times larger than its textures */
    v = f.fv;
    v.width = 2 * W, v.height = 2 * H;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "framebuffer");
    v.framebuffer = 0;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "color_texture");
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "is 32x32, the frame view 64x64");
    /* only too short: a frame view W x 2H over the W x H attachment (the 2W x 2H case above
     * passes a check that wants both sides short) */
    v = f.fv;
    v.height = 2 * H;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "framebuffer");
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "is 32x32, smaller than the frame view 32x64");
    /* a colour texture with no colour bits at all: stencil only (depth has its own case above) */
    GLuint stencil;
    glCreateTextures(GL_TEXTURE_2D, 1, &stencil);
    glTextureStorage2D(stencil, 1, GL_STENCIL_INDEX8, W, H);
    v = f.fv;
    v.color_texture = stencil;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "not a colour format");
    glDeleteTextures(1, &stencil);
    v = f.fv;
    v.framebuffer = 777;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "framebuffer 777 is not a framebuffer name");
    /* near/far: swapped fields; fields that disagree with the projection; a projection built
     * with near > far (two frames of that took 4 minutes in the water march) */
    v = f.fv;
    v.near_plane = 100, v.far_plane = 0.1f;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "far_plane 0.1 must be finite and > near_plane 100");
    v = f.fv;
    v.near_plane = 0.5f;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "near_plane 0.5, but proj has near 0.1");
    v = f.fv;
    v.near_plane = 0.101f; /* 1% off: the planes disagree (the 5x case passes a loose check) */
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "near_plane 0.101, but proj has near 0.1");
    v = f.fv;
    v.far_plane = 50;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "far_plane 50, but proj has far 100");
    v = f.fv;
    ref_camera bad = {{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.8, W, H, 100, 0.1};
    ref_camera_matrices(&bad, v.view, v.proj);
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "proj maps near");
    v = f.fv;
    v.near_plane = v.far_plane = 0; /* both 0: taken from the projection */
    expect(api, ctx, &v, VFX_OK, NULL);
    assert_true(fabs(max_h(api, ctx) - h_ref) <= 1e-6 * h_ref);
    v = f.fv;
    v.near_plane = NAN;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "near_plane nan must be > 0");
    v = f.fv;
    v.fov_y = 4;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "fov_y 4 outside [0, pi)");
    v = f.fv;
    v.eye[1] = INFINITY;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "eye[1] is not finite");
    /* an eye the view matrix does not have (issue 28: accepted, the water then missed
     * everywhere); within float32 rounding it passes, also far from the origin */
    v = f.fv;
    v.eye[2] = 4;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "frame view eye (0, 0, 4) is not the view matrix's eye (0, 0, 5)");
    v = f.fv;
    v.eye[0] = 1e-3f; /* tolerance here 256 FLT_EPSILON x 5 = 1.5e-4 */
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "is not the view matrix's eye");
    v = f.fv;
    v.eye[2] = 0; /* (0, 0, 0): unset, taken from the view (zero means default) */
    expect(api, ctx, &v, VFX_OK, NULL);
    v = f.fv;
    v.eye[2] = nextafterf(5.f, 6.f);
    expect(api, ctx, &v, VFX_OK, NULL);
    v = f.fv;
    ref_camera far_cam = {{3e5, 1e3, 2e5}, {3e5 - 4, 1e3, 2e5 - 3}, {0, 1, 0}, 0.8, W, H, 0.1, 100};
    ref_camera_matrices(&far_cam, v.view, v.proj);
    for (int k = 0; k < 3; ++k) v.eye[k] = (float)far_cam.eye[k];
    expect(api, ctx, &v, VFX_OK, NULL);
    /* an orthographic projection: planes derived from it (both 0) and checked against it;
     * swapping its near/far formulas in projection_planes fails here */
    v = f.fv;
    memset(v.proj, 0, sizeof v.proj);
    v.proj[0] = 2.f / 4, v.proj[5] = 2.f / 4, v.proj[10] = -2.f / (100 - 0.1f);
    v.proj[14] = -(100 + 0.1f) / (100 - 0.1f), v.proj[15] = 1;
    v.fov_y = 0;
    expect(api, ctx, &v, VFX_OK, NULL);
    v.near_plane = v.far_plane = 0;
    expect(api, ctx, &v, VFX_OK, NULL);
    v.near_plane = 0.1f, v.far_plane = 50;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "far_plane 50, but proj has far 100");
    v.near_plane = 1, v.far_plane = 100;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "near_plane 1, but proj has near 0.");
    v = f.fv;
    v.effects = 1u << 9;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "effects 0x200 has bits of no effect");
    vfx_log_id fid = VFX_LOG_ID_NONE;
    api->last_error(ctx, &fid);
    assert_int_equal(fid, VFX_LOG_ID_FRAME_VIEW);
    /* version 2: the cubemap must be one */
    vfx_frame_view v2 = f.fv;
    v2.environment_cubemap = f.color;
    expect(api, ctx, &v2, VFX_ERR_INVALID_ARGUMENT,
           "environment_cubemap");
    expect(api, ctx, &v2, VFX_ERR_INVALID_ARGUMENT, "is a GL_TEXTURE_2D texture, need a GL_TEXTURE_CUBE_MAP texture");
    v2.environment_cubemap = f.cube;
    expect(api, ctx, &v2, VFX_OK, NULL);
    /* a frame view of another type is reported as that */
    v = f.fv;
    v.type = VFX_TYPE_BEAMS_VIEW;
    expect(api, ctx, &v, VFX_ERR_ABI, "frame view (vfx_frame_view) has type 6, need 2");
    /* an effects layer must be an RGBA16F texture: refused naming the field, with its own id
     * (gl/effects_layer checks the rest) */
    vfx_frame_view lv = f.fv;
    lv.layer_texture = f.color;
    expect(api, ctx, &lv, VFX_ERR_INVALID_ARGUMENT, "layer_texture");
    vfx_log_id id = VFX_LOG_ID_NONE;
    api->last_error(ctx, &id);
    assert_int_equal(id, VFX_LOG_ID_LAYER_TEXTURE);
    /* a chained struct of an unknown type is skipped */
    const future_ext ext = {(vfx_struct_type)0x7000abcd, NULL, {0}};
    lv = f.fv;
    lv.next = &ext;
    expect(api, ctx, &lv, VFX_OK, NULL);
    /* the last good frame still renders */
    expect(api, ctx, &f.fv, VFX_OK, NULL);
    /* NULL outputs: their own error, not the last one */
    assert_int_equal(api->render(ctx, &v), VFX_ERR_ABI);
    assert_int_equal(api->read_raw(ctx, VFX_EFFECT_BEAMS, NULL, 0), VFX_ERR_INVALID_ARGUMENT);
    assert_true(test_last_error_is(api, ctx, VFX_LOG_ID_API_ARGUMENT, "read_raw: out"));
    assert_int_equal(api->get_stats(ctx, NULL), VFX_ERR_INVALID_ARGUMENT);
    assert_true(test_last_error_is(api, ctx, VFX_LOG_ID_API_ARGUMENT, "get_stats: out"));
    api->destroy(ctx);
    free_fixture(&f);
    assert_int_equal(glGetError(), GL_NO_ERROR);
}

/* No effect will draw: nothing is queried (an absent effect costs nothing), but the planes are
 * still checked. */
static void test_nothing_drawn(void **state)
{
    (void)state;
    test_log log = {0};
    vfx_context_desc host = {.type = VFX_TYPE_CONTEXT_DESC, .gl_get_proc_address = test_gl_proc, .user = &log, .log = test_vfx_log_fn};
    const vfx_plugin_api *api = plugin_api();
    vfx_context *ctx;
    assert_int_equal(api->create(&host, &ctx), VFX_OK);
    fixture f;
    make_fixture(&f);
    vfx_frame_view v = f.fv;
    v.depth_texture = 4242;
    expect(api, ctx, &v, VFX_OK, NULL);
    v.near_plane = 100, v.far_plane = 0.1f;
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "far_plane");
    api->destroy(ctx);
    free_fixture(&f);
}

/* Water parameters of an unknown type (99) refused at update, naming it; an unknown chained struct
 * is skipped; a GL buffer column that names no buffer is refused (water/water_gpu checks the rest),
 * and a GL buffer kernel column is not supported. */
static void test_unknown_water_params_version(void **state)
{
    (void)state;
    test_log log = {0};
    const vfx_plugin_api *api = plugin_api();
    vfx_context_desc host = {.type = VFX_TYPE_CONTEXT_DESC, .gl_get_proc_address = test_gl_proc,
                         .user = &log, .log = test_vfx_log_fn, .particle_chunk_count = one_chunk,
                         .particle_chunk = four_particles, .water_params = params_v99};
    vfx_context *ctx;
    assert_int_equal(api->create(&host, &ctx), VFX_OK);
    if (!(api->effects_built & VFX_EFFECT_BIT(VFX_EFFECT_WATER))) {
        api->destroy(ctx);
        return;
    }
    assert_int_equal(api->update(ctx, 0.0, 0.0f), VFX_ERR_ABI);
    vfx_log_id id = VFX_LOG_ID_NONE;
    assert_non_null(strstr(api->last_error(ctx, &id), "water: host water_params (vfx_water_params) has type 99, need 4"));
    assert_int_equal(id, VFX_LOG_ID_STRUCT_TYPE);
    api->destroy(ctx);
    host.water_params = params_future_chain;
    assert_int_equal(api->create(&host, &ctx), VFX_OK);
    assert_int_equal(api->update(ctx, 0.0, 0.0f), VFX_OK);
    api->destroy(ctx);
    host.particle_chunk = gpu_particles;
    assert_int_equal(api->create(&host, &ctx), VFX_OK);
    assert_int_equal(api->update(ctx, 0.0, 0.0f), VFX_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(api->last_error(ctx, &id), "gpu_pos.buffer 5000 is not a buffer object"));
    assert_int_equal(id, VFX_LOG_ID_GPU_COLUMN);
    api->destroy(ctx);
    host.particle_chunk = gpu_kernel;
    assert_int_equal(api->create(&host, &ctx), VFX_OK);
    assert_int_equal(api->update(ctx, 0.0, 0.0f), VFX_ERR_INVALID_ARGUMENT); /* GL kernels need GL positions */
    assert_true(test_last_error_is(api, ctx, VFX_LOG_ID_GPU_COLUMN, "gpu_kernel with CPU positions"));
    api->destroy(ctx);
}

/* Defect 7: a callback without its partner called through NULL (particle_chunk_count set,
 * particle_chunk NULL). Refused at create, naming both; at update when the copy changed. */
static void test_callback_pairs(void **state)
{
    (void)state;
    test_log log = {0};
    const vfx_plugin_api *api = plugin_api();
    vfx_context *ctx = (vfx_context *)&log;
    vfx_context_desc host = {.type = VFX_TYPE_CONTEXT_DESC, .gl_get_proc_address = test_gl_proc, .user = &log, .log = test_vfx_log_fn,
                         .particle_chunk_count = one_chunk};
    assert_int_equal(api->create(&host, &ctx), VFX_ERR_INVALID_ARGUMENT);
    assert_null(ctx);
    assert_true(test_log_is(&log, VFX_LOG_ID_CONTEXT_DESC, "particle_chunk_count is set but particle_chunk is NULL"));
    host.particle_chunk_count = NULL;
    host.volume_count = one_volume;
    assert_int_equal(api->create(&host, &ctx), VFX_ERR_INVALID_ARGUMENT);
    assert_true(test_log_is(&log, VFX_LOG_ID_CONTEXT_DESC, "volume_count is set but volume is NULL"));
    host.volume_count = NULL;
    host.free = host_free;
    assert_int_equal(api->create(&host, &ctx), VFX_ERR_INVALID_ARGUMENT);
    assert_true(test_log_is(&log, VFX_LOG_ID_CONTEXT_DESC, "free is set but alloc is NULL"));
    host.free = NULL;
    assert_int_equal(api->create(&host, &ctx), VFX_OK);
    ctx->host.particle_chunk_count = one_chunk; /* the copy damaged after create */
    assert_int_equal(api->update(ctx, 0.0, 0.0f), VFX_ERR_INVALID_ARGUMENT);
    assert_true(test_last_error_is(api, ctx, VFX_LOG_ID_CONTEXT_DESC, "update: context desc: particle_chunk_count"));
    api->destroy(ctx);
}

/* ------------------------------------------------------------------ attacks on the v2 views */

typedef struct attack_host {
    vfx_beams_view bv;
    vfx_beam beam;
    vfx_volume_view vv;
} attack_host;

static vfx_result attack_beams(void *user, vfx_beams_view *out)
{
    attack_host *a = user;
    if (out->type != VFX_TYPE_BEAMS_VIEW)
        return VFX_ERR_NOT_FOUND;
    *out = a->bv;
    return VFX_OK;
}
static uint32_t attack_volume_count(void *user) { (void)user; return 1; }
static vfx_result attack_volume(void *user, uint32_t index, vfx_volume_view *out)
{
    attack_host *a = user;
    (void)index;
    *out = a->vv;
    return VFX_OK;
}

static const float k_pts[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
static const uint32_t k_tet[4] = {0, 1, 2, 3}, k_bad_tet[4] = {0, 1, 2, 9};
static const float k_scalar[4] = {0, 1, 2, 3};
static const float k_rgba[8] = {0, 0, 0, 0, 1, 1, 1, 2};

static void good_views(attack_host *a)
{
    memset(a, 0, sizeof *a);
    a->beam = (vfx_beam){.type = VFX_TYPE_BEAM, .head = {-1, 0, 0}, .length = 2, .dir = {1, 0, 0}, .radius = 0.6f, .a = 0.5f,
                                 .b = 0.5f, .eps = 0.05f, .color = {1, 1, 1, 1}};
    a->bv = (vfx_beams_view){.type = VFX_TYPE_BEAMS_VIEW, .count = 1,
                              .beams = &a->beam};
    a->vv = (vfx_volume_view){.type = VFX_TYPE_VOLUME_VIEW,
                                      .point_count = 4, .tet_count = 1, .points = k_pts, .tets = k_tet,
                                      .scalar = k_scalar, .transfer_rgba = k_rgba, .transfer_count = 2};
}

/* One update + render with the attack host's views; expects `code` and `part` in the message. */
static void attack(const vfx_plugin_api *api, attack_host *a, const fixture *f, vfx_result code, const char *part)
{
    test_log log = {0};
    vfx_context_desc host = {.type = VFX_TYPE_CONTEXT_DESC, .gl_get_proc_address = test_gl_proc, .user = a, .log = NULL,
                         .beams = attack_beams, .volume_count = attack_volume_count, .volume = attack_volume};
    (void)log;
    vfx_context *ctx;
    assert_int_equal(api->create(&host, &ctx), VFX_OK);
    vfx_result r = api->update(ctx, 0.0, 0.0f);
    if (r == VFX_OK)
        r = api->render(ctx, &f->fv);
    const char *msg = api->last_error(ctx, NULL);
    if (r != code || (part && !strstr(msg, part)))
        fail_msg("attack: got %d \"%s\", want %d containing \"%s\"", r, msg, code, part ? part : "");
    api->destroy(ctx);
    assert_int_equal(glGetError(), GL_NO_ERROR);
}

/* Renders the attack host's views, expects OK, stat `name` == value and a finite raw image. */
static void check_counted(const vfx_plugin_api *api, attack_host *a, const fixture *f, const char *name, double value)
{
    vfx_context_desc host = {.type = VFX_TYPE_CONTEXT_DESC, .gl_get_proc_address = test_gl_proc, .user = a,
                         .volume_count = attack_volume_count, .volume = attack_volume};
    vfx_context *ctx;
    assert_int_equal(api->create(&host, &ctx), VFX_OK);
    ctx->debug.sync_counters = true;
    if (api->update(ctx, 0.0, 0.0f) || api->render(ctx, &f->fv))
        fail_msg("%s", api->last_error(ctx, NULL));
    vfx_stats st = {.type = VFX_TYPE_STATS};
    assert_int_equal(api->get_stats(ctx, &st), VFX_OK);
    double got = -1;
    for (uint32_t i = 0; i < st.count; ++i)
        if (!strcmp(st.entries[i].name, name))
            got = st.entries[i].value;
    if (got != value) {
        for (uint32_t i = 0; i < st.count; ++i)
            printf("  %s = %g\n", st.entries[i].name, st.entries[i].value);
        fail_msg("%s = %g, want %g", name, got, value);
    }
    static float raw[W * H];
    assert_int_equal(api->read_raw(ctx, VFX_EFFECT_VOLUME, raw, W * H), VFX_OK);
    for (int i = 0; i < W * H; ++i)
        assert_true(isfinite(raw[i]));
    api->destroy(ctx);
}

static void test_v2_views(void **state)
{
    (void)state;
    const vfx_plugin_api *api = plugin_api();
    fixture f;
    make_fixture(&f);
    attack_host a;
    good_views(&a);
    bool vol = api->effects_built & VFX_EFFECT_BIT(VFX_EFFECT_VOLUME);
    if (!vol)
        a.vv.point_count = 0, a.vv.tet_count = 0;
    attack(api, &a, &f, VFX_OK, NULL);
    /* beams v2: each field out of range, named */
    struct { const char *field; void (*set)(attack_host *); } beam_cases[] = {
        {"ramp 7", NULL}, {"falloff 9", NULL}, {"intensity", NULL}, {"exposure", NULL}, {"flow_amount", NULL},
    };
    (void)beam_cases;
    good_views(&a); a.beam.ramp = 7;
    attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "beams[0]: vfx_beam.ramp 7 outside 1..2 or 0");
    good_views(&a); a.beam.falloff = 9;
    attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "falloff 9");
    good_views(&a); a.beam.intensity = NAN;
    attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "beams[0]: vfx_beam.intensity nan outside (0, 1000000] or 0");
    good_views(&a); a.beam.exposure = 1e30f;
    attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "beams[0]: vfx_beam.exposure 1e+30 outside [-64, 64]");
    good_views(&a); a.beam.flow_amount = 2;
    attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "beams[0]: vfx_beam.flow_amount 2 outside [0, 1]");
    good_views(&a); a.beam.flow_scale = -1;
    attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "beams[0]: vfx_beam.flow_scale -1 outside [0, 1000000]");
    good_views(&a); a.bv.bloom_levels = 99;
    attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "bloom_levels 99");
    good_views(&a); a.bv.bloom_strength = -1;
    attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "bloom_strength -1");
    good_views(&a); a.bv.bloom = 5;
    attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "bloom 5");
    good_views(&a); a.bv.beams = NULL;
    attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "non-NULL array");
    good_views(&a); a.bv.count = 1u << 30;
    attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "1073741824 beams (at most");
    good_views(&a); a.beam.radius = NAN;
    attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "beams[0]:");
    if (vol) {
        /* volume v2 */
        good_views(&a); a.vv.tets = k_bad_tet;
        attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "volume[0]: tet 0 uses point 9 of 4");
        static const float dec[2] = {0.5f, 0.25f}, nan2[2] = {0, NAN};
        good_views(&a); a.vv.transfer_scalar = dec;
        attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "transfer_scalar[1] = 0.25");
        good_views(&a); a.vv.transfer_scalar = nan2;
        attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "transfer_scalar[1] = nan");
        good_views(&a); a.vv.transfer_method = 9;
        attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "volume[0]: vfx_volume_view.transfer_method 9 outside 0..1");
        good_views(&a); a.vv.transfer_count = VFX_VOLUME_MAX_TRANSFER + 1;
        attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "volume[0]: vfx_volume_view.transfer_count 1025 outside 2..1024 or 0");
        good_views(&a); a.vv.ert_threshold = 2;
        attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "volume[0]: vfx_volume_view.ert_threshold 2 outside (0, 1] or 0");
        /* a DxD termination table of 65,535^2 entries per worker: refused, not allocated */
        good_views(&a); a.vv.tiles = 65535;
        attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "volume[0]: vfx_volume_view.tiles 65535 outside 1..1024 or 0");
        good_views(&a); a.vv.workers = 100000;
        attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "volume[0]: vfx_volume_view.workers 100000 outside 0..256");
        good_views(&a); a.vv.update_c = 1u << 31;
        attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "volume[0]: vfx_volume_view.update_c 2147483648 outside 1..1048576 or 0");
        good_views(&a); a.vv.model[0] = NAN;
        attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "volume[0]: vfx_volume_view.model[0] nan outside");
        good_views(&a); a.vv.scalar_min = NAN;
        attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "volume[0]: vfx_volume_view.scalar_min nan outside");
        /* every scalar NaN or Inf (issue 28): named as that, with or without a given range (it
         * was reported as a bad transfer function) */
        static const float nan4[4] = {NAN, NAN, INFINITY, -NAN};
        for (int ranged = 0; ranged < 2; ++ranged) {
            good_views(&a); a.vv.scalar = nan4;
            a.vv.scalar_min = 0, a.vv.scalar_max = ranged ? 3.f : 0.f;
            attack(api, &a, &f, VFX_ERR_INVALID_ARGUMENT, "volume[0]: all 4 scalars are NaN or infinite");
        }
        /* a NaN or Inf coordinate: that cell is skipped, the good one drawn, the image finite */
        good_views(&a);
        check_counted(api, &a, &f, "volume.cells_scanned", 1);
        static float bad_pts[15];
        static const uint32_t two[8] = {0, 1, 2, 3, 0, 1, 2, 4};
        static const float sc5[5] = {0, 1, 2, 3, 4};
        for (int inf = 0; inf < 2; ++inf) {
            memcpy(bad_pts, k_pts, sizeof k_pts);
            bad_pts[12] = 0, bad_pts[13] = 0, bad_pts[14] = inf ? INFINITY : NAN;
            good_views(&a);
            a.vv.points = bad_pts, a.vv.point_count = 5, a.vv.tets = two, a.vv.tet_count = 2;
            a.vv.scalar = sc5;
            check_counted(api, &a, &f, "volume.cells_scanned", 1); /* the good cell still drawn */
        }
        good_views(&a); a.vv.type = (vfx_struct_type)70;
        attack(api, &a, &f, VFX_ERR_ABI, "host volume view (vfx_volume_view) has type 70, need 7");
    }
    free_fixture(&f);
}

/* The frame gate's VolfxFrame block (issue 23): after a render, the buffer bound at
 * VOLFX_FRAME_BINDING holds the checked camera and what is derived from it. References in
 * float64 from the float matrices the host gave: proj*view summed in double (the gate
 * multiplies in float, error <= 4 ulp of the largest product, bounded by 1e-5 relative to the
 * matrix's largest entry here); the inverses checked by M * M^-1 = I in double within 1e-4
 * (the near/far ratio of 1000 makes the projection's condition number ~1e3, and float32
 * inverses lose about that many ulps); the camera-relative matrix is proj * (view without its
 * translation), and its inverse maps clip points back onto directions from the eye. */
static void mul_d(const float *a, const float *b, double *out)
{
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) {
            double s = 0;
            for (int k = 0; k < 4; ++k)
                s += (double)a[k * 4 + r] * b[c * 4 + k];
            out[c * 4 + r] = s;
        }
}

static void expect_identity(const float *a, const float *b, double tol)
{
    double p[16];
    mul_d(a, b, p);
    for (int i = 0; i < 16; ++i)
        assert_true(fabs(p[i] - (i % 5 == 0 ? 1.0 : 0.0)) <= tol);
}

static void test_frame_block(void **state)
{
    (void)state;
    test_log log = {0};
    fixture f;
    vfx_context *ctx = open_beams(&log, &f);
    const vfx_plugin_api *api = plugin_api();
    vfx_frame_view v3 = f.fv;
    v3.near_plane = 0, v3.far_plane = 0; /* filled from proj by the gate */
    v3.origin[0] = 1e6, v3.origin[1] = -2.5, v3.origin[2] = 3.0;
    v3.color_hdr = 1;
    v3.environment_cubemap = f.cube;
    v3.view_id = 7;
    ctx->gl_skip_restore = true; /* the block stays bound after the call only without the restore */
    expect(api, ctx, &v3, VFX_OK, NULL);
    GLint buf = 0;
    glGetIntegeri_v(GL_UNIFORM_BUFFER_BINDING, VOLFX_FRAME_BINDING, &buf);
    assert_true(buf != 0);
    GLint64 bytes = 0;
    glGetNamedBufferParameteri64v((GLuint)buf, GL_BUFFER_SIZE, &bytes);
    assert_true(bytes >= (GLint64)sizeof(volfx_frame_block));
    volfx_frame_block b;
    glGetNamedBufferSubData((GLuint)buf, 0, sizeof b, &b);
    const float *V = f.fv.view, *P = f.fv.proj;
    for (int i = 0; i < 16; ++i)
        assert_true(b.view[i] == V[i] && b.proj[i] == P[i]);
    double vp[16], big = 0;
    mul_d(P, V, vp);
    for (int i = 0; i < 16; ++i)
        big = fmax(big, fabs(vp[i]));
    for (int i = 0; i < 16; ++i)
        assert_true(fabs(b.view_proj[i] - vp[i]) <= 1e-5 * big);
    expect_identity(b.view_proj, b.inv_view_proj, 1e-4);
    expect_identity(V, b.inv_view, 1e-4);
    float rot[16];
    memcpy(rot, V, sizeof rot);
    rot[12] = rot[13] = rot[14] = 0;
    mul_d(P, rot, vp);
    for (int i = 0; i < 16; ++i)
        assert_true(fabs(b.cam_view_proj[i] - vp[i]) <= 1e-5 * big);
    expect_identity(b.cam_view_proj, b.inv_cam_view_proj, 1e-4);
    for (int k = 0; k < 3; ++k)
        assert_true(b.eye_fov[k] == f.fv.eye[k]);
    assert_true(b.eye_fov[3] == f.fv.fov_y);
    /* near/far of the perspective matrix, 0.1 and 100 (ref_camera_matrices), to float rounding */
    assert_true(fabs(b.planes_size[0] - 0.1) <= 1e-5 && fabs(b.planes_size[1] - 100.0) <= 1e-2);
    assert_true(b.planes_size[2] == W && b.planes_size[3] == H);
    assert_true(b.origin_hdr[0] == 1e6f && b.origin_hdr[1] == -2.5f && b.origin_hdr[2] == 3.0f);
    assert_true(b.origin_hdr[3] == 1.0f);
    assert_int_equal(b.flags[0], 1);
    assert_int_equal(b.flags[1], 7);
    assert_int_equal(b.flags[2], 0xffffffffu); /* effects 0: all */
    api->destroy(ctx);
    free_fixture(&f);
}

/* vfx_frame_depth (docs/integration.md "The engine's own depth"): each bad field refused with its
 * name and VFX_LOG_ID_FRAME_DEPTH; a reversed proj (near beyond far) refused without the chain and
 * read as reversed-Z with it, so a depth of 1 is then the near plane (the beam hidden) and 0 the
 * far plane (the beam as with no depth); a depth renderbuffer and a framebuffer's depth read as
 * the same depth texture is. */
static void expect_depth_id(const vfx_plugin_api *api, vfx_context *ctx, const vfx_frame_view *fv, const char *part)
{
    expect(api, ctx, fv, VFX_ERR_INVALID_ARGUMENT, part);
    vfx_log_id id = VFX_LOG_ID_NONE;
    api->last_error(ctx, &id);
    assert_int_equal(id, VFX_LOG_ID_FRAME_DEPTH);
}

static void test_frame_depth_fields(void **state)
{
    (void)state;
    test_log log = {0};
    fixture f;
    vfx_context *ctx = open_beams(&log, &f);
    const vfx_plugin_api *api = plugin_api();
    expect(api, ctx, &f.fv, VFX_OK, NULL);
    double h_ref = max_h(api, ctx);
    assert_true(h_ref > 0.1);
    GLuint rb[2], fb_depth, fb_none;
    glCreateRenderbuffers(2, rb);
    glNamedRenderbufferStorage(rb[0], GL_DEPTH24_STENCIL8, W, H);
    glNamedRenderbufferStorage(rb[1], GL_RGBA8, W, H);
    glCreateFramebuffers(1, &fb_depth);
    glNamedFramebufferRenderbuffer(fb_depth, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, rb[0]);
    glCreateFramebuffers(1, &fb_none);
    glNamedFramebufferRenderbuffer(fb_none, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb[1]);
    vfx_frame_depth fd = {.type = VFX_TYPE_FRAME_DEPTH};
    vfx_frame_view v = f.fv;
    v.next = &fd;
    fd.depth_convention = (vfx_depth_convention)7;
    expect_depth_id(api, ctx, &v, "vfx_frame_depth depth_convention 7 is none of");
    fd = (vfx_frame_depth){.type = VFX_TYPE_FRAME_DEPTH, .depth_renderbuffer = rb[0], .depth_framebuffer = fb_depth};
    expect_depth_id(api, ctx, &v, "names both depth_renderbuffer");
    fd = (vfx_frame_depth){.type = VFX_TYPE_FRAME_DEPTH, .depth_renderbuffer = 4242};
    expect_depth_id(api, ctx, &v, "depth_renderbuffer 4242 is not a renderbuffer name");
    fd.depth_renderbuffer = rb[1];
    expect_depth_id(api, ctx, &v, "not a depth format");
    fd = (vfx_frame_depth){.type = VFX_TYPE_FRAME_DEPTH, .depth_framebuffer = 4243};
    expect_depth_id(api, ctx, &v, "depth_framebuffer 4243 is not a framebuffer name");
    fd.depth_framebuffer = fb_none;
    expect_depth_id(api, ctx, &v, "has no depth attachment");
    /* the renderbuffer and the framebuffer at depth 1 (far): the beam as with the texture */
    glClearNamedFramebufferfi(fb_depth, GL_DEPTH_STENCIL, 0, 1.0f, 0);
    fd = (vfx_frame_depth){.type = VFX_TYPE_FRAME_DEPTH, .depth_renderbuffer = rb[0]};
    expect(api, ctx, &v, VFX_OK, NULL);
    assert_true(fabs(max_h(api, ctx) - h_ref) <= 1e-6 * h_ref);
    fd = (vfx_frame_depth){.type = VFX_TYPE_FRAME_DEPTH, .depth_framebuffer = fb_depth};
    expect(api, ctx, &v, VFX_OK, NULL);
    assert_true(fabs(max_h(api, ctx) - h_ref) <= 1e-6 * h_ref);
    /* at depth 0 (the near plane) the beam is hidden: the renderbuffer's depth is what is read */
    glClearNamedFramebufferfi(fb_depth, GL_DEPTH_STENCIL, 0, 0.0f, 0);
    expect(api, ctx, &v, VFX_OK, NULL);
    assert_true(max_h(api, ctx) == 0.0);
    /* a reversed proj: refused without the chain, reversed-Z with it */
    ref_camera rev = {{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.8, W, H, 100, 0.1};
    v = f.fv;
    ref_camera_matrices(&rev, v.view, v.proj);
    expect(api, ctx, &v, VFX_ERR_INVALID_ARGUMENT, "a reversed-Z proj needs a chained vfx_frame_depth");
    fd = (vfx_frame_depth){.type = VFX_TYPE_FRAME_DEPTH};
    v.next = &fd;
    expect(api, ctx, &v, VFX_OK, NULL); /* f.depth holds 1: the near plane now */
    assert_true(max_h(api, ctx) == 0.0);
    const float zero = 0.0f;
    glClearTexImage(f.depth, 0, GL_DEPTH_COMPONENT, GL_FLOAT, &zero);
    expect(api, ctx, &v, VFX_OK, NULL); /* 0: the far plane, 100 */
    assert_true(fabs(max_h(api, ctx) - h_ref) <= 1e-6 * h_ref);
    glDeleteRenderbuffers(2, rb);
    glDeleteFramebuffers(1, &fb_depth);
    glDeleteFramebuffers(1, &fb_none);
    free_fixture(&f);
    api->destroy(ctx);
}

/* docs/integration.md "Conventions", colour and alpha: the beams (additive, alpha 0) into a linear
 * RGBA16F target and into a GL_SRGB8_ALPHA8 one, both cleared to black with alpha 0.5. The sRGB
 * target holds the linear target's radiance encoded (the plugin turns GL_FRAMEBUFFER_SRGB on for
 * the frame and the host's off comes back): |byte/255 - srgb(L)| <= 1/255 (the byte's rounding,
 * twice: the beams' blend reads the stored byte back, decodes, adds and encodes again; measured
 * 0.64/255 at most on llvmpipe) + 12.92 x 2^-11 L (RGBA16F's rounding of L, times the encoding's
 * largest slope); destination
 * alpha stays 0.5 in both. A plugin that wrote linear values into the sRGB target, or alpha 1,
 * fails. */
static double srgb_encode(double l)
{
    l = l < 0 ? 0 : l > 1 ? 1 : l;
    return l <= 0.0031308 ? 12.92 * l : 1.055 * pow(l, 1 / 2.4) - 0.055;
}

static void test_conventions_colour_alpha(void **state)
{
    (void)state;
    test_log log = {0};
    fixture f;
    vfx_context *ctx = open_beams(&log, &f);
    const vfx_plugin_api *api = plugin_api();
    GLuint tex[2], fbo[2];
    const GLenum fmt[2] = {GL_RGBA16F, GL_SRGB8_ALPHA8};
    glCreateTextures(GL_TEXTURE_2D, 2, tex);
    glCreateFramebuffers(2, fbo);
    static float px[2][W * H * 4];
    for (int k = 0; k < 2; ++k) {
        glTextureStorage2D(tex[k], 1, fmt[k], W, H);
        glNamedFramebufferTexture(fbo[k], GL_COLOR_ATTACHMENT0, tex[k], 0);
        const float clear[4] = {0, 0, 0, 0.5f};
        glClearNamedFramebufferfv(fbo[k], GL_COLOR, 0, clear);
        vfx_frame_view v = f.fv;
        v.framebuffer = fbo[k];
        glDisable(GL_FRAMEBUFFER_SRGB);
        expect(api, ctx, &v, VFX_OK, NULL);
        assert_false(glIsEnabled(GL_FRAMEBUFFER_SRGB)); /* the host's state back */
        if (k == 0)
            glGetTextureImage(tex[k], 0, GL_RGBA, GL_FLOAT, (GLsizei)sizeof px[k], px[k]);
    }
    static uint8_t enc[W * H * 4];
    glGetTextureImage(tex[1], 0, GL_RGBA, GL_UNSIGNED_BYTE, (GLsizei)sizeof enc, enc);
    int lit = 0;
    double worst = 0;
    for (int q = 0; q < W * H; ++q) {
        assert_true(fabs(px[0][4 * q + 3] - 0.5) <= 1e-3); /* RGBA16F's 0.5 is exact; nothing written */
        assert_true(abs((int)enc[4 * q + 3] - 128) <= 1);  /* 0.5 in 8 bits: 127.5 rounded */
        for (int c = 0; c < 3; ++c) {
            double l = px[0][4 * q + c], want = srgb_encode(l), got = enc[4 * q + c] / 255.0;
            double tol = 1.0 / 255 + 12.92 * 0x1p-11 * fmin(l, 1.0) + 1e-6;
            worst = fmax(worst, fabs(got - want) / tol);
            if (fabs(got - want) > tol)
                fail_msg("pixel %d channel %d: linear %.6g, sRGB byte %u (%.6g), want %.6g (linear as is %.6g)", q, c,
                         l, enc[4 * q + c], got, want, fmin(l, 1.0));
            lit += c == 0 && l > 0.05;
        }
    }
    print_message("sRGB target vs linear: %d lit pixels, largest error/bound %.3g\n", lit, worst);
    assert_true(lit > 20); /* the beam is in view */
    glDeleteFramebuffers(2, fbo);
    glDeleteTextures(2, tex);
    free_fixture(&f);
    api->destroy(ctx);
}

/* docs/integration.md "Conventions", destination alpha of the water: a particle lattice drawn into an
 * RGBA16F target cleared with alpha 0.5: alpha 1 exactly where the water is (read_raw's distance
 * >= 0: it replaces), 0.5 untouched elsewhere. */
static vfx_result lattice_particles(void *user, uint32_t c, vfx_particle_view *out)
{
    static float x[216], y[216], z[216];
    (void)user, (void)c;
    for (int i = 0; i < 216; ++i) /* a 6x6x6 lattice of spacing 0.2 around the origin */
        x[i] = 0.2f * (float)(i % 6) - 0.5f, y[i] = 0.2f * (float)(i / 6 % 6) - 0.5f, z[i] = 0.2f * (float)(i / 36) - 0.5f;
    *out = (vfx_particle_view){.type = VFX_TYPE_PARTICLE_VIEW, .count = 216, .pos = {x, y, z}};
    return VFX_OK;
}

static void test_conventions_water_alpha(void **state)
{
    (void)state;
    test_log log = {0};
    vfx_context_desc host = {.type = VFX_TYPE_CONTEXT_DESC, .gl_get_proc_address = test_gl_proc, .user = &log,
                             .log = test_vfx_log_fn, .particle_chunk_count = one_chunk,
                             .particle_chunk = lattice_particles};
    const vfx_plugin_api *api = plugin_api();
    if (!(api->effects_built & VFX_EFFECT_BIT(VFX_EFFECT_WATER)))
        skip();
    vfx_context *ctx;
    assert_int_equal(api->create(&host, &ctx), VFX_OK);
    assert_int_equal(api->update(ctx, 0.0, 0.0f), VFX_OK);
    fixture f;
    make_fixture(&f);
    GLuint tex, fbo;
    glCreateTextures(GL_TEXTURE_2D, 1, &tex);
    glTextureStorage2D(tex, 1, GL_RGBA16F, W, H);
    glCreateFramebuffers(1, &fbo);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, tex, 0);
    const float clear[4] = {0.2f, 0.2f, 0.2f, 0.5f};
    glClearNamedFramebufferfv(fbo, GL_COLOR, 0, clear);
    vfx_frame_view v = f.fv;
    v.framebuffer = fbo;
    expect(api, ctx, &v, VFX_OK, NULL);
    static float px[W * H * 4], dist[W * H];
    glGetTextureImage(tex, 0, GL_RGBA, GL_FLOAT, (GLsizei)sizeof px, px);
    assert_int_equal(api->read_raw(ctx, VFX_EFFECT_WATER, dist, W * H), VFX_OK);
    int water = 0;
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) {
            float a = px[4 * ((H - 1 - j) * W + i) + 3]; /* read_raw is top row first, GL bottom first */
            bool wet = dist[j * W + i] >= 0;
            water += wet;
            assert_true(a == (wet ? 1.0f : 0.5f));
        }
    print_message("water destination alpha: %d water pixels at 1, the rest 0.5\n", water);
    assert_true(water > 40);
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &tex);
    free_fixture(&f);
    api->destroy(ctx);
}

int main(void)
{
    g_gl = test_gl_or_skip();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_frame_fields),
        cmocka_unit_test(test_frame_depth_fields),
        cmocka_unit_test(test_conventions_colour_alpha),
        cmocka_unit_test(test_conventions_water_alpha),
        cmocka_unit_test(test_nothing_drawn),
        cmocka_unit_test(test_callback_pairs),
        cmocka_unit_test(test_unknown_water_params_version),
        cmocka_unit_test(test_v2_views),
        cmocka_unit_test(test_frame_block),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    rt_gl_context_destroy(g_gl);
    return rc;
}
