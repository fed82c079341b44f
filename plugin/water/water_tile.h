/* water_tile.h — method TILE (ours) of the water effect: particles binned per 8x8 screen tile on
 * the GPU (count, prefix sum, scatter), then a per-pixel march over the pixel's tile list that
 * cannot end undecided (exact ray interval, windowed local lists, an upper bound of the field
 * between samples that opens subintervals, regula falsi); it also writes the surface gradient
 * and back distance, so no billboard pass runs. The same march finishes the paper method's
 * sample-cap pixels. */
#ifndef VOLFX_WATER_TILE_H
#define VOLFX_WATER_TILE_H

#include "gpu/gl.h"
#include "effect.h"
#include "water_params.h"

typedef struct volfx_water_tile volfx_water_tile;

/* What one TILE frame needs from the water effect's state (borrowed, not owned). */
typedef struct volfx_water_tile_input {
    const GLuint *cols;              /* x, y, z position columns (SSBOs of `count` floats) */
    uint32_t count;                  /* particles in the columns, non-finite ones included */
    const volfx_water_core *params;  /* defaults already applied */
    uint32_t width, height;
    GLuint dist_tex;                 /* R32F target: distance along the ray or -1 */
    GLuint counters;                 /* the effect's counter buffer (fenced readback ring) */
    uint32_t last_entries;           /* tile entries a recent frame needed (0: unknown) */
    const float *view_proj;          /* proj * view, column-major */
    const float *lo, *hi;            /* box of the finite particles (depth slabs) */
    const float *eye;                /* this frame's eye */
    float focal_px;                  /* pixels per unit at distance 1 (proj[5] * height / 2) */
    uint64_t frame_no;               /* the water effect's frame: temporal reuse needs the last one */
    /* per-particle kernels (water_aniso.h; 0: the isotropic kernel of radius h, the seed's):
     * the ANISO variants of the passes read centres, matrices and boxes from it */
    GLuint kernels;
    float rbound;                    /* every particle's bounding radius is at most this */
    const float *inv_view_proj;      /* the frame gate's inverse of view_proj (the march's rays) */
    bool has_depth;                  /* the host's depth texture is bound (targets->host_depth) */
} volfx_water_tile_input;

/* Makes the (empty) tile state; NULL on allocation failure. */
volfx_water_tile *volfx_water_tile_create(vfx_context *ctx);
/* Frees the buffers and the state; NULL allowed. */
void volfx_water_tile_destroy(vfx_context *ctx, volfx_water_tile *t);
/* Bins the particles into the screen tiles of this frame (pass water.tile_bin). */
vfx_result volfx_water_tile_bin(vfx_context *ctx, volfx_water_tile *t, const volfx_water_tile_input *in);
/* Per-pixel march (pass water.tile_march): writes in->dist_tex, and at found pixels the
 * gradient (xyz grad sum P, w sum P) into grad_tex and the back distance into back_tex.
 * Unless disabled: starts from the previous frame's hits reprojected (pass water.tile_reproject,
 * each start proven by the field bound), and marches one ray per 2x2 block, then upsamples or
 * marches the other pixels (pass water.tile_upsample). */
vfx_result volfx_water_tile_march(vfx_context *ctx, volfx_water_tile *t, const volfx_water_tile_input *in,
                                  const volfx_frame_targets *targets, GLuint grad_tex, GLuint back_tex);
/* Finishes the paper method's sample-cap pixels (state texture x == 3) from its next sample
 * (next_tex), its last outside sample starting the bracket (pass water.finish); writes
 * in->dist_tex at those pixels only. */
vfx_result volfx_water_tile_finish(vfx_context *ctx, volfx_water_tile *t, const volfx_water_tile_input *in,
                                   const volfx_frame_targets *targets, GLuint st_tex, GLuint next_tex);

#endif
