/* water_effect.h — what tests read of the water effect beyond the public read_raw. */
#ifndef VFX_WATER_EFFECT_H
#define VFX_WATER_EFFECT_H

#include "plugin_internal.h"

/* Copies the surface gradient target of the last water render: 4 floats per pixel, top row
 * first, (grad sum P, sum P) at the found surface point, zeros where no water. The shading
 * normal is -xyz normalised. VFX_ERR_NOT_FOUND when the effect is absent. */
vfx_result vfx_water_debug_gradient(vfx_context *ctx, float *out, size_t count);

#endif
