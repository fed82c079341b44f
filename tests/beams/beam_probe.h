/* beam_probe.h — the float32 closed form the beam tests hold against the float64 references is
 * the shader's own: shaders/beams/field_probe.comp runs beam_field.glsl on the test's rays (one
 * compute dispatch over a batch) on the GL the test runs on (llvmpipe in CI). Positions go to the
 * shader relative to each ray's origin, rounded to float32 from float64, as the effect packs them. */
#ifndef VFX_TEST_BEAM_PROBE_H
#define VFX_TEST_BEAM_PROBE_H

#include <epoxy/gl.h>
#include <stdlib.h>
#include <string.h>

#include "beams/beam_field.h"
#include "debug.h"
#include "volfx_lab.h"
#include "test_plugin.h"

/* One ray of a batch: the beam (straight, anatomy or polyline), float32 origin and unit direction. */
typedef struct beam_probe_ray {
    const volfx_beam_d *beam;
    float o[3], v[3];
    float t0, t1;
} beam_probe_ray;

/* field_probe.comp's ProbeCase (std430). */
typedef struct beam_probe_case {
    float m_l[4], d_r[4], ab_eps[4], an0[4], an1[4], v_t0[4], t1_poly[4];
} beam_probe_case;

/* A plugin context with the lab on the current GL context (the program cache, file:line errors). */
static inline vfx_context *beam_probe_open(const vfx_plugin_api **api_out)
{
    /* the probe is a lab shader (volfx_lab_shaders): a context with the lab attached builds it */
    vfx_context *ctx = test_plugin_open(api_out);
    return ctx && volfx_lab_attach(ctx) == VFX_OK ? ctx : NULL;
}

/* out[i] = the shader's H of rays[i]; false when the probe could not run (its error printed). */
static inline bool beam_probe_eval(vfx_context *ctx, const beam_probe_ray *rays, uint32_t n, float *out)
{
    GLuint prog = volfx_gpu_compute(ctx, "beams/field_probe.comp", NULL);
    if (!prog || n == 0)
        return n == 0;
    beam_probe_case *c = calloc(n, sizeof *c);
    float(*joints)[4] = calloc((size_t)n * VOLFX_BEAM_MAX_JOINTS + 1, sizeof *joints);
    uint32_t nj_total = 0;
    for (uint32_t i = 0; i < n; ++i) {
        const volfx_beam_d *b = rays[i].beam;
        const double o[3] = {rays[i].o[0], rays[i].o[1], rays[i].o[2]};
        for (int k = 0; k < 3; ++k) {
            c[i].m_l[k] = (float)(b->head[k] - o[k]);
            c[i].d_r[k] = (float)b->dir[k];
            c[i].v_t0[k] = rays[i].v[k];
        }
        c[i].m_l[3] = (float)b->length;
        c[i].d_r[3] = (float)b->radius;
        c[i].ab_eps[0] = (float)b->a, c[i].ab_eps[1] = (float)b->b, c[i].ab_eps[2] = (float)b->eps;
        c[i].ab_eps[3] = b->smooth ? 1.f : 0.f;
        c[i].an0[0] = (float)b->head_radius, c[i].an0[1] = (float)b->orb_radius, c[i].an0[2] = (float)b->orb_a;
        if (b->joint_count < 2) { /* a polyline has no body profile (beam_field_anat.h anatomy_d) */
            c[i].an1[0] = (float)b->taper, c[i].an1[1] = (float)b->surge;
            c[i].an1[2] = (float)b->surge_inv_wl, c[i].an1[3] = (float)b->surge_phase;
        }
        c[i].v_t0[3] = rays[i].t0;
        c[i].t1_poly[0] = rays[i].t1;
        if (b->joint_count >= 2) {
            c[i].t1_poly[1] = (float)nj_total;
            c[i].t1_poly[2] = (float)b->joint_count;
            for (int j = 0; j < b->joint_count; ++j, ++nj_total)
                for (int k = 0; k < 3; ++k)
                    joints[nj_total][k] = (float)(b->joints[j][k] - o[k]);
        }
    }
    GLuint buf[3];
    glCreateBuffers(3, buf);
    glNamedBufferStorage(buf[0], (GLsizeiptr)(n * sizeof *c), c, 0);
    glNamedBufferStorage(buf[1], (GLsizeiptr)((nj_total + 1) * sizeof *joints), joints, 0);
    glNamedBufferStorage(buf[2], (GLsizeiptr)n * 4, NULL, GL_MAP_READ_BIT);
    glUseProgram(prog);
    glUniform1ui(glGetUniformLocation(prog, "u_count"), n);
    for (GLuint k = 0; k < 3; ++k)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, k, buf[k]);
    glDispatchCompute((n + 63) / 64, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(buf[2], 0, (GLsizeiptr)n * 4, out);
    glDeleteBuffers(3, buf);
    free(c);
    free(joints);
    return glGetError() == GL_NO_ERROR;
}

#endif
