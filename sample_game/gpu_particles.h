/* gpu_particles.h — the game's GPU-resident particles (--gpu-particles): the particle table
 * columns copied into one GL buffer, position and velocity interleaved (24 bytes a particle,
 * chunk after chunk), which the plugin reads as GL buffer columns (vfx_particle_view.gpu_pos /
 * gpu_vel) instead of the CPU arrays. The game's simulation runs on the CPU, so the copy is the
 * host's; an engine with a GPU simulation hands its own buffer the same way. */
#ifndef GAME_GPU_PARTICLES_H
#define GAME_GPU_PARTICLES_H

#include <stdint.h>

#include "volfx/volfx.h"

#define GAME_GPU_PARTICLE_STRIDE 24u /* x y z vx vy vz */

typedef struct game_gpu_particles {
    uint32_t buffer;     /* GL buffer name (0 until the first upload) */
    uint64_t bytes;      /* its size */
    float *staging;      /* the interleaved copy, grown with the buffer */
    uint64_t *revisions; /* each chunk's revision at its last upload (0: always upload) */
    uint32_t chunk_cap;
    uint64_t uploaded;   /* particles copied by the last call (0 when every revision was unchanged) */
} game_gpu_particles;

/* Copies the CPU columns of `n` chunks into the buffer (a chunk whose nonzero revision is that
 * of its last upload is not copied again) and turns each view into GL buffer columns: pos[] and
 * vel[] NULL, gpu_pos / gpu_vel at the chunk's place. A chunk without velocities keeps none.
 * VFX_ERR_OUT_OF_MEMORY when the copy cannot grow, VFX_ERR_GL when the buffer cannot be made. */
vfx_result game_gpu_particles_upload(game_gpu_particles *g, vfx_particle_view *chunks, uint32_t n);
/* Deletes the buffer and frees the copy. */
void game_gpu_particles_free(game_gpu_particles *g);

#endif
