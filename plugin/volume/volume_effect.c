/* volume_effect.c — translucent tetrahedral volumes in the plugin: the host's mesh is rendered
 * by the CPU cell-projection renderer (tetra/: ERT, subscreen termination, a persistent pool of
 * workers with weak sharing and load balancing), clipped per pixel by the ray distance to the
 * nearest opaque thing, then composited "over" the host frame.
 *
 * The clip distance comes from a GPU pass (host depth -> ray distance, min with the water's
 * distance) read back through a pixel-pack buffer and a fence: the CPU uses the previous
 * frame's distances, so it never waits for the GPU (the first frame after a resize waits
 * once). The renderer writes its image straight into a persistently mapped upload buffer (two,
 * alternating, each fenced) from which the texture is filled. When neither the mesh, the scalars, the transfer function, the camera nor the clip
 * distances changed since the last render, the render is skipped and the last image reused. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "gpu/pass.h"
#include "effect.h"
#include "param_ranges.h"
#include "lab_hooks.h"
#include "tet_render.h"

/* std140 mirror of shaders/volume/distance.frag's own block (the camera comes from the frame
 * gate's VolfxFrame block) */
typedef struct volume_dist_ubo {
    float water[4];  /* 1 when the water's distance is bound */
} volume_dist_ubo;

typedef struct volume_state {
    GLuint prog, tex;
    GLuint dist_prog, dist_tex, dist_fbo;
    GLuint pbo[2];
    GLsync fence[2];
    uint64_t frame;             /* frames rendered since the last resize */
    volfx_ubo ubo;
    uint32_t width, height;
    float *rgba;                /* the last image: width*height*4, premultiplied, row 0 = bottom */
    float *heap_rgba;           /* the image when the upload buffers cannot be mapped */
    GLuint up_pbo[2];           /* persistently mapped upload buffers the renderer writes into */
    float *up_map[2];
    GLsync up_fence[2];         /* the texture upload from up_pbo[k] is done once signalled */
    int up_slot;                /* buffer holding the last image */
    float *max_dist;            /* width*height ray distances to the nearest opaque surface */
    vfx_volume_view view;       /* the host's (next cleared) */
    volfx_lab_volume_off lab_off; /* what a vfx_lab_volume switched off (lab_hooks.h) */
    tet_mesh mesh;              /* points into the host's arrays (no copy) */
    uint64_t revision;
    float data_min, data_max;
    tet_tf_point tf_points[VFX_VOLUME_MAX_TRANSFER];
    tet_pool *pool;
    uint64_t last_key;          /* inputs of the image in rgba; 0 = none */
    uint64_t skipped;           /* renders skipped since creation */
    bool warned_many;
} volume_state;

/* tet_result's values are vfx_result's (tetra/tet_result.h), checked here where both are seen. */
_Static_assert(TET_OK == (int)VFX_OK && TET_ERR_INVALID_ARGUMENT == (int)VFX_ERR_INVALID_ARGUMENT &&
                   TET_ERR_OUT_OF_MEMORY == (int)VFX_ERR_OUT_OF_MEMORY &&
                   TET_ERR_FORMAT == (int)VFX_ERR_FORMAT && TET_ERR_NUMERIC == (int)VFX_ERR_NUMERIC,
               "tet_result and vfx_result codes differ");
static vfx_result from_tet(tet_result r) { return (vfx_result)r; }
/* The log id of a tet library failure: the plugin checks the view's fields before (ranges,
 * transfer function, indices), so what the library still refuses is memory or the mesh. */
static vfx_log_id tet_log_id(tet_result r)
{
    return r == TET_ERR_OUT_OF_MEMORY ? VFX_LOG_ID_OUT_OF_MEMORY : VFX_LOG_ID_VOLUME_MESH;
}

static bool volume_present(vfx_context *ctx)
{
    return ctx->host.volume_count && ctx->host.volume && ctx->host.volume_count(ctx->host.user) > 0;
}

static void release_targets(vfx_context *ctx, volume_state *s)
{
    for (int k = 0; k < 2; ++k) {
        if (s->fence[k])
            glDeleteSync(s->fence[k]);
        s->fence[k] = 0;
    }
    glDeleteBuffers(2, s->pbo);
    for (int k = 0; k < 2; ++k) {
        if (s->up_fence[k])
            glDeleteSync(s->up_fence[k]);
        s->up_fence[k] = 0;
        if (s->up_map[k])
            glUnmapNamedBuffer(s->up_pbo[k]);
        s->up_map[k] = NULL;
    }
    glDeleteBuffers(2, s->up_pbo);
    s->up_pbo[0] = s->up_pbo[1] = 0;
    glDeleteFramebuffers(1, &s->dist_fbo);
    glDeleteTextures(1, &s->dist_tex);
    glDeleteTextures(1, &s->tex);
    s->pbo[0] = s->pbo[1] = s->dist_fbo = s->dist_tex = s->tex = 0;
    volfx_free(ctx, s->heap_rgba);
    volfx_free(ctx, s->max_dist);
    s->rgba = s->heap_rgba = s->max_dist = NULL;
}

static void volume_destroy(vfx_context *ctx, void *state)
{
    volume_state *s = state;
    if (!s)
        return;
    release_targets(ctx, s);
    volfx_ubo_destroy(&s->ubo);
    tet_pool_destroy(s->pool);
    volfx_free(ctx, s);
}

static vfx_result volume_create(vfx_context *ctx, void **out)
{
    volume_state *s = volfx_alloc(ctx, sizeof *s);
    if (!s)
        return VFX_ERR_OUT_OF_MEMORY;
    s->prog = volfx_gpu_program(ctx, "common/fullscreen.vert", "volume/composite.frag", NULL);
    s->dist_prog = volfx_gpu_program(ctx, "common/fullscreen.vert", "volume/distance.frag", NULL);
    if (!s->prog || !s->dist_prog || !volfx_ubo_create(ctx, &s->ubo, sizeof(volume_dist_ubo), "volume.dist_ubo")) {
        volume_destroy(ctx, s);
        return VFX_ERR_GL;
    }
    *out = s;
    return VFX_OK;
}

static vfx_result volume_resize(vfx_context *ctx, void *state, uint32_t w, uint32_t h)
{
    volume_state *s = state;
    release_targets(ctx, s);
    glCreateTextures(GL_TEXTURE_2D, 1, &s->tex);
    glTextureStorage2D(s->tex, 1, GL_RGBA32F, (GLsizei)w, (GLsizei)h);
    volfx_gpu_label(GL_TEXTURE, s->tex, "volume.image");
    glCreateTextures(GL_TEXTURE_2D, 1, &s->dist_tex);
    glTextureStorage2D(s->dist_tex, 1, GL_R32F, (GLsizei)w, (GLsizei)h);
    volfx_gpu_label(GL_TEXTURE, s->dist_tex, "volume.distance");
    glCreateFramebuffers(1, &s->dist_fbo);
    glNamedFramebufferTexture(s->dist_fbo, GL_COLOR_ATTACHMENT0, s->dist_tex, 0);
    size_t n = (size_t)w * h;
    glCreateBuffers(2, s->pbo);
    for (int k = 0; k < 2; ++k) {
        glNamedBufferStorage(s->pbo[k], (GLsizeiptr)(n * sizeof(float)), NULL, GL_MAP_READ_BIT);
        volfx_gpu_label(GL_BUFFER, s->pbo[k], "volume.distance_readback");
    }
    /* the renderer writes straight into a mapped buffer and the texture is filled from it on
     * the GPU's side: no copy of the image through the driver on the frame path */
    const GLbitfield map = GL_MAP_READ_BIT | GL_MAP_WRITE_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
    glCreateBuffers(2, s->up_pbo);
    for (int k = 0; k < 2; ++k) {
        glNamedBufferStorage(s->up_pbo[k], (GLsizeiptr)(n * 4 * sizeof(float)), NULL, map);
        s->up_map[k] = glMapNamedBufferRange(s->up_pbo[k], 0, (GLsizeiptr)(n * 4 * sizeof(float)), map);
        volfx_gpu_label(GL_BUFFER, s->up_pbo[k], "volume.image_upload");
    }
    if (!s->up_map[0] || !s->up_map[1]) /* cannot map: render into memory, upload by copy */
        s->heap_rgba = volfx_alloc(ctx, n * 4 * sizeof(float));
    s->up_slot = 0;
    s->rgba = s->heap_rgba ? s->heap_rgba : s->up_map[0];
    s->max_dist = volfx_alloc(ctx, n * sizeof(float));
    vfx_result r = s->rgba && s->max_dist ? volfx_gpu_check_target(ctx, s->dist_fbo, "volume: distance target", w, h)
                   : volfx_fail(ctx, VFX_ERR_OUT_OF_MEMORY, VFX_LOG_ID_OUT_OF_MEMORY,
                                "volume: targets for %ux%u: out of memory (%.2f GB)", w, h,
                                (double)n * 64.0 / 1e9);
    if (r) {
        /* nothing half made stays: no mapped pointer, no error flag left for a later check */
        while (glGetError() != GL_NO_ERROR) {
        }
        release_targets(ctx, s);
        s->width = s->height = 0;
        return r;
    }
    memset(s->rgba, 0, n * 4 * sizeof(float));
    s->width = w, s->height = h;
    s->frame = 0;
    s->last_key = 0;
    return VFX_OK;
}

/* The host's view of volume 0 (a zeroed one with its type set); the host keeps the type. */
static vfx_result fetch_view(vfx_context *ctx, vfx_volume_view *v)
{
    memset(v, 0, sizeof *v);
    v->type = VFX_TYPE_VOLUME_VIEW;
    if (ctx->host.volume(ctx->host.user, 0, v) != VFX_OK)
        return volfx_fail(ctx, VFX_ERR_ABI, VFX_LOG_ID_HOST_CALLBACK,
                          "volume[0]: the host's volume callback failed");
    return volfx_check_type(ctx, v, VFX_TYPE_VOLUME_VIEW, "volume[0]: host volume view (vfx_volume_view)");
}

static vfx_result check_transfer(vfx_context *ctx, const vfx_volume_view *v)
{
    const vfx_volume_view *v1 = v;
    if (!v1->transfer_rgba)
        return VFX_OK;
    if (v1->transfer_count < 2 || v1->transfer_count > VFX_VOLUME_MAX_TRANSFER)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_VOLUME_TRANSFER,
                          "volume[0]: transfer function of %u entries (need 2..%u)",
                          v1->transfer_count, VFX_VOLUME_MAX_TRANSFER);
    for (uint32_t i = 0; i < 4 * v1->transfer_count; ++i)
        if (!isfinite(v1->transfer_rgba[i]) || (i % 4 == 3 && v1->transfer_rgba[i] < 0))
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_VOLUME_TRANSFER,
                              "volume[0]: transfer_rgba[%u] component %u is %g (finite, alpha >= 0)", i / 4, i % 4,
                              (double)v1->transfer_rgba[i]);
    if (v->transfer_scalar)
        for (uint32_t i = 0; i < v1->transfer_count; ++i) {
            float t = v->transfer_scalar[i];
            if (!(t >= 0 && t <= 1) || (i > 0 && !(t > v->transfer_scalar[i - 1])))
                return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_VOLUME_TRANSFER,
                                  "volume[0]: transfer_scalar[%u] = %g (need increasing values in [0, 1])", i,
                                  (double)t);
        }
    return VFX_OK;
}

/* The lab's struct in the view's chain (ablation switches of the renderer): read by the lab
 * library only; without one attached (libvolfx) it is refused by name. */
static vfx_result read_lab(vfx_context *ctx, const void *chain, volfx_lab_volume_off *off)
{
    const void *lab = volfx_chain_find(chain, VFX_TYPE_LAB_VOLUME);
    if (!lab)
        return VFX_OK;
    if (!ctx->lab)
        return volfx_fail(ctx, VFX_ERR_UNSUPPORTED, VFX_LOG_ID_STRUCT_TYPE,
                          "volume[0]: a vfx_lab_volume (type 0x%x) is chained into vfx_volume_view: lab structs are "
                          "read only with the lab library attached (volfx_lab_attach: tests and benches), not by "
                          "libvolfx", (unsigned)VFX_TYPE_LAB_VOLUME);
    return ctx->lab->volume_struct(ctx, lab, off);
}

static vfx_result volume_update(vfx_context *ctx, void *state, double time, float dt)
{
    (void)time, (void)dt;
    volume_state *s = state;
    uint32_t n = ctx->host.volume_count(ctx->host.user);
    if (n > 1 && !s->warned_many) {
        volfx_log(ctx, VFX_LOG_WARN, VFX_LOG_ID_VOLUME_EXTRA,
                  "volume: the host has %u volumes; only the first is drawn", n);
        s->warned_many = true;
    }
    vfx_volume_view v;
    vfx_result r = fetch_view(ctx, &v);
    if (r != VFX_OK)
        return r;
    volfx_lab_volume_off lab_off = {0};
    if ((r = read_lab(ctx, v.next, &lab_off)) != VFX_OK)
        return r;
    v.next = NULL;
    const vfx_volume_view *v1 = &v;
    if (!v1->points || !v1->tets || !v1->scalar || v1->point_count == 0 || v1->tet_count == 0)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_VOLUME_MESH,
                          "volume[0]: needs points, tets and scalar arrays and counts > 0 (%u points, %u tets)",
                          v1->point_count, v1->tet_count);
    /* every number against its documented range first (plugin/param_ranges.c): ert_threshold,
     * tiles (a DxD table per worker: 65,535 asked for 4.3e9 entries each), update_c, workers,
     * the transfer's count and method, the model matrix, the scalar domain */
    if ((r = volfx_volume_view_check_ranges(ctx, v1)) != VFX_OK)
        return r;
    if ((r = check_transfer(ctx, &v)) != VFX_OK)
        return r;
    /* tet indices are checked once per revision: the renderer trusts them */
    const vfx_volume_view *old = &s->view;
    if (v1->revision != s->revision || v1->tets != old->tets || v1->scalar != old->scalar ||
        v1->points != old->points || v1->point_count != old->point_count || v1->tet_count != old->tet_count) {
        for (uint64_t i = 0; i < (uint64_t)v1->tet_count * 4; ++i)
            if (v1->tets[i] >= v1->point_count)
                return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_VOLUME_MESH,
                                  "volume[0]: tet %llu uses point %u of %u",
                                  (unsigned long long)(i / 4), v1->tets[i], v1->point_count);
        s->data_min = INFINITY, s->data_max = -INFINITY;
        for (uint32_t i = 0; i < v1->point_count; ++i)
            if (isfinite(v1->scalar[i])) {
                s->data_min = fminf(s->data_min, v1->scalar[i]);
                s->data_max = fmaxf(s->data_max, v1->scalar[i]);
            }
        /* nothing finite: the renderer would skip every cell, and the empty range reached the
         * transfer function as a bad one (issue 28) */
        if (!(s->data_min <= s->data_max))
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_VOLUME_SCALAR,
                              "volume[0]: all %u scalars are NaN or infinite "
                              "(nothing to draw)", v1->point_count);
        s->revision = v1->revision;
        s->last_key = 0; /* new data: never reuse the old image, whatever the key says */
    }
    s->view = v;
    s->lab_off = lab_off;
    memset(&s->mesh, 0, sizeof s->mesh);
    s->mesh.point_count = v1->point_count;
    s->mesh.tet_count = v1->tet_count;
    s->mesh.points = (float *)v1->points; /* read only: the renderer takes a const mesh */
    s->mesh.tets = (uint32_t *)v1->tets;
    s->mesh.scalar = (float *)v1->scalar;
    return VFX_OK;
}

/* GPU: the ray distance to the host's depth (the renderer's own ray model: view depth from the
 * projection, times |(dx, dy, -1)|), min with the water's distance, into dist_tex, copied into
 * this frame's pack buffer and fenced. */
static void distance_pass(vfx_context *ctx, volume_state *s, const volfx_frame_targets *targets, int slot)
{
    volume_dist_ubo u = {{targets->water_dist ? 1.f : 0.f, 0, 0, 0}};
    volfx_ubo_update(&s->ubo, &u, sizeof u);
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "volume.distance", .framebuffer = s->dist_fbo,
                                             .width = s->width, .height = s->height});
    glUseProgram(s->dist_prog);
    volfx_ubo_bind(&s->ubo, 0);
    glBindTextureUnit(0, targets->scene_depth);
    glBindTextureUnit(1, targets->water_dist ? targets->water_dist : targets->scene_depth);
    volfx_gpu_fullscreen(ctx);
    glUseProgram(0);
    volfx_pass_end(ctx);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, s->pbo[slot]);
    glGetTextureImage(s->dist_tex, 0, GL_RED, GL_FLOAT, (GLsizei)((size_t)s->width * s->height * sizeof(float)), NULL);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    if (s->fence[slot])
        glDeleteSync(s->fence[slot]);
    s->fence[slot] = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
}

/* Copies the distances of slot into max_dist once its fence has signalled (waiting only when
 * it is this frame's slot, the first frame after a resize). */
static vfx_result read_distances(vfx_context *ctx, volume_state *s, int slot)
{
    const GLuint64 forever = 5000000000ull; /* 5 s */
    GLenum st = glClientWaitSync(s->fence[slot], GL_SYNC_FLUSH_COMMANDS_BIT, forever);
    if (st != GL_ALREADY_SIGNALED && st != GL_CONDITION_SATISFIED)
        return volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR,
                          "volume: distance readback did not complete (0x%x)", st);
    size_t bytes = (size_t)s->width * s->height * sizeof(float);
    const void *p = glMapNamedBufferRange(s->pbo[slot], 0, (GLsizeiptr)bytes, GL_MAP_READ_BIT);
    if (!p)
        return volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR, "volume: cannot map the distance readback");
    memcpy(s->max_dist, p, bytes);
    glUnmapNamedBuffer(s->pbo[slot]);
    return VFX_OK;
}

/* The renderer's transfer function from the view: the default ramp, or every table entry
 * (evenly spaced, or at transfer_scalar) over the domain. */
static void make_tf(volume_state *s, tet_tf *tf)
{
    const vfx_volume_view *v = &s->view;
    *tf = (tet_tf){.smin = v->scalar_min, .smax = v->scalar_max, .tau_lo = 0.2f, .tau_hi = 3.0f,
                   .color_lo = {0.1f, 0.3f, 0.9f}, .color_hi = {1.0f, 0.85f, 0.3f}};
    if (!(v->scalar_max > v->scalar_min))
        tf->smin = s->data_min, tf->smax = s->data_max > s->data_min ? s->data_max : s->data_min + 1;
    tf->method = s->view.transfer_method == VFX_VOLUME_TRANSFER_PREINTEGRATED ? TET_TF_PREINTEGRATED : TET_TF_EXACT;
    if (!v->transfer_rgba)
        return;
    const uint32_t n = v->transfer_count;
    const double range = (double)tf->smax - tf->smin;
    for (uint32_t i = 0; i < n; ++i) {
        tet_tf_point *p = &s->tf_points[i];
        double t = s->view.transfer_scalar ? s->view.transfer_scalar[i] : (double)i / (n - 1);
        /* evenly spaced: the ends exactly at the domain's ends (no rounding of smin + range) */
        bool end = !s->view.transfer_scalar && (i == 0 || i == n - 1);
        p->s = end ? (i == 0 ? tf->smin : tf->smax) : (float)(tf->smin + range * t);
        memcpy(p->rgb, v->transfer_rgba + 4 * i, sizeof p->rgb);
        p->tau = v->transfer_rgba[4 * i + 3];
    }
    /* a domain so narrow that float rounding merges breakpoints: keep them increasing */
    for (uint32_t i = 1; i < n; ++i)
        if (!(s->tf_points[i].s > s->tf_points[i - 1].s))
            s->tf_points[i].s = nextafterf(s->tf_points[i - 1].s, INFINITY);
    tf->points = s->tf_points;
    tf->count = (int)n;
}

static uint64_t hash_bytes(uint64_t h, const void *data, size_t n)
{
    const unsigned char *b = data;
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        uint64_t w;
        memcpy(&w, b + i, sizeof w);
        h = (h ^ w) * 0x9e3779b97f4a7c15ull;
        h ^= h >> 31;
    }
    for (; i < n; ++i)
        h = (h ^ b[i]) * 0x100000001b3ull;
    return h;
}

/* Everything the image depends on besides the mesh arrays (whose changes bump the revision). */
static uint64_t render_key(const volume_state *s, const tet_camera *cam, const tet_tf *tf, const tet_options *o)
{
    const vfx_volume_view *v = &s->view;
    uint64_t h = 0x51ed270b0a1f3c5dull;
    const void *ptrs[3] = {v->points, v->tets, v->scalar};
    h = hash_bytes(h, &v->revision, sizeof v->revision);
    h = hash_bytes(h, ptrs, sizeof ptrs);
    h = hash_bytes(h, cam, sizeof *cam);
    h = hash_bytes(h, tf, offsetof(tet_tf, points));
    h = hash_bytes(h, &tf->count, sizeof tf->count);
    h = hash_bytes(h, &tf->method, sizeof tf->method);
    if (tf->count)
        h = hash_bytes(h, tf->points, (size_t)tf->count * sizeof *tf->points);
    tet_options oo = *o;
    oo.max_dist = NULL;
    h = hash_bytes(h, &oo, sizeof oo);
    h = hash_bytes(h, s->max_dist, (size_t)s->width * s->height * sizeof(float));
    return h ? h : 1;
}

static vfx_result volume_render(vfx_context *ctx, void *state, volfx_frame_targets *targets)
{
    volume_state *s = state;
    const vfx_volume_view *v = &s->view;
    /* this frame's distances go to one pack buffer; the render uses the previous frame's */
    const int slot = (int)(s->frame & 1u), prev = slot ^ 1;
    distance_pass(ctx, s, targets, slot);
    const bool late = s->frame > 0 && s->fence[prev];
    vfx_result r = read_distances(ctx, s, late ? prev : slot);
    if (r != VFX_OK)
        return r;
    s->frame++;
    volfx_stat_set(ctx, "volume.clip_frames_late", late ? 1 : 0);

    tet_camera cam;
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    bool has_model = false;
    for (int i = 0; i < 16; ++i)
        has_model |= v->model[i] != 0;
    volfx_mat4_mul(targets->view, has_model ? v->model : identity, cam.view); /* model-view */
    memcpy(cam.proj, targets->proj, sizeof cam.proj);
    cam.width = (int)s->width, cam.height = (int)s->height;
    tet_tf tf;
    make_tf(s, &tf);
    tet_options o;
    tet_options_default(&o);
    o.ert = !s->lab_off.ert;
    o.share = !s->lab_off.share;
    o.dlb = !s->lab_off.dlb;
    if (v->ert_threshold > 0) o.ert_threshold = v->ert_threshold;
    if (v->tiles) o.tiles_d = (int)v->tiles;
    if (v->update_c) o.update_c = (int)v->update_c;
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    o.workers = v->workers ? (int)v->workers : (int)(cores > 0 ? (cores < 64 ? cores : 64) : 1);
    o.max_dist = s->max_dist;
    char err[256];
    if (s->pool && tet_pool_workers(s->pool) != o.workers) {
        tet_pool_destroy(s->pool);
        s->pool = NULL;
    }
    if (!s->pool && (r = from_tet(tet_pool_create(o.workers, &s->pool, err, sizeof err))) != VFX_OK)
        return volfx_fail(ctx, r, tet_log_id((tet_result)r), "volume[0]: %s", err);

    const uint64_t key = render_key(s, &cam, &tf, &o);
    if (key == s->last_key) {
        s->skipped++;
        volfx_stat_set(ctx, "volume.render_skipped", 1);
    } else {
        tet_counters c;
        s->last_key = 0;
        /* the other upload buffer, once the GPU has read it (two renders ago) */
        const int up = s->up_slot ^ 1;
        float *dst = s->heap_rgba;
        if (!dst) {
            if (s->up_fence[up]) {
                glClientWaitSync(s->up_fence[up], GL_SYNC_FLUSH_COMMANDS_BIT, 5000000000ull);
                glDeleteSync(s->up_fence[up]);
                s->up_fence[up] = 0;
            }
            dst = s->up_map[up];
        }
        tet_result rr = tet_render_pool(s->pool, &s->mesh, &cam, &tf, &o, dst, &c, NULL, err, sizeof err);
        if (rr != TET_OK)
            return volfx_fail(ctx, from_tet(rr), tet_log_id(rr), "volume[0]: %s", err);
        s->last_key = key;
        volfx_stat_set(ctx, "volume.render_skipped", 0);
        volfx_stat_set(ctx, "volume.cells_scanned", (double)c.cells_scanned);
        volfx_stat_set(ctx, "volume.cells_skipped_ert", (double)c.cells_skipped_ert);
        volfx_stat_set(ctx, "volume.cells_nan", (double)c.cells_nan); /* skipped: NaN point or scalar */
        volfx_stat_set(ctx, "volume.segments", (double)c.segments_made);
        volfx_stat_set(ctx, "volume.tf_pieces", (double)c.tf_pieces);
        volfx_stat_set(ctx, "volume.t_sc_ms", c.t_sc_ms);
        volfx_stat_set(ctx, "volume.t_update_ms", c.t_update_ms);
        s->rgba = dst;
        if (s->heap_rgba) {
            glTextureSubImage2D(s->tex, 0, 0, 0, (GLsizei)s->width, (GLsizei)s->height, GL_RGBA, GL_FLOAT, dst);
        } else {
            glBindBuffer(GL_PIXEL_UNPACK_BUFFER, s->up_pbo[up]);
            glTextureSubImage2D(s->tex, 0, 0, 0, (GLsizei)s->width, (GLsizei)s->height, GL_RGBA, GL_FLOAT, NULL);
            glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
            s->up_fence[up] = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
            s->up_slot = up;
        }
    }
    volfx_stat_set(ctx, "volume.renders_skipped_total", (double)s->skipped);
    glBindTextureUnit(0, s->tex);
    volfx_composite_targets(ctx, targets, "volume.composite", s->prog, VOLFX_BLEND_OVER_PREMUL);
    const char *e = volfx_gpu_error_string();
    return e ? volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR, "volume render: %s", e) : VFX_OK;
}

static vfx_result volume_read_raw(vfx_context *ctx, void *state, float *out, size_t count)
{
    volume_state *s = state;
    if (count < (size_t)s->width * s->height)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_READ_BUFFER_SIZE,
                          "volume read_raw: buffer too small");
    for (uint32_t y = 0; y < s->height; ++y) /* accumulated opacity, top row first */
        for (uint32_t x = 0; x < s->width; ++x)
            out[(size_t)y * s->width + x] = s->rgba[4 * ((size_t)(s->height - 1 - y) * s->width + x) + 3];
    return VFX_OK;
}

const volfx_effect_ops volfx_volume_ops = {
    .name = "volume",
    .kind = VFX_EFFECT_VOLUME,
    .present = volume_present,
    .create = volume_create,
    .destroy = volume_destroy,
    .resize = volume_resize,
    .update = volume_update,
    .render = volume_render,
    .read_raw = volume_read_raw,
};
