/* volfx_lab.h — the laboratory: the research switches of the plugin (ablation bits, baseline
 * methods, the volume renderer's and the beams' baselines) and the lab library that draws the
 * water's baselines (plugin/lab). NOT installed and not part of the ABI's promise: tests and
 * benches link the lab library, attach it to their context and chain these structs into a public
 * struct's `next` to reproduce the measurements in docs/ (docs/abi.md "Lab structs"). libvolfx
 * holds no lab code: without volfx_lab_attach a vfx_lab_water, or a lab method, is refused by
 * name (VFX_ERR_UNSUPPORTED). */
#ifndef VOLFX_LAB_H
#define VOLFX_LAB_H

#include <volfx/volfx.h>

/* Attaches the lab library to ctx (a context of the statically linked plugin, in the same
 * program): from now on ctx reads vfx_lab_water and draws the water's BRUTE and GRID methods.
 * VFX_ERR_INVALID_ARGUMENT for NULL. Lab library only (tests, benches): libvolfx has no such symbol. */
vfx_result volfx_lab_attach(vfx_context *ctx);

/* Type values of the lab structs, far from the public ones. */
#define VFX_TYPE_LAB_WATER ((vfx_struct_type)0x4c414201)
#define VFX_TYPE_LAB_BEAMS ((vfx_struct_type)0x4c414202)
#define VFX_TYPE_LAB_VOLUME ((vfx_struct_type)0x4c414203)

/* Bits of vfx_lab_water.disable: each switches one technique of the water off, for ablations
 * (docs/water.md). The public features_off bits (VFX_WATER_NO_SPRAY, VFX_WATER_NO_SSR) share
 * this bit space and may be given here too. */
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

/* Baseline methods of the water (vfx_lab_water.method; the public ones may be given too). */
#define VFX_WATER_METHOD_BRUTE 1u /* per-pixel march over all particles (compute) */
#define VFX_WATER_METHOD_GRID 2u  /* per-pixel march over a uniform grid (compute) */

/* Chained into vfx_water_params.next. */
typedef struct vfx_lab_water {
    vfx_struct_type type;  /* VFX_TYPE_LAB_WATER */
    const void *next;
    uint32_t disable;      /* VFX_WATER_NO_* bits, added to features_off */
    uint32_t method;       /* 0 -> vfx_water_params.method; else a vfx_water_method or BRUTE/GRID */
} vfx_lab_water;

/* Chained into vfx_beams_view.next: the ray-marching baseline instead of the closed form. */
#define VFX_BEAMS_METHOD_CLOSED_FORM 0u
#define VFX_BEAMS_METHOD_MARCH 1u
typedef struct vfx_lab_beams {
    vfx_struct_type type;   /* VFX_TYPE_LAB_BEAMS */
    const void *next;
    uint32_t method;        /* VFX_BEAMS_METHOD_* */
    uint32_t march_samples; /* ray-marching baseline samples; 0 -> 32 */
} vfx_lab_beams;

/* Bits of vfx_lab_volume.disable. */
enum {
    VFX_VOLUME_NO_ERT = 1u << 0,   /* no early ray termination at all */
    VFX_VOLUME_NO_SHARE = 1u << 1, /* workers do not share ERT tables */
    VFX_VOLUME_NO_DLB = 1u << 2,   /* no dynamic load balancing */
};

/* Chained into vfx_volume_view.next. */
typedef struct vfx_lab_volume {
    vfx_struct_type type;  /* VFX_TYPE_LAB_VOLUME */
    const void *next;
    uint32_t disable;      /* VFX_VOLUME_NO_* bits */
} vfx_lab_volume;

#endif
