/* water_params.h — the water's parameters as the effect draws them: the host's (any version of
 * vfx_water_params), checked, with the preset's values in every field the host left 0
 * (docs/water.md "Presets"), and h from the particles' spacing when the host gives none. */
#ifndef VOLFX_WATER_PARAMS_H
#define VOLFX_WATER_PARAMS_H

#include "effect.h"
#include "water_aniso.h"
#include "water_switches.h"

/* The fields every method reads, resolved: the host's, with the lab's disable bits and method
 * override folded in. */
typedef struct volfx_water_core {
    float h, threshold;
    uint32_t max_samples;
    float step;
    uint32_t refine_iters, pyramid_level;
    uint32_t disable;      /* VFX_WATER_NO_* (lab bits | features_off | the preset's) */
    uint32_t method;       /* never 0 */
    float color[3], absorption, ior;
} volfx_water_core;

/* The resolved parameters of one frame. */
typedef struct volfx_water_resolved {
    volfx_water_core p;          /* every default applied, method never 0; h and step 0 while
                                    h waits for the particles' spacing (volfx_water_params_set_h) */
    volfx_water_kernel_params kp;
    uint32_t preset;             /* VFX_WATER_PRESET_LOW .. _ULTRA (never DEFAULT) */
    float step_div;              /* step = h / step_div when the host gave no step */
    uint32_t look;               /* WATER_LOOK_* bits of the preset */
    bool absorption_per_h;       /* the host gave no absorption: WATER_ABSORPTION_H / h */
} volfx_water_resolved;

/* The look's parts and the savings each preset switches on (docs/water.md "Shading"): the
 * host's image as the surroundings' light, the sun's GGX lobe, the anisotropic shapes at half
 * rate (every other upload). */
#define WATER_LOOK_HOST_LIGHT 1u
#define WATER_LOOK_GGX 2u
#define WATER_LOOK_ANISO_HALF_RATE 8u
/* the plugin's own lights (the beams' line and point lights) on the surface and in the body */
#define WATER_LOOK_FX_LIGHTS 16u
/* the foam layer (water_foam.h); without it the diffuse splat's per-particle foam */
#define WATER_LOOK_FOAM_LAYER 32u
/* steam puffs at a beam's impact on the water (water_diffuse.h) */
#define WATER_LOOK_STEAM 64u
/* The default absorption, per unit of h: a pool 3 h deep takes 1 - e^-2 of the red light
 * behind it (tint's 1 - 0.15) and fills with the deep colour; a sheet h/4 thick keeps 84% (red) to 92% (blue). */
#define WATER_ABSORPTION_H 0.8f

/* Reads the host's parameters (and a vfx_lab_water in their chain), checks them and applies the
 * preset; an unknown method, kernel or preset, or a value outside its documented range that
 * would hang or silently draw nothing, fails with VFX_ERR_INVALID_ARGUMENT naming the field. */
vfx_result volfx_water_params_resolve(vfx_context *ctx, const vfx_water_params *in, volfx_water_resolved *out);
/* Sets h and the preset's step that depends on it; an explicit step outside [h/1024, h] fails
 * with VFX_ERR_INVALID_ARGUMENT naming it. */
vfx_result volfx_water_params_set_h(vfx_context *ctx, volfx_water_resolved *r, float h);

/* The particles' spacing: the median distance from a sample of up to 512 particles to their
 * nearest other particle (a hashed grid over `m` candidate positions, xyz interleaved, every
 * `stride`-th of the finite particles: the result is scaled by cbrt(stride)); 0 when no
 * particle has a neighbour at a nonzero distance. Allocates m + 2^k words, freed again;
 * -1 on allocation failure. */
double volfx_water_spacing(vfx_context *ctx, const float *xyz, uint32_t m, uint32_t stride);

#endif
