/* test_hardening.c — issue 28's outside attack, the classes that need an effect drawing through
 * the real plugin: TILE on a tile list longer than llvmpipe's loop budget (drew nothing and
 * counted every pixel as left), beams at the documented extremes of exposure and saturate_c (NaN:
 * the beam vanished), an out-of-memory target reported as what it is, and a frame view of
 * framebuffer 0 (the default framebuffer, which a surfaceless context does not have). */
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
#include <sys/resource.h>

#include "camera_ref.h"
#include "context.h"
#include "test_util.h"
#include "volfx_lab.h"
#include "water_ref.h"

typedef struct host {
    test_log log;
    float *x, *y, *z;
    uint32_t n;
    uint32_t method, refine;
    float h;        /* 0: 0.02 */
    vfx_struct_type beams_type; /* 0: VFX_TYPE_BEAMS_VIEW */
    vfx_lab_water lab;          /* chained into the water parameters: the method */
    vfx_beam beam;
    float saturate_c;
} host;

static uint32_t one_chunk(void *user) { return ((host *)user)->n ? 1u : 0u; }

static vfx_result chunk(void *user, uint32_t c, vfx_particle_view *out)
{
    (void)c;
    host *s = user;
    *out = (vfx_particle_view){.type = VFX_TYPE_PARTICLE_VIEW, .count = s->n,
                               .pos = {s->x, s->y, s->z}};
    return VFX_OK;
}

static vfx_result water_params(void *user, vfx_water_params *out)
{
    host *s = user;
    /* the method through the lab: the baselines (BRUTE, GRID) are lab methods */
    s->lab = (vfx_lab_water){.type = VFX_TYPE_LAB_WATER, .method = s->method};
    *out = (vfx_water_params){.type = VFX_TYPE_WATER_PARAMS, .next = &s->lab,
                              .h = s->h ? s->h : 0.02f, .refine_iters = s->refine};
    return VFX_OK;
}

static vfx_result beams_view(void *user, vfx_beams_view *out)
{
    host *s = user;
    if (out->type != VFX_TYPE_BEAMS_VIEW)
        return VFX_ERR_ABI;
    *out = (vfx_beams_view){.type = s->beams_type ? s->beams_type : VFX_TYPE_BEAMS_VIEW, .count = 1,
                            .saturate_c = s->saturate_c};
    out->beams = &s->beam;
    return VFX_OK;
}

typedef struct session {
    vfx_plugin_api api;
    vfx_context *ctx;
    vfx_context_desc hapi;
    GLuint fbo, col, scene;
    uint32_t w, h;
} session;

static void session_open(session *ss, host *s, uint32_t w, uint32_t h, GLenum fmt)
{
    memset(ss, 0, sizeof *ss);
    ss->hapi = (vfx_context_desc){.type = VFX_TYPE_CONTEXT_DESC, .gl_get_proc_address = test_gl_proc,
                              .user = s, .log = test_vfx_log_fn};
    if (s->n) {
        ss->hapi.particle_chunk_count = one_chunk;
        ss->hapi.particle_chunk = chunk;
        ss->hapi.water_params = water_params;
    } else {
        ss->hapi.beams = beams_view;
    }
    ss->api.type = VFX_TYPE_PLUGIN_API;
    assert_int_equal(vfx_plugin_entry(VFX_ABI_VERSION, NULL, &ss->api), VFX_OK);
    assert_int_equal(ss->api.create(&ss->hapi, &ss->ctx), VFX_OK);
    assert_int_equal(volfx_lab_attach(ss->ctx), VFX_OK); /* the lab's methods and bits */
    ss->ctx->debug.sync_counters = true;
    ss->w = w, ss->h = h;
    glCreateTextures(GL_TEXTURE_2D, 1, &ss->col);
    glTextureStorage2D(ss->col, 1, fmt, (GLsizei)w, (GLsizei)h);
    glCreateTextures(GL_TEXTURE_2D, 1, &ss->scene);
    glTextureStorage2D(ss->scene, 1, fmt, (GLsizei)w, (GLsizei)h);
    glCreateFramebuffers(1, &ss->fbo);
    glNamedFramebufferTexture(ss->fbo, GL_COLOR_ATTACHMENT0, ss->col, 0);
    const float black[4] = {0, 0, 0, 1};
    glClearTexImage(ss->col, 0, GL_RGBA, GL_FLOAT, black);
    glClearTexImage(ss->scene, 0, GL_RGBA, GL_FLOAT, black);
}

static void session_close(session *ss)
{
    ss->api.destroy(ss->ctx);
    glDeleteFramebuffers(1, &ss->fbo);
    GLuint t[] = {ss->col, ss->scene};
    glDeleteTextures(2, t);
}

static vfx_frame_view frame_of(const session *ss, const ref_camera *cam)
{
    vfx_frame_view fv = {.type = VFX_TYPE_FRAME_VIEW, .framebuffer = ss->fbo,
                         .color_texture = ss->scene, .width = (uint32_t)cam->width, .height = (uint32_t)cam->height,
                         .fov_y = (float)cam->fov_y, .near_plane = (float)cam->near_plane,
                         .far_plane = (float)cam->far_plane};
    for (int k = 0; k < 3; ++k) fv.eye[k] = (float)cam->eye[k];
    ref_camera_matrices(cam, fv.view, fv.proj);
    return fv;
}

static vfx_result session_frame(session *ss, const ref_camera *cam)
{
    vfx_frame_view fv = frame_of(ss, cam);
    vfx_result r = ss->api.update(ss->ctx, 0.0, 0.0f);
    return r ? r : ss->api.render(ss->ctx, &fv);
}

static double stat(session *ss, const char *name)
{
    vfx_stats st = {.type = VFX_TYPE_STATS};
    assert_int_equal(ss->api.get_stats(ss->ctx, &st), VFX_OK);
    for (uint32_t k = 0; k < st.count; ++k)
        if (!strcmp(st.entries[k].name, name)) return st.entries[k].value;
    return -1;
}

/* The float64 reference's distances of host s (isotropic, h/32 samples and bisection). */
static void reference(const host *s, const ref_camera *cam, float *out)
{
    double fwd[3], right[3], up[3];
    ref_camera_basis(cam, fwd, right, up);
    ref_water_camera rc = {{cam->eye[0], cam->eye[1], cam->eye[2]}, {fwd[0], fwd[1], fwd[2]}, {up[0], up[1], up[2]},
                           cam->fov_y, (uint32_t)cam->width, (uint32_t)cam->height};
    ref_water_params rp = ref_water_default_params();
    rp.h = s->h ? s->h : 0.02;
    rp.step = rp.h / 32;
    char err[256];
    assert_int_equal(ref_water_render(&rc, s->x, s->y, s->z, s->n, &rp, out, NULL, NULL, err), 0);
}

/* 42^3 = 74,088 particles at a spacing of h/2 in a cube 0.41 wide, seen whole by one 8x8 tile:
 * every pixel's list holds all of them, more than the 65,535 loop iterations llvmpipe gives one
 * shader invocation (all loops together; Mesa gallivm's loop limiter), after which every loop
 * ends early without a word. The attack's case (262,144 particles in a 0.8 box at 96x64: TILE
 * 46-54 water pixels, GRID 144, TILE 0 with temporal reuse and the reduced resolution off) is
 * the same limit at a size that takes 20 s here. Before: 0 found, every pixel counted as left,
 * 0 undecided, nothing logged. Now each pixel whose loops the driver may have cut is counted
 * undecided and a warning says why; no pixel is drawn that the float64 reference does not
 * have; GRID (short cell lists) draws the reference's pixels. On a driver without the limit
 * (any GPU) TILE draws them: then the first branch below holds trivially with 0 undecided. */
static void test_tile_loop_budget(void **state)
{
    (void)state;
    host s = {0};
    const uint32_t side = 42;
    s.n = side * side * side;
    s.x = malloc(s.n * 4), s.y = malloc(s.n * 4), s.z = malloc(s.n * 4);
    for (uint32_t i = 0; i < s.n; ++i) {
        s.x[i] = 0.01f * (float)(i % side) - 0.205f;
        s.y[i] = 0.01f * (float)(i / side % side) - 0.205f;
        s.z[i] = 0.01f * (float)(i / side / side) - 0.205f;
    }
    const ref_camera cam = {{0.3, 0.4, 1.5}, {0, 0, 0}, {0, 1, 0}, 0.6, 8, 8, 0.1, 50};
    float ref[64], tile[64], grid[64];
    reference(&s, &cam, ref);
    int ref_hits = 0;
    for (int i = 0; i < 64; ++i) ref_hits += ref[i] >= 0;
    assert_true(ref_hits >= 8); /* the cube covers about a fifth of the 64 pixels */
    session ss;
    s.method = VFX_WATER_METHOD_TILE;
    session_open(&ss, &s, 8, 8, GL_RGBA8);
    assert_int_equal(session_frame(&ss, &cam), VFX_OK);
    assert_int_equal(ss.api.read_raw(ss.ctx, VFX_EFFECT_WATER, tile, 64), VFX_OK);
    double found = stat(&ss, "water.pixels_found"), undecided = stat(&ss, "water.pixels_undecided");
    print_message("TILE: found %.0f, undecided %.0f, left %.0f, reference %d; log: %s\n", found, undecided,
                  stat(&ss, "water.pixels_left"), ref_hits, s.log.last);
    int false_hits = 0, missed = 0;
    for (int i = 0; i < 64; ++i) false_hits += tile[i] >= 0 && ref[i] < 0, missed += tile[i] < 0 && ref[i] >= 0;
    assert_int_equal(false_hits, 0);
    /* every reference pixel TILE did not draw is counted undecided (none silently "left") */
    assert_true(undecided >= missed);
    if (missed) {
        assert_true(test_log_is(&s.log, VFX_LOG_ID_WATER_UNDECIDED_PIXELS, "65,535 loop iterations"));
    }
    session_close(&ss);
    if (missed) {
        /* without the tests' counter sync (as a game runs): the warning comes with frame 1 (it
         * came from frame 2, the counters' ring a frame late, so a one-frame run said nothing) */
        s.log = (test_log){0};
        session_open(&ss, &s, 8, 8, GL_RGBA8);
        ss.ctx->debug.sync_counters = false;
        assert_int_equal(session_frame(&ss, &cam), VFX_OK);
        assert_true(test_log_is(&s.log, VFX_LOG_ID_WATER_UNDECIDED_PIXELS, "in frame"));
        session_close(&ss);
    }
    s.method = VFX_WATER_METHOD_GRID;
    s.log = (test_log){0};
    session_open(&ss, &s, 8, 8, GL_RGBA8);
    assert_int_equal(session_frame(&ss, &cam), VFX_OK);
    assert_int_equal(ss.api.read_raw(ss.ctx, VFX_EFFECT_WATER, grid, 64), VFX_OK);
    int agree = 0;
    for (int i = 0; i < 64; ++i) agree += (grid[i] >= 0) == (ref[i] >= 0);
    print_message("GRID: %d of 64 pixels agree with the reference\n", agree);
    /* one grazing silhouette pixel may differ (the reference's h/32 samples against GRID's step) */
    assert_true(agree >= 63);
    session_close(&ss);
    free(s.x), free(s.y), free(s.z);
}

/* Reads the RGBA16F output; returns the largest red value and counts non-finite components. */
static float read_out(const session *ss, int *nonfinite)
{
    size_t n = (size_t)ss->w * ss->h * 4;
    float *px = malloc(n * 4);
    glGetTextureImage(ss->col, 0, GL_RGBA, GL_FLOAT, (GLsizei)(n * 4), px);
    float m = 0;
    *nonfinite = 0;
    for (size_t i = 0; i < n; ++i) {
        if (!isfinite(px[i])) ++*nonfinite;
        else if (i % 4 == 0 && px[i] > m) m = px[i];
    }
    free(px);
    return m;
}

/* The documented extremes: exposure -64..64 stops, saturate_c (0, 1e6]. exposure 63/64 and c
 * 1e-30 made the ramp's x * x Inf and x^2 / (x^2 + 9) NaN: the beam vanished; 62 was white. Now
 * every gain gives a finite frame (RGBA16F, where an Inf or NaN would show) and a beam at least
 * as bright as at exposure 0; -64 and c 1e6 give a finite, dim one. */
static void test_beams_extreme_gain(void **state)
{
    (void)state;
    const ref_camera cam = {{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.8, 32, 24, 0.1, 100};
    const struct { float exposure, c; int bright; } cases[] = {
        {0, 1, 0}, {62, 1, 1}, {63, 1, 1}, {64, 1, 1}, {0, 1e-30f, 1}, {64, 1e-30f, 1}, {-64, 1, -1}, {0, 1e6f, -1},
    };
    float base = 0;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        host s = {0};
        s.beam = (vfx_beam){.type = VFX_TYPE_BEAM, .head = {-1, 0, 0}, .dir = {1, 0, 0}, .length = 2, .radius = 0.5f, .a = 0.05f,
                                    .b = 0.03f, .eps = 0.02f, .color = {1, 0.5f, 0.2f, 1},
                             .exposure = cases[k].exposure};
        s.saturate_c = cases[k].c;
        session ss;
        session_open(&ss, &s, 32, 24, GL_RGBA16F);
        assert_int_equal(session_frame(&ss, &cam), VFX_OK);
        int bad;
        float m = read_out(&ss, &bad);
        print_message("exposure %g, c %g: brightest red %g, %d non-finite\n", (double)cases[k].exposure,
                      (double)cases[k].c, (double)m, bad);
        assert_int_equal(bad, 0);
        if (k == 0) base = m;
        assert_true(base > 0.05f);
        if (cases[k].bright > 0) assert_true(m >= base);
        if (cases[k].bright < 0) assert_true(m < base);
        session_close(&ss);
    }
}

static host beam_host(void)
{
    host s = {0};
    s.beam = (vfx_beam){.type = VFX_TYPE_BEAM, .head = {-1, 0, 0}, .dir = {1, 0, 0}, .length = 2, .radius = 0.5f, .a = 0.05f,
                                .b = 0.03f, .eps = 0.02f};
    return s;
}

/* Framebuffer 0 names the default framebuffer, which the surfaceless context here does not have:
 * refused naming the field (before: "beams render: GL_INVALID_FRAMEBUFFER_OPERATION", no field),
 * no GL error left behind, and the next frame into a framebuffer object draws. */
static void test_framebuffer_zero(void **state)
{
    (void)state;
    const ref_camera cam = {{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.8, 16, 16, 0.1, 100};
    host s = beam_host();
    session ss;
    session_open(&ss, &s, 16, 16, GL_RGBA8);
    vfx_frame_view fv = frame_of(&ss, &cam);
    fv.framebuffer = 0;
    assert_int_equal(ss.api.update(ss.ctx, 0.0, 0.0f), VFX_OK);
    vfx_result r = ss.api.render(ss.ctx, &fv);
    print_message("framebuffer 0: %d %s\n", r, ss.api.last_error(ss.ctx, NULL));
    assert_int_equal(r, VFX_ERR_INVALID_ARGUMENT);
    assert_true(test_last_error_is(&ss.api, ss.ctx, VFX_LOG_ID_FRAME_VIEW, "framebuffer 0 is the default framebuffer"));
    assert_int_equal(glGetError(), GL_NO_ERROR);
    assert_int_equal(session_frame(&ss, &cam), VFX_OK);
    session_close(&ss);
}

static size_t vm_size_bytes(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    size_t kb = 0;
    while (f && fgets(line, sizeof line, f))
        if (sscanf(line, "VmSize: %zu kB", &kb) == 1)
            break;
    if (f)
        fclose(f);
    return kb * 1024;
}

/* The attack's 16,384^2 frame ran out of memory in the effects' targets and was told "incomplete
 * framebuffer". Here the same failure at 4096x3072 (the beams' H, light and bloom targets, about
 * 170 MiB) under an address-space limit 64 MiB above what the process holds: the GL reports
 * GL_OUT_OF_MEMORY and the plugin says out of memory, naming the target and the size; after the
 * limit is lifted the context draws again. Skipped where the limit cannot be set. */
static void test_target_out_of_memory(void **state)
{
    (void)state;
#if defined(__SANITIZE_ADDRESS__)
    skip(); /* ASan's allocator aborts where the limit makes an allocation fail (it reserves terabytes) */
#endif
    const ref_camera small = {{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.8, 16, 16, 0.1, 100};
    ref_camera big = small;
    big.width = 4096, big.height = 3072;
    host s = beam_host();
    session ss;
    session_open(&ss, &s, 16, 16, GL_RGBA8);
    assert_int_equal(session_frame(&ss, &small), VFX_OK); /* programs built */
    GLuint tex, fbo; /* the host's own target of the big frame, made before the limit */
    glCreateTextures(GL_TEXTURE_2D, 1, &tex);
    glTextureStorage2D(tex, 1, GL_RGBA8, 4096, 3072);
    glCreateFramebuffers(1, &fbo);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, tex, 0);
    vfx_frame_view fv = frame_of(&ss, &big);
    fv.framebuffer = fbo, fv.color_texture = 0;
    struct rlimit old;
    assert_int_equal(getrlimit(RLIMIT_AS, &old), 0);
    size_t vm = vm_size_bytes();
    struct rlimit lim = {vm + (64u << 20), old.rlim_max};
    if (!vm || (old.rlim_max != RLIM_INFINITY && lim.rlim_cur > old.rlim_max) || setrlimit(RLIMIT_AS, &lim) != 0) {
        session_close(&ss);
        skip();
    }
    vfx_result r = ss.api.update(ss.ctx, 0.0, 0.0f);
    if (!r) r = ss.api.render(ss.ctx, &fv);
    setrlimit(RLIMIT_AS, &old);
    print_message("4096x3072 under a limit of VmSize + 64 MiB: %d %s\n", r, ss.api.last_error(ss.ctx, NULL));
    assert_int_equal(r, VFX_ERR_OUT_OF_MEMORY);
    vfx_log_id id = VFX_LOG_ID_NONE; /* host memory or GL memory: whichever ran out first */
    assert_non_null(strstr(ss.api.last_error(ss.ctx, &id), "4096x3072"));
    assert_true(id == VFX_LOG_ID_OUT_OF_MEMORY || id == VFX_LOG_ID_GPU_OUT_OF_MEMORY);
    while (glGetError() != GL_NO_ERROR) {}
    assert_int_equal(session_frame(&ss, &small), VFX_OK);
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &tex);
    session_close(&ss);
}

/* refine_iters 60..64 (documented 1..64): the attack saw 2.7% of a water body turn transparent
 * in patches, differing between runs. Not reproduced on this tree (TILE's and the paper's
 * refinements stop once the bracket closes or guard fa == fb; measured also on the default and
 * water-only scenes at 96x64); kept as a regression test: the paper's 1,000-particle layers at
 * 48x32 with 64 iterations (the documented maximum; 60 measured the same) in every method have
 * at most the holes and false hits of 3 iterations against the float64 reference, and two runs
 * find the same pixels at the same distances (to the atomics' summation order). */
static void test_refine_iters_high(void **state)
{
    (void)state;
    host s = {0};
    s.n = 1000;
    s.x = malloc(s.n * 4), s.y = malloc(s.n * 4), s.z = malloc(s.n * 4);
    ref_water_layers(s.n, 0.3, s.x, s.y, s.z);
    s.h = 0.61f;
    const ref_camera cam = {{0, 4.3, 8}, {0, 0.15, 0}, {0, 1, 0}, 0.9, 48, 32, 0.1, 100};
    enum { N = 48 * 32 };
    static float ref[N], d3[N], a[N], b[N];
    reference(&s, &cam, ref);
    const uint32_t methods[] = {VFX_WATER_METHOD_TILE, VFX_WATER_METHOD_GRID, VFX_WATER_METHOD_BRUTE,
                                VFX_WATER_METHOD_PAPER};
    for (int m = 0; m < 4; ++m) {
        s.method = methods[m];
        ref_water_error e3;
        for (int k = 0; k < 2; ++k) {
            const uint32_t iters[] = {3, 64};
            s.refine = iters[k];
            for (int run = 0; run < (k ? 2 : 1); ++run) {
                session ss;
                session_open(&ss, &s, 48, 32, GL_RGBA8);
                assert_int_equal(session_frame(&ss, &cam), VFX_OK);
                assert_int_equal(ss.api.read_raw(ss.ctx, VFX_EFFECT_WATER, k == 0 ? d3 : run ? b : a, N), VFX_OK);
                session_close(&ss);
            }
            ref_water_error e;
            assert_int_equal(ref_water_compare(k == 0 ? d3 : a, NULL, ref, NULL, N, 0.61, &e), 0);
            print_message("method %u, refine %u: ref hits %u, holes %.4f, false %.4f\n", methods[m], iters[k],
                          e.ref_hits, e.hole_rate, e.false_hit_rate);
            if (k == 0) {
                e3 = e;
                continue;
            }
            assert_true(e.ref_hits > 300);
            /* the same coverage as 3 iterations: the refinement moves a hit along its ray, it
             * never turns a found pixel into a miss (the attack's transparent patches) */
            assert_true(e.hole_rate <= e3.hole_rate && e.false_hit_rate <= e3.false_hit_rate);
            /* Two runs agree pixel for pixel on hit or miss; a hit's distance may differ in its
             * last bits, because TILE's and GRID's scatter order a slab's entries by atomics,
             * which changes the field's summation order (measured: 0 to 7.8e-7 h in three runs
             * under load; bit-for-bit equality failed once in CI-like conditions). 1e-4 h is
             * over 100x that and still far below a step of the march (h/8). */
            float worst = 0.f;
            for (int p = 0; p < N; ++p) {
                assert_int_equal(a[p] < 0.f, b[p] < 0.f);
                worst = fmaxf(worst, fabsf(a[p] - b[p]));
            }
            print_message("method %u: two runs differ by at most %.3g h\n", methods[m], worst / s.h);
            assert_true(worst <= 1e-4f * s.h);
        }
    }
    free(s.x), free(s.y), free(s.z);
}

/* Views of a struct version the plugin does not know (99) are refused at update with VFX_ERR_ABI
 * naming the version (issue 28 asked; the beams view is the case here, water params in
 * gl/frame_check), and the same context draws once the host answers a known version. */
static void test_unknown_view_version(void **state)
{
    (void)state;
    const ref_camera cam = {{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.8, 16, 16, 0.1, 100};
    host s = beam_host();
    s.beams_type = (vfx_struct_type)99;
    session ss;
    session_open(&ss, &s, 16, 16, GL_RGBA8);
    vfx_result r = session_frame(&ss, &cam);
    print_message("beams view of type 99: %d %s\n", r, ss.api.last_error(ss.ctx, NULL));
    assert_int_equal(r, VFX_ERR_ABI);
    assert_true(test_last_error_is(&ss.api, ss.ctx, VFX_LOG_ID_STRUCT_TYPE, "vfx_beams_view) has type 99"));
    s.beams_type = VFX_TYPE_NONE;
    assert_int_equal(session_frame(&ss, &cam), VFX_OK);
    session_close(&ss);
}

int main(void)
{
    rt_gl_context *gl = test_gl_or_skip();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tile_loop_budget),
        cmocka_unit_test(test_beams_extreme_gain),
        cmocka_unit_test(test_framebuffer_zero),
        cmocka_unit_test(test_target_out_of_memory),
        cmocka_unit_test(test_refine_iters_high),
        cmocka_unit_test(test_unknown_view_version),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    rt_gl_context_destroy(gl);
    return rc;
}
