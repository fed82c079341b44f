/* water_grid.h — the GRID baseline of the water effect: a uniform particle grid (cell >= h)
 * built on the GPU each frame (count, prefix sum, scatter), then a per-pixel compute march over
 * it with empty-space skipping; the same sampling rule and refinement as the BRUTE baseline. */
#ifndef VOLFX_WATER_GRID_H
#define VOLFX_WATER_GRID_H

#include "gpu/gl.h"
#include "effect.h"
#include "water_params.h"

typedef struct volfx_water_grid volfx_water_grid;

/* What one GRID frame needs from the water effect's state (borrowed, not owned). */
typedef struct volfx_water_grid_input {
    const GLuint *cols;              /* x, y, z position columns (SSBOs of `count` floats) */
    uint32_t count;                  /* particles in the columns, non-finite ones included */
    uint32_t finite;                 /* of which finite (0: nothing to draw) */
    const float *lo, *hi;            /* box of the finite particles */
    const volfx_water_core *params;  /* defaults already applied */
    uint32_t width, height;
    GLuint dist_tex;                 /* R32F target: distance along the ray or -1 */
    GLuint counters;                 /* the effect's counter buffer (fenced readback ring) */
    uint64_t data_rev;               /* changes whenever the columns were uploaded again */
} volfx_water_grid_input;

/* Makes the (empty) grid state; NULL on allocation failure (error recorded). */
volfx_water_grid *volfx_water_grid_create(vfx_context *ctx);
/* Frees the grid's buffers and the state; NULL allowed. */
void volfx_water_grid_destroy(vfx_context *ctx, volfx_water_grid *g);
/* Builds the grid from in->cols unless data_rev, count and h are those of the last build, then
 * writes in->dist_tex; adds water.samples / pixels_found / pixels_sample_cap / pixels_left /
 * grid cells visited / sphere tests into in->counters (no readback here); sets water.grid_cells,
 * water.grid_cell_size and water.grid_rebuilt (0/1). */
vfx_result volfx_water_grid_render(vfx_context *ctx, volfx_water_grid *g, const volfx_water_grid_input *in,
                                 const vfx_frame_view *frame, const volfx_frame_targets *targets);

/* The march inputs BRUTE (brute.comp) and GRID (grid.comp MODE_MARCH) share, on the current
 * program prog: dist_tex as image 0, the scene depth on unit 1, the ray (inverse view-projection,
 * eye), the sampling rule (h, T, step, sample cap), refinement (off with VFX_WATER_NO_REFINE)
 * and whether there is scene depth. */
void volfx_water_march_bind(vfx_context *ctx, GLuint prog, GLuint dist_tex, const volfx_water_core *p,
                          const vfx_frame_view *frame, const volfx_frame_targets *targets);

#endif
