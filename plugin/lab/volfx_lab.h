/* volfx_lab.h — the laboratory: the research switches of the plugin (ablation bits, baseline
 * methods, the volume renderer's and the beams' baselines) and the lab library that draws the
 * water's baselines (plugin/lab). NOT installed and not part of the ABI's promise: tests and
 * benches link the lab library, attach it to their context and chain these structs into a public
 * struct's `next` to reproduce the measurements in docs/ (docs/abi.md "Lab structs"). libvolfx
 * holds no lab code: without volfx_lab_attach a lab struct (vfx_lab_water, vfx_lab_beams,
 * vfx_lab_volume) or a lab method is refused by name (VFX_ERR_UNSUPPORTED). */
#ifndef VOLFX_LAB_H
#define VOLFX_LAB_H

#include <volfx/volfx.h>

/* The lab structs' type values (lab_types.h), and the water's VFX_WATER_NO_* disable bits and
 * baseline methods (water/water_switches.h): both the product's own headers, which it reads
 * without this one. The public features_off bits (VFX_WATER_NO_SPRAY, VFX_WATER_NO_SSR) share the
 * water's bit space and may be given in vfx_lab_water.disable too. */
#include "lab_types.h"
#include "water/water_switches.h"

/* Attaches the lab library to ctx (a context of the statically linked plugin, in the same
 * program): from now on ctx reads vfx_lab_water, vfx_lab_beams and vfx_lab_volume, draws the
 * water's BRUTE and GRID methods and the beams' ray-marching baseline. VFX_ERR_INVALID_ARGUMENT
 * for NULL. Lab library only (tests, benches): libvolfx has no such symbol. */
vfx_result volfx_lab_attach(vfx_context *ctx);

/* Chained into vfx_water_params.next. */
typedef struct vfx_lab_water {
    vfx_struct_type type;  /* VFX_TYPE_LAB_WATER */
    const void *next;
    uint32_t disable;      /* VFX_WATER_NO_* bits, added to features_off */
    uint32_t method;       /* 0 -> vfx_water_params.method; else a vfx_water_method or BRUTE/GRID */
} vfx_lab_water;

/* Chained into vfx_beams_view.next: the ray-marching baseline instead of the closed form (the
 * lab's, lab_beams.c; march_samples' range is lab_ranges.h's). */
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
