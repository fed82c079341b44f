/* lab_water.h — the water's entries of the lab's hook table (lab_hooks.h): the vfx_lab_water
 * struct, the BRUTE and GRID marches and their state. */
#ifndef VOLFX_LAB_WATER_H
#define VOLFX_LAB_WATER_H

#include "lab_hooks.h"
#include "volfx_lab.h"

/* lab_hooks.h water_struct: the disable bits (unknown ones refused) and the method. */
vfx_result volfx_lab_water_struct(vfx_context *ctx, const void *lab, uint32_t *disable, uint32_t *method);
/* lab_hooks.h water_march: BRUTE or GRID into in->dist_tex. */
vfx_result volfx_lab_water_march(vfx_context *ctx, void **state, uint32_t method, const volfx_lab_water_input *in,
                                 const volfx_frame_targets *targets);
/* lab_hooks.h water_free. */
void volfx_lab_water_free(vfx_context *ctx, void *state);
/* lab_hooks.h water_counters: GRID's stats (BRUTE has none). */
void volfx_lab_water_counters(vfx_context *ctx, uint32_t method, const uint32_t *c);

#endif
