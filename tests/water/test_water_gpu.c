/* GPU-resident particles (plugin/water/water_gather.c, shaders/water/gather.comp): the same
 * particles handed over as CPU columns and as a GL buffer (positions and velocities interleaved
 * in one buffer, at an offset that is not a multiple of the storage-buffer alignment) give the
 * same image and the same water raw dump, with methods TILE (anisotropic kernels, temporal reuse,
 * diffuse particles) and PAPER, over several frames (the first frame reads the GL buffer's box
 * back, the later ones use the box read back a few frames late); with a kernel column (6 floats
 * a particle, in a second buffer at its own offset and stride) TILE draws the same from kernel[]
 * and gpu_kernel; and every malformed buffer column is refused with the field's name. */
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
/* interleaved layout of the host's buffer: 16 bytes of something else first, then per particle
 * x y z, a float of padding, vx vy vz (28 bytes: neither 16 nor the alignment divides it) */
#define LEAD 16u
#define STRIDE 28u
/* the kernel buffer: 8 bytes first, then 6 floats and 2 of padding a particle */
#define KLEAD 8u
#define KSTRIDE 32u

typedef struct host {
    test_particle_host ph;      /* first: the CPU columns, the parameters and the log */
    float *base;                /* frame 0's positions, xyz a particle */
    float move[3];              /* what every particle moves by each frame */
    bool gpu;                   /* hand the GL buffer instead of the arrays */
    GLuint buf;
    vfx_gpu_column pos, vel;    /* the columns handed over (tests break them) */
    bool with_kernel;           /* hand the kernel column too (kernel[] or gpu_kernel) */
    bool kern_both;             /* hand kernel[] beside gpu_kernel (refused) */
    float *kern;                /* 6 floats a particle: xx xy xz yy yz zz */
    GLuint kbuf;
    vfx_gpu_column kcol;
} host;

static vfx_result chunk_view(void *user, uint32_t index, vfx_particle_view *out)
{
    host *h = user;
    (void)index;
    out->count = h->ph.n;
    if (!h->gpu) {
        out->pos[0] = h->ph.x, out->pos[1] = h->ph.y, out->pos[2] = h->ph.z;
        out->vel[0] = h->ph.vx, out->vel[1] = h->ph.vy, out->vel[2] = h->ph.vz;
    } else {
        out->gpu_pos = h->pos, out->gpu_vel = h->vel;
    }
    if (h->with_kernel && (!h->gpu || h->kern_both))
        out->kernel = h->kern;
    if (h->with_kernel && h->gpu)
        out->gpu_kernel = h->kcol;
    return VFX_OK;
}


/* A jittered slab of particles at spacing 0.05 with a shearing, rising velocity field (spray). */
static void make_host(host *s, uint32_t nx, uint32_t ny, uint32_t nz)
{
    memset(s, 0, sizeof *s);
    const float origin[3] = {-0.4f, -0.2f, -0.4f};
    test_particle_host_lattice(&s->ph, nx, ny, nz, 0.05f, origin, 0.02f, 777);
    for (uint32_t i = 0; i < s->ph.n; ++i) {
        float top = (float)((i / nz) % ny) / (float)(ny - 1);
        s->ph.vx[i] = 2.5f * sinf(9.0f * s->ph.x[i] + 4.0f * s->ph.z[i]);
        s->ph.vy[i] = 3.5f * top * top;
        s->ph.vz[i] = 0.7f * cosf(5.0f * s->ph.z[i] - 2.0f * s->ph.x[i]);
    }
    /* one particle NaN: skipped by both paths and counted */
    s->ph.y[7] = NAN;
    s->ph.params.type = VFX_TYPE_WATER_PARAMS;
    /* h left 0: estimated from the spacing, by both paths */
    s->base = malloc(3 * sizeof(float) * s->ph.n);
    for (uint32_t p = 0; p < s->ph.n; ++p)
        s->base[3 * p] = s->ph.x[p], s->base[3 * p + 1] = s->ph.y[p], s->base[3 * p + 2] = s->ph.z[p];
    glCreateBuffers(1, &s->buf);
    glNamedBufferStorage(s->buf, (GLsizeiptr)(LEAD + (size_t)s->ph.n * STRIDE), NULL, GL_DYNAMIC_STORAGE_BIT);
    s->pos = (vfx_gpu_column){s->buf, STRIDE, LEAD};
    s->vel = (vfx_gpu_column){s->buf, STRIDE, LEAD + 16u};
    /* kernels: diagonally dominant (eigenvalues within [0.6, 1.5]), stretched and sheared
     * differently from particle to particle, so a wrong component or particle shows */
    s->kern = malloc(6 * sizeof(float) * s->ph.n);
    size_t kbytes = KLEAD + (size_t)s->ph.n * KSTRIDE;
    unsigned char *img = calloc(1, kbytes);
    for (uint32_t p = 0; p < s->ph.n; ++p) {
        float *g = s->kern + 6 * (size_t)p;
        g[0] = 1.0f + 0.3f * sinf(0.7f * (float)p), g[1] = 0.1f * cosf(1.3f * (float)p), g[2] = 0.05f;
        g[3] = 0.9f + 0.2f * cosf(0.4f * (float)p), g[4] = -0.08f * sinf(2.1f * (float)p), g[5] = 1.1f;
        float rec[8] = {g[0], g[1], g[2], g[3], g[4], g[5], -7.0f, -7.0f}; /* padding never read */
        memcpy(img + KLEAD + (size_t)p * KSTRIDE, rec, sizeof rec);
    }
    glCreateBuffers(1, &s->kbuf);
    glNamedBufferStorage(s->kbuf, (GLsizeiptr)kbytes, img, 0);
    free(img);
    s->kcol = (vfx_gpu_column){s->kbuf, KSTRIDE, KLEAD};
}

/* Frame f's positions (frame 0's moved f times) into the columns and the interleaved buffer. */
static void host_frame(host *s, int f)
{
    size_t bytes = LEAD + (size_t)s->ph.n * STRIDE;
    unsigned char *img = calloc(1, bytes);
    for (uint32_t p = 0; p < s->ph.n; ++p) {
        s->ph.x[p] = s->base[3 * p] + (float)f * s->move[0];
        s->ph.y[p] = s->base[3 * p + 1] + (float)f * s->move[1];
        s->ph.z[p] = s->base[3 * p + 2] + (float)f * s->move[2];
        float rec[7] = {s->ph.x[p], s->ph.y[p], s->ph.z[p], -1.0f, s->ph.vx[p], s->ph.vy[p], s->ph.vz[p]};
        memcpy(img + LEAD + (size_t)p * STRIDE, rec, sizeof rec);
    }
    glNamedBufferSubData(s->buf, 0, (GLsizeiptr)bytes, img);
    free(img);
}

static void free_host(host *s)
{
    test_particle_host_free(&s->ph);
    free(s->base), free(s->kern);
    glDeleteBuffers(1, &s->buf);
    glDeleteBuffers(1, &s->kbuf);
}

typedef struct session {
    vfx_plugin_api api;
    vfx_context *ctx;
    GLuint fbo, col, scene, depth;
    vfx_frame_view fv;
} session;

static void session_open(session *ss, host *h)
{
    memset(ss, 0, sizeof *ss);
    vfx_context_desc api = test_particle_host_desc(&h->ph);
    api.particle_chunk = chunk_view; /* the CPU columns or the GL buffer's */
    ss->api.type = VFX_TYPE_PLUGIN_API;
    assert_int_equal(vfx_plugin_entry(VFX_ABI_VERSION, NULL, &ss->api), VFX_OK);
    assert_int_equal(ss->api.create(&api, &ss->ctx), VFX_OK);
    glCreateTextures(GL_TEXTURE_2D, 1, &ss->col);
    glTextureStorage2D(ss->col, 1, GL_RGBA8, W, H);
    glCreateFramebuffers(1, &ss->fbo);
    glNamedFramebufferTexture(ss->fbo, GL_COLOR_ATTACHMENT0, ss->col, 0);
    /* the host's scene colour: a pattern the refraction shows */
    uint8_t *pix = malloc(W * H * 4);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            uint8_t *p = pix + 4 * (y * W + x);
            p[0] = (uint8_t)((x * 8) & 255), p[1] = (uint8_t)((y * 12) & 255), p[2] = ((x / 8 + y / 8) & 1) ? 200 : 40, p[3] = 255;
        }
    glCreateTextures(GL_TEXTURE_2D, 1, &ss->scene);
    glTextureStorage2D(ss->scene, 1, GL_RGBA8, W, H);
    glTextureSubImage2D(ss->scene, 0, 0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, pix);
    free(pix);
    ss->fv = (vfx_frame_view){.type = VFX_TYPE_FRAME_VIEW, .framebuffer = ss->fbo,
                              .color_texture = ss->scene, .width = W, .height = H};
    /* looking down the -z axis, tilted 25 degrees down */
    const float eye[3] = {0.0f, 0.9f, 1.8f};
    test_frame_view_look(&ss->fv, eye, 0.44f);
}

static void session_close(session *ss)
{
    ss->api.destroy(ss->ctx);
    glDeleteFramebuffers(1, &ss->fbo);
    GLuint t[] = {ss->col, ss->scene};
    glDeleteTextures(2, t);
}

static double stat_of(session *ss, const char *name) { return test_stat(&ss->api, ss->ctx, name); }

typedef struct shot {
    uint8_t rgba[W * H * 4];
    float raw[W * H];
    double h, nan, lag, outside, gpu, diffuse;
} shot;

/* FRAMES frames (dt 1/60: the diffuse particles are generated and advected) of the host's
 * particles through the CPU or the GPU path; the last frame's image, raw dump and stats. */
#define FRAMES 6
static void render(host *h, bool gpu, uint32_t method, shot *out)
{
    h->gpu = gpu;
    h->ph.params.method = method;
    session ss;
    session_open(&ss, h);
    for (int f = 0; f < FRAMES; ++f) {
        host_frame(h, f);
        const float clear[4] = {0.1f, 0.2f, 0.3f, 1.0f};
        glClearNamedFramebufferfv(ss.fbo, GL_COLOR, 0, clear);
        assert_int_equal(ss.api.update(ss.ctx, f / 60.0, 1.0f / 60.0f), VFX_OK);
        if (ss.api.render(ss.ctx, &ss.fv) != VFX_OK)
            fail_msg("render: %s", ss.api.last_error(ss.ctx, NULL));
    }
    glGetTextureImage(ss.col, 0, GL_RGBA, GL_UNSIGNED_BYTE, sizeof out->rgba, out->rgba);
    assert_int_equal(ss.api.read_raw(ss.ctx, VFX_EFFECT_WATER, out->raw, W * H), VFX_OK);
    out->h = stat_of(&ss, "water.h");
    out->nan = stat_of(&ss, "water.nan_skipped");
    out->lag = stat_of(&ss, "water.gpu_box_lag");
    out->outside = stat_of(&ss, "water.gpu_box_outside");
    out->gpu = stat_of(&ss, "water.gpu_particles");
    out->diffuse = stat_of(&ss, "water.diffuse_spray") + stat_of(&ss, "water.diffuse_foam") +
                   stat_of(&ss, "water.diffuse_bubbles");
    session_close(&ss);
}

/* Both paths feed the passes the same bits: the gather copies each float unchanged into the same
 * columns the CPU upload fills (NaN included), the box and the non-finite count are the same
 * numbers (the first frame reads the gathered positions back and scans them as the CPU path
 * scans its arrays; later frames use that box, unmoved in a still scene), so every pass runs the
 * same program on the same input. What is left is the GPU's own freedom: TILE's list scatter and
 * the spray's blending run in atomic order, so the CPU path against itself differs between runs
 * by up to 1 ulp of a distance (2.4e-7 at distances near 2) in a few dozen pixels and by 2/255 in
 * a few colour pixels (measured: CPU_TWICE=1 runs this test's comparison on two CPU-path
 * sessions). The bounds are those plus margin: distances within 1e-6 (4 ulp), colours within
 * 2/255, at most 1% of the pixels different. A real difference (a wrong offset, stride or
 * component moves a particle by a spacing, 0.05) changes distances by ~1e-2 over many pixels.
 * Moving water: the GPU path's box is the late one grown by its motion, not the exact one, which
 * changes only where sums start (the neighbour grid's origin, TILE's depth slabs): the same
 * bounds on the size of the differences hold, not on their number. */
static void compare_paths(uint32_t method, bool moving, bool kernel)
{
    host h;
    make_host(&h, 16, 8, 16);
    h.with_kernel = kernel;
    if (moving) /* a fifth of the spacing a frame: the late box must be grown to cover it */
        h.move[0] = 0.01f, h.move[1] = 0.004f, h.move[2] = -0.006f;
    static shot cpu, gpu;
    render(&h, false, method, &cpu);
    render(&h, getenv("CPU_TWICE") == NULL, method, &gpu); /* CPU_TWICE: the CPU path's own spread */
    uint32_t water = 0, diff = 0, rawdiff = 0;
    int maxc = 0;
    double maxr = 0;
    for (int p = 0; p < W * H; ++p) {
        water += cpu.raw[p] >= 0;
        rawdiff += memcmp(&cpu.raw[p], &gpu.raw[p], sizeof(float)) != 0;
        diff += memcmp(cpu.rgba + 4 * p, gpu.rgba + 4 * p, 4) != 0;
        for (int k = 0; k < 4; ++k) {
            int d = abs((int)cpu.rgba[4 * p + k] - (int)gpu.rgba[4 * p + k]);
            maxc = d > maxc ? d : maxc;
        }
        if (cpu.raw[p] >= 0 || gpu.raw[p] >= 0) {
            double d = fabs((double)cpu.raw[p] - gpu.raw[p]);
            maxr = d > maxr ? d : maxr;
        }
    }
    printf("%s%s method %u: h %.4f, %u water pixels, %u raw and %u colour pixels differ, diffuse %g / %g, max colour %d raw %g, box lag %g\n", moving ? "moving" : "still", kernel ? " kernel column" : "", method, cpu.h,
           water, rawdiff, diff, cpu.diffuse, gpu.diffuse, maxc, maxr, gpu.lag);
    assert_true(cpu.h > 0);
    assert_true(cpu.h == gpu.h);
    assert_true(cpu.nan == 1 && gpu.nan == 1);
    if (!getenv("CPU_TWICE")) {
        assert_true(cpu.gpu == 0 && gpu.gpu == h.ph.n);
        /* the last frames used the late box, and no particle lay outside it */
        assert_true(gpu.lag >= 1);
        assert_true(gpu.outside == 0);
    }
    assert_true(water > W * H / 10); /* the water covers a good part of the view */
    if (method != VFX_WATER_METHOD_PAPER)
        assert_true(cpu.diffuse > 0 && cpu.diffuse == gpu.diffuse); /* the velocities reached the spray */
    assert_true(maxr <= 1e-6);
    assert_true(maxc <= 2);
    assert_true(diff <= W * H / 100);
    if (!moving) /* moving, the grown box reorders the neighbour grid's and the slabs' sums: any
                    water pixel may differ by an ulp or two (measured: 379 of 711, 2 ulp at most) */
        assert_true(rawdiff <= W * H / 100);
    free_host(&h);
}

static void test_tile(void **state) { (void)state; compare_paths(VFX_WATER_METHOD_TILE, false, false); }
static void test_paper(void **state) { (void)state; compare_paths(VFX_WATER_METHOD_PAPER, false, false); }
/* the host's kernels (TILE only: the paper method refuses a kernel column), as kernel[] and as
 * gpu_kernel: the gather copies the floats unchanged, so the same bounds hold */
static void test_tile_kernel(void **state) { (void)state; compare_paths(VFX_WATER_METHOD_TILE, false, true); }
/* moving water: the box the passes use lags and is grown by its recent motion; no particle falls
 * outside it and the image is the CPU path's */
static void test_tile_moving(void **state) { (void)state; compare_paths(VFX_WATER_METHOD_TILE, true, false); }
static void test_paper_moving(void **state) { (void)state; compare_paths(VFX_WATER_METHOD_PAPER, true, false); }

/* One broken field at a time: update refuses it with VFX_ERR_INVALID_ARGUMENT naming it. */
static void test_refused(void **state)
{
    (void)state;
    host h;
    make_host(&h, 4, 4, 4);
    h.gpu = true;
    GLuint never = 0;
    glGenBuffers(1, &never); /* a name, never bound: not a buffer object yet */
    const struct { vfx_gpu_column pos, vel; const char *field; } cases[] = {
        {{never, STRIDE, LEAD}, {0, 0, 0}, "gpu_pos.buffer"},
        {{h.buf + 1000, STRIDE, LEAD}, {0, 0, 0}, "gpu_pos.buffer"},
        {{h.buf, 8, LEAD}, {0, 0, 0}, "gpu_pos.stride"},
        {{h.buf, 30, 0}, {0, 0, 0}, "gpu_pos.stride"},
        {{h.buf, STRIDE, 2}, {0, 0, 0}, "gpu_pos.offset"},
        {{h.buf, STRIDE, LEAD + 20}, {0, 0, 0}, "GL_BUFFER_SIZE"},        /* the last particle passes the end */
        {{h.buf, STRIDE, 1ull << 40}, {0, 0, 0}, "GL_BUFFER_SIZE"},
        {{h.buf, STRIDE, LEAD}, {h.buf, STRIDE, LEAD + 20}, "gpu_vel.offset"},
        {{h.buf, STRIDE, LEAD}, {h.buf, 4, LEAD + 16}, "gpu_vel.stride"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        h.pos = cases[k].pos, h.vel = cases[k].vel;
        session ss;
        session_open(&ss, &h);
        vfx_result r = ss.api.update(ss.ctx, 0.0, 1.0f / 60.0f);
        vfx_log_id id = VFX_LOG_ID_NONE;
        const char *msg = ss.api.last_error(ss.ctx, &id);
        assert_int_equal(id, VFX_LOG_ID_GPU_COLUMN);
        printf("case %zu: %s\n", k, msg);
        assert_int_equal(r, VFX_ERR_INVALID_ARGUMENT);
        assert_non_null(strstr(msg, cases[k].field));
        session_close(&ss);
    }
    glDeleteBuffers(1, &never);
    free_host(&h);
}

/* The kernel column in a GL buffer: each malformed column refused naming gpu_kernel's field
 * (VFX_LOG_ID_GPU_COLUMN), kernel[] beside gpu_kernel refused, and a kernel that is not positive
 * definite refused naming the particle (the CPU column's check, on the gathered floats). */
static void test_kernel_refused(void **state)
{
    (void)state;
    host h;
    make_host(&h, 4, 4, 4);
    h.gpu = true, h.with_kernel = true;
    /* a copy of the kernel buffer with particle 5's xx negative (kbuf itself is immutable) */
    GLsizeiptr kbytes = KLEAD + (GLsizeiptr)h.ph.n * KSTRIDE;
    GLuint bad;
    glCreateBuffers(1, &bad);
    glNamedBufferStorage(bad, kbytes, NULL, GL_DYNAMIC_STORAGE_BIT);
    glCopyNamedBufferSubData(h.kbuf, bad, 0, 0, kbytes);
    const float minus = -1.0f;
    glNamedBufferSubData(bad, KLEAD + 5 * KSTRIDE, 4, &minus);
    const struct { vfx_gpu_column kcol; bool both; vfx_log_id id; const char *field; } cases[] = {
        {{h.kbuf, 20, KLEAD}, false, VFX_LOG_ID_GPU_COLUMN, "gpu_kernel.stride"}, /* shorter than 6 floats */
        {{h.kbuf, KSTRIDE, 2}, false, VFX_LOG_ID_GPU_COLUMN, "gpu_kernel.offset"},
        {{h.kbuf, KSTRIDE, KLEAD + 16}, false, VFX_LOG_ID_GPU_COLUMN, "GL_BUFFER_SIZE"},
        {{h.kbuf + 1000, KSTRIDE, KLEAD}, false, VFX_LOG_ID_GPU_COLUMN, "gpu_kernel.buffer"},
        {{h.kbuf, KSTRIDE, KLEAD}, true, VFX_LOG_ID_GPU_COLUMN, "names both kernel and gpu_kernel"},
        {{bad, KSTRIDE, KLEAD}, false, VFX_LOG_ID_WATER_PARTICLE_VALUE,
         "particle 5: kernel (vfx_particle_view.gpu_kernel) has eigenvalue"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        h.kcol = cases[k].kcol, h.kern_both = cases[k].both;
        session ss;
        session_open(&ss, &h);
        vfx_result r = ss.api.update(ss.ctx, 0.0, 1.0f / 60.0f);
        printf("kernel case %zu: %s\n", k, ss.api.last_error(ss.ctx, NULL));
        assert_int_equal(r, VFX_ERR_INVALID_ARGUMENT);
        assert_true(test_last_error_is(&ss.api, ss.ctx, cases[k].id, cases[k].field));
        session_close(&ss);
    }
    glDeleteBuffers(1, &bad);
    free_host(&h);
}

int main(void)
{
    rt_gl_context *gl = test_gl_or_skip();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tile),
        cmocka_unit_test(test_paper),
        cmocka_unit_test(test_tile_moving),
        cmocka_unit_test(test_paper_moving),
        cmocka_unit_test(test_refused),
        cmocka_unit_test(test_tile_kernel),
        cmocka_unit_test(test_kernel_refused),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    rt_gl_context_destroy(gl);
    return rc;
}
