/* volume_effect.c — seed 002 in the plugin: the host's tetrahedral volume is rendered by the CPU
 * cell-projection renderer (tet_render.c: ERT, subscreen termination, threaded workers with
 * weak sharing and load balancing), clipped per pixel by the host's depth and the water's ray
 * distance, then composited "over" the host frame by one fullscreen pass. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "gpu/pass.h"
#include "effect.h"
#include "tet_render.h"

typedef struct volume_state {
    GLuint prog, tex;
    uint32_t width, height;
    float *rgba;        /* width*height*4, premultiplied, row 0 = bottom */
    float *max_dist;    /* width*height ray distances to the nearest host surface */
    float *depth;       /* read-back host depth */
    vfx_volume_view view;
    tet_mesh mesh;  /* points into the host's arrays (no copy) */
    uint64_t revision;
    float data_min, data_max;
    bool warned_many;
} volume_state;

static bool volume_present(vfx_context *ctx)
{
    return ctx->host.volume_count && ctx->host.volume && ctx->host.volume_count(ctx->host.user) > 0;
}

static void volume_destroy(vfx_context *ctx, void *state)
{
    volume_state *s = state;
    if (!s)
        return;
    glDeleteTextures(1, &s->tex);
    volfx_free(ctx, s->rgba);
    volfx_free(ctx, s->max_dist);
    volfx_free(ctx, s->depth);
    volfx_free(ctx, s);
}

static vfx_result volume_create(vfx_context *ctx, void **out)
{
    volume_state *s = volfx_alloc(ctx, sizeof *s);
    if (!s)
        return VFX_ERR_OUT_OF_MEMORY;
    s->prog = volfx_gpu_program(ctx, "common/fullscreen.vert", "volume/composite.frag", NULL);
    if (!s->prog) {
        volume_destroy(ctx, s);
        return VFX_ERR_GL;
    }
    *out = s;
    return VFX_OK;
}

static vfx_result volume_resize(vfx_context *ctx, void *state, uint32_t w, uint32_t h)
{
    volume_state *s = state;
    glDeleteTextures(1, &s->tex);
    glCreateTextures(GL_TEXTURE_2D, 1, &s->tex);
    glTextureStorage2D(s->tex, 1, GL_RGBA32F, (GLsizei)w, (GLsizei)h);
    volfx_gpu_label(GL_TEXTURE, s->tex, "volume.image");
    volfx_free(ctx, s->rgba);
    volfx_free(ctx, s->max_dist);
    volfx_free(ctx, s->depth);
    size_t n = (size_t)w * h;
    s->rgba = volfx_alloc(ctx, n * 4 * sizeof(float));
    s->max_dist = volfx_alloc(ctx, n * sizeof(float));
    s->depth = volfx_alloc(ctx, n * sizeof(float));
    s->width = w, s->height = h;
    return s->rgba && s->max_dist && s->depth ? VFX_OK : VFX_ERR_OUT_OF_MEMORY;
}

static vfx_result volume_update(vfx_context *ctx, void *state, double time, float dt)
{
    (void)time, (void)dt;
    volume_state *s = state;
    uint32_t n = ctx->host.volume_count(ctx->host.user);
    if (n > 1 && !s->warned_many) {
        volfx_log(ctx, VFX_LOG_WARN, "volume: the host has %u volumes; only the first is drawn", n);
        s->warned_many = true;
    }
    vfx_volume_view v = {.size = sizeof v, .version = VFX_VOLUME_VIEW_VERSION};
    if (ctx->host.volume(ctx->host.user, 0, &v) != VFX_OK || v.version != VFX_VOLUME_VIEW_VERSION)
        return volfx_fail(ctx, VFX_ERR_ABI, "volume: host view of version %u (need %u)", v.version,
                        VFX_VOLUME_VIEW_VERSION);
    if (!v.points || !v.tets || !v.scalar || v.point_count == 0 || v.tet_count == 0)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT,
                        "volume[0]: needs points, tets and scalar arrays and counts > 0 (%u points, %u tets)",
                        v.point_count, v.tet_count);
    if (v.transfer_rgba && v.transfer_count < 2)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "volume[0]: transfer function needs >= 2 entries");
    if (!(v.ert_threshold >= 0 && v.ert_threshold <= 1))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "volume[0]: ert_threshold %g outside [0, 1]",
                        (double)v.ert_threshold);
    /* tet indices are checked once per revision: the renderer trusts them */
    if (v.revision != s->revision || v.tets != s->view.tets || v.scalar != s->view.scalar) {
        for (uint64_t i = 0; i < (uint64_t)v.tet_count * 4; ++i)
            if (v.tets[i] >= v.point_count)
                return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "volume[0]: tet %llu uses point %u of %u",
                                (unsigned long long)(i / 4), v.tets[i], v.point_count);
        s->data_min = INFINITY, s->data_max = -INFINITY;
        for (uint32_t i = 0; i < v.point_count; ++i)
            if (isfinite(v.scalar[i])) {
                s->data_min = fminf(s->data_min, v.scalar[i]);
                s->data_max = fmaxf(s->data_max, v.scalar[i]);
            }
        s->revision = v.revision;
    }
    s->view = v;
    memset(&s->mesh, 0, sizeof s->mesh);
    s->mesh.point_count = v.point_count;
    s->mesh.tet_count = v.tet_count;
    s->mesh.points = (float *)v.points; /* read only: the renderer takes a const mesh */
    s->mesh.tets = (uint32_t *)v.tets;
    s->mesh.scalar = (float *)v.scalar;
    return VFX_OK;
}

static vfx_result volume_render(vfx_context *ctx, void *state, const vfx_frame_view *frame,
                                volfx_frame_targets *targets)
{
    volume_state *s = state;
    const vfx_volume_view *v = &s->view;
    size_t n = (size_t)s->width * s->height;
    /* Ray distance to the nearest opaque thing: the host's depth, and the water when present. */
    glGetTextureImage(targets->scene_depth, 0, GL_DEPTH_COMPONENT, GL_FLOAT, (GLsizei)(n * sizeof(float)), s->depth);
    double eye[3];
    for (int k = 0; k < 3; ++k)
        eye[k] = -((double)frame->view[k * 4 + 0] * frame->view[12] + (double)frame->view[k * 4 + 1] * frame->view[13]
                   + (double)frame->view[k * 4 + 2] * frame->view[14]);
    const float *m = targets->inv_view_proj;
    for (uint32_t y = 0; y < s->height; ++y)
        for (uint32_t x = 0; x < s->width; ++x) {
            size_t p = (size_t)y * s->width + x;
            float d = s->depth[p];
            if (d >= 1.f) {
                s->max_dist[p] = INFINITY;
                continue;
            }
            double ndc[4] = {(x + 0.5) / s->width * 2 - 1, (y + 0.5) / s->height * 2 - 1, d * 2.0 - 1, 1};
            double w[4] = {0, 0, 0, 0};
            for (int r = 0; r < 4; ++r)
                for (int c = 0; c < 4; ++c)
                    w[r] += m[c * 4 + r] * ndc[c];
            double dx = w[0] / w[3] - eye[0], dy = w[1] / w[3] - eye[1], dz = w[2] / w[3] - eye[2];
            s->max_dist[p] = (float)sqrt(dx * dx + dy * dy + dz * dz);
        }
    if (targets->water_dist) {
        glGetTextureImage(targets->water_dist, 0, GL_RED, GL_FLOAT, (GLsizei)(n * sizeof(float)), s->depth);
        for (size_t p = 0; p < n; ++p)
            if (s->depth[p] >= 0 && s->depth[p] < s->max_dist[p])
                s->max_dist[p] = s->depth[p];
    }
    tet_camera cam;
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    bool has_model = false;
    for (int i = 0; i < 16; ++i)
        has_model |= v->model[i] != 0;
    volfx_mat4_mul(frame->view, has_model ? v->model : identity, cam.view);
    memcpy(cam.proj, frame->proj, sizeof cam.proj);
    cam.width = (int)s->width, cam.height = (int)s->height;
    /* The renderer's transfer function is linear between two ends: the view's table gives its
     * first and last entries (alpha = extinction per unit length). */
    tet_tf tf = {.smin = v->scalar_min, .smax = v->scalar_max, .tau_lo = 0.2f, .tau_hi = 3.0f,
                     .color_lo = {0.1f, 0.3f, 0.9f}, .color_hi = {1.0f, 0.85f, 0.3f}};
    if (!(v->scalar_max > v->scalar_min))
        tf.smin = s->data_min, tf.smax = s->data_max > s->data_min ? s->data_max : s->data_min + 1;
    if (v->transfer_rgba) {
        const float *lo = v->transfer_rgba, *hi = v->transfer_rgba + 4 * (v->transfer_count - 1);
        memcpy(tf.color_lo, lo, sizeof tf.color_lo);
        memcpy(tf.color_hi, hi, sizeof tf.color_hi);
        tf.tau_lo = lo[3], tf.tau_hi = hi[3];
    }
    tet_options o;
    tet_options_default(&o);
    o.ert = !(v->disable & VFX_VOLUME_NO_ERT);
    o.share = !(v->disable & VFX_VOLUME_NO_SHARE);
    o.dlb = !(v->disable & VFX_VOLUME_NO_DLB);
    if (v->ert_threshold > 0) o.ert_threshold = v->ert_threshold;
    if (v->tiles) o.tiles_d = (int)v->tiles;
    if (v->update_c) o.update_c = (int)v->update_c;
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    o.workers = v->workers ? (int)v->workers : (int)(cores > 0 ? (cores < 64 ? cores : 64) : 1);
    o.max_dist = s->max_dist;
    tet_counters c;
    char err[256];
    int r = tet_render_workers(&s->mesh, &cam, &tf, &o, s->rgba, &c, NULL, err);
    if (r != VFX_OK)
        return volfx_fail(ctx, (vfx_result)r, "volume[0]: %s", err);
    volfx_stat_set(ctx, "volume.cells_scanned", (double)c.cells_scanned);
    volfx_stat_set(ctx, "volume.cells_skipped_ert", (double)c.cells_skipped_ert);
    volfx_stat_set(ctx, "volume.segments", (double)c.segments_made);
    volfx_stat_set(ctx, "volume.t_sc_ms", c.t_sc_ms);
    volfx_stat_set(ctx, "volume.t_update_ms", c.t_update_ms);
    glTextureSubImage2D(s->tex, 0, 0, 0, (GLsizei)s->width, (GLsizei)s->height, GL_RGBA, GL_FLOAT, s->rgba);
    glBindTextureUnit(0, s->tex);
    volfx_composite(ctx, frame, "volume.composite", s->prog, VOLFX_BLEND_OVER_PREMUL);
    const char *e = volfx_gpu_error_string();
    return e ? volfx_fail(ctx, VFX_ERR_GL, "volume render: %s", e) : VFX_OK;
}

static vfx_result volume_read_raw(vfx_context *ctx, void *state, float *out, size_t count)
{
    volume_state *s = state;
    if (count < (size_t)s->width * s->height)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "volume read_raw: buffer too small");
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
