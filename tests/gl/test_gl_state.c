/* The GL state contract (docs/integration.md) through the real game host and the real plugin:
 *  - a host that leaves hostile state before every plugin call (both faces culled, a 1x1 scissor,
 *    colour and depth writes off, depth GREATER, odd blending, lines, stencil, rasterizer
 *    discard, flipped clip control, odd textures, samplers, uniform/storage buffers and images
 *    on every unit) gets the clean host's image, bit for bit;
 *  - every binding and state this test tracks (its own glGet list, wider than what the plugin
 *    saves: more units, more targets, more indices) reads the same after each call as before;
 *  - a GL 4.5 compatibility-profile context renders what a core one does.
 * `test_gl_state --bench N` times the save and restore: N frames, update + render CPU time with
 * and without it, interleaved frame by frame, medians (docs/integration.md quotes it). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <epoxy/gl.h>
#include <stdio.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "context.h"
#include "demo_scene.h"
#include "test_util.h"

#define W 96
#define H 54
#define FRAMES 2
#define UNITS 16  /* the plugin uses 0..7 */
#define UBOS 12   /* 0..7 */
#define SSBOS 20  /* 0..15 */
#define IMAGES 8

/* ----------------------------------------------------------------- the test's own snapshot */

typedef struct snap {
    int64_t v[2048];
    char name[2048][48];
    int n;
} snap;

static void put(snap *s, const char *name, int64_t v)
{
    if (s->n >= 2048)
        fail_msg("snapshot full");
    snprintf(s->name[s->n], sizeof s->name[0], "%s", name);
    s->v[s->n++] = v;
}

static void put_i(snap *s, const char *name, GLenum e)
{
    GLint v[4] = {0};
    glGetIntegerv(e, v);
    put(s, name, v[0]);
}

static void put_i_n(snap *s, const char *name, GLenum e, int n)
{
    GLint v[4] = {0};
    glGetIntegerv(e, v);
    char b[48];
    for (int i = 0; i < n; ++i) {
        snprintf(b, sizeof b, "%s[%d]", name, i);
        put(s, b, v[i]);
    }
}

static void put_indexed(snap *s, const char *name, GLenum e, GLuint count)
{
    char b[48];
    for (GLuint i = 0; i < count; ++i) {
        GLint64 v = 0;
        glGetInteger64i_v(e, i, &v);
        snprintf(b, sizeof b, "%s(%u)", name, i);
        put(s, b, v);
    }
}

#define PUT(s, e) put_i(s, #e, e)
#define ON(s, e) put(s, "enabled " #e, glIsEnabled(e))

static void take(snap *s)
{
    s->n = 0;
    PUT(s, GL_DRAW_FRAMEBUFFER_BINDING); PUT(s, GL_READ_FRAMEBUFFER_BINDING); PUT(s, GL_RENDERBUFFER_BINDING);
    PUT(s, GL_CURRENT_PROGRAM); PUT(s, GL_VERTEX_ARRAY_BINDING); PUT(s, GL_ARRAY_BUFFER_BINDING);
    PUT(s, GL_ELEMENT_ARRAY_BUFFER_BINDING); PUT(s, GL_DRAW_INDIRECT_BUFFER_BINDING);
    PUT(s, GL_DISPATCH_INDIRECT_BUFFER_BINDING); PUT(s, GL_PIXEL_PACK_BUFFER_BINDING);
    PUT(s, GL_PIXEL_UNPACK_BUFFER_BINDING); PUT(s, GL_UNIFORM_BUFFER_BINDING);
    PUT(s, GL_SHADER_STORAGE_BUFFER_BINDING); PUT(s, GL_COPY_READ_BUFFER_BINDING);
    PUT(s, GL_COPY_WRITE_BUFFER_BINDING); PUT(s, GL_ACTIVE_TEXTURE); PUT(s, GL_PROGRAM_PIPELINE_BINDING);
    GLint active = 0;
    glGetIntegerv(GL_ACTIVE_TEXTURE, &active);
    char b[48];
    static const struct { GLenum e; const char *n; } units[] = {
        {GL_TEXTURE_BINDING_2D, "2d"}, {GL_TEXTURE_BINDING_CUBE_MAP, "cube"}, {GL_TEXTURE_BINDING_3D, "3d"},
        {GL_TEXTURE_BINDING_2D_ARRAY, "2d_array"}, {GL_SAMPLER_BINDING, "sampler"}};
    for (GLuint u = 0; u < UNITS; ++u) {
        glActiveTexture(GL_TEXTURE0 + u);
        for (size_t k = 0; k < sizeof units / sizeof units[0]; ++k) {
            snprintf(b, sizeof b, "unit %u %s", u, units[k].n);
            put_i(s, b, units[k].e);
        }
    }
    glActiveTexture((GLenum)active);
    put_indexed(s, "ubo", GL_UNIFORM_BUFFER_BINDING, UBOS);
    put_indexed(s, "ubo start", GL_UNIFORM_BUFFER_START, UBOS);
    put_indexed(s, "ubo size", GL_UNIFORM_BUFFER_SIZE, UBOS);
    put_indexed(s, "ssbo", GL_SHADER_STORAGE_BUFFER_BINDING, SSBOS);
    put_indexed(s, "ssbo start", GL_SHADER_STORAGE_BUFFER_START, SSBOS);
    put_indexed(s, "ssbo size", GL_SHADER_STORAGE_BUFFER_SIZE, SSBOS);
    put_indexed(s, "image", GL_IMAGE_BINDING_NAME, IMAGES);
    put_indexed(s, "image level", GL_IMAGE_BINDING_LEVEL, IMAGES);
    put_indexed(s, "image access", GL_IMAGE_BINDING_ACCESS, IMAGES);
    put_indexed(s, "image format", GL_IMAGE_BINDING_FORMAT, IMAGES);
    put_indexed(s, "image layered", GL_IMAGE_BINDING_LAYERED, IMAGES);
    put_i_n(s, "viewport", GL_VIEWPORT, 4);
    put_i_n(s, "scissor box", GL_SCISSOR_BOX, 4);
    GLdouble dr[2];
    glGetDoublev(GL_DEPTH_RANGE, dr);
    put(s, "depth range near x1e6", (int64_t)(dr[0] * 1e6));
    put(s, "depth range far x1e6", (int64_t)(dr[1] * 1e6));
    PUT(s, GL_DEPTH_FUNC); PUT(s, GL_DEPTH_WRITEMASK); PUT(s, GL_CULL_FACE_MODE); PUT(s, GL_FRONT_FACE);
    put_i_n(s, "polygon mode", GL_POLYGON_MODE, 1);
    PUT(s, GL_CLIP_ORIGIN); PUT(s, GL_CLIP_DEPTH_MODE); PUT(s, GL_STENCIL_WRITEMASK); PUT(s, GL_STENCIL_FUNC);
    PUT(s, GL_STENCIL_REF); PUT(s, GL_STENCIL_VALUE_MASK); PUT(s, GL_STENCIL_FAIL);
    PUT(s, GL_STENCIL_PASS_DEPTH_FAIL); PUT(s, GL_STENCIL_PASS_DEPTH_PASS); PUT(s, GL_STENCIL_BACK_WRITEMASK);
    PUT(s, GL_STENCIL_BACK_FUNC); PUT(s, GL_STENCIL_BACK_REF); PUT(s, GL_STENCIL_BACK_VALUE_MASK);
    PUT(s, GL_STENCIL_BACK_FAIL); PUT(s, GL_STENCIL_BACK_PASS_DEPTH_FAIL); PUT(s, GL_STENCIL_BACK_PASS_DEPTH_PASS);
    PUT(s, GL_LOGIC_OP_MODE);
    for (GLuint i = 0; i < 8; ++i) {
        static const struct { GLenum e; const char *n; } bl[] = {
            {GL_BLEND_SRC_RGB, "src_rgb"}, {GL_BLEND_DST_RGB, "dst_rgb"}, {GL_BLEND_SRC_ALPHA, "src_a"},
            {GL_BLEND_DST_ALPHA, "dst_a"}, {GL_BLEND_EQUATION_RGB, "eq_rgb"}, {GL_BLEND_EQUATION_ALPHA, "eq_a"}};
        for (size_t k = 0; k < sizeof bl / sizeof bl[0]; ++k) {
            GLint v = 0;
            glGetIntegeri_v(bl[k].e, i, &v);
            snprintf(b, sizeof b, "blend %s(%u)", bl[k].n, i);
            put(s, b, v);
        }
        GLboolean m[4];
        glGetBooleani_v(GL_COLOR_WRITEMASK, i, m);
        snprintf(b, sizeof b, "colour mask(%u)", i);
        put(s, b, m[0] | m[1] << 1 | m[2] << 2 | m[3] << 3);
        snprintf(b, sizeof b, "blend enabled(%u)", i);
        put(s, b, glIsEnabledi(GL_BLEND, i));
    }
    PUT(s, GL_PACK_ALIGNMENT); PUT(s, GL_PACK_ROW_LENGTH); PUT(s, GL_PACK_SKIP_ROWS); PUT(s, GL_PACK_SKIP_PIXELS);
    PUT(s, GL_UNPACK_ALIGNMENT); PUT(s, GL_UNPACK_ROW_LENGTH); PUT(s, GL_UNPACK_SKIP_ROWS);
    PUT(s, GL_UNPACK_SKIP_PIXELS); PUT(s, GL_UNPACK_IMAGE_HEIGHT);
    ON(s, GL_CULL_FACE); ON(s, GL_DEPTH_TEST); ON(s, GL_SCISSOR_TEST); ON(s, GL_STENCIL_TEST);
    ON(s, GL_PRIMITIVE_RESTART); ON(s, GL_PRIMITIVE_RESTART_FIXED_INDEX); ON(s, GL_RASTERIZER_DISCARD);
    ON(s, GL_FRAMEBUFFER_SRGB); ON(s, GL_POLYGON_OFFSET_FILL); ON(s, GL_DEPTH_CLAMP);
    ON(s, GL_SAMPLE_ALPHA_TO_COVERAGE); ON(s, GL_COLOR_LOGIC_OP); ON(s, GL_DITHER); ON(s, GL_MULTISAMPLE);
}

static void expect_same(const snap *before, const snap *after, const char *call)
{
    assert_int_equal(before->n, after->n);
    int bad = 0;
    for (int i = 0; i < before->n; ++i)
        if (before->v[i] != after->v[i]) {
            fprintf(stderr, "%s changed %s: %lld -> %lld\n", call, before->name[i], (long long)before->v[i],
                    (long long)after->v[i]);
            ++bad;
        }
    assert_int_equal(bad, 0);
}

/* ----------------------------------------------------------------- the hostile host */

typedef struct hostile {
    GLuint tex2d[UNITS], cube, tex3d, array, sampler, vao, prog, fbo, fbo_read, fbo_tex, rb, buf[4], image;
} hostile;

static GLuint tiny_program(void)
{
    static const char *vs = "#version 450\nvoid main() { gl_Position = vec4(0.0); }\n";
    static const char *fs = "#version 450\nout vec4 c; void main() { c = vec4(1.0); }\n";
    GLuint p = glCreateProgram(), s[2] = {glCreateShader(GL_VERTEX_SHADER), glCreateShader(GL_FRAGMENT_SHADER)};
    glShaderSource(s[0], 1, &vs, NULL);
    glShaderSource(s[1], 1, &fs, NULL);
    for (int i = 0; i < 2; ++i) {
        glCompileShader(s[i]);
        glAttachShader(p, s[i]);
    }
    glLinkProgram(p);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    assert_true(ok);
    glDeleteShader(s[0]);
    glDeleteShader(s[1]);
    return p;
}

static void hostile_make(hostile *h)
{
    memset(h, 0, sizeof *h);
    glCreateTextures(GL_TEXTURE_2D, UNITS, h->tex2d);
    for (int u = 0; u < UNITS; ++u)
        glTextureStorage2D(h->tex2d[u], 1, GL_RGBA8, 2, 2);
    glCreateTextures(GL_TEXTURE_CUBE_MAP, 1, &h->cube);
    glTextureStorage2D(h->cube, 1, GL_RGBA8, 2, 2);
    glCreateTextures(GL_TEXTURE_3D, 1, &h->tex3d);
    glTextureStorage3D(h->tex3d, 1, GL_RGBA8, 2, 2, 2);
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &h->array);
    glTextureStorage3D(h->array, 1, GL_RGBA8, 2, 2, 2);
    glCreateTextures(GL_TEXTURE_2D, 1, &h->image);
    glTextureStorage2D(h->image, 1, GL_RGBA32F, 4, 4);
    glCreateSamplers(1, &h->sampler); /* nearest, repeat, depth compare: wrong for every plugin read */
    glSamplerParameteri(h->sampler, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glSamplerParameteri(h->sampler, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glSamplerParameteri(h->sampler, GL_TEXTURE_WRAP_S, GL_MIRRORED_REPEAT);
    glSamplerParameteri(h->sampler, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glSamplerParameterf(h->sampler, GL_TEXTURE_LOD_BIAS, 4.f);
    glCreateVertexArrays(1, &h->vao);
    h->prog = tiny_program();
    glCreateTextures(GL_TEXTURE_2D, 1, &h->fbo_tex);
    glTextureStorage2D(h->fbo_tex, 1, GL_RGBA8, 1, 1);
    glCreateFramebuffers(1, &h->fbo);
    glNamedFramebufferTexture(h->fbo, GL_COLOR_ATTACHMENT0, h->fbo_tex, 0);
    glCreateFramebuffers(1, &h->fbo_read);
    glNamedFramebufferTexture(h->fbo_read, GL_COLOR_ATTACHMENT0, h->fbo_tex, 0);
    glCreateRenderbuffers(1, &h->rb);
    glNamedRenderbufferStorage(h->rb, GL_DEPTH_COMPONENT24, 1, 1);
    glCreateBuffers(4, h->buf);
    for (int i = 0; i < 4; ++i)
        glNamedBufferData(h->buf[i], 4096, NULL, GL_DYNAMIC_DRAW);
    glVertexArrayElementBuffer(h->vao, h->buf[3]);
}

static void hostile_free(hostile *h)
{
    glDeleteTextures(UNITS, h->tex2d);
    GLuint t[] = {h->cube, h->tex3d, h->array, h->image, h->fbo_tex};
    glDeleteTextures(5, t);
    glDeleteSamplers(1, &h->sampler);
    glDeleteVertexArrays(1, &h->vao);
    glDeleteProgram(h->prog);
    glDeleteFramebuffers(1, &h->fbo);
    glDeleteFramebuffers(1, &h->fbo_read);
    glDeleteRenderbuffers(1, &h->rb);
    glDeleteBuffers(4, h->buf);
}

static void hostile_apply(const hostile *h)
{
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, h->fbo);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, h->fbo_read);
    glBindRenderbuffer(GL_RENDERBUFFER, h->rb);
    glUseProgram(h->prog);
    glBindVertexArray(h->vao);
    glBindBuffer(GL_ARRAY_BUFFER, h->buf[0]);
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, h->buf[1]);
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, h->buf[2]);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, h->buf[0]); /* a read-back into client memory would go here */
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, h->buf[1]);
    glBindBuffer(GL_COPY_READ_BUFFER, h->buf[2]);
    glBindBuffer(GL_COPY_WRITE_BUFFER, h->buf[3]);
    for (GLuint u = 0; u < UNITS; ++u) {
        glActiveTexture(GL_TEXTURE0 + u);
        glBindTexture(GL_TEXTURE_2D, h->tex2d[u]);
        glBindTexture(GL_TEXTURE_CUBE_MAP, h->cube);
        glBindTexture(GL_TEXTURE_3D, h->tex3d);
        glBindTexture(GL_TEXTURE_2D_ARRAY, h->array);
        glBindSampler(u, h->sampler);
    }
    glActiveTexture(GL_TEXTURE5);
    for (GLuint i = 0; i < UBOS; ++i)
        glBindBufferRange(GL_UNIFORM_BUFFER, i, h->buf[i % 4], 256, 512);
    for (GLuint i = 0; i < SSBOS; ++i)
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, i, h->buf[(i + 1) % 4], 0, 1024);
    glBindBuffer(GL_UNIFORM_BUFFER, h->buf[2]);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, h->buf[3]);
    for (GLuint i = 0; i < IMAGES; ++i)
        glBindImageTexture(i, h->image, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glViewport(1, 2, 3, 4);
    glScissor(0, 0, 1, 1);
    glEnable(GL_SCISSOR_TEST);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_COLOR, GL_DST_ALPHA, GL_ZERO, GL_ONE_MINUS_SRC_COLOR);
    glBlendEquationSeparate(GL_FUNC_REVERSE_SUBTRACT, GL_MIN);
    glBlendFunci(1, GL_CONSTANT_COLOR, GL_SRC_ALPHA_SATURATE);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glColorMaski(2, GL_TRUE, GL_FALSE, GL_TRUE, GL_FALSE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_FALSE);
    glDepthRange(0.2, 0.7);
    glEnable(GL_STENCIL_TEST);
    glStencilFunc(GL_NEVER, 1, 0xff);
    glStencilMask(0x0f);
    glStencilOpSeparate(GL_FRONT, GL_INCR, GL_DECR_WRAP, GL_INVERT); /* the beams' pass sets these */
    glStencilFuncSeparate(GL_BACK, GL_GEQUAL, 3, 0x3c);
    glStencilMaskSeparate(GL_BACK, 0x70);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_FRONT_AND_BACK);
    glFrontFace(GL_CW);
    glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
    glEnable(GL_FRAMEBUFFER_SRGB);
    glClipControl(GL_UPPER_LEFT, GL_ZERO_TO_ONE);
    glEnable(GL_PRIMITIVE_RESTART);
    glEnable(GL_RASTERIZER_DISCARD);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(4.f, 100.f);
    glEnable(GL_DEPTH_CLAMP);
    glEnable(GL_SAMPLE_ALPHA_TO_COVERAGE);
    glEnable(GL_COLOR_LOGIC_OP);
    glLogicOp(GL_XOR);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glPixelStorei(GL_PACK_ROW_LENGTH, 7);
    glPixelStorei(GL_PACK_SKIP_ROWS, 2);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 8);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 5);
    glPixelStorei(GL_UNPACK_SKIP_PIXELS, 3);
    glPixelStorei(GL_UNPACK_IMAGE_HEIGHT, 9);
}

/* Back to GL's initial state for the host's renderer (it sets what it changes from it). */
static void gl_initial(void)
{
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    glUseProgram(0);
    glBindVertexArray(0);
    GLenum bufs[] = {GL_ARRAY_BUFFER, GL_DRAW_INDIRECT_BUFFER, GL_DISPATCH_INDIRECT_BUFFER, GL_PIXEL_PACK_BUFFER,
                     GL_PIXEL_UNPACK_BUFFER, GL_COPY_READ_BUFFER, GL_COPY_WRITE_BUFFER, GL_UNIFORM_BUFFER,
                     GL_SHADER_STORAGE_BUFFER};
    for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; ++i)
        glBindBuffer(bufs[i], 0);
    for (GLuint u = 0; u < UNITS; ++u) {
        glActiveTexture(GL_TEXTURE0 + u);
        glBindTexture(GL_TEXTURE_2D, 0);
        glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
        glBindTexture(GL_TEXTURE_3D, 0);
        glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
        glBindSampler(u, 0);
    }
    glActiveTexture(GL_TEXTURE0);
    for (GLuint i = 0; i < SSBOS; ++i) {
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, i, 0);
        if (i < UBOS)
            glBindBufferBase(GL_UNIFORM_BUFFER, i, 0);
        if (i < IMAGES)
            glBindImageTexture(i, 0, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R8);
    }
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ZERO);
    glBlendEquation(GL_FUNC_ADD);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDisable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDepthRange(0.0, 1.0);
    glDisable(GL_STENCIL_TEST);
    glStencilFunc(GL_ALWAYS, 0, 0xff);
    glStencilMask(0xffffffffu);
    glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
    glDisable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    glDisable(GL_FRAMEBUFFER_SRGB);
    glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
    GLenum off[] = {GL_PRIMITIVE_RESTART, GL_RASTERIZER_DISCARD, GL_POLYGON_OFFSET_FILL, GL_DEPTH_CLAMP,
                    GL_SAMPLE_ALPHA_TO_COVERAGE, GL_COLOR_LOGIC_OP};
    for (size_t i = 0; i < sizeof off / sizeof off[0]; ++i)
        glDisable(off[i]);
    glPolygonOffset(0.f, 0.f);
    glLogicOp(GL_COPY);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glPixelStorei(GL_PACK_ROW_LENGTH, 0);
    glPixelStorei(GL_PACK_SKIP_ROWS, 0);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glPixelStorei(GL_UNPACK_SKIP_PIXELS, 0);
    glPixelStorei(GL_UNPACK_IMAGE_HEIGHT, 0);
}

/* The plugin api the host calls, wrapped: hostile state and a snapshot before each call, the
 * snapshot compared after it, then GL's initial state back for the host. */
static const vfx_plugin_api *real_api;
static hostile *the_hostile;
static int wrapped_calls;

static void before(snap *s)
{
    hostile_apply(the_hostile);
    take(s);
}

static void after(const snap *s, const char *call)
{
    snap *a = malloc(sizeof *a);
    take(a);
    expect_same(s, a, call);
    if (wrapped_calls == 0)
        fprintf(stderr, "%d state values compared after each call\n", a->n);
    free(a);
    gl_initial();
    ++wrapped_calls;
}

static vfx_result w_update(vfx_context *ctx, double time, float dt)
{
    snap *s = malloc(sizeof *s);
    before(s);
    vfx_result r = real_api->update(ctx, time, dt);
    after(s, "update");
    free(s);
    return r;
}

static vfx_result w_render(vfx_context *ctx, const vfx_frame_view *frame)
{
    snap *s = malloc(sizeof *s);
    before(s);
    vfx_result r = real_api->render(ctx, frame);
    after(s, "render");
    free(s);
    return r;
}

static vfx_result w_read_raw(vfx_context *ctx, vfx_effect_kind effect, float *out, size_t count)
{
    snap *s = malloc(sizeof *s);
    before(s);
    vfx_result r = real_api->read_raw(ctx, effect, out, count);
    after(s, "read_raw");
    free(s);
    return r;
}

/* ----------------------------------------------------------------- runs */

typedef struct run_out {
    uint8_t rgba[W * H * 4];
    float water_raw[W * H];
} run_out;

static game_app *open_app(bool compat, test_log *log, game_demo *demo)
{
    game_app_desc d = {.mode = RT_GL_HEADLESS, .width = W, .height = H, .gl_compat = compat,
                       .logger = {test_log_fn, log}};
    game_app *app;
    if (game_app_create(&d, &app) != VFX_OK) {
        if (compat) /* no compatibility context here: the core runs still ran */
            return NULL;
        exit(VFX_TEST_SKIP);
    }
    assert_int_equal(game_demo_load(app, demo, NULL, 0), VFX_OK);
    return app;
}

static bool run(bool hostile_host, bool compat, run_out *out)
{
    test_log log = {0};
    game_demo demo;
    game_app *app = open_app(compat, &log, &demo);
    if (!app)
        return false;
    hostile h;
    vfx_plugin_api wrapped;
    if (hostile_host) {
        hostile_make(&h);
        the_hostile = &h;
        real_api = app->api;
        wrapped = *app->api;
        wrapped.update = w_update;
        wrapped.render = w_render;
        wrapped.read_raw = w_read_raw;
        app->api = &wrapped;
    }
    if (compat) { /* the context is what the test says it is */
        GLint mask = 0;
        glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &mask);
        assert_true(mask & GL_CONTEXT_COMPATIBILITY_PROFILE_BIT);
    }
    for (int f = 0; f < FRAMES; ++f) {
        game_demo_animate(app, &demo, 1.f / 60.f);
        assert_int_equal(game_app_frame(app, 1.f / 60.f), VFX_OK);
    }
    assert_int_equal(rt_renderer_read_rgba(app->renderer, out->rgba), VFX_OK);
    assert_int_equal(app->api->read_raw(app->ctx, VFX_EFFECT_WATER, out->water_raw, W * H), VFX_OK);
    assert_int_equal(log.errors, 0);
    if (hostile_host) {
        app->api = real_api;
        hostile_free(&h);
    }
    game_demo_free(app, &demo);
    game_app_destroy(app);
    return true;
}

/* Two runs of the same frames: the same image. Two clean runs themselves differ in a few water
 * distances by up to 2 ulps (9.5e-7 at the scene's ~4 m: the water's tile pass sums in the order
 * its atomics land; 63 of 746 water pixels in the worst of 8 runs), and an 8-bit colour may then
 * round the other way: distances must agree to 8 ulps (4 * FLT_EPSILON relative, 4x margin) and
 * colours to 1 level on at most 0.5% of the values. What a state leak does is far larger: a
 * culled composite loses the effect (water covers ~750 of the 5,184 pixels), a host sampler or
 * clip control moves every value. */
static void expect_same_image(const run_out *a, const run_out *b, const char *what)
{
    int lit = 0, rgba_diff = 0, max_rgba = 0, raw_diff = 0, raw_far = 0;
    for (int i = 0; i < W * H * 4; ++i) {
        int d = abs(a->rgba[i] - b->rgba[i]);
        rgba_diff += d != 0;
        max_rgba = d > max_rgba ? d : max_rgba;
    }
    double max_raw = 0;
    for (int i = 0; i < W * H; ++i) {
        double d = fabs((double)a->water_raw[i] - b->water_raw[i]);
        raw_diff += d != 0;
        raw_far += !(d <= 4 * FLT_EPSILON * fmax(1.0, fabs(a->water_raw[i])));
        lit += a->water_raw[i] >= 0;
        max_raw = d > max_raw ? d : max_raw;
    }
    fprintf(stderr, "%s: %d of %d rgba values differ (by %d at most), %d of %d water distances (by %g at "
            "most); water covers %d pixels\n", what, rgba_diff, W * H * 4, max_rgba, raw_diff, W * H, max_raw, lit);
    assert_true(lit > 100); /* the scene's water is in view: the comparison sees an effect */
    assert_int_equal(raw_far, 0);
    assert_true(max_rgba <= 1 && rgba_diff <= W * H * 4 / 200);
}

static run_out clean; /* the clean core host's run, made once for both tests */
static bool clean_made;

static const run_out *clean_run(void)
{
    if (!clean_made)
        run(false, false, &clean);
    clean_made = true;
    return &clean;
}

static void test_hostile_host(void **state)
{
    (void)state;
    run_out *hostile_run = malloc(sizeof *hostile_run);
    wrapped_calls = 0;
    run(true, false, hostile_run);
    assert_true(wrapped_calls >= 2 * FRAMES + 1);
    expect_same_image(clean_run(), hostile_run, "hostile host vs clean host");
    free(hostile_run);
}

static void test_compat_profile(void **state)
{
    (void)state;
    run_out *compat = malloc(sizeof *compat);
    if (!run(false, true, compat)) {
        free(compat);
        skip();
    }
    expect_same_image(clean_run(), compat, "compatibility profile vs core");
    free(compat);
}

/* vfx_gl_state_desc.skip_restore, read at create(), whose baseline pass is the call watched: with
 * it the host's hostile state is left changed (at least culling and the depth test, which the
 * baseline turns off), without it every value the test tracks reads as before. */
static int create_under_hostile(game_app *app, hostile *h, const vfx_gl_state_desc *gs, test_log *log)
{
    vfx_context_desc d = {.type = VFX_TYPE_CONTEXT_DESC, .next = gs, .gl_get_proc_address = test_gl_proc,
                          .user = log, .log = test_vfx_log_fn};
    snap *b = malloc(sizeof *b), *a = malloc(sizeof *a);
    b->n = a->n = 0;
    hostile_apply(h);
    take(b);
    vfx_context *ctx = NULL;
    assert_int_equal(app->api->create(&d, &ctx), VFX_OK);
    take(a);
    assert_int_equal(a->n, b->n);
    int changed = 0;
    for (int i = 0; i < b->n; ++i)
        changed += a->v[i] != b->v[i];
    if (!gs || !gs->skip_restore)
        expect_same(b, a, "create");
    else {
        int seen = 0;
        for (int i = 0; i < b->n; ++i)
            if (!strcmp(b->name[i], "enabled GL_CULL_FACE") || !strcmp(b->name[i], "enabled GL_DEPTH_TEST")) {
                assert_true(b->v[i] == 1 && a->v[i] == 0);
                ++seen;
            }
        assert_int_equal(seen, 2);
    }
    app->api->destroy(ctx);
    gl_initial();
    free(a);
    free(b);
    return changed;
}

static void test_skip_restore(void **state)
{
    (void)state;
    test_log log = {0};
    game_demo demo;
    game_app *app = open_app(false, &log, &demo);
    hostile h;
    hostile_make(&h);
    vfx_gl_state_desc keep = {.type = VFX_TYPE_GL_STATE_DESC}, skip = {.type = VFX_TYPE_GL_STATE_DESC, .skip_restore = 1};
    assert_int_equal(create_under_hostile(app, &h, NULL, &log), 0);
    assert_int_equal(create_under_hostile(app, &h, &keep, &log), 0);
    int changed = create_under_hostile(app, &h, &skip, &log);
    fprintf(stderr, "skip_restore: %d state values left changed by create\n", changed);
    assert_true(changed >= 2);
    assert_int_equal(log.errors, 0);
    hostile_free(&h);
    game_demo_free(app, &demo);
    game_app_destroy(app);
}

/* ----------------------------------------------------------------- the cost */

static double cpu_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t); /* the caller's thread: llvmpipe's workers left out */
    return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double call_ms; /* update + render CPU time of the frame being made */

static vfx_result t_update(vfx_context *ctx, double time, float dt)
{
    double t0 = cpu_ms();
    vfx_result r = real_api->update(ctx, time, dt);
    call_ms += cpu_ms() - t0;
    return r;
}

static vfx_result t_render(vfx_context *ctx, const vfx_frame_view *frame)
{
    double t0 = cpu_ms();
    vfx_result r = real_api->render(ctx, frame);
    call_ms += cpu_ms() - t0;
    return r;
}

/* The default scene through the game: update + render CPU time of the calling thread with the
 * save and restore (even frames) and without (odd), after 10 warm frames, medians. */
static int bench(int frames)
{
    test_log log = {0};
    game_demo demo;
    game_app *app = open_app(false, &log, &demo);
    double *t[2] = {calloc((size_t)frames, sizeof(double)), calloc((size_t)frames, sizeof(double))};
    int n[2] = {0, 0};
    real_api = app->api;
    vfx_plugin_api timed = *app->api;
    timed.update = t_update;
    timed.render = t_render;
    app->api = &timed;
    for (int f = -10; f < 2 * frames; ++f) {
        int off = f & 1;
        app->ctx->gl_skip_restore = off;
        call_ms = 0;
        game_demo_animate(app, &demo, 1.f / 60.f);
        if (game_app_frame(app, 1.f / 60.f))
            return 1;
        if (f >= 0)
            t[off][n[off]++] = call_ms;
    }
    for (int k = 0; k < 2; ++k)
        qsort(t[k], (size_t)n[k], sizeof(double), cmp_d);
    double with = t[0][n[0] / 2], without = t[1][n[1] / 2];
    printf("update+render CPU ms a frame (calling thread), medians of %d interleaved frames each, %ux%u "
           "default scene: with save/restore %.4f, without %.4f, difference %.4f (%.1f%%)\n", frames, W, H,
           with, without, with - without, 100 * (with - without) / without);
    app->api = real_api;
    free(t[0]);
    free(t[1]);
    game_demo_free(app, &demo);
    game_app_destroy(app);
    return 0;
}

/* The save + restore pair alone (what one API call adds), n times after a frame of the
 * default scene, in batches of 100: the median batch's time per pair. */
static int bench_pair(int n)
{
    test_log log = {0};
    game_demo demo;
    game_app *app = open_app(false, &log, &demo);
    game_demo_animate(app, &demo, 1.f / 60.f);
    if (game_app_frame(app, 1.f / 60.f))
        return 1;
    /* the plugin's table is still this thread's after its last call (gpu/gl.h) */
    volfx_gl_saved *s = malloc(sizeof *s);
    int batches = n / 100 > 0 ? n / 100 : 1;
    double *t = calloc((size_t)batches, sizeof(double));
    for (int b = 0; b < batches; ++b) {
        double t0 = cpu_ms();
        for (int i = 0; i < 100; ++i) {
            volfx_gl_state_save(s, false);
            volfx_gl_state_restore(s);
        }
        t[b] = (cpu_ms() - t0) / 100;
    }
    qsort(t, (size_t)batches, sizeof(double), cmp_d);
    printf("save + restore CPU us a call (calling thread), median of %d batches of 100: %.2f\n", batches,
           1e3 * t[batches / 2]);
    free(t);
    free(s);
    game_demo_free(app, &demo);
    game_app_destroy(app);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc == 3 && !strcmp(argv[1], "--bench"))
        return bench(atoi(argv[2]));
    if (argc == 3 && !strcmp(argv[1], "--bench-pair"))
        return bench_pair(atoi(argv[2]));
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hostile_host),
        cmocka_unit_test(test_compat_profile),
        cmocka_unit_test(test_skip_restore),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
