/* water_paper.c — method PAPER of the water effect (seed 000, Mishima et al.): billboard init
 * by depth test (eq. 1), potentials by additive blending into RGBA16F at 4 samples per texel,
 * sample update with two distance buffers and depth-tested gap jumping (eqs. 2-4), min/max
 * pyramid culling, eq. 5 interpolation and eq. 6 regula falsi (each pass again by blending);
 * the gradient and back-distance passes that shade it (and the lab methods' hits). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "gpu/gpu.h"
#include "gpu/pass.h"
#include "context.h"
#include "water_internal.h"

GLuint volfx_water_make_tex(GLenum fmt, uint32_t w, uint32_t h, int levels, const char *label)
{
    GLuint t;
    glCreateTextures(GL_TEXTURE_2D, 1, &t);
    glTextureStorage2D(t, levels, fmt, (GLsizei)w, (GLsizei)h);
    glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    volfx_gpu_label(GL_TEXTURE, t, label);
    return t;
}

void volfx_water_frame_upload(water_state *s, const volfx_frame_targets *targets)
{
    const volfx_water_core *p = &s->params;
    /* farthest point of the particles' box grown by h: beyond it no sample can be inside */
    float t_end = 0;
    for (int c = 0; c < 8; ++c) {
        float d2 = 0;
        for (int k = 0; k < 3; ++k) {
            float v = ((c >> k) & 1 ? s->hi[k] + p->h : s->lo[k] - p->h) - targets->eye[k];
            d2 += v * v;
        }
        if (d2 > t_end) t_end = d2;
    }
    water_frame_block blk = {
        .h = p->h, .threshold = p->threshold, .step = p->step, .t_end = sqrtf(t_end),
        .near_plane = targets->near_plane > 0 ? targets->near_plane : 0.01f, .max_samples = p->max_samples,
        .count = s->count, .has_depth = targets->host_depth != 0,
        .size = {(int32_t)s->width, (int32_t)s->height}, .sizef = {(float)s->width, (float)s->height}};
    memcpy(blk.inv_view_proj, targets->inv_view_proj, sizeof blk.inv_view_proj);
    memcpy(blk.view_proj, s->view_proj, sizeof blk.view_proj);
    memcpy(blk.eye, targets->eye, sizeof blk.eye);
    volfx_ubo_update(&s->frame_ubo, &blk, sizeof blk);
    volfx_ubo_bind(&s->frame_ubo, 4);
}

void volfx_water_bind_depth(const volfx_frame_targets *targets)
{
    if (targets->host_depth)
        glBindTextureUnit(1, targets->host_depth);
}

void volfx_water_dispatch(const water_state *s)
{
    glDispatchCompute((s->width + 7) / 8, (s->height + 7) / 8, 1);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
}

/* Min/max pyramid of the distances in `src` (level 0 from `pyr0`, 2x2 reductions by `pyrd`
 * down to `level`): the tiles the billboard passes cull against. */
static void build_pyramid(const water_state *s, GLuint pyr0, GLuint pyrd, const volfx_frame_targets *targets, GLuint src,
                          int level)
{
    glUseProgram(pyr0);
    volfx_water_bind_depth(targets);
    glBindImageTexture(2, src, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32F);
    glBindImageTexture(5, s->pyr, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RG32F);
    volfx_water_dispatch(s);
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

/* Potentials at the current samples (tex `at`, NS samples from it) into s->pot: additive
 * blending of billboards (technique 3) or the compute-shader sum (VFX_WATER_NO_BLEND). */
static vfx_result potential_pass(vfx_context *ctx, water_state *s, const volfx_frame_targets *targets, GLuint at, int ns,
                                 int cull)
{
    char defs[96];
    if (s->params.disable & VFX_WATER_NO_BLEND) {
        snprintf(defs, sizeof defs, "#define MODE_POTSUM\n#define NS %d\n", ns);
        GLuint prog = volfx_gpu_compute(ctx, "water/march.comp", defs);
        if (!prog)
            return VFX_ERR_GL;
        glUseProgram(prog);
        volfx_water_bind_depth(targets);
        glBindImageTexture(2, at, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32F);
        glBindImageTexture(5, s->pot, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
        volfx_water_dispatch(s);
        return VFX_OK;
    }
    snprintf(defs, sizeof defs, "#define PASS_POT\n#define NS %d\n", ns);
    GLuint prog = volfx_gpu_program(ctx, "water/billboard.vert", "water/billboard.frag", defs);
    if (!prog)
        return VFX_ERR_GL;
    /* inside the caller's timed pass (water.potential or water.refine) */
    volfx_pass_apply(ctx, &(volfx_pass_desc){.framebuffer = s->fbo_pot, .width = s->width, .height = s->height,
                                             .clear_color = true, .blend = VOLFX_BLEND_ADD});
    glUseProgram(prog);
    volfx_water_bind_depth(targets);
    glBindTextureUnit(0, at);
    glBindTextureUnit(1, s->pyr);
    int level = (int)s->params.pyramid_level;
    if (level >= s->pyr_levels)
        level = s->pyr_levels - 1;
    glUniform1i(volfx_gpu_uniform(ctx, prog, "u_pyr_level"), level);
    glUniform1i(volfx_gpu_uniform(ctx, prog, "u_cull"), cull);
    draw_billboards(ctx, s);
    volfx_pass_reset();
    return VFX_OK;
}

/* A depth-tested billboard pass into the distance buffer: each pixel keeps its nearest cube
 * front face. With after = 0 that is the initial sample (eq. 1); with the t'_next texture bound
 * as `after`, the nearest candidate region at or beyond it (eqs. 3-4). */
static void nearest_face_pass(vfx_context *ctx, const water_state *s, GLuint prog, const volfx_frame_targets *targets,
                              GLuint after)
{
    /* inside the caller's timed pass (water.init or water.skip) */
    volfx_pass_apply(ctx, &(volfx_pass_desc){.framebuffer = s->fbo_dist, .width = s->width, .height = s->height,
                                             .clear_color = true, .clear_rgba = {1e30f, 1e30f, 1e30f, 1e30f},
                                             .clear_depth = true, .depth = VOLFX_DEPTH_TEST_WRITE});
    glUseProgram(prog);
    volfx_water_bind_depth(targets);
    if (after)
        glBindTextureUnit(0, after);
    draw_billboards(ctx, s);
    volfx_pass_reset();
}

/* Shading inputs at the found surface, for every method: the gradient pass (additive
 * blending of grad P and P at the surface point, tile-culled against the pyramid of the final
 * distances like the potential passes) and the back-distance pass (max blending of the ray's
 * exit from each particle's ball of radius h(1 - T)). */
vfx_result volfx_water_surface_passes(vfx_context *ctx, water_state *s, const volfx_frame_targets *targets)
{
    const volfx_water_core *p = &s->params;
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
    /* the pyramid is compute: the gradient target's state applies to the draw after it */
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.normal", .framebuffer = s->fbo_grad, .width = s->width,
                                             .height = s->height, .clear_color = true, .blend = VOLFX_BLEND_ADD});
    if (cull)
        build_pyramid(s, pyr0, pyrd, targets, ctx->water_dist_tex, level);
    glUseProgram(grad);
    volfx_water_bind_depth(targets);
    glUniform1i(volfx_gpu_uniform(ctx, grad, "u_pyr_level"), level);
    glUniform1i(volfx_gpu_uniform(ctx, grad, "u_cull"), cull);
    glBindTextureUnit(0, ctx->water_dist_tex);
    glBindTextureUnit(1, s->pyr);
    draw_billboards(ctx, s);
    volfx_pass_end(ctx);

    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.back", .framebuffer = s->fbo_back, .width = s->width,
                                             .height = s->height, .clear_color = true, .blend = VOLFX_BLEND_MAX});
    glUseProgram(back);
    volfx_water_bind_depth(targets);
    /* every point within h(1 - T) of a particle is inside (one term alone reaches T^2), so
     * these balls lie in the water: exact for a lone particle, short of a merged body's back */
    float rho = p->h * (1.0f - p->threshold);
    glUniform1f(volfx_gpu_uniform(ctx, back, "u_rho"), rho > 0 ? rho : 0.0f);
    glBindTextureUnit(0, ctx->water_dist_tex);
    draw_billboards(ctx, s);
    volfx_pass_end(ctx);
    return VFX_OK;
}

/* The refinement's compute steps (eqs. 5-6) read and write the pixel state, the bracket and the
 * refined distance at image units 0-2: prog in use with those bound and the host depth. */
static void refine_step_begin(const water_state *s, GLuint prog, const volfx_frame_targets *targets)
{
    glUseProgram(prog);
    volfx_water_bind_depth(targets);
    glBindImageTexture(0, s->st, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    glBindImageTexture(1, s->br, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    glBindImageTexture(2, s->reft, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32F);
}

vfx_result volfx_water_paper_march(vfx_context *ctx, water_state *s, const volfx_frame_targets *targets)
{
    const volfx_water_core *p = &s->params;
    const uint32_t dis = p->disable;
    const int ns = (dis & VFX_WATER_NO_PACK4) ? 1 : 4;
    const int cull = !(dis & VFX_WATER_NO_PYRAMID);
    for (int k = 0; k < 3; ++k)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)k, s->cols[k]);
    float zero[4] = {0, 0, 0, 0};
    glClearTexImage(s->st, 0, GL_RGBA, GL_FLOAT, zero);
    glClearTexImage(s->br, 0, GL_RGBA, GL_FLOAT, zero);
    char defs[96];

    /* (1) initial sample: nearest cube front face per pixel by the depth test (eq. 1) */
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.init", .compute = true});
    if (dis & VFX_WATER_NO_BILLBOARD_INIT) {
        float nearv[4] = {targets->near_plane, 0, 0, 0};
        glClearTexImage(s->cur, 0, GL_RED, GL_FLOAT, nearv);
    } else {
        GLuint prog = volfx_gpu_program(ctx, "water/billboard.vert", "water/billboard.frag", "#define PASS_INIT\n#define NS 1\n");
        if (!prog)
            return VFX_ERR_GL;
        nearest_face_pass(ctx, s, prog, targets, 0);
    }
    volfx_pass_end(ctx);

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
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.march", .compute = true});
    for (uint32_t it = 0; it < iters; ++it) {
        /* (5) min/max pyramid of the current samples, 2x2 reductions down to `level` */
        if (cull) {
            volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.pyramid", .compute = true});
            build_pyramid(s, pyr0, pyrd, targets, s->cur, level);
            volfx_pass_end(ctx);
        }
        /* (3)+(4) potentials at NS consecutive samples */
        volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.potential", .compute = true});
        vfx_result r = potential_pass(ctx, s, targets, s->cur, ns, cull);
        volfx_pass_end(ctx);
        if (r)
            return r;
        /* inside/outside, stop flag, t'_next = t + NS w (eq. 2) into buffer 1 */
        volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.update", .compute = true});
        glUseProgram(upd);
        volfx_water_bind_depth(targets);
        glBindImageTexture(0, s->st, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
        glBindImageTexture(1, s->br, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
        glBindImageTexture(2, s->cur, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32F);
        glBindImageTexture(3, s->next1, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
        glBindTextureUnit(0, s->pot);
        volfx_water_dispatch(s);
        volfx_pass_end(ctx);
        /* (2) jump over gaps: buffer 2 = nearest candidate region at or after t'_next
         * (eqs. 3-4, depth test); without it the next sample is t'_next itself */
        volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.skip", .compute = true});
        if (dis & VFX_WATER_NO_SKIP) {
            GLuint t = s->cur;
            s->cur = s->next1;
            s->next1 = t;
            glNamedFramebufferTexture(s->fbo_dist, GL_COLOR_ATTACHMENT0, s->cur, 0);
        } else {
            nearest_face_pass(ctx, s, skip, targets, s->next1);
        }
        volfx_pass_end(ctx);
    }

    volfx_pass_end(ctx);

    /* (6) eq. 5 then eq. 6 regula falsi, each iteration's potential again by blending */
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.refine", .compute = true});
    GLuint interp = volfx_gpu_compute(ctx, "water/march.comp", "#define MODE_INTERP\n#define NS 1\n");
    GLuint refine = volfx_gpu_compute(ctx, "water/march.comp", "#define MODE_REFINE\n#define NS 1\n");
    GLuint fin = volfx_gpu_compute(ctx, "water/march.comp", "#define MODE_FINAL\n#define NS 1\n");
    if (!interp || !refine || !fin)
        return VFX_ERR_GL;
    refine_step_begin(s, interp, targets);
    volfx_water_dispatch(s);
    uint32_t riters = (dis & VFX_WATER_NO_REFINE) ? 0 : p->refine_iters;
    for (uint32_t it = 0; it < riters; ++it) {
        vfx_result r = potential_pass(ctx, s, targets, s->reft, 1, 0);
        if (r)
            return r;
        refine_step_begin(s, refine, targets);
        glBindTextureUnit(0, s->pot);
        volfx_water_dispatch(s);
    }
    refine_step_begin(s, fin, targets);
    glBindImageTexture(3, ctx->water_dist_tex, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    glBindImageTexture(4, s->cur, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32F);
    volfx_water_dispatch(s);
    volfx_pass_end(ctx);
    return VFX_OK;
}
