/* gpu_particles.c — see gpu_particles.h. */
#include "gpu_particles.h"

#include <epoxy/gl.h>
#include <stdlib.h>
#include <string.h>

/* A buffer (and copy) of at least `bytes`, grown by half again so a slowly growing count does not
 * reallocate every frame; every revision is forgotten (the new buffer holds nothing). */
static vfx_result ensure(game_gpu_particles *g, uint64_t bytes, uint32_t chunks)
{
    if (chunks > g->chunk_cap) {
        uint64_t *r = realloc(g->revisions, chunks * sizeof *r);
        if (!r)
            return VFX_ERR_OUT_OF_MEMORY;
        memset(r + g->chunk_cap, 0, (chunks - g->chunk_cap) * sizeof *r);
        g->revisions = r;
        g->chunk_cap = chunks;
    }
    if (bytes <= g->bytes && g->buffer)
        return VFX_OK;
    uint64_t want = bytes + bytes / 2 + 64;
    float *s = realloc(g->staging, (size_t)want);
    if (!s)
        return VFX_ERR_OUT_OF_MEMORY;
    g->staging = s;
    if (g->buffer)
        glDeleteBuffers(1, &g->buffer);
    glCreateBuffers(1, &g->buffer);
    glNamedBufferStorage(g->buffer, (GLsizeiptr)want, NULL, GL_DYNAMIC_STORAGE_BIT);
    if (glGetError() != GL_NO_ERROR)
        return VFX_ERR_GL;
    g->bytes = want;
    memset(g->revisions, 0, g->chunk_cap * sizeof *g->revisions);
    return VFX_OK;
}

vfx_result game_gpu_particles_upload(game_gpu_particles *g, vfx_particle_view *chunks, uint32_t n)
{
    uint64_t total = 0;
    for (uint32_t c = 0; c < n; ++c)
        total += chunks[c].count;
    vfx_result r = ensure(g, total * GAME_GPU_PARTICLE_STRIDE, n);
    if (r)
        return r;
    g->uploaded = 0;
    uint64_t off = 0;
    for (uint32_t c = 0; c < n; ++c) {
        vfx_particle_view *v = &chunks[c];
        bool vel = v->vel[0] && v->vel[1] && v->vel[2];
        if (v->count && !(v->revision && v->revision == g->revisions[c])) {
            float *s = g->staging;
            for (uint32_t i = 0; i < v->count; ++i) {
                float *p = s + 6 * (size_t)i;
                for (int k = 0; k < 3; ++k) {
                    p[k] = v->pos[k][i];
                    p[3 + k] = vel ? v->vel[k][i] : 0.0f;
                }
            }
            glNamedBufferSubData(g->buffer, (GLintptr)off, (GLsizeiptr)v->count * GAME_GPU_PARTICLE_STRIDE, s);
            g->uploaded += v->count;
            g->revisions[c] = v->revision;
        }
        for (int k = 0; k < 3; ++k)
            v->pos[k] = v->vel[k] = NULL;
        v->gpu_pos = (vfx_gpu_column){g->buffer, GAME_GPU_PARTICLE_STRIDE, off};
        if (vel)
            v->gpu_vel = (vfx_gpu_column){g->buffer, GAME_GPU_PARTICLE_STRIDE, off + 12};
        off += (uint64_t)v->count * GAME_GPU_PARTICLE_STRIDE;
    }
    return VFX_OK;
}

void game_gpu_particles_free(game_gpu_particles *g)
{
    if (g->buffer)
        glDeleteBuffers(1, &g->buffer);
    free(g->staging);
    free(g->revisions);
    memset(g, 0, sizeof *g);
}
