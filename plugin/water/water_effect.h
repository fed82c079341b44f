/* water_effect.h — what tests read of the water effect beyond the public read_raw. */
#ifndef VOLFX_WATER_EFFECT_H
#define VOLFX_WATER_EFFECT_H

#include "context.h"
#include "water/water_foam.h"

/* Copies the surface gradient target of the last water render: 4 floats per pixel, top row
 * first, (grad sum P, sum P) at the found surface point, zeros where no water. The shading
 * normal is -xyz normalised. VFX_ERR_NOT_FOUND when the effect is absent. */
vfx_result volfx_water_debug_gradient(vfx_context *ctx, float *out, size_t count);
/* Copies the paper method's final per-pixel class of the last render, top row first: 1 surface
 * found, 2 left the particles' box or hit the host depth, 3 sample cap reached (the counters
 * water.pixels_found / _left / _sample_cap count these). VFX_ERR_NOT_FOUND unless the last
 * frame used the paper method. */
vfx_result volfx_water_debug_pixel_class(vfx_context *ctx, uint8_t *out, size_t count);

/* Copies the per-particle kernels of the last TILE frame that used them: 16 floats a particle
 * (centre xyz, bounding radius; G xx xy xz yy; G yz zz 0 0; half-extents xyz 0; see
 * water_aniso.h) and, if nbrs != NULL, the neighbour counts (0s when no neighbour search ran).
 * VFX_ERR_NOT_FOUND when none. */
vfx_result volfx_water_debug_kernels(vfx_context *ctx, float *out, uint32_t *nbrs, size_t particles);

/* Copies the diffuse particles of the last step (water_diffuse.h volfx_water_diffuse_debug: 4
 * potentials a fluid particle, 8 floats a pool entry, the pool's size). VFX_ERR_NOT_FOUND when
 * no step ran. */
vfx_result volfx_water_debug_diffuse(vfx_context *ctx, float *pot, size_t fluid, float *pool, size_t pool_cap,
                                     uint32_t *alive);

/* The foam layer (water_foam.h): its grid and, if out != NULL, its density (nx x nz floats, row
 * by row from z0). VFX_ERR_NOT_FOUND before the layer has run. */
vfx_result volfx_water_debug_foam(vfx_context *ctx, volfx_water_foam_grid *g, float *out, size_t cap);
/* Overwrites the foam layer's density (nx x nz floats); with in NULL it only wakes the layer (its
 * next update runs and makes the grid, as if foam had been seen). */
vfx_result volfx_water_debug_foam_write(vfx_context *ctx, const float *in, size_t n);

#endif
