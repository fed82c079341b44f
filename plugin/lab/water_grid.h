/* water_grid.h — the lab's GRID baseline of the water effect: a uniform particle grid (cell >= h)
 * built on the GPU each frame (count, prefix sum, scatter), then a per-pixel compute march over
 * it with empty-space skipping; the same sampling rule and refinement as the BRUTE baseline. */
#ifndef VOLFX_WATER_GRID_H
#define VOLFX_WATER_GRID_H

#include "gpu/gl.h"
#include "effect.h"
#include "lab_hooks.h"
#include "water/water_params.h"

typedef struct volfx_water_grid volfx_water_grid;

/* Makes the (empty) grid state; NULL on allocation failure (error recorded). */
volfx_water_grid *volfx_water_grid_create(vfx_context *ctx);
/* Frees the grid's buffers and the state; NULL allowed. */
void volfx_water_grid_destroy(vfx_context *ctx, volfx_water_grid *g);
/* Builds the grid from in->cols unless data_rev, count and h are those of the last build, then
 * writes in->dist_tex; adds water.samples / pixels_found / pixels_sample_cap / pixels_left /
 * grid cells visited / sphere tests into in->counters (no readback here); sets water.grid_cells,
 * water.grid_cell_size and water.grid_rebuilt (0/1). */
vfx_result volfx_water_grid_render(vfx_context *ctx, volfx_water_grid *g, const volfx_lab_water_input *in,
                                 const volfx_frame_targets *targets);

/* The march inputs BRUTE (brute.comp) and GRID (grid.comp MODE_MARCH) share, on the current
 * program prog: dist_tex as image 0, the scene depth on unit 1, the ray (inverse view-projection,
 * eye), the sampling rule (h, T, step, sample cap), refinement (off with VFX_WATER_NO_REFINE)
 * and whether there is scene depth. */
void volfx_water_march_bind(vfx_context *ctx, GLuint prog, GLuint dist_tex, const volfx_water_core *p,
                          const volfx_frame_targets *targets);

#endif
