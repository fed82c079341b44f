/* The effects layer (docs/integration.md "Effects layer"): a scene with all three effects (water
 * with spray, a beam across it, a tetrahedral volume) rendered by one context straight into the
 * host's framebuffer and by another into an RGBA16F layer, which is then composited over the
 * host's colour on the CPU, in double, with dst = layer.rgb + dst * (1 - layer.a): the two
 * images agree to the precision of the formats. Also: what the layer's alpha holds (1 on water,
 * 0 under beams alone, the opacity under the volume), an empty frame's cleared layer, and the
 * layer texture's checks. */
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

#include "context.h"
#include "test_particle_host.h"
#include "test_util.h"

#define W 96
#define H 64

typedef struct host {
    test_particle_host ph; /* first: the particles, and the log the plugin's user pointer reaches */
    vfx_beam beam;
    float points[12];
    uint32_t tet[4];
    float scalar[4];
    bool water, beams, volume;
} host;

static uint32_t chunk_count(void *user) { return ((host *)user)->water ? 1 : 0; }


static vfx_result beams_view(void *user, vfx_beams_view *out)
{
    host *h = user;
    if (!h->beams)
        return VFX_ERR_NOT_FOUND;
    out->count = 1;
    out->beams = &h->beam;
    return VFX_OK;
}

static uint32_t volume_count(void *user) { return ((host *)user)->volume ? 1 : 0; }

static vfx_result volume_view(void *user, uint32_t index, vfx_volume_view *out)
{
    host *h = user;
    (void)index;
    out->point_count = 4, out->tet_count = 1;
    out->points = h->points, out->tets = h->tet, out->scalar = h->scalar;
    out->workers = 1;
    out->revision = 1;
    return VFX_OK;
}

static void make_host(host *s)
{
    memset(s, 0, sizeof *s);
    const uint32_t nx = 14, ny = 6, nz = 10;
    const float origin[3] = {-0.55f, -0.3f, -0.3f};
    test_particle_host_lattice(&s->ph, nx, ny, nz, 0.05f, origin, 0.02f, 99);
    for (uint32_t i = 0; i < s->ph.n; ++i) {
        float top = (float)((i / nz) % ny) / (float)(ny - 1);
        s->ph.vx[i] = 2.5f * sinf(9.0f * s->ph.x[i]), s->ph.vy[i] = 3.5f * top * top, s->ph.vz[i] = 0.7f * cosf(5.0f * s->ph.z[i]);
    }
    /* a beam across the view in front of the water, partly over it */
    s->beam = (vfx_beam){.type = VFX_TYPE_BEAM, .head = {0.6f, 0.15f, 0.2f}, .length = 1.2f, .dir = {1, 0, 0}, .radius = 0.06f, .a = 1.0f,
                         .b = 0.6f, .eps = 0.01f, .color = {0.3f, 0.6f, 1.0f, 1.0f}};
    /* a tetrahedron on the right, partly over the water, the default transfer function */
    const float pts[12] = {0.1f, -0.35f, -0.2f, 0.7f, -0.35f, -0.1f, 0.35f, 0.35f, -0.15f, 0.4f, -0.2f, 0.35f};
    memcpy(s->points, pts, sizeof pts);
    for (uint32_t k = 0; k < 4; ++k) s->tet[k] = k;
    const float sc[4] = {0.2f, 1.0f, 0.6f, 0.9f};
    memcpy(s->scalar, sc, sizeof sc);
    s->water = s->beams = s->volume = true;
}

static void free_host(host *s) { test_particle_host_free(&s->ph); }

typedef struct session {
    vfx_plugin_api api;
    vfx_context *ctx;
    GLuint fbo, out, scene, layer;
    vfx_frame_view fv;
} session;

/* the host's scene colour: a pattern, in [0, 1.5] (an HDR host's colour passes 1) */
static void pattern(float *px)
{
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            float *p = px + 4 * (y * W + x);
            p[0] = 0.2f + 1.3f * (float)x / W, p[1] = 0.3f + 0.4f * (float)y / H, p[2] = ((x / 16 + y / 16) & 1) ? 0.6f : 0.3f;
            p[3] = 1.0f;
        }
}

static GLuint texture(GLenum fmt)
{
    GLuint t;
    glCreateTextures(GL_TEXTURE_2D, 1, &t);
    glTextureStorage2D(t, 1, fmt, W, H);
    return t;
}

static void session_open(session *ss, host *h, bool layer)
{
    memset(ss, 0, sizeof *ss);
    vfx_context_desc api = {.type = VFX_TYPE_CONTEXT_DESC, .gl_get_proc_address = test_gl_proc,
                        .user = h, .log = test_vfx_log_fn, .particle_chunk_count = chunk_count,
                        .particle_chunk = test_particle_host_chunk, .beams = beams_view, .volume_count = volume_count,
                        .volume = volume_view};
    ss->api.type = VFX_TYPE_PLUGIN_API;
    assert_int_equal(vfx_plugin_entry(VFX_ABI_VERSION, NULL, &ss->api), VFX_OK);
    assert_int_equal(ss->api.create(&api, &ss->ctx), VFX_OK);
    ss->out = texture(GL_RGBA16F);
    ss->scene = texture(GL_RGBA16F);
    float *px = malloc(sizeof(float) * 4 * W * H);
    pattern(px);
    glTextureSubImage2D(ss->scene, 0, 0, 0, W, H, GL_RGBA, GL_FLOAT, px);
    glTextureSubImage2D(ss->out, 0, 0, 0, W, H, GL_RGBA, GL_FLOAT, px);
    free(px);
    glCreateFramebuffers(1, &ss->fbo);
    glNamedFramebufferTexture(ss->fbo, GL_COLOR_ATTACHMENT0, ss->out, 0);
    if (layer)
        ss->layer = texture(GL_RGBA16F);
    ss->fv = (vfx_frame_view){.type = VFX_TYPE_FRAME_VIEW, .framebuffer = layer ? 0 : ss->fbo,
                              .color_texture = ss->scene, .width = W, .height = H, .color_hdr = 1,
                              .layer_texture = ss->layer};
    const float eye[3] = {0.0f, 0.5f, 1.6f};
    test_frame_view_look(&ss->fv, eye, 0.3f);
}

static void session_close(session *ss)
{
    ss->api.destroy(ss->ctx);
    glDeleteFramebuffers(1, &ss->fbo);
    GLuint t[] = {ss->out, ss->scene, ss->layer};
    glDeleteTextures(ss->layer ? 3 : 2, t);
}

#define FRAMES 3
/* FRAMES frames; the last frame's host image (direct) or layer (layered) as floats */
static void render(host *h, bool layer, float *out)
{
    session ss;
    session_open(&ss, h, layer);
    for (int f = 0; f < FRAMES; ++f) {
        /* the host draws its scene anew each frame: its colour into its framebuffer */
        glCopyImageSubData(ss.scene, GL_TEXTURE_2D, 0, 0, 0, 0, ss.out, GL_TEXTURE_2D, 0, 0, 0, 0, W, H, 1);
        assert_int_equal(ss.api.update(ss.ctx, f / 60.0, 1.0f / 60.0f), VFX_OK);
        if (ss.api.render(ss.ctx, &ss.fv) != VFX_OK)
            fail_msg("render: %s", ss.api.last_error(ss.ctx, NULL));
    }
    glGetTextureImage(layer ? ss.layer : ss.out, 0, GL_RGBA, GL_FLOAT, sizeof(float) * 4 * W * H, out);
    session_close(&ss);
}

/* The direct image against the layer composited over the host's colour. Both sides round to
 * RGBA16F (11 significant bits: relative error <= 2^-11 per rounding): the direct image at each
 * effect's blend into the host's target (water write, volume over, beams add, spray over), the
 * layer at the same blends into it, then once more where the host composites (here in double,
 * from the pattern stored as half). A value v thus differs by at most ~4 roundings of 2^-11 |v|
 * on either side: the bound is 8 x 2^-11 x max(|v|, 2^-4) per channel (the floor covers the
 * absolute error of terms that cancel, as the over's dst x (1 - a)); measured worst: 0.53 of it.
 * The GPU's own freedom (TILE's list scatter and the spray's blending run in atomic order: on
 * llvmpipe two direct runs are identical, LAYER_TWICE=1, but a GPU may order them otherwise) is
 * allowed in at most 1% of the channels. A wrong alpha (the beams' 0 made 0.2) fails 18,432. */
static void test_layer_equals_direct(void **state)
{
    (void)state;
    host h;
    make_host(&h);
    float *direct = malloc(sizeof(float) * 4 * W * H), *layer = malloc(sizeof(float) * 4 * W * H);
    float *bg = malloc(sizeof(float) * 4 * W * H);
    render(&h, false, direct);
    render(&h, getenv("LAYER_TWICE") == NULL, layer); /* LAYER_TWICE: direct twice, the paths' own spread */
    /* the pattern as the host's RGBA16F texture holds it */
    GLuint t = texture(GL_RGBA16F);
    pattern(bg);
    glTextureSubImage2D(t, 0, 0, 0, W, H, GL_RGBA, GL_FLOAT, bg);
    glGetTextureImage(t, 0, GL_RGBA, GL_FLOAT, sizeof(float) * 4 * W * H, bg);
    glDeleteTextures(1, &t);
    uint32_t off = 0, opaque = 0, additive = 0, partial = 0;
    double worst = 0;
    for (int p = 0; p < W * H; ++p) {
        double a = layer[4 * p + 3];
        bool changed = false;
        for (int k = 0; k < 3; ++k) {
            double comp = layer[4 * p + k] + bg[4 * p + k] * (1.0 - a), d = direct[4 * p + k];
            double tol = 8.0 * ldexp(1.0, -11) * fmax(fabs(d), 0.0625);
            worst = fmax(worst, fabs(comp - d) / tol);
            off += fabs(comp - d) > tol;
            changed = changed || fabs(d - bg[4 * p + k]) > 1e-3;
        }
        opaque += a > 0.999;
        additive += changed && a == 0.0;
        partial += a > 0.01 && a < 0.99;
    }
    printf("layer: %u opaque, %u additive-only, %u partial pixels; %u channels off (worst %.2f x tolerance)\n", opaque,
           additive, partial, off, worst);
    /* every effect shows, with the alpha it is documented to have */
    assert_true(opaque > W * H / 20);   /* water: alpha 1 */
    assert_true(additive > W * H / 50); /* beams (and their bloom) alone: alpha 0 */
    assert_true(partial > W * H / 100); /* the volume: its opacity */
    assert_true(off <= 3u * W * H / 100); /* 1% of the 3 W H channels */
    free(direct), free(layer), free(bg);
    free_host(&h);
}

/* Nothing to draw (no effect present): the layer is still cleared to transparent black. */
static void test_empty_frame_clears(void **state)
{
    (void)state;
    host h;
    make_host(&h);
    session ss;
    session_open(&ss, &h, true);
    const float junk[4] = {0.5f, 0.25f, 1.0f, 1.0f};
    glClearTexImage(ss.layer, 0, GL_RGBA, GL_FLOAT, junk);
    h.water = h.beams = h.volume = false;
    assert_int_equal(ss.api.update(ss.ctx, 0.0, 1.0f / 60.0f), VFX_OK);
    assert_int_equal(ss.api.render(ss.ctx, &ss.fv), VFX_OK);
    float *px = malloc(sizeof(float) * 4 * W * H);
    glGetTextureImage(ss.layer, 0, GL_RGBA, GL_FLOAT, sizeof(float) * 4 * W * H, px);
    for (int i = 0; i < 4 * W * H; ++i)
        assert_true(px[i] == 0.0f);
    free(px);
    session_close(&ss);
    free_host(&h);
}

/* A layer texture that is no texture, of another target, format or size is refused by name. */
static void test_layer_refused(void **state)
{
    (void)state;
    host h;
    make_host(&h);
    GLuint rgba8 = texture(GL_RGBA8), small, cube;
    glCreateTextures(GL_TEXTURE_2D, 1, &small);
    glTextureStorage2D(small, 1, GL_RGBA16F, W / 2, H);
    glCreateTextures(GL_TEXTURE_CUBE_MAP, 1, &cube);
    glTextureStorage2D(cube, 1, GL_RGBA16F, 8, 8);
    const struct { GLuint tex; const char *what; } cases[] = {
        {rgba8 + 1000, "not a texture name"}, {rgba8, "GL_RGBA16F"}, {small, "must match"}, {cube, "GL_TEXTURE_CUBE_MAP"}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        session ss;
        session_open(&ss, &h, true);
        ss.fv.layer_texture = cases[k].tex;
        assert_int_equal(ss.api.update(ss.ctx, 0.0, 1.0f / 60.0f), VFX_OK);
        assert_int_equal(ss.api.render(ss.ctx, &ss.fv), VFX_ERR_INVALID_ARGUMENT);
        vfx_log_id id = VFX_LOG_ID_NONE;
        const char *msg = ss.api.last_error(ss.ctx, &id);
        assert_int_equal(id, VFX_LOG_ID_LAYER_TEXTURE);
        printf("case %zu: %s\n", k, msg);
        assert_non_null(strstr(msg, "layer_texture"));
        assert_non_null(strstr(msg, cases[k].what));
        session_close(&ss);
    }
    GLuint t[] = {rgba8, small, cube};
    glDeleteTextures(3, t);
    free_host(&h);
}

int main(void)
{
    rt_gl_context *gl = test_gl_or_skip();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_layer_equals_direct),
        cmocka_unit_test(test_empty_frame_clears),
        cmocka_unit_test(test_layer_refused),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    rt_gl_context_destroy(gl);
    return rc;
}
