/* beams_effect.c — seed 003 on the GPU: beams binned to screen tiles on the CPU, one
 * fullscreen pass integrating the closed form per pixel up to the host's depth (and the
 * water's), one pass adding the light into the host frame. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "beams/beam_field.h"
#include "gpu/gpu.h"
#include "effect.h"

#define TILE_PX 16
#define MAX_BEAMS (1u << 20)

typedef struct beam_gpu {
    float m_l[4], d_r[4], ab_eps[4], color[4];
} beam_gpu;

typedef struct beams_state {
    GLuint prog_closed, prog_march, prog_composite;
    GLuint beam_buf, range_buf, list_buf;
    size_t beam_cap, range_cap, list_cap; /* bytes */
    GLuint acc_tex, acc_fbo;
    uint32_t width, height, tiles_x, tiles_y;
    vfx_beams_view view;
    volfx_beam_d *beams;        /* validated, normalised */
    beam_gpu *gpu;
    uint32_t (*rects)[4];     /* per beam: its tile rectangle this frame */
    bool *visible;            /* per beam: on screen this frame */
    uint32_t count, capacity;
    uint32_t *ranges, *list;  /* 2 per tile; tile lists */
    uint32_t list_capacity;
} beams_state;

static bool beams_present(vfx_context *ctx)
{
    vfx_beams_view v = {.size = sizeof v, .version = VFX_BEAMS_VIEW_VERSION};
    return ctx->host.beams && ctx->host.beams(ctx->host.user, &v) == VFX_OK && v.count > 0;
}

static void beams_destroy(vfx_context *ctx, void *state)
{
    beams_state *s = state;
    if (!s)
        return;
    GLuint bufs[3] = {s->beam_buf, s->range_buf, s->list_buf};
    glDeleteBuffers(3, bufs);
    glDeleteTextures(1, &s->acc_tex);
    glDeleteFramebuffers(1, &s->acc_fbo);
    volfx_free(ctx, s->beams);
    volfx_free(ctx, s->gpu);
    volfx_free(ctx, s->rects);
    volfx_free(ctx, s->visible);
    volfx_free(ctx, s->ranges);
    volfx_free(ctx, s->list);
    volfx_free(ctx, s); /* programs belong to the shared cache */
}

static vfx_result beams_create(vfx_context *ctx, void **out)
{
    beams_state *s = volfx_alloc(ctx, sizeof *s);
    if (!s)
        return VFX_ERR_OUT_OF_MEMORY;
    s->prog_closed = volfx_gpu_program(ctx, "common/fullscreen.vert", "beams/integrate.frag", NULL);
    s->prog_composite = volfx_gpu_program(ctx, "common/fullscreen.vert", "beams/composite.frag", NULL);
    if (!s->prog_closed || !s->prog_composite) {
        beams_destroy(ctx, s);
        return VFX_ERR_GL;
    }
    GLuint bufs[3];
    glCreateBuffers(3, bufs);
    s->beam_buf = bufs[0], s->range_buf = bufs[1], s->list_buf = bufs[2];
    volfx_gpu_label(GL_BUFFER, s->beam_buf, "beams.beams");
    volfx_gpu_label(GL_BUFFER, s->range_buf, "beams.tile_ranges");
    volfx_gpu_label(GL_BUFFER, s->list_buf, "beams.tile_lists");
    *out = s;
    return VFX_OK;
}

static vfx_result beams_resize(vfx_context *ctx, void *state, uint32_t w, uint32_t h)
{
    beams_state *s = state;
    glDeleteTextures(1, &s->acc_tex);
    glDeleteFramebuffers(1, &s->acc_fbo);
    glCreateTextures(GL_TEXTURE_2D, 1, &s->acc_tex);
    glTextureStorage2D(s->acc_tex, 1, GL_RGBA32F, (GLsizei)w, (GLsizei)h);
    volfx_gpu_label(GL_TEXTURE, s->acc_tex, "beams.H");
    glCreateFramebuffers(1, &s->acc_fbo);
    glNamedFramebufferTexture(s->acc_fbo, GL_COLOR_ATTACHMENT0, s->acc_tex, 0);
    if (glCheckNamedFramebufferStatus(s->acc_fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        return volfx_fail(ctx, VFX_ERR_GL, "beams: H target %ux%u incomplete", w, h);
    s->width = w, s->height = h;
    s->tiles_x = (w + TILE_PX - 1) / TILE_PX;
    s->tiles_y = (h + TILE_PX - 1) / TILE_PX;
    volfx_free(ctx, s->ranges);
    s->ranges = volfx_alloc(ctx, (size_t)s->tiles_x * s->tiles_y * 2 * sizeof(uint32_t));
    return s->ranges ? VFX_OK : VFX_ERR_OUT_OF_MEMORY;
}

static vfx_result beams_update(vfx_context *ctx, void *state, double time, float dt)
{
    (void)time, (void)dt;
    beams_state *s = state;
    vfx_beams_view v = {.size = sizeof v, .version = VFX_BEAMS_VIEW_VERSION};
    vfx_result r = ctx->host.beams(ctx->host.user, &v);
    if (r || v.version != VFX_BEAMS_VIEW_VERSION)
        return volfx_fail(ctx, VFX_ERR_ABI, "beams: host view of version %u (need %u)", v.version,
                        VFX_BEAMS_VIEW_VERSION);
    if (v.count > MAX_BEAMS || !v.beams)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "beams: %u beams (at most %u, non-NULL array)",
                        v.count, MAX_BEAMS);
    if (!(v.saturate_c >= 0) || !isfinite(v.saturate_c) || !(v.far_distance >= 0) || !isfinite(v.far_distance))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "beams: saturate_c and far_distance must be finite and >= 0");
    if (v.count > s->capacity) {
        volfx_free(ctx, s->beams);
        volfx_free(ctx, s->gpu);
        volfx_free(ctx, s->rects);
        volfx_free(ctx, s->visible);
        s->beams = volfx_alloc(ctx, v.count * sizeof *s->beams);
        s->gpu = volfx_alloc(ctx, v.count * sizeof *s->gpu);
        s->rects = volfx_alloc(ctx, v.count * sizeof *s->rects);
        s->visible = volfx_alloc(ctx, v.count * sizeof *s->visible);
        s->capacity = (s->beams && s->gpu && s->rects && s->visible) ? v.count : 0;
        if (!s->capacity)
            return VFX_ERR_OUT_OF_MEMORY;
    }
    char err[200];
    for (uint32_t i = 0; i < v.count; ++i)
        if (volfx_beam_validate(&v.beams[i], &s->beams[i], err, sizeof err))
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "beams[%u]: %s", i, err);
    s->count = v.count;
    s->view = v;
    for (uint32_t i = 0; i < v.count; ++i) {
        const float *c = v.beams[i].color;
        bool none = c[0] == 0 && c[1] == 0 && c[2] == 0;
        for (int k = 0; k < 4; ++k)
            s->gpu[i].color[k] = none ? 1.f : c[k];
    }
    return VFX_OK;
}

/* Screen rectangle (in tiles) a beam can touch: its bounding sphere's box projected; the whole
 * screen when the sphere reaches the near side of the eye. Conservative, never misses a pixel. */
static bool beam_tiles(const beams_state *s, const float vp_rot[16], const double rel_c[3],
                       double rad, uint32_t rect[4])
{
    double minx = 1e30, miny = 1e30, maxx = -1e30, maxy = -1e30;
    for (int k = 0; k < 8; ++k) {
        double p[3] = {rel_c[0] + (k & 1 ? rad : -rad), rel_c[1] + (k & 2 ? rad : -rad),
                       rel_c[2] + (k & 4 ? rad : -rad)};
        double cl[4];
        for (int r = 0; r < 4; ++r)
            cl[r] = vp_rot[r] * p[0] + vp_rot[4 + r] * p[1] + vp_rot[8 + r] * p[2] + vp_rot[12 + r];
        if (!(cl[3] > 1e-6)) { /* behind or at the eye: cover everything */
            rect[0] = 0, rect[1] = 0, rect[2] = s->tiles_x - 1, rect[3] = s->tiles_y - 1;
            return true;
        }
        double x = cl[0] / cl[3], y = cl[1] / cl[3];
        minx = fmin(minx, x), maxx = fmax(maxx, x), miny = fmin(miny, y), maxy = fmax(maxy, y);
    }
    if (maxx < -1 || minx > 1 || maxy < -1 || miny > 1)
        return false;
    double px0 = (fmax(minx, -1) * 0.5 + 0.5) * s->width, px1 = (fmin(maxx, 1) * 0.5 + 0.5) * s->width;
    double py0 = (fmax(miny, -1) * 0.5 + 0.5) * s->height, py1 = (fmin(maxy, 1) * 0.5 + 0.5) * s->height;
    rect[0] = (uint32_t)fmin(floor(px0 / TILE_PX), s->tiles_x - 1);
    rect[2] = (uint32_t)fmin(floor(px1 / TILE_PX), s->tiles_x - 1);
    rect[1] = (uint32_t)fmin(floor(py0 / TILE_PX), s->tiles_y - 1);
    rect[3] = (uint32_t)fmin(floor(py1 / TILE_PX), s->tiles_y - 1);
    return true;
}

static vfx_result upload(vfx_context *ctx, GLuint buf, size_t *cap, const void *data, size_t bytes)
{
    if (bytes == 0)
        bytes = 16; /* an empty SSBO binding is invalid; keep a tiny one */
    if (bytes > *cap) {
        glNamedBufferData(buf, (GLsizeiptr)bytes, NULL, GL_DYNAMIC_DRAW);
        *cap = bytes;
    }
    if (data)
        glNamedBufferSubData(buf, 0, (GLsizeiptr)bytes, data);
    const char *e = volfx_gpu_error_string();
    return e ? volfx_fail(ctx, VFX_ERR_GL, "beams: buffer upload of %zu bytes: %s", bytes, e) : VFX_OK;
}

static vfx_result beams_render(vfx_context *ctx, void *state, const vfx_frame_view *frame,
                               volfx_frame_targets *targets)
{
    beams_state *s = state;
    /* Camera-relative frame: the eye is the origin and heads are M - eye in double, so a beam
     * a million units away keeps float32 digits. */
    float view_rot[16], vp_rot[16], inv[16];
    memcpy(view_rot, frame->view, sizeof view_rot);
    view_rot[12] = view_rot[13] = view_rot[14] = 0.f;
    volfx_mat4_mul(frame->proj, view_rot, vp_rot);
    if (!volfx_mat4_invert(vp_rot, inv))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "beams: camera rotation*projection is singular");
    /* eye = -R^T t from the view matrix (robust even when frame->eye is not filled) */
    double eye[3];
    for (int k = 0; k < 3; ++k)
        eye[k] = -((double)frame->view[k * 4 + 0] * frame->view[12] + (double)frame->view[k * 4 + 1] * frame->view[13]
                   + (double)frame->view[k * 4 + 2] * frame->view[14]);
    uint32_t ntiles = s->tiles_x * s->tiles_y;
    uint32_t (*rects)[4] = s->rects; /* sized with the beams in update: no per-frame allocation */
    bool *visible = s->visible;
    memset(s->ranges, 0, (size_t)ntiles * 2 * sizeof(uint32_t));
    uint64_t pairs = 0;
    for (uint32_t i = 0; i < s->count; ++i) {
        const volfx_beam_d *b = &s->beams[i];
        beam_gpu *g = &s->gpu[i];
        double rel[3], centre[3];
        for (int k = 0; k < 3; ++k) {
            rel[k] = b->head[k] - eye[k];
            centre[k] = rel[k] + 0.5 * b->length * b->dir[k];
            g->m_l[k] = (float)rel[k];
            g->d_r[k] = (float)b->dir[k];
        }
        g->m_l[3] = (float)b->length, g->d_r[3] = (float)b->radius;
        g->ab_eps[0] = (float)b->a, g->ab_eps[1] = (float)b->b, g->ab_eps[2] = (float)b->eps, g->ab_eps[3] = 0;
        visible[i] = beam_tiles(s, vp_rot, centre, 0.5 * b->length + b->radius, rects[i]);
        if (!visible[i])
            continue;
        for (uint32_t ty = rects[i][1]; ty <= rects[i][3]; ++ty)
            for (uint32_t tx = rects[i][0]; tx <= rects[i][2]; ++tx)
                s->ranges[2 * (ty * s->tiles_x + tx) + 1]++;
        pairs += (uint64_t)(rects[i][2] - rects[i][0] + 1) * (rects[i][3] - rects[i][1] + 1);
    }
    if (pairs > UINT32_MAX / 2) {
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "beams: %llu beam-tile pairs", (unsigned long long)pairs);
    }
    uint32_t offset = 0, empty = 0;
    for (uint32_t t = 0; t < ntiles; ++t) {
        s->ranges[2 * t] = offset;
        offset += s->ranges[2 * t + 1];
        empty += s->ranges[2 * t + 1] == 0;
        s->ranges[2 * t + 1] = 0; /* refilled below as a cursor */
    }
    if (pairs > s->list_capacity) {
        volfx_free(ctx, s->list);
        s->list = volfx_alloc(ctx, pairs * sizeof(uint32_t));
        s->list_capacity = s->list ? (uint32_t)pairs : 0;
    }
    if (pairs && !s->list)
        return VFX_ERR_OUT_OF_MEMORY;
    for (uint32_t i = 0; i < s->count; ++i) {
        if (!visible[i])
            continue;
        for (uint32_t ty = rects[i][1]; ty <= rects[i][3]; ++ty)
            for (uint32_t tx = rects[i][0]; tx <= rects[i][2]; ++tx) {
                uint32_t t = ty * s->tiles_x + tx;
                s->list[s->ranges[2 * t] + s->ranges[2 * t + 1]++] = i;
            }
    }
    volfx_stat_set(ctx, "beams.count", s->count);
    volfx_stat_set(ctx, "beams.tiles", ntiles);
    volfx_stat_set(ctx, "beams.tiles_empty", empty);
    volfx_stat_set(ctx, "beams.pairs", (double)pairs);
    volfx_stat_set(ctx, "beams.pairs_culled", (double)s->count * ntiles - (double)pairs);
    vfx_result r;
    if ((r = upload(ctx, s->beam_buf, &s->beam_cap, s->gpu, s->count * sizeof(beam_gpu)))
        || (r = upload(ctx, s->range_buf, &s->range_cap, s->ranges, (size_t)ntiles * 2 * sizeof(uint32_t)))
        || (r = upload(ctx, s->list_buf, &s->list_cap, s->list, pairs * sizeof(uint32_t))))
        return r;

    bool march = s->view.method == 1;
    GLuint prog = s->prog_closed;
    if (march) {
        if (!s->prog_march)
            s->prog_march = volfx_gpu_program(ctx, "common/fullscreen.vert", "beams/integrate.frag",
                                            "#define VOLFX_BEAMS_MARCH 1");
        if (!(prog = s->prog_march))
            return VFX_ERR_GL;
    }
    float far = s->view.far_distance > 0 ? s->view.far_distance : frame->far_plane;
    if (!(far > 0))
        far = 1e30f;
    volfx_gpu_pass_begin(ctx, march ? "beams.march" : "beams.integrate");
    glBindFramebuffer(GL_FRAMEBUFFER, s->acc_fbo);
    glViewport(0, 0, (GLsizei)s->width, (GLsizei)s->height);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glUseProgram(prog);
    glUniformMatrix4fv(glGetUniformLocation(prog, "u_inv_rot_view_proj"), 1, GL_FALSE, inv);
    glUniform1f(glGetUniformLocation(prog, "u_far"), far);
    glUniform1i(glGetUniformLocation(prog, "u_tile_px"), TILE_PX);
    glUniform1i(glGetUniformLocation(prog, "u_tiles_x"), (GLint)s->tiles_x);
    glUniform1i(glGetUniformLocation(prog, "u_samples"), (GLint)(s->view.march_samples ? s->view.march_samples : 32));
    glUniform1i(glGetUniformLocation(prog, "u_has_water"), targets->water_dist != 0);
    glUniform1i(glGetUniformLocation(prog, "u_scene_depth"), 0);
    glUniform1i(glGetUniformLocation(prog, "u_water_dist"), 1);
    glBindTextureUnit(0, targets->scene_depth);
    glBindTextureUnit(1, targets->water_dist);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, s->beam_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, s->range_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, s->list_buf);
    volfx_gpu_fullscreen(ctx);
    volfx_gpu_pass_end(ctx);

    volfx_gpu_pass_begin(ctx, "beams.composite");
    glBindFramebuffer(GL_FRAMEBUFFER, frame->framebuffer);
    glViewport(0, 0, (GLsizei)frame->width, (GLsizei)frame->height);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glUseProgram(s->prog_composite);
    glUniform1i(glGetUniformLocation(s->prog_composite, "u_acc"), 0);
    glUniform1f(glGetUniformLocation(s->prog_composite, "u_c"), s->view.saturate_c > 0 ? s->view.saturate_c : 1.f);
    glUniform1i(glGetUniformLocation(s->prog_composite, "u_smooth"), s->view.saturation == VFX_SATURATE_SMOOTH);
    glBindTextureUnit(0, s->acc_tex);
    volfx_gpu_fullscreen(ctx);
    glDisable(GL_BLEND);
    glUseProgram(0);
    volfx_gpu_pass_end(ctx);
    const char *e = volfx_gpu_error_string();
    return e ? volfx_fail(ctx, VFX_ERR_GL, "beams render: %s", e) : VFX_OK;
}

static vfx_result beams_read_raw(vfx_context *ctx, void *state, float *out, size_t count)
{
    beams_state *s = state;
    size_t n = (size_t)s->width * s->height;
    if (count < n)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "beams read_raw: %zu floats < %zu", count, n);
    return volfx_gpu_read_top_first(ctx, s->acc_tex, GL_RGBA, 4, 0, s->width, s->height, out);
}

const volfx_effect_ops volfx_beams_ops = {
    .name = "beams",
    .kind = VFX_EFFECT_BEAMS,
    .present = beams_present,
    .create = beams_create,
    .destroy = beams_destroy,
    .resize = beams_resize,
    .update = beams_update,
    .render = beams_render,
    .read_raw = beams_read_raw,
};
