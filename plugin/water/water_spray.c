/* water_spray.c — spray and foam (shaders/water/spray.vert, spray.frag). The speed of each
 * particle is computed on the CPU from the host's velocity columns while the positions upload
 * (one float a particle), so the spray count is known without a readback. */
#include <math.h>
#include <string.h>

#include "gpu/gpu.h"
#include "gpu/pass.h"
#include "water_spray.h"

/* Speeds (scene units per second) where a particle starts to show as spray and where it is
 * fully white: between the paddle's own speed and a splash's in the sample scenes (metres). */
#define SPRAY_SPEED_LO 1.2f
#define SPRAY_SPEED_HI 2.6f
/* billboard radius in units of h: about a particle's spacing (h = 2 x spacing) */
#define SPRAY_RADIUS_H 0.45f
/* an isolated particle (fewer neighbours than the anisotropic kernels' Ne) at this speed or
 * more is a drop in flight: spray, even below SPRAY_SPEED_LO */
#define SPRAY_SPEED_ISOLATED 0.3f

struct volfx_water_spray {
    GLuint speed;       /* one float a particle */
    uint32_t cap;       /* particles `speed` holds */
    float *staging;     /* one chunk's speeds */
    uint32_t staging_cap;
    uint32_t fast;      /* particles at or above SPRAY_SPEED_LO in the last upload */
    int has_vel;        /* every chunk of the last upload gave velocities */
};

volfx_water_spray *volfx_water_spray_create(vfx_context *ctx)
{
    volfx_water_spray *sp = volfx_alloc(ctx, sizeof *sp);
    if (sp)
        memset(sp, 0, sizeof *sp);
    return sp;
}

void volfx_water_spray_destroy(vfx_context *ctx, volfx_water_spray *sp)
{
    if (!sp)
        return;
    if (sp->speed)
        glDeleteBuffers(1, &sp->speed);
    volfx_free(ctx, sp->staging);
    volfx_free(ctx, sp);
}

vfx_result volfx_water_spray_begin(vfx_context *ctx, volfx_water_spray *sp, uint32_t total)
{
    sp->fast = 0;
    sp->has_vel = total > 0;
    if (total <= sp->cap && sp->speed)
        return VFX_OK;
    if (sp->speed)
        glDeleteBuffers(1, &sp->speed);
    sp->speed = volfx_gpu_storage((size_t)total * sizeof(float), "water.spray_speed");
    sp->cap = sp->speed ? total : 0;
    if (!sp->speed)
        return volfx_fail(ctx, VFX_ERR_OUT_OF_MEMORY, "water spray: speed column for %u particles", total);
    return VFX_OK;
}

vfx_result volfx_water_spray_chunk(vfx_context *ctx, volfx_water_spray *sp, uint32_t first,
                                   const vfx_particle_view *v)
{
    if (!v->count)
        return VFX_OK;
    if (first + (uint64_t)v->count > sp->cap)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "water spray: chunk at %u of %u particles passes the %u uploaded",
                          first, v->count, sp->cap);
    if (!v->vel[0] || !v->vel[1] || !v->vel[2]) {
        sp->has_vel = 0; /* a chunk without velocities: no spray this frame */
        return VFX_OK;
    }
    if (v->count > sp->staging_cap) {
        volfx_free(ctx, sp->staging);
        sp->staging = volfx_alloc(ctx, (size_t)v->count * sizeof *sp->staging);
        sp->staging_cap = sp->staging ? v->count : 0;
        if (!sp->staging)
            return VFX_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t i = 0; i < v->count; ++i) {
        float a = v->vel[0][i], b = v->vel[1][i], c = v->vel[2][i];
        float s = sqrtf(a * a + b * b + c * c);
        /* NaN or Inf velocity: not spray (the shader draws only finite speeds in range) */
        s = isfinite(s) ? s : 0.0f;
        sp->staging[i] = s;
        sp->fast += s >= SPRAY_SPEED_LO;
    }
    glNamedBufferSubData(sp->speed, (GLintptr)first * 4, (GLsizeiptr)v->count * 4, sp->staging);
    return VFX_OK;
}

vfx_result volfx_water_spray_draw(vfx_context *ctx, volfx_water_spray *sp, const GLuint cols[3], uint32_t count,
                                  const vfx_water_params *p, const vfx_frame_view *frame,
                                  const volfx_frame_targets *targets, GLuint dist_tex, GLuint vao,
                                  GLuint neighbours, uint32_t min_neighbours)
{
    uint32_t drawn = sp->has_vel ? sp->fast : 0;
    volfx_stat_set(ctx, "water.spray_particles", drawn);
    if (!neighbours)
        min_neighbours = 0;
    if ((!drawn && !min_neighbours) || !sp->has_vel || !count || count > sp->cap)
        return VFX_OK;
    GLuint prog = volfx_gpu_program(ctx, "water/spray.vert", "water/spray.frag", NULL);
    if (!prog)
        return VFX_ERR_GL;
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.spray", .framebuffer = frame->framebuffer,
                                             .width = frame->width, .height = frame->height,
                                             .blend = VOLFX_BLEND_OVER_PREMUL});
    glUseProgram(prog);
    for (int k = 0; k < 3; ++k)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)k, cols[k]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, sp->speed);
    if (min_neighbours)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, neighbours);
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_min_nb"), min_neighbours);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_speed_isolated"), SPRAY_SPEED_ISOLATED);
    glBindTextureUnit(0, dist_tex);
    glBindTextureUnit(1, frame->depth_texture);
    glUniformMatrix4fv(volfx_gpu_uniform(ctx, prog, "u_view_proj"), 1, GL_FALSE, targets->view_proj);
    glUniformMatrix4fv(volfx_gpu_uniform(ctx, prog, "u_inv_view_proj"), 1, GL_FALSE, targets->inv_view_proj);
    glUniform3fv(volfx_gpu_uniform(ctx, prog, "u_eye"), 1, frame->eye);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_radius"), SPRAY_RADIUS_H * p->h);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_h"), p->h);
    glUniform2f(volfx_gpu_uniform(ctx, prog, "u_speed"), SPRAY_SPEED_LO, SPRAY_SPEED_HI);
    glUniform1i(volfx_gpu_uniform(ctx, prog, "u_has_depth"), frame->depth_texture != 0);
    glUniform1i(volfx_gpu_uniform(ctx, prog, "u_hdr"), targets->color_hdr);
    glBindVertexArray(vao);
    glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, (GLsizei)count);
    volfx_pass_end(ctx);
    return VFX_OK;
}
