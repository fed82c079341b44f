/* water_aniso.h — per-particle kernels of the water effect for method TILE: the anisotropic
 * kernels of Yu & Turk 2013 computed on the GPU from the positions (hashed uniform grid by
 * counting sort, weighted covariance, Jacobi eigen-decomposition, stretch clamp, Laplacian
 * smoothing of the centres), or the host's kernel column, each divided by the host's radius
 * column (shaders/water/aniso.comp). */
#ifndef VOLFX_WATER_ANISO_H
#define VOLFX_WATER_ANISO_H

#include "gpu/gl.h"
#include "effect.h"
#include "water/water_gather.h"

typedef struct volfx_water_aniso volfx_water_aniso;

/* The kernel parameters of vfx_water_params, checked and with defaults applied. */
typedef struct volfx_water_kernel_params {
    uint32_t kernel;          /* VFX_WATER_KERNEL_ISOTROPIC or _ANISOTROPIC (never DEFAULT) */
    float radius;             /* neighbourhood radius / h */
    float max_stretch;        /* kr */
    uint32_t min_neighbours;  /* Ne */
    float scale;              /* ks */
    float smoothing;          /* lambda, 0 = none */
} volfx_water_kernel_params;

/* Bytes per particle of the kernel buffer: 4 vec4 (centre and bounding radius; G xx xy xz yy;
 * G yz zz; half-extents of the ellipsoid's axis-aligned box). */
#define VOLFX_WATER_KERNEL_STRIDE 64u

/* Checks the v2 part of the host's parameters (version 1: all defaults) and fills out; an
 * out-of-range field fails with VFX_ERR_INVALID_ARGUMENT naming it. */
vfx_result volfx_water_kernel_params_check(vfx_context *ctx, const vfx_water_params *in,
                                           volfx_water_kernel_params *out);

/* Makes the (empty) state; NULL on allocation failure. */
volfx_water_aniso *volfx_water_aniso_create(vfx_context *ctx);
/* Frees the buffers and the state; NULL allowed. */
void volfx_water_aniso_destroy(vfx_context *ctx, volfx_water_aniso *a);

/* Host columns. Begin before the chunks' upload with the total and which columns any chunk has;
 * then one call per chunk (NULL columns: radius 1, identity kernel); each value is checked
 * (finite; radius and the kernel's eigenvalues in [1e-3, 1e3]) with an error naming the chunk,
 * the particle and the field. */
vfx_result volfx_water_aniso_columns_begin(vfx_context *ctx, volfx_water_aniso *a, uint32_t total, bool radius,
                                           bool kernel);
vfx_result volfx_water_aniso_columns_chunk(vfx_context *ctx, volfx_water_aniso *a, uint32_t chunk, uint32_t first,
                                           uint32_t count, const float *radius, const float *kernel);
/* The same for a chunk whose kernel column is in a GL buffer (vfx_particle_view.gpu_kernel,
 * checked by volfx_water_gather_check): gathered on the GPU into the kernels' buffer, then read
 * back for the same checks (messages name gpu_kernel). */
vfx_result volfx_water_aniso_columns_gpu_chunk(vfx_context *ctx, volfx_water_aniso *a, volfx_water_gather *g,
                                               uint32_t chunk, uint32_t first, uint32_t count, const float *radius,
                                               const volfx_gpu_column *kernel);
/* Whether the last columns_begin had a radius or a kernel column (then TILE needs the kernels
 * even for the isotropic kernel). */
bool volfx_water_aniso_has_columns(const volfx_water_aniso *a);

/* What one kernel pass needs (borrowed). */
typedef struct volfx_water_aniso_input {
    const GLuint *cols;       /* x, y, z position columns */
    uint32_t count;           /* particles, non-finite included */
    const float *lo, *hi;     /* box of the finite particles */
    float h;
    const volfx_water_kernel_params *kp;
    GLuint counters;          /* the effect's counter buffer: slots 24 (stretched), 25 (isotropic) */
    uint64_t data_rev;        /* changes whenever the columns were uploaded again */
    bool half_rate;           /* the shapes every other upload (the preset, a frame with dt > 0; smoothing 0 only) */
} volfx_water_aniso_input;

/* Computes the kernel buffer (pass water.aniso) unless the positions, columns and parameters
 * are those of the last pass (water.aniso_skipped 1); at the half rate, an upload after a full
 * pass only moves the centres to the new positions (pass water.aniso_centre,
 * water.aniso_half_skipped 1) and keeps the shapes one upload old. */
vfx_result volfx_water_aniso_compute(vfx_context *ctx, volfx_water_aniso *a, const volfx_water_aniso_input *in);
/* The kernel buffer of the last pass (VOLFX_WATER_KERNEL_STRIDE bytes a particle); 0 before. */
GLuint volfx_water_aniso_kernels(const volfx_water_aniso *a);
/* A uint per particle: its neighbours within the neighbourhood radius in the last pass; fewer
 * than Ne means isolated (spray). 0 (no buffer) before a pass and when the last one searched no
 * neighbours (the isotropic kernel with a radius column, host kernels). */
GLuint volfx_water_aniso_neighbours(const volfx_water_aniso *a);
/* The hashed neighbour grid of the positions (for the diffuse particles): cell `cell`
 * (neighbourhood radius x h) from `origin`, `buckets` (a power of two) hashed as aniso.comp's
 * bucket_of; start[b] .. start[b + 1] index `sorted` (vec4: position, the particle's index as
 * float bits). */
typedef struct volfx_water_aniso_grid {
    GLuint sorted, start;
    uint32_t buckets;
    float cell, origin[3];
} volfx_water_aniso_grid;
/* Describes the grid of in's positions, building it first unless the last build (the kernel
 * pass's or this one's, pass water.aniso_grid) was of the same upload, count, cell and box. */
vfx_result volfx_water_aniso_grid_build(vfx_context *ctx, volfx_water_aniso *a, const volfx_water_aniso_input *in,
                                        volfx_water_aniso_grid *out);
/* A bound of every particle's bounding radius over h (kr^(2/3) ks times the largest radius
 * column value, or the host kernels' largest 1 / eigenvalue): the binning's depth slabs. */
float volfx_water_aniso_sigma_bound(const volfx_water_aniso *a);

#endif
