/* water_gather.h — GPU-resident particles: the host's GL buffers (positions, velocities,
 * kernels) checked and gathered on the GPU into the water's own layout (shaders/water/gather.comp),
 * and what the CPU path measures on the CPU arrays (the particles' box, the non-finite count)
 * answered from a GPU reduction read back a few frames late (docs/water.md "Input"). */
#ifndef VOLFX_WATER_GATHER_H
#define VOLFX_WATER_GATHER_H

#include <stdbool.h>
#include <stdint.h>

#include "gpu/gl.h"
#include "context.h"

/* One column of a host GL buffer (the ABI's vfx_gpu_column): particle i's element starts at
 * offset + i * stride bytes; buffer 0: none. */
typedef vfx_gpu_column volfx_gpu_column;

/* Readbacks of the box in flight: a result is read once its fence has signalled, never waited for. */
#define WATER_GATHER_RING 4

typedef struct volfx_water_gather volfx_water_gather;

/* The late box: the finite particles' box of an earlier upload, the non-finite count and the
 * particles that lay outside the box that upload's passes used. */
typedef struct volfx_water_gather_box {
    float lo[3], hi[3];
    uint32_t bad, outside;
    uint64_t upload; /* the upload (1, 2, ...) it was measured on */
} volfx_water_gather_box;

/* Makes the gatherer (nothing on the GPU yet); NULL when out of memory. */
volfx_water_gather *volfx_water_gather_create(vfx_context *ctx);
/* Deletes its buffers and fences; NULL allowed. */
void volfx_water_gather_destroy(vfx_context *ctx, volfx_water_gather *g);

/* Checks column `field` ("gpu_pos", "gpu_vel", "gpu_kernel") of chunk `chunk` for `count` particles of `elem`
 * bytes: a buffer name of this context (glIsBuffer), stride >= elem and a multiple of 4, offset a
 * multiple of 4, and offset + stride * (count - 1) + elem within its GL_BUFFER_SIZE. Every refusal
 * is VFX_ERR_INVALID_ARGUMENT (VFX_LOG_ID_GPU_COLUMN) naming the field. */
vfx_result volfx_water_gather_check(vfx_context *ctx, uint32_t chunk, const char *field, const volfx_gpu_column *col,
                                    uint32_t count, uint32_t elem);

/* Starts an upload that has GPU columns: collects the box readbacks that have finished (without
 * waiting), clears this upload's reduction. `box` is the box its passes will use (counted against:
 * the outside count). */
vfx_result volfx_water_gather_begin(vfx_context *ctx, volfx_water_gather *g, const float lo[3], const float hi[3]);
/* Positions of `count` particles from `col` into the three columns cols[] at particle `first`,
 * reduced into this upload's box. */
vfx_result volfx_water_gather_positions(vfx_context *ctx, volfx_water_gather *g, const volfx_gpu_column *col,
                                        uint32_t count, const GLuint cols[3], uint32_t first);
/* Velocities of `count` particles from `col` into `vel` (vec4 each) at particle `first`. */
vfx_result volfx_water_gather_velocities(vfx_context *ctx, volfx_water_gather *g, const volfx_gpu_column *col,
                                         uint32_t count, GLuint vel, uint32_t first);
/* Kernel columns (6 floats) of `count` particles from `col` into `kern` (6 floats a particle) at
 * particle `first`, unchanged. */
vfx_result volfx_water_gather_kernels(vfx_context *ctx, volfx_water_gather *g, const volfx_gpu_column *col,
                                      uint32_t count, GLuint kern, uint32_t first);
/* Ends the upload: its box is copied for a readback a few frames later (fenced). */
void volfx_water_gather_end(volfx_water_gather *g);
/* The newest box read back so far and the one before it (false when none); `uploads` the
 * uploads made so far. */
bool volfx_water_gather_late(const volfx_water_gather *g, volfx_water_gather_box *newest,
                             volfx_water_gather_box *before, uint64_t *uploads);
/* Records an exact box of the current upload (the blocking path measured it): the next uploads
 * start from it. */
void volfx_water_gather_set_exact(volfx_water_gather *g, const float lo[3], const float hi[3], uint32_t bad);

#endif
