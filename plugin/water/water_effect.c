/* water_effect.c — metaball water (seed 000, Mishima et al.). Method PAPER: billboard init by
 * depth test (eq. 1), potentials by additive blending into RGBA16F at 4 samples per texel,
 * sample update with two distance buffers and depth-tested gap jumping (eqs. 2-4), min/max
 * pyramid culling, eq. 5 interpolation and eq. 6 regula falsi (each pass again by blending).
 * Method BRUTE: per-pixel compute march over every particle. Method GRID: per-pixel compute
 * march over a uniform grid built on the GPU (water_grid.c). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "water/water_effect.h"
#include "gpu/gpu.h"
#include "effect.h"
#include "context.h"
#include "water_grid.h"
#include "water_tile.h"
#include "water_aniso.h"
#include "water_spray.h"

/* Counter readback ring: frames the GPU may run behind before a result is dropped. */
#define WATER_COUNTER_RING 3
/* march.comp's 8 (PAPER and the gradient pass), GRID's cells visited and sphere tests,
 * tile.comp's 14 (TILE and the paper method's finishing pass) and aniso.comp's 2 */
#define WATER_COUNTERS 27
/* Particles the effect takes at most: positions are 12 bytes each (12 GiB at the limit) and a
 * particle index must fit the int of gl_InstanceID and of the draw's instance count. */
#define WATER_MAX_PARTICLES (1u << 30)
/* The gradient target accumulates signed terms up to 2/h that partly cancel at the surface:
 * RGBA16F rounds each add to ~5e-4 relative. Measured on the blob test with the brute-force
 * surface (exact to 1e-5 h): mean normal error 0.025 deg in RGBA16F, 0.002 deg in RGBA32F.
 * The pass runs once per frame, not per march iteration, so the wider format costs little. */
#define WATER_GRAD_FORMAT GL_RGBA32F

/* One position buffer triple: particles [first, first + count) of the concatenated chunks. */
typedef struct water_group {
    GLuint cols[3];
    uint32_t first, count;
} water_group;

typedef struct water_state {
    GLuint cols[3];        /* group 0's columns: the compute paths (brute, NO_BLEND) read only it */
    water_group *groups;   /* position buffers of at most buffer_cap particles each */
    uint32_t group_count;
    uint32_t gl_cap;       /* particles one SSBO binding holds (GL_MAX_SHADER_STORAGE_BLOCK_SIZE) */
    uint32_t buffer_cap;   /* particles per buffer in use: gl_cap or the lower debug knob */
    uint32_t capacity;     /* particles the groups hold */
    uint32_t count;        /* particles uploaded (NaN ones included: the shaders skip them) */
    uint32_t nan_count;
    uint32_t width, height;
    vfx_water_params params;
    volfx_water_kernel_params kp; /* the kernel (vfx_water_params2), checked */
    volfx_water_aniso *aniso; /* per-particle kernels (TILE), made when asked for or given */
    volfx_water_grid *grid;  /* GRID baseline state, made the first time GRID is asked for */
    volfx_water_tile *tile;  /* TILE lists (TILE, and PAPER's finishing pass), made when needed */
    volfx_water_spray *spray; /* spray and foam from the host's velocities */
    float lo[3], hi[3];    /* box of the finite particles */
    /* upload skipping: the host's per-chunk revisions of the last upload (0 = untracked: the
     * host gives none, so every frame uploads); data_rev counts uploads, which GRID keys on */
    uint64_t *chunk_rev;
    uint32_t chunk_rev_count;
    uint64_t data_rev;
    int upload_skipped;    /* this frame's update found every revision unchanged */
    uint32_t last_method_drawn; /* method of the last frame: debug_pixel_class reads PAPER's state */
    /* paper pipeline targets */
    GLuint cur, next1, pot, st, br, reft, depth, pyr, fbo_dist, fbo_pot, counters;
    GLuint grad, back, fbo_grad, fbo_back; /* surface gradient and back distance (shading) */
    int pyr_levels;
    /* counters: copied into ring[slot] and fenced each frame, read once the fence signals */
    GLuint ring[WATER_COUNTER_RING];
    GLsync fence[WATER_COUNTER_RING];
    uint64_t ring_frame[WATER_COUNTER_RING];
    uint32_t ring_method[WATER_COUNTER_RING];
    uint64_t frame_no;
    uint32_t last[WATER_COUNTERS];
    uint64_t last_frame;   /* frame whose counters `last` holds */
    uint32_t last_method;
    int have_last;
    uint32_t dropped;      /* counter results overwritten before the GPU finished them */
    float view_proj[16];
    GLuint vao; /* empty: billboards are built from gl_VertexID / gl_InstanceID */
} water_state;

static void paper_free(water_state *s)
{
    GLuint tex[] = {s->cur, s->next1, s->pot, s->st, s->br, s->reft, s->depth, s->pyr, s->grad, s->back};
    glDeleteTextures(10, tex);
    GLuint fb[] = {s->fbo_dist, s->fbo_pot, s->fbo_grad, s->fbo_back};
    glDeleteFramebuffers(4, fb);
    s->cur = s->next1 = s->pot = s->st = s->br = s->reft = s->depth = s->pyr = 0;
    s->grad = s->back = 0;
    s->fbo_dist = s->fbo_pot = s->fbo_grad = s->fbo_back = 0;
}

static void groups_free(vfx_context *ctx, water_state *s)
{
    for (uint32_t g = 0; g < s->group_count; ++g)
        glDeleteBuffers(3, s->groups[g].cols);
    volfx_free(ctx, s->groups);
    s->groups = NULL;
    s->group_count = 0;
    s->capacity = 0;
    s->cols[0] = s->cols[1] = s->cols[2] = 0;
}

static GLuint make_tex(GLenum fmt, uint32_t w, uint32_t h, int levels, const char *label)
{
    GLuint t;
    glCreateTextures(GL_TEXTURE_2D, 1, &t);
    glTextureStorage2D(t, levels, fmt, (GLsizei)w, (GLsizei)h);
    glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    volfx_gpu_label(GL_TEXTURE, t, label);
    return t;
}

static void water_defaults(vfx_water_params *p)
{
    if (!(p->h > 0) || !isfinite(p->h)) p->h = 0.61f;
    if (!(p->threshold > 0) || !isfinite(p->threshold)) p->threshold = 0.765625f;
    if (p->max_samples == 0) p->max_samples = 64;
    if (!(p->step > 0) || !isfinite(p->step)) p->step = p->h / 8.0f;
    if (p->refine_iters == 0) p->refine_iters = 3;
    if (p->pyramid_level == 0) p->pyramid_level = 3;
    if (p->color[0] == 0 && p->color[1] == 0 && p->color[2] == 0) {
        p->color[0] = 0.15f; p->color[1] = 0.55f; p->color[2] = 0.6f;
    }
    if (!(p->absorption > 0)) p->absorption = 0.6f;
    if (!(p->ior > 1)) p->ior = 1.333f;
}

static bool water_present(vfx_context *ctx)
{
    return ctx->host.particle_chunk_count && ctx->host.particle_chunk_count(ctx->host.user) > 0;
}

static vfx_result water_create(vfx_context *ctx, void **out)
{
    water_state *s = volfx_alloc(ctx, sizeof *s);
    if (!s)
        return VFX_ERR_OUT_OF_MEMORY;
    glCreateVertexArrays(1, &s->vao);
    /* one SSBO binding must hold a whole column */
    GLint64 block = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &block);
    uint64_t cap = block > 0 ? (uint64_t)block / sizeof(float) : (1u << 24);
    s->gl_cap = cap > WATER_MAX_PARTICLES ? WATER_MAX_PARTICLES : (uint32_t)cap;
    glCreateBuffers(WATER_COUNTER_RING, s->ring);
    for (int k = 0; k < WATER_COUNTER_RING; ++k)
        glNamedBufferStorage(s->ring[k], WATER_COUNTERS * sizeof(uint32_t), NULL, GL_MAP_READ_BIT);
    *out = s;
    return VFX_OK;
}

static void water_destroy(vfx_context *ctx, void *state)
{
    water_state *s = state;
    groups_free(ctx, s);
    paper_free(s);
    volfx_water_grid_destroy(ctx, s->grid);
    volfx_water_tile_destroy(ctx, s->tile);
    volfx_water_aniso_destroy(ctx, s->aniso);
    volfx_water_spray_destroy(ctx, s->spray);
    volfx_free(ctx, s->chunk_rev);
    glDeleteVertexArrays(1, &s->vao);
    for (int k = 0; k < WATER_COUNTER_RING; ++k)
        if (s->fence[k])
            glDeleteSync(s->fence[k]);
    glDeleteBuffers(WATER_COUNTER_RING, s->ring);
    if (s->counters)
        glDeleteBuffers(1, &s->counters);
    if (ctx->water_dist_tex) {
        glDeleteTextures(1, &ctx->water_dist_tex);
        ctx->water_dist_tex = 0;
    }
    volfx_free(ctx, s);
}

static vfx_result water_resize(vfx_context *ctx, void *state, uint32_t width, uint32_t height)
{
    water_state *s = state;
    if (ctx->water_dist_tex)
        glDeleteTextures(1, &ctx->water_dist_tex);
    glCreateTextures(GL_TEXTURE_2D, 1, &ctx->water_dist_tex);
    glTextureStorage2D(ctx->water_dist_tex, 1, GL_R32F, (GLsizei)width, (GLsizei)height);
    glTextureParameteri(ctx->water_dist_tex, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(ctx->water_dist_tex, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    volfx_gpu_label(GL_TEXTURE, ctx->water_dist_tex, "water.dist");
    s->width = width;
    s->height = height;
    paper_free(s);
    s->cur = make_tex(GL_R32F, width, height, 1, "water.dist_cur");
    s->next1 = make_tex(GL_R32F, width, height, 1, "water.dist_next");
    s->pot = make_tex(GL_RGBA16F, width, height, 1, "water.potential");
    s->st = make_tex(GL_RGBA32F, width, height, 1, "water.state");
    s->br = make_tex(GL_RGBA32F, width, height, 1, "water.bracket");
    s->reft = make_tex(GL_R32F, width, height, 1, "water.refine_t");
    s->depth = make_tex(GL_DEPTH_COMPONENT32F, width, height, 1, "water.depth");
    int levels = 1;
    while (levels < 8 && ((width >> levels) > 0 || (height >> levels) > 0))
        ++levels;
    s->pyr_levels = levels;
    s->pyr = make_tex(GL_RG32F, width, height, levels, "water.minmax_pyramid");
    s->grad = make_tex(WATER_GRAD_FORMAT, width, height, 1, "water.surface_gradient");
    s->back = make_tex(GL_R32F, width, height, 1, "water.back_distance");
    glCreateFramebuffers(1, &s->fbo_grad);
    glNamedFramebufferTexture(s->fbo_grad, GL_COLOR_ATTACHMENT0, s->grad, 0);
    glCreateFramebuffers(1, &s->fbo_back);
    glNamedFramebufferTexture(s->fbo_back, GL_COLOR_ATTACHMENT0, s->back, 0);
    glCreateFramebuffers(1, &s->fbo_dist);
    glNamedFramebufferTexture(s->fbo_dist, GL_COLOR_ATTACHMENT0, s->cur, 0);
    glNamedFramebufferTexture(s->fbo_dist, GL_DEPTH_ATTACHMENT, s->depth, 0);
    glCreateFramebuffers(1, &s->fbo_pot);
    glNamedFramebufferTexture(s->fbo_pot, GL_COLOR_ATTACHMENT0, s->pot, 0);
    if (glCheckNamedFramebufferStatus(s->fbo_dist, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE ||
        glCheckNamedFramebufferStatus(s->fbo_pot, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE ||
        glCheckNamedFramebufferStatus(s->fbo_grad, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE ||
        glCheckNamedFramebufferStatus(s->fbo_back, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        return volfx_fail(ctx, VFX_ERR_GL, "water resize %ux%u: incomplete framebuffer", width, height);
    if (!s->counters) {
        glCreateBuffers(1, &s->counters);
        glNamedBufferStorage(s->counters, WATER_COUNTERS * sizeof(uint32_t), NULL, GL_DYNAMIC_STORAGE_BIT);
    }
    const char *e = volfx_gpu_error_string();
    if (e)
        return volfx_fail(ctx, VFX_ERR_GL, "water resize %ux%u: %s", width, height, e);
    return VFX_OK;
}

/* Position buffers for `total` particles, at most buffer_cap each (recreated when the count
 * grows past what they hold, or the cap changed). */
static vfx_result ensure_groups(vfx_context *ctx, water_state *s, uint32_t total)
{
    uint32_t cap = s->gl_cap;
    if (ctx->debug.water_buffer_cap && ctx->debug.water_buffer_cap < cap)
        cap = ctx->debug.water_buffer_cap;
    uint32_t need = total ? (uint32_t)(((uint64_t)total + cap - 1) / cap) : 1;
    if (s->groups && total <= s->capacity && need == s->group_count && cap == s->buffer_cap) {
        /* as many particles or fewer: same buffers (each sized for its group at capacity) */
        for (uint32_t g = 0; g < need; ++g) {
            uint32_t first = g * cap;
            s->groups[g].count = total > first ? (total - first < cap ? total - first : cap) : 0;
        }
        return VFX_OK;
    }
    groups_free(ctx, s);
    s->buffer_cap = cap;
    s->groups = volfx_alloc(ctx, need * sizeof *s->groups);
    if (!s->groups)
        return VFX_ERR_OUT_OF_MEMORY;
    s->group_count = need;
    for (uint32_t g = 0; g < need; ++g) {
        water_group *w = &s->groups[g];
        w->first = g * cap;
        w->count = total - w->first < cap ? total - w->first : cap;
        glCreateBuffers(3, w->cols);
        for (int k = 0; k < 3; ++k)
            glNamedBufferStorage(w->cols[k], (GLsizeiptr)(w->count ? w->count : 1) * 4, NULL, GL_DYNAMIC_STORAGE_BIT);
    }
    memcpy(s->cols, s->groups[0].cols, sizeof s->cols);
    s->capacity = total;
    const char *e = volfx_gpu_error_string();
    if (e) {
        groups_free(ctx, s);
        return volfx_fail(ctx, VFX_ERR_OUT_OF_MEMORY, "water: position buffers for %u particles (%u buffers of at most %u): %s",
                        total, need, cap, e);
    }
    return VFX_OK;
}

/* Asks the host for chunk `c`, offering version 2; a version-1 answer has no kernel column. */
static vfx_result query_chunk(vfx_context *ctx, uint32_t c, vfx_particle_view2 *v)
{
    memset(v, 0, sizeof *v);
    v->v1.size = sizeof *v;
    v->v1.version = VFX_PARTICLE_VIEW2_VERSION;
    vfx_result r = ctx->host.particle_chunk(ctx->host.user, c, &v->v1);
    if (r == VFX_OK && !(v->v1.version == VFX_PARTICLE_VIEW2_VERSION && v->v1.size >= sizeof *v))
        v->kernel = NULL; /* nothing a version-1 host wrote */
    return r;
}

static vfx_result water_update(vfx_context *ctx, void *state, double time, float dt)
{
    (void)time;
    (void)dt;
    water_state *s = state;
    /* version 2 offered; a version-1 host writes only v1 (the rest stays 0: defaults) */
    vfx_water_params2 p2;
    memset(&p2, 0, sizeof p2);
    p2.v1.size = sizeof p2;
    p2.v1.version = VFX_WATER_PARAMS2_VERSION;
    if (ctx->host.water_params) {
        vfx_result r = ctx->host.water_params(ctx->host.user, &p2.v1);
        if (r != VFX_OK && r != VFX_ERR_NOT_FOUND)
            return volfx_fail(ctx, r, "water: host water_params failed (%d)", (int)r);
        if (r == VFX_ERR_NOT_FOUND)
            memset(&p2, 0, sizeof p2);
    }
    s->params = p2.v1;
    water_defaults(&s->params);
    uint32_t pver = p2.v1.version == VFX_WATER_PARAMS2_VERSION && p2.v1.size >= sizeof p2 ? VFX_WATER_PARAMS2_VERSION
                                                                                         : VFX_WATER_PARAMS_VERSION;
    vfx_result kr = volfx_water_kernel_params_check(ctx, &p2, pver, &s->kp);
    if (kr)
        return kr;
    uint32_t chunks = ctx->host.particle_chunk_count(ctx->host.user);
    uint64_t total = 0;
    /* every chunk with the nonzero revision of the last upload (0: the host tracks none) */
    int revs_same = s->chunk_rev != NULL && s->chunk_rev_count == chunks;
    bool any_radius = false, any_kernel = false;
    for (uint32_t c = 0; c < chunks; ++c) {
        vfx_particle_view2 v2;
        vfx_particle_view v;
        vfx_result r = query_chunk(ctx, c, &v2);
        v = v2.v1;
        if (r)
            return volfx_fail(ctx, r, "water: particle chunk %u of %u failed (%d)", c, chunks, (int)r);
        any_radius = any_radius || (v.count && v.radius);
        any_kernel = any_kernel || (v.count && v2.kernel);
        if (v.count && (!v.pos[0] || !v.pos[1] || !v.pos[2]))
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "water: particle chunk %u has %u particles but a NULL position column", c, v.count);
        total += v.count;
        revs_same = revs_same && v.revision != 0 && v.revision == s->chunk_rev[c];
    }
    if (total > WATER_MAX_PARTICLES)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT,
                        "water: %u particle chunks hold %llu particles, more than the limit of %u (2^30)",
                        chunks, (unsigned long long)total, WATER_MAX_PARTICLES);
    GLuint before = s->groups ? s->groups[0].cols[0] : 0;
    uint32_t before_groups = s->group_count;
    vfx_result gr = ensure_groups(ctx, s, (uint32_t)total);
    if (gr)
        return gr;
    /* The same revisions, the same total and the same buffers: the columns already hold these
     * positions (the box and the NaN count are still right), so nothing is read or uploaded. */
    int same = revs_same && total == s->count && s->groups[0].cols[0] == before &&
               s->group_count == before_groups;
    s->upload_skipped = same;
    if (same)
        return VFX_OK;
    if (chunks != s->chunk_rev_count) {
        volfx_free(ctx, s->chunk_rev);
        s->chunk_rev_count = 0;
        s->chunk_rev = chunks ? volfx_alloc(ctx, chunks * sizeof *s->chunk_rev) : NULL;
        if (chunks && !s->chunk_rev)
            return VFX_ERR_OUT_OF_MEMORY;
        s->chunk_rev_count = chunks;
    }
    /* cleared first: an upload that fails half way leaves 0s, so the next frame uploads again */
    if (chunks)
        memset(s->chunk_rev, 0, chunks * sizeof *s->chunk_rev);
    ++s->data_rev;
    if ((any_radius || any_kernel) && !s->aniso && !(s->aniso = volfx_water_aniso_create(ctx)))
        return VFX_ERR_OUT_OF_MEMORY;
    if (s->aniso) {
        vfx_result r = volfx_water_aniso_columns_begin(ctx, s->aniso, (uint32_t)total, any_radius, any_kernel);
        if (r)
            return r;
    }
    if (!s->spray && !(s->spray = volfx_water_spray_create(ctx)))
        return VFX_ERR_OUT_OF_MEMORY;
    if ((gr = volfx_water_spray_begin(ctx, s->spray, (uint32_t)total)))
        return gr;
    uint32_t off = 0, nan_count = 0;
    int seen = 0;
    for (uint32_t c = 0; c < chunks; ++c) {
        vfx_particle_view2 v2;
        vfx_result r = query_chunk(ctx, c, &v2);
        vfx_particle_view v = v2.v1;
        if (r || off + (uint64_t)v.count > total)
            return volfx_fail(ctx, r ? r : VFX_ERR_INVALID_ARGUMENT,
                            "water: particle chunk %u changed between the count and the upload", c);
        /* a chunk may straddle buffers: it goes in pieces, each inside one group */
        for (uint32_t done = 0; done < v.count;) {
            uint32_t at = off + done, g = at / s->buffer_cap, within = at - s->groups[g].first;
            uint32_t n = s->groups[g].count - within;
            if (n > v.count - done)
                n = v.count - done;
            for (int k = 0; k < 3; ++k)
                glNamedBufferSubData(s->groups[g].cols[k], (GLintptr)within * 4, (GLsizeiptr)n * 4, v.pos[k] + done);
            done += n;
        }
        /* NaN/Inf positions are uploaded as they are and skipped by the shaders (a NaN
         * distance fails every `<` test); counted here so the host can see them. */
        for (uint32_t i = 0; i < v.count; ++i) {
            float q[3] = {v.pos[0][i], v.pos[1][i], v.pos[2][i]};
            if (!isfinite(q[0]) || !isfinite(q[1]) || !isfinite(q[2])) {
                ++nan_count;
                continue;
            }
            for (int k = 0; k < 3; ++k) {
                if (!seen || q[k] < s->lo[k]) s->lo[k] = q[k];
                if (!seen || q[k] > s->hi[k]) s->hi[k] = q[k];
            }
            seen = 1;
        }
        if (s->aniso && (r = volfx_water_aniso_columns_chunk(ctx, s->aniso, c, off, v.count, v.radius, v2.kernel)))
            return r;
        if ((r = volfx_water_spray_chunk(ctx, s->spray, off, &v)))
            return r;
        off += v.count;
        s->chunk_rev[c] = v.revision;
    }
    s->count = off;
    s->nan_count = nan_count;
    const char *e = volfx_gpu_error_string();
    if (e)
        return volfx_fail(ctx, VFX_ERR_GL, "water upload of %u particles: %s", off, e);
    return VFX_OK;
}


static void set_common(vfx_context *ctx, GLuint prog, const water_state *s, const vfx_frame_view *frame,
                       const volfx_frame_targets *targets, float t_end)
{
    const vfx_water_params *p = &s->params;
    glUniformMatrix4fv(volfx_gpu_uniform(ctx, prog, "u_inv_view_proj"), 1, GL_FALSE, targets->inv_view_proj);
    glUniform3fv(volfx_gpu_uniform(ctx, prog, "u_eye"), 1, frame->eye);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_h"), p->h);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_T"), p->threshold);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_step"), p->step);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_t_end"), t_end);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_near"), frame->near_plane > 0 ? frame->near_plane : 0.01f);
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_max_samples"), p->max_samples);
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_count"), s->count);
    glUniform1i(volfx_gpu_uniform(ctx, prog, "u_has_depth"), frame->depth_texture != 0);
    glUniform2i(volfx_gpu_uniform(ctx, prog, "u_size"), (GLint)s->width, (GLint)s->height);
    glUniform2f(volfx_gpu_uniform(ctx, prog, "u_sizef"), (float)s->width, (float)s->height);
    if (frame->depth_texture)
        glBindTextureUnit(1, frame->depth_texture);
}

static void dispatch(const water_state *s)
{
    glDispatchCompute((s->width + 7) / 8, (s->height + 7) / 8, 1);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
}

/* Min/max pyramid of the distances in `src` (level 0 from `pyr0`, 2x2 reductions by `pyrd`
 * down to `level`): the tiles the billboard passes cull against. */
static void build_pyramid(vfx_context *ctx, const water_state *s, GLuint pyr0, GLuint pyrd, const vfx_frame_view *frame,
                          const volfx_frame_targets *targets, float t_end, GLuint src, int level)
{
    glUseProgram(pyr0);
    set_common(ctx, pyr0, s, frame, targets, t_end);
    glBindImageTexture(2, src, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32F);
    glBindImageTexture(5, s->pyr, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RG32F);
    dispatch(s);
    glUseProgram(pyrd);
    for (int l = 1; l <= level; ++l) {
        glBindImageTexture(5, s->pyr, l, GL_FALSE, 0, GL_WRITE_ONLY, GL_RG32F);
        glBindImageTexture(6, s->pyr, l - 1, GL_FALSE, 0, GL_READ_ONLY, GL_RG32F);
        uint32_t w = s->width >> l, h = s->height >> l;
        glDispatchCompute(((w ? w : 1) + 7) / 8, ((h ? h : 1) + 7) / 8, 1);
        glMemoryBarrier(GL_ALL_BARRIER_BITS);
    }
}

/* Draws every particle's billboard with `prog` (one instanced strip). */
static void draw_billboards(vfx_context *ctx, const water_state *s)
{
    (void)ctx;
    glBindVertexArray(s->vao);
    /* one draw per buffer, in order: the blending order (hence the rounding) is the same as
     * one draw over all particles */
    for (uint32_t g = 0; g < s->group_count; ++g) {
        if (!s->groups[g].count)
            continue;
        for (int k = 0; k < 3; ++k)
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)k, s->groups[g].cols[k]);
        glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, (GLsizei)s->groups[g].count);
    }
    for (int k = 0; k < 3; ++k)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)k, s->cols[k]);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
}

static vfx_result brute_march(vfx_context *ctx, water_state *s, const vfx_frame_view *frame,
                              volfx_frame_targets *targets)
{
    GLuint prog = volfx_gpu_compute(ctx, "water/brute.comp", NULL);
    if (!prog)
        return VFX_ERR_GL;
    volfx_gpu_pass_begin(ctx, "water.brute");
    glUseProgram(prog);
    for (int k = 0; k < 3; ++k)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)k, s->cols[k]);
    volfx_water_march_bind(ctx, prog, ctx->water_dist_tex, &s->params, frame, targets);
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_count"), s->count);
    glDispatchCompute((s->width + 7) / 8, (s->height + 7) / 8, 1);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
    volfx_gpu_pass_end(ctx);
    return VFX_OK;
}

/* Potentials at the current samples (tex `at`, NS samples from it) into s->pot: additive
 * blending of billboards (technique 3) or the compute-shader sum (VFX_WATER_NO_BLEND). */
static vfx_result potential_pass(vfx_context *ctx, water_state *s, const vfx_frame_view *frame,
                                 const volfx_frame_targets *targets, GLuint at, int ns, int cull,
                                 float t_end)
{
    char defs[96];
    if (s->params.disable & VFX_WATER_NO_BLEND) {
        snprintf(defs, sizeof defs, "#define MODE_POTSUM\n#define NS %d\n", ns);
        GLuint prog = volfx_gpu_compute(ctx, "water/march.comp", defs);
        if (!prog)
            return VFX_ERR_GL;
        glUseProgram(prog);
        set_common(ctx, prog, s, frame, targets, t_end);
        glBindImageTexture(2, at, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32F);
        glBindImageTexture(5, s->pot, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
        dispatch(s);
        return VFX_OK;
    }
    snprintf(defs, sizeof defs, "#define PASS_POT\n#define NS %d\n", ns);
    GLuint prog = volfx_gpu_program(ctx, "water/billboard.vert", "water/billboard.frag", defs);
    if (!prog)
        return VFX_ERR_GL;
    glBindFramebuffer(GL_FRAMEBUFFER, s->fbo_pot);
    glViewport(0, 0, (GLsizei)s->width, (GLsizei)s->height);
    float zero[4] = {0, 0, 0, 0};
    glClearNamedFramebufferfv(s->fbo_pot, GL_COLOR, 0, zero);
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glBlendEquation(GL_FUNC_ADD);
    glUseProgram(prog);
    set_common(ctx, prog, s, frame, targets, t_end);
    glUniformMatrix4fv(volfx_gpu_uniform(ctx, prog, "u_view_proj"), 1, GL_FALSE, s->view_proj);
    glBindTextureUnit(0, at);
    glBindTextureUnit(1, s->pyr);
    int level = (int)s->params.pyramid_level;
    if (level >= s->pyr_levels)
        level = s->pyr_levels - 1;
    glUniform1i(volfx_gpu_uniform(ctx, prog, "u_pyr_level"), level);
    glUniform1i(volfx_gpu_uniform(ctx, prog, "u_cull"), cull);
    draw_billboards(ctx, s);
    glDisable(GL_BLEND);
    return VFX_OK;
}

/* A depth-tested billboard pass into the distance buffer: each pixel keeps its nearest cube
 * front face. With after = 0 that is the initial sample (eq. 1); with the t'_next texture bound
 * as `after`, the nearest candidate region at or beyond it (eqs. 3-4). */
static void nearest_face_pass(vfx_context *ctx, const water_state *s, GLuint prog,
                              const vfx_frame_view *frame, const volfx_frame_targets *targets,
                              float t_end, const float vp[16], GLuint after)
{
    static const float far4[4] = {1e30f, 1e30f, 1e30f, 1e30f};
    glBindFramebuffer(GL_FRAMEBUFFER, s->fbo_dist);
    glViewport(0, 0, (GLsizei)s->width, (GLsizei)s->height);
    glClearNamedFramebufferfv(s->fbo_dist, GL_COLOR, 0, far4);
    glClearNamedFramebufferfi(s->fbo_dist, GL_DEPTH_STENCIL, 0, 1.0f, 0);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glUseProgram(prog);
    set_common(ctx, prog, s, frame, targets, t_end);
    glUniformMatrix4fv(volfx_gpu_uniform(ctx, prog, "u_view_proj"), 1, GL_FALSE, vp);
    if (after)
        glBindTextureUnit(0, after);
    draw_billboards(ctx, s);
    glDisable(GL_DEPTH_TEST);
}

/* Shading inputs at the found surface, for every method: the gradient pass (additive
 * blending of grad P and P at the surface point, tile-culled against the pyramid of the final
 * distances like the potential passes) and the back-distance pass (max blending of the ray's
 * exit from each particle's ball of radius h(1 - T)). */
static vfx_result surface_passes(vfx_context *ctx, water_state *s, const vfx_frame_view *frame,
                                 const volfx_frame_targets *targets)
{
    const vfx_water_params *p = &s->params;
    const int cull = !(p->disable & VFX_WATER_NO_PYRAMID);
    int level = (int)p->pyramid_level;
    if (level >= s->pyr_levels)
        level = s->pyr_levels - 1;
    GLuint pyr0 = volfx_gpu_compute(ctx, "water/march.comp", "#define MODE_PYR0\n#define NS 1\n");
    GLuint pyrd = volfx_gpu_compute(ctx, "water/march.comp", "#define MODE_PYRDOWN\n#define NS 1\n");
    GLuint grad = volfx_gpu_program(ctx, "water/billboard.vert", "water/billboard.frag", "#define PASS_GRAD\n#define NS 1\n");
    GLuint back = volfx_gpu_program(ctx, "water/billboard.vert", "water/billboard.frag", "#define PASS_BACK\n#define NS 1\n");
    if (!pyr0 || !pyrd || !grad || !back)
        return VFX_ERR_GL;
    static const float zero[4] = {0, 0, 0, 0};

    volfx_gpu_pass_begin(ctx, "water.normal");
    if (cull)
        build_pyramid(ctx, s, pyr0, pyrd, frame, targets, 0, ctx->water_dist_tex, level);
    glBindFramebuffer(GL_FRAMEBUFFER, s->fbo_grad);
    glViewport(0, 0, (GLsizei)s->width, (GLsizei)s->height);
    glClearNamedFramebufferfv(s->fbo_grad, GL_COLOR, 0, zero);
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glBlendEquation(GL_FUNC_ADD);
    glUseProgram(grad);
    set_common(ctx, grad, s, frame, targets, 0);
    glUniformMatrix4fv(volfx_gpu_uniform(ctx, grad, "u_view_proj"), 1, GL_FALSE, s->view_proj);
    glUniform1i(volfx_gpu_uniform(ctx, grad, "u_pyr_level"), level);
    glUniform1i(volfx_gpu_uniform(ctx, grad, "u_cull"), cull);
    glBindTextureUnit(0, ctx->water_dist_tex);
    glBindTextureUnit(1, s->pyr);
    draw_billboards(ctx, s);
    volfx_gpu_pass_end(ctx);

    volfx_gpu_pass_begin(ctx, "water.back");
    glBindFramebuffer(GL_FRAMEBUFFER, s->fbo_back);
    glClearNamedFramebufferfv(s->fbo_back, GL_COLOR, 0, zero);
    glBlendEquation(GL_MAX);
    glUseProgram(back);
    set_common(ctx, back, s, frame, targets, 0);
    glUniformMatrix4fv(volfx_gpu_uniform(ctx, back, "u_view_proj"), 1, GL_FALSE, s->view_proj);
    /* every point within h(1 - T) of a particle is inside (one term alone reaches T^2), so
     * these balls lie in the water: exact for a lone particle, short of a merged body's back */
    float rho = p->h * (1.0f - p->threshold);
    glUniform1f(volfx_gpu_uniform(ctx, back, "u_rho"), rho > 0 ? rho : 0.0f);
    glBindTextureUnit(0, ctx->water_dist_tex);
    draw_billboards(ctx, s);
    glBlendEquation(GL_FUNC_ADD);
    glDisable(GL_BLEND);
    volfx_gpu_pass_end(ctx);
    return VFX_OK;
}

static void publish_counters(vfx_context *ctx, water_state *s)
{
    const uint32_t *c = s->last;
    const int paper = s->last_method == VFX_WATER_METHOD_PAPER;
    const int grid = s->last_method == VFX_WATER_METHOD_GRID;
    if (paper) {
        volfx_stat_set(ctx, "water.fragments_culled", c[0]);
        volfx_stat_set(ctx, "water.potential_fragments", c[1]);
    }
    if (paper || grid) { /* both marches count samples and pixel classes in the same slots */
        volfx_stat_set(ctx, "water.samples", c[2]);
        volfx_stat_set(ctx, "water.pixels_found", c[3]);
        volfx_stat_set(ctx, "water.pixels_sample_cap", c[4]);
        volfx_stat_set(ctx, "water.pixels_left", c[5]);
    }
    const int tile = s->last_method == VFX_WATER_METHOD_TILE;
    if (tile) {
        volfx_stat_set(ctx, "water.samples", c[2]);
        volfx_stat_set(ctx, "water.pixels_found", c[3]);
        volfx_stat_set(ctx, "water.pixels_left", c[5]);
        volfx_stat_set(ctx, "water.pixels_undecided", c[12]);
        volfx_stat_set(ctx, "water.tile_dense_pixels", c[13]);
        volfx_stat_set(ctx, "water.tile_subdivision_samples", c[15]);
        volfx_stat_set(ctx, "water.tile_temporal_reused", c[18]);
        volfx_stat_set(ctx, "water.tile_temporal_fallback", c[19]);
        volfx_stat_set(ctx, "water.tile_temporal_steps_skipped", c[20]);
        volfx_stat_set(ctx, "water.tile_temporal_proof_samples", c[21]);
        volfx_stat_set(ctx, "water.tile_temporal_samples_saved", (double)c[20] - c[21]);
        volfx_stat_set(ctx, "water.tile_half_upsampled", c[22]);
        volfx_stat_set(ctx, "water.tile_half_remarched", c[23]);
    }
    volfx_stat_set(ctx, "water.spray_isolated", c[26]);
    if (paper) {
        /* the cap pixels the finishing pass took (0 with VFX_WATER_NO_FINISH), and what is left
         * undecided: cap pixels not finished plus those the finishing march could not decide */
        volfx_stat_set(ctx, "water.pixels_finished", c[11]);
        volfx_stat_set(ctx, "water.pixels_undecided", (double)c[4] - c[11] + c[12]);
    }
    if (tile || (paper && c[11])) {
        volfx_stat_set(ctx, "water.tile_entries", c[10]);
        volfx_stat_set(ctx, "water.tile_sphere_tests", c[14]);
        volfx_stat_set(ctx, "water.tile_global_particles", c[16]);
        volfx_stat_set(ctx, "water.tile_overflow_pixels", c[17]);
    }
    if (tile && c[24] + c[25] > 0) {
        volfx_stat_set(ctx, "water.aniso_stretched", c[24]);
        volfx_stat_set(ctx, "water.aniso_isotropic", c[25]);
    }
    if (grid) {
        volfx_stat_set(ctx, "water.grid_cells_visited", c[8]);
        volfx_stat_set(ctx, "water.grid_sphere_tests", c[9]);
    }
    volfx_stat_set(ctx, "water.normal_fragments_culled", c[6]);
    volfx_stat_set(ctx, "water.normal_fragments", c[7]);
    volfx_stat_set(ctx, "water.counters_age", (double)(s->frame_no - 1 - s->last_frame));
}

/* Counters without a stall: this frame's are copied into a ring slot and fenced; every slot
 * whose fence has signalled is read (the copy is done, so the read does not wait) and the
 * newest is reported, `water.counters_age` frames old. A slot still in flight when its turn
 * comes again (the GPU 3 frames behind) is waited for. debug.sync_counters waits for this
 * frame's at once (tests, benchmarks). */
static void counters_frame_end(vfx_context *ctx, water_state *s, uint32_t method)
{
    const GLuint64 forever = 60ull * 1000000000ull;
    uint32_t slot = (uint32_t)(s->frame_no % WATER_COUNTER_RING);
    if (s->fence[slot])
        glClientWaitSync(s->fence[slot], GL_SYNC_FLUSH_COMMANDS_BIT, forever);
    for (int pass = 0; pass < 2; ++pass) {
        for (uint32_t k = 0; k < WATER_COUNTER_RING; ++k) {
            if (!s->fence[k])
                continue;
            GLenum st = glClientWaitSync(s->fence[k], 0, 0);
            if (st != GL_ALREADY_SIGNALED && st != GL_CONDITION_SATISFIED)
                continue;
            if (!s->have_last || s->ring_frame[k] > s->last_frame) {
                glGetNamedBufferSubData(s->ring[k], 0, sizeof s->last, s->last);
                s->last_frame = s->ring_frame[k];
                s->last_method = s->ring_method[k];
                s->have_last = 1;
            }
            glDeleteSync(s->fence[k]);
            s->fence[k] = 0;
        }
        if (pass == 1)
            break;
        /* this frame's copy after the older slots are read, so the poll sees them first */
        glCopyNamedBufferSubData(s->counters, s->ring[slot], 0, 0, sizeof s->last);
        s->fence[slot] = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
        s->ring_frame[slot] = s->frame_no;
        s->ring_method[slot] = method;
        if (ctx->debug.sync_counters)
            glClientWaitSync(s->fence[slot], GL_SYNC_FLUSH_COMMANDS_BIT, forever);
        else
            break;
    }
    ++s->frame_no;
    if (s->have_last)
        publish_counters(ctx, s);
}

static vfx_result paper_march(vfx_context *ctx, water_state *s, const vfx_frame_view *frame,
                              volfx_frame_targets *targets)
{
    const vfx_water_params *p = &s->params;
    const uint32_t dis = p->disable;
    const int ns = (dis & VFX_WATER_NO_PACK4) ? 1 : 4;
    const int cull = !(dis & VFX_WATER_NO_PYRAMID);
    /* farthest point of the particles' box grown by h: beyond it no sample can be inside */
    float t_end = 0;
    for (int c = 0; c < 8; ++c) {
        float d2 = 0;
        for (int k = 0; k < 3; ++k) {
            float v = ((c >> k) & 1 ? s->hi[k] + p->h : s->lo[k] - p->h) - frame->eye[k];
            d2 += v * v;
        }
        if (d2 > t_end) t_end = d2;
    }
    t_end = sqrtf(t_end);
    float vp[16];
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) {
            float a = 0;
            for (int k = 0; k < 4; ++k)
                a += frame->proj[k * 4 + r] * frame->view[c * 4 + k];
            vp[c * 4 + r] = a;
        }
    memcpy(s->view_proj, vp, sizeof vp);
    for (int k = 0; k < 3; ++k)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)k, s->cols[k]);
    float zero[4] = {0, 0, 0, 0};
    glClearTexImage(s->st, 0, GL_RGBA, GL_FLOAT, zero);
    glClearTexImage(s->br, 0, GL_RGBA, GL_FLOAT, zero);
    char defs[96];

    /* (1) initial sample: nearest cube front face per pixel by the depth test (eq. 1) */
    volfx_gpu_pass_begin(ctx, "water.init");
    if (dis & VFX_WATER_NO_BILLBOARD_INIT) {
        float nearv[4] = {frame->near_plane, 0, 0, 0};
        glClearTexImage(s->cur, 0, GL_RED, GL_FLOAT, nearv);
    } else {
        GLuint prog = volfx_gpu_program(ctx, "water/billboard.vert", "water/billboard.frag", "#define PASS_INIT\n#define NS 1\n");
        if (!prog)
            return VFX_ERR_GL;
        nearest_face_pass(ctx, s, prog, frame, targets, t_end, vp, 0);
    }
    volfx_gpu_pass_end(ctx);

    uint32_t iters = (p->max_samples + (uint32_t)ns - 1) / (uint32_t)ns;
    snprintf(defs, sizeof defs, "#define MODE_UPDATE\n#define NS %d\n", ns);
    GLuint upd = volfx_gpu_compute(ctx, "water/march.comp", defs);
    snprintf(defs, sizeof defs, "#define MODE_PYR0\n#define NS %d\n", ns);
    GLuint pyr0 = volfx_gpu_compute(ctx, "water/march.comp", defs);
    GLuint pyrd = volfx_gpu_compute(ctx, "water/march.comp", "#define MODE_PYRDOWN\n#define NS 1\n");
    GLuint skip = volfx_gpu_program(ctx, "water/billboard.vert", "water/billboard.frag", "#define PASS_SKIP\n#define NS 1\n");
    if (!upd || !pyr0 || !pyrd || !skip)
        return VFX_ERR_GL;
    int level = (int)p->pyramid_level;
    if (level >= s->pyr_levels)
        level = s->pyr_levels - 1;
    volfx_gpu_pass_begin(ctx, "water.march");
    for (uint32_t it = 0; it < iters; ++it) {
        /* (5) min/max pyramid of the current samples, 2x2 reductions down to `level` */
        if (cull) {
            volfx_gpu_pass_begin(ctx, "water.pyramid");
            build_pyramid(ctx, s, pyr0, pyrd, frame, targets, t_end, s->cur, level);
            volfx_gpu_pass_end(ctx);
        }
        /* (3)+(4) potentials at NS consecutive samples */
        volfx_gpu_pass_begin(ctx, "water.potential");
        vfx_result r = potential_pass(ctx, s, frame, targets, s->cur, ns, cull, t_end);
        volfx_gpu_pass_end(ctx);
        if (r)
            return r;
        /* inside/outside, stop flag, t'_next = t + NS w (eq. 2) into buffer 1 */
        volfx_gpu_pass_begin(ctx, "water.update");
        glUseProgram(upd);
        set_common(ctx, upd, s, frame, targets, t_end);
        glBindImageTexture(0, s->st, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
        glBindImageTexture(1, s->br, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
        glBindImageTexture(2, s->cur, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32F);
        glBindImageTexture(3, s->next1, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
        glBindTextureUnit(0, s->pot);
        dispatch(s);
        volfx_gpu_pass_end(ctx);
        /* (2) jump over gaps: buffer 2 = nearest candidate region at or after t'_next
         * (eqs. 3-4, depth test); without it the next sample is t'_next itself */
        volfx_gpu_pass_begin(ctx, "water.skip");
        if (dis & VFX_WATER_NO_SKIP) {
            GLuint t = s->cur;
            s->cur = s->next1;
            s->next1 = t;
            glNamedFramebufferTexture(s->fbo_dist, GL_COLOR_ATTACHMENT0, s->cur, 0);
        } else {
            nearest_face_pass(ctx, s, skip, frame, targets, t_end, vp, s->next1);
        }
        volfx_gpu_pass_end(ctx);
    }

    volfx_gpu_pass_end(ctx);

    /* (6) eq. 5 then eq. 6 regula falsi, each iteration's potential again by blending */
    volfx_gpu_pass_begin(ctx, "water.refine");
    GLuint interp = volfx_gpu_compute(ctx, "water/march.comp", "#define MODE_INTERP\n#define NS 1\n");
    GLuint refine = volfx_gpu_compute(ctx, "water/march.comp", "#define MODE_REFINE\n#define NS 1\n");
    GLuint fin = volfx_gpu_compute(ctx, "water/march.comp", "#define MODE_FINAL\n#define NS 1\n");
    if (!interp || !refine || !fin)
        return VFX_ERR_GL;
    glUseProgram(interp);
    set_common(ctx, interp, s, frame, targets, t_end);
    glBindImageTexture(0, s->st, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    glBindImageTexture(1, s->br, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    glBindImageTexture(2, s->reft, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32F);
    dispatch(s);
    uint32_t riters = (dis & VFX_WATER_NO_REFINE) ? 0 : p->refine_iters;
    for (uint32_t it = 0; it < riters; ++it) {
        vfx_result r = potential_pass(ctx, s, frame, targets, s->reft, 1, 0, t_end);
        if (r)
            return r;
        glUseProgram(refine);
        set_common(ctx, refine, s, frame, targets, t_end);
        glBindImageTexture(0, s->st, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
        glBindImageTexture(1, s->br, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
        glBindImageTexture(2, s->reft, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32F);
        glBindTextureUnit(0, s->pot);
        dispatch(s);
    }
    glUseProgram(fin);
    set_common(ctx, fin, s, frame, targets, t_end);
    glBindImageTexture(0, s->st, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    glBindImageTexture(1, s->br, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    glBindImageTexture(2, s->reft, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32F);
    glBindImageTexture(3, ctx->water_dist_tex, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    glBindImageTexture(4, s->cur, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32F);
    dispatch(s);
    volfx_gpu_pass_end(ctx);
    return VFX_OK;
}

static vfx_result grid_march(vfx_context *ctx, water_state *s, const vfx_frame_view *frame,
                             const volfx_frame_targets *targets)
{
    if (!s->grid && !(s->grid = volfx_water_grid_create(ctx)))
        return VFX_ERR_OUT_OF_MEMORY;
    volfx_water_grid_input in = {s->cols, s->count, s->count - s->nan_count, s->lo, s->hi, &s->params,
                               s->width, s->height, ctx->water_dist_tex, s->counters, s->data_rev};
    return volfx_water_grid_render(ctx, s->grid, &in, frame, targets);
}

static vfx_result tile_lists(vfx_context *ctx, water_state *s, volfx_water_tile_input *in,
                             const vfx_frame_view *frame)
{
    if (!s->tile && !(s->tile = volfx_water_tile_create(ctx)))
        return VFX_ERR_OUT_OF_MEMORY;
    *in = (volfx_water_tile_input){s->cols, s->count, &s->params, s->width, s->height, ctx->water_dist_tex,
                                   s->counters, s->have_last ? s->last[10] : 0, s->view_proj, s->lo, s->hi,
                                   frame->eye, fabsf(frame->proj[5]) * 0.5f * (float)s->height, s->frame_no, 0, 0.0f};
    /* per-particle kernels: the anisotropic ones, or the host's radius / kernel columns */
    if (s->params.method == VFX_WATER_METHOD_TILE &&
        (s->kp.kernel == VFX_WATER_KERNEL_ANISOTROPIC || volfx_water_aniso_has_columns(s->aniso))) {
        if (!s->aniso && !(s->aniso = volfx_water_aniso_create(ctx)))
            return VFX_ERR_OUT_OF_MEMORY;
        volfx_water_aniso_input ai = {s->cols, s->count, s->lo, s->hi, s->params.h, &s->kp, s->counters, s->data_rev};
        vfx_result r = volfx_water_aniso_compute(ctx, s->aniso, &ai);
        if (r)
            return r;
        in->kernels = volfx_water_aniso_kernels(s->aniso);
        in->rbound = s->params.h * volfx_water_aniso_sigma_bound(s->aniso);
    }
    return volfx_water_tile_bin(ctx, s->tile, in);
}

static vfx_result tile_march(vfx_context *ctx, water_state *s, const vfx_frame_view *frame,
                             const volfx_frame_targets *targets)
{
    volfx_water_tile_input in;
    vfx_result r = tile_lists(ctx, s, &in, frame);
    return r ? r : volfx_water_tile_march(ctx, s->tile, &in, frame, targets, s->grad, s->back);
}

/* The paper method's sample-cap pixels, finished by TILE's march from where they stopped. */
static vfx_result paper_finish(vfx_context *ctx, water_state *s, const vfx_frame_view *frame,
                               const volfx_frame_targets *targets)
{
    volfx_water_tile_input in;
    vfx_result r = tile_lists(ctx, s, &in, frame);
    return r ? r : volfx_water_tile_finish(ctx, s->tile, &in, frame, targets, s->st, s->cur);
}

static vfx_result water_render(vfx_context *ctx, void *state, const vfx_frame_view *frame,
                               volfx_frame_targets *targets)
{
    water_state *s = state;
    const vfx_water_params *p = &s->params;
    targets->water_dist = ctx->water_dist_tex;
    volfx_stat_set(ctx, "water.position_buffers", s->group_count);
    if (s->group_count > 1 && (p->method != VFX_WATER_METHOD_PAPER || (p->disable & VFX_WATER_NO_BLEND)))
        return volfx_fail(ctx, VFX_ERR_UNSUPPORTED,
                        "water: %u particles span %u position buffers of at most %u; method %u%s reads one "
                        "buffer (only the paper method's billboard passes draw several)",
                        s->count, s->group_count, s->buffer_cap, p->method,
                        (p->disable & VFX_WATER_NO_BLEND) ? " with NO_BLEND" : "");
    volfx_mat4_mul(frame->proj, frame->view, s->view_proj);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, s->counters);
    glClearNamedBufferData(s->counters, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
    volfx_stat_set(ctx, "water.particles", s->count);
    volfx_stat_set(ctx, "water.nan_skipped", s->nan_count);
    volfx_stat_set(ctx, "water.upload_skipped", s->upload_skipped);
    s->last_method_drawn = UINT32_MAX; /* until this frame completes: nothing for debug_pixel_class */
    vfx_result r;
    /* the seed's method and the baselines draw the isotropic kernel of radius h only */
    if (p->method != VFX_WATER_METHOD_TILE &&
        (s->kp.kernel == VFX_WATER_KERNEL_ANISOTROPIC || volfx_water_aniso_has_columns(s->aniso)))
        return volfx_fail(ctx, VFX_ERR_UNSUPPORTED,
                          "water: %s is drawn by method TILE (3) only; method %u draws the isotropic kernel of radius h "
                          "(scene key water.quality.kernel / method)",
                          s->kp.kernel == VFX_WATER_KERNEL_ANISOTROPIC ? "the anisotropic kernel (vfx_water_params2.kernel)"
                                                                        : "a per-particle radius or kernel column (vfx_particle_view.radius, vfx_particle_view2.kernel)",
                          p->method);
    if (p->method == VFX_WATER_METHOD_PAPER) {
        r = paper_march(ctx, s, frame, targets);
        /* the tile lists read one position buffer: with several, the cap pixels stay holes
         * (counted in water.pixels_undecided) */
        if (r == VFX_OK && !(p->disable & VFX_WATER_NO_FINISH) && s->group_count == 1)
            r = paper_finish(ctx, s, frame, targets);
    } else if (p->method == VFX_WATER_METHOD_TILE)
        r = tile_march(ctx, s, frame, targets);
    else if (p->method == VFX_WATER_METHOD_BRUTE)
        r = brute_march(ctx, s, frame, targets);
    else if (p->method == VFX_WATER_METHOD_GRID)
        r = grid_march(ctx, s, frame, targets);
    else
        r = volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "water: unknown method %u in vfx_water_params (0 paper, 1 brute, 2 grid, 3 tile)", p->method);
    if (r != VFX_OK)
        return r;
    /* TILE wrote the gradient and back distance from its own lists */
    if (!(p->disable & VFX_WATER_NO_SHADING) && p->method != VFX_WATER_METHOD_TILE &&
        (r = surface_passes(ctx, s, frame, targets)) != VFX_OK)
        return r;

    GLuint shade = volfx_gpu_program(ctx, "common/fullscreen.vert", "water/shade.frag", NULL);
    if (!shade)
        return VFX_ERR_GL;
    volfx_gpu_pass_begin(ctx, "water.shade");
    glBindFramebuffer(GL_FRAMEBUFFER, frame->framebuffer);
    glViewport(0, 0, (GLsizei)frame->width, (GLsizei)frame->height);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glUseProgram(shade);
    glBindTextureUnit(0, ctx->water_dist_tex);
    glBindTextureUnit(1, frame->color_texture);
    glBindTextureUnit(2, s->grad);
    glBindTextureUnit(3, s->back);
    glBindTextureUnit(4, frame->depth_texture);
    glUniformMatrix4fv(volfx_gpu_uniform(ctx, shade, "u_inv_view_proj"), 1, GL_FALSE, targets->inv_view_proj);
    glUniformMatrix4fv(volfx_gpu_uniform(ctx, shade, "u_view_proj"), 1, GL_FALSE, targets->view_proj);
    glUniform3fv(volfx_gpu_uniform(ctx, shade, "u_eye"), 1, frame->eye);
    glUniform1f(volfx_gpu_uniform(ctx, shade, "u_h"), p->h);
    glUniform1i(volfx_gpu_uniform(ctx, shade, "u_refract_view"), (p->disable & VFX_WATER_NO_REFRACT_TRACE) != 0);
    glUniform1f(volfx_gpu_uniform(ctx, shade, "u_absorption"), p->absorption);
    glUniform1f(volfx_gpu_uniform(ctx, shade, "u_ior"), p->ior);
    glUniform3fv(volfx_gpu_uniform(ctx, shade, "u_tint"), 1, p->color);
    glUniform1i(volfx_gpu_uniform(ctx, shade, "u_flat"), (p->disable & VFX_WATER_NO_SHADING) != 0);
    glUniform1i(volfx_gpu_uniform(ctx, shade, "u_has_color"), frame->color_texture != 0);
    glUniform1i(volfx_gpu_uniform(ctx, shade, "u_has_depth"), frame->depth_texture != 0);
    if (targets->environment_cubemap)
        glBindTextureUnit(5, targets->environment_cubemap);
    glUniform1i(volfx_gpu_uniform(ctx, shade, "u_has_env"), targets->environment_cubemap != 0);
    glUniform1i(volfx_gpu_uniform(ctx, shade, "u_hdr"), targets->color_hdr);
    volfx_gpu_fullscreen(ctx);
    volfx_gpu_pass_end(ctx);
    if (!(p->disable & (VFX_WATER_NO_SPRAY | VFX_WATER_NO_SHADING)) && s->spray && s->group_count == 1 &&
        (r = volfx_water_spray_draw(ctx, s->spray, s->cols, s->count, p, frame, targets, ctx->water_dist_tex, s->vao,
                                     s->kp.kernel == VFX_WATER_KERNEL_ANISOTROPIC ? volfx_water_aniso_neighbours(s->aniso) : 0,
                                     s->kp.min_neighbours)))
        return r;
    counters_frame_end(ctx, s, p->method);
    s->last_method_drawn = p->method;
    const char *e = volfx_gpu_error_string();
    if (e)
        return volfx_fail(ctx, VFX_ERR_GL, "water render: %s", e);
    return VFX_OK;
}

vfx_result volfx_water_debug_gradient(vfx_context *ctx, float *out, size_t count)
{
    water_state *s = ctx->effect_state[VFX_EFFECT_WATER];
    if (!s || !s->grad)
        return volfx_fail(ctx, VFX_ERR_NOT_FOUND, "water debug gradient: no water effect or no render yet");
    size_t n = (size_t)s->width * s->height * 4;
    if (!out || count < n)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "water debug gradient: %zu floats, need %zu", count, n);
    return volfx_gpu_read_top_first(ctx, s->grad, GL_RGBA, 4, -1, s->width, s->height, out);
}

vfx_result volfx_water_debug_pixel_class(vfx_context *ctx, uint8_t *out, size_t count)
{
    water_state *s = ctx->effect_state[VFX_EFFECT_WATER];
    if (!s || !s->st || s->frame_no == 0 || s->last_method_drawn != VFX_WATER_METHOD_PAPER)
        return volfx_fail(ctx, VFX_ERR_NOT_FOUND, "water debug pixel class: no paper-method frame rendered yet");
    size_t n = (size_t)s->width * s->height;
    if (!out || count < n)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "water debug pixel class: %zu bytes, need %zu", count, n);
    float *cls = volfx_alloc(ctx, n * sizeof *cls);
    if (!cls)
        return VFX_ERR_OUT_OF_MEMORY;
    vfx_result r = volfx_gpu_read_top_first(ctx, s->st, GL_RGBA, 4, 0, s->width, s->height, cls);
    for (size_t p = 0; r == VFX_OK && p < n; ++p)
        out[p] = (uint8_t)cls[p];
    volfx_free(ctx, cls);
    return r;
}

vfx_result volfx_water_debug_kernels(vfx_context *ctx, float *out, uint32_t *nbrs, size_t particles)
{
    water_state *s = ctx->effect_state[VFX_EFFECT_WATER];
    GLuint kern = s ? volfx_water_aniso_kernels(s->aniso) : 0;
    if (!kern)
        return volfx_fail(ctx, VFX_ERR_NOT_FOUND, "water debug kernels: no per-particle kernels computed yet");
    if (!out || particles < s->count)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "water debug kernels: room for %zu particles, need %u", particles, s->count);
    glGetNamedBufferSubData(kern, 0, (GLsizeiptr)s->count * VOLFX_WATER_KERNEL_STRIDE, out);
    if (nbrs)
        glGetNamedBufferSubData(volfx_water_aniso_neighbours(s->aniso), 0, (GLsizeiptr)s->count * 4, nbrs);
    const char *e = volfx_gpu_error_string();
    return e ? volfx_fail(ctx, VFX_ERR_GL, "water debug kernels: %s", e) : VFX_OK;
}

static vfx_result water_read_raw(vfx_context *ctx, void *state, float *out, size_t count)
{
    water_state *s = state;
    size_t n = (size_t)s->width * s->height;
    if (count < n || !ctx->water_dist_tex)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "water read_raw: %zu floats, need %zu", count, n);
    return volfx_gpu_read_top_first(ctx, ctx->water_dist_tex, GL_RED, 1, -1, s->width, s->height, out);
}

const volfx_effect_ops volfx_water_ops = {
    .name = "water",
    .kind = VFX_EFFECT_WATER,
    .present = water_present,
    .create = water_create,
    .destroy = water_destroy,
    .resize = water_resize,
    .update = water_update,
    .render = water_render,
    .read_raw = water_read_raw,
};
