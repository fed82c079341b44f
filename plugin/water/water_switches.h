/* water_switches.h — the water's technique switches: the VFX_WATER_NO_* bits the product's
 * presets and passes test (resolved into volfx_water_core.disable), and the method numbers of the
 * lab's baselines, which the product routes to the lab (lab_hooks.h). One bit space with the
 * public features_off bits (VFX_WATER_NO_SPRAY, VFX_WATER_NO_SSR in volfx.h). Not installed: the
 * lab's header (plugin/lab/volfx_lab.h) includes it, so tests and benches set the same bits
 * through vfx_lab_water; a host reaches only the public ones. */
#ifndef VOLFX_WATER_SWITCHES_H
#define VOLFX_WATER_SWITCHES_H

#include <volfx/volfx.h>

/* Each switches one technique of the water off, for ablations (the paper's techniques 1-6:
 * docs/water-paper.md; TILE's: docs/water-method.md). */
enum {
    VFX_WATER_NO_BILLBOARD_INIT = 1u << 0, /* technique 1: start every ray at the near plane */
    VFX_WATER_NO_SKIP = 1u << 1,           /* technique 2: fixed steps, no gap jumping */
    VFX_WATER_NO_BLEND = 1u << 2,          /* technique 3: compute-shader sum instead of blending */
    VFX_WATER_NO_PACK4 = 1u << 3,          /* technique 4: one sample per texel, not four */
    VFX_WATER_NO_PYRAMID = 1u << 4,        /* technique 5: no min/max pyramid culling */
    VFX_WATER_NO_REFINE = 1u << 5,         /* technique 6: linear interpolation only */
    VFX_WATER_NO_SHADING = 1u << 6,        /* flat colour: for tests that compare coverage */
    /* PAPER: leave the pixels that spent max_samples undecided (holes), as the seed does,
     * instead of finishing them with TILE's march */
    VFX_WATER_NO_FINISH = 1u << 7,
    /* TILE: evaluate the field over the tile's whole list at every sample */
    VFX_WATER_NO_LOCAL_LIST = 1u << 8,
    /* TILE: plain steps, no bound-driven subdivision (features thinner than a step can be missed) */
    VFX_WATER_NO_SUBDIVIDE = 1u << 9,
    /* TILE: no screen tiles: every pixel reads every particle */
    VFX_WATER_NO_TILES = 1u << 10,
    /* shading: absorb over the view ray's thickness and look the host colour up at a fixed
     * screen offset, instead of tracing the refracted ray through the water */
    VFX_WATER_NO_REFRACT_TRACE = 1u << 11,
    /* TILE: no temporal reuse (the previous frame's hits, reprojected, as proven starting points) */
    VFX_WATER_NO_TEMPORAL = 1u << 12,
    /* TILE: no reduced-resolution march (one ray per 2x2 block, the rest upsampled where the
     * block agrees and marched where it does not) */
    VFX_WATER_NO_HALF_RES = 1u << 13,
    VFX_WATER_NO_DIFFUSE = VFX_WATER_NO_SPRAY,
};
/* Every bit of the water's disable space. */
#define VFX_WATER_DISABLE_ALL ((1u << 16) - 1u)

/* The lab's baseline methods (vfx_lab_water.method; the public ones may be given too): drawn by
 * the lab library only (lab_hooks.h water_march). */
#define VFX_WATER_METHOD_BRUTE 1u /* per-pixel march over all particles (compute) */
#define VFX_WATER_METHOD_GRID 2u  /* per-pixel march over a uniform grid (compute) */

#endif
