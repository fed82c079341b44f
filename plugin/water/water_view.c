/* water_view.c — the water's per-view state (issue 24): each view id of the frame view (version
 * 3; versions 1 and 2 are view 0) keeps its own size-dependent targets and its own TILE state
 * (bins and the temporal history), so views rendered alternately keep their histories and no
 * size change reallocates another view's targets. The targets of the view being drawn are
 * copied into water_state's fields (the passes read them there). TILE frames allocate only the
 * distance, gradient and back-distance targets; the paper method's, BRUTE's and GRID's targets
 * come the first time one of them draws in that view. */
#include <string.h>

#include "gpu/gpu.h"
#include "water_internal.h"

/* TILE's textures a pixel: R32F distance, RGBA32F gradient, R32F back distance */
#define TILE_TARGET_BYTES 24u
/* the others' on top: 2 R32F distances, RGBA16F potentials, 2 RGBA32F state and bracket, R32F
 * refine t, a 32-bit depth and the RG32F min/max pyramid (4/3 of a level) */
#define PAPER_TARGET_BYTES 67u

static void targets_free(water_view *v)
{
    GLuint tex[] = {v->dist, v->cur, v->next1, v->pot, v->st, v->br, v->reft, v->depth, v->pyr, v->grad, v->back};
    glDeleteTextures((GLsizei)(sizeof tex / sizeof tex[0]), tex);
    GLuint fb[] = {v->fbo_dist, v->fbo_pot, v->fbo_grad, v->fbo_back};
    glDeleteFramebuffers(4, fb);
    uint32_t id = v->id;
    bool live = v->live;
    uint64_t used = v->used, frames = v->frames;
    volfx_water_tile *tile = v->tile;
    memset(v, 0, sizeof *v);
    v->id = id, v->live = live, v->used = used, v->frames = frames, v->tile = tile;
}

static vfx_result targets_make(vfx_context *ctx, water_view *v, uint32_t width, uint32_t height, bool paper)
{
    uint64_t px = (uint64_t)width * height;
    uint64_t bytes = px * (TILE_TARGET_BYTES + (paper ? PAPER_TARGET_BYTES : 0u));
    if (bytes > WATER_VIEW_BYTES_MAX)
        return volfx_fail(ctx, VFX_ERR_UNSUPPORTED, VFX_LOG_ID_WATER_VIEW_TOO_LARGE,
                          "water: a %ux%u view needs %.1f GiB of water targets (%u bytes a pixel%s), more than the %.0f GiB "
                          "one view's water may take (docs/water.md \"Views\"); nothing was allocated",
                          width, height, (double)bytes / (1u << 30), TILE_TARGET_BYTES + (paper ? PAPER_TARGET_BYTES : 0u),
                          paper ? " with the paper method's" : " for TILE", (double)WATER_VIEW_BYTES_MAX / (1u << 30));
    if (!v->dist || v->width != width || v->height != height) {
        targets_free(v);
        v->width = width;
        v->height = height;
        v->dist = volfx_water_make_tex(GL_R32F, width, height, 1, "water.dist");
        v->grad = volfx_water_make_tex(WATER_GRAD_FORMAT, width, height, 1, "water.surface_gradient");
        v->back = volfx_water_make_tex(GL_R32F, width, height, 1, "water.back_distance");
        glCreateFramebuffers(1, &v->fbo_grad);
        glNamedFramebufferTexture(v->fbo_grad, GL_COLOR_ATTACHMENT0, v->grad, 0);
        glCreateFramebuffers(1, &v->fbo_back);
        glNamedFramebufferTexture(v->fbo_back, GL_COLOR_ATTACHMENT0, v->back, 0);
    }
    if (paper && !v->cur) {
        v->cur = volfx_water_make_tex(GL_R32F, width, height, 1, "water.dist_cur");
        v->next1 = volfx_water_make_tex(GL_R32F, width, height, 1, "water.dist_next");
        v->pot = volfx_water_make_tex(GL_RGBA16F, width, height, 1, "water.potential");
        v->st = volfx_water_make_tex(GL_RGBA32F, width, height, 1, "water.state");
        v->br = volfx_water_make_tex(GL_RGBA32F, width, height, 1, "water.bracket");
        v->reft = volfx_water_make_tex(GL_R32F, width, height, 1, "water.refine_t");
        v->depth = volfx_water_make_tex(GL_DEPTH_COMPONENT32F, width, height, 1, "water.depth");
        int levels = 1;
        while (levels < 8 && ((width >> levels) > 0 || (height >> levels) > 0))
            ++levels;
        v->pyr_levels = levels;
        v->pyr = volfx_water_make_tex(GL_RG32F, width, height, levels, "water.minmax_pyramid");
        glCreateFramebuffers(1, &v->fbo_dist);
        glNamedFramebufferTexture(v->fbo_dist, GL_COLOR_ATTACHMENT0, v->cur, 0);
        glNamedFramebufferTexture(v->fbo_dist, GL_DEPTH_ATTACHMENT, v->depth, 0);
        glCreateFramebuffers(1, &v->fbo_pot);
        glNamedFramebufferTexture(v->fbo_pot, GL_COLOR_ATTACHMENT0, v->pot, 0);
    }
    const char *e = volfx_gpu_error_string();
    if (e) {
        targets_free(v);
        const bool oom = strstr(e, "OUT_OF_MEMORY") != NULL;
        return volfx_fail(ctx, oom ? VFX_ERR_OUT_OF_MEMORY : VFX_ERR_GL,
                          oom ? VFX_LOG_ID_GPU_OUT_OF_MEMORY : VFX_LOG_ID_GL_ERROR, "water: targets of a %ux%u view (%.2f GiB): %s", width, height, (double)bytes / (1u << 30), e);
    }
    GLuint fbs[] = {v->fbo_grad, v->fbo_back, v->fbo_dist, v->fbo_pot};
    for (int k = 0; k < 4; ++k)
        if (fbs[k] && glCheckNamedFramebufferStatus(fbs[k], GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
            targets_free(v);
            return volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_FRAMEBUFFER_INCOMPLETE,
                              "water: targets of a %ux%u view: incomplete framebuffer", width, height);
        }
    return VFX_OK;
}

/* The active view's targets into the fields the passes read. */
static void activate(vfx_context *ctx, water_state *s, const water_view *v)
{
    s->width = v->width, s->height = v->height;
    s->cur = v->cur, s->next1 = v->next1, s->pot = v->pot, s->st = v->st, s->br = v->br, s->reft = v->reft;
    s->depth = v->depth, s->pyr = v->pyr, s->grad = v->grad, s->back = v->back;
    s->fbo_dist = v->fbo_dist, s->fbo_pot = v->fbo_pot, s->fbo_grad = v->fbo_grad, s->fbo_back = v->fbo_back;
    s->pyr_levels = v->pyr_levels;
    s->tile = v->tile;
    ctx->water_dist_tex = v->dist;
}

vfx_result volfx_water_view_begin(vfx_context *ctx, water_state *s, uint32_t id, uint32_t width, uint32_t height,
                                  bool paper)
{
    water_view *v = NULL;
    for (uint32_t k = 0; k < VFX_MAX_VIEWS && !v; ++k)
        if (s->views[k].live && s->views[k].id == id)
            v = &s->views[k];
    if (!v) {
        /* a new id takes a free slot, else the least recently drawn view's (which starts afresh
         * if it comes back) */
        v = &s->views[0];
        for (uint32_t k = 1; k < VFX_MAX_VIEWS; ++k) {
            water_view *c = &s->views[k];
            if (v->live && (!c->live || c->used < v->used))
                v = c;
        }
        targets_free(v);
        volfx_water_tile_destroy(ctx, v->tile);
        memset(v, 0, sizeof *v);
        v->live = true;
        v->id = id;
    }
    v->used = ++s->view_clock;
    s->active = (int)(v - s->views);
    vfx_result r = targets_make(ctx, v, width, height, paper);
    activate(ctx, s, v);
    if (r)
        s->active = -1;
    return r;
}

void volfx_water_view_end(water_state *s, bool drawn)
{
    if (s->active < 0)
        return;
    water_view *v = &s->views[s->active];
    v->tile = s->tile; /* made during the frame, when TILE first drew in this view */
    v->frames += drawn;
}

uint64_t volfx_water_view_frames(const water_state *s)
{
    return s->active >= 0 ? s->views[s->active].frames : 0;
}

void volfx_water_views_destroy(vfx_context *ctx, water_state *s)
{
    for (uint32_t k = 0; k < VFX_MAX_VIEWS; ++k) {
        targets_free(&s->views[k]);
        volfx_water_tile_destroy(ctx, s->views[k].tile);
        memset(&s->views[k], 0, sizeof s->views[k]);
    }
    s->tile = NULL;
    ctx->water_dist_tex = 0;
    s->active = -1;
}
