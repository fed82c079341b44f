/* water_foam.h — the water's foam layer (docs/water.md "Foam layer"): one foam density over the
 * water's horizontal extent, a 2D grid in world x and z (texels of cell x h) that persists from
 * update to update. Each update (pass water.foam, shaders/water/foam.comp): the fluid particles'
 * velocities are averaged per texel over the water's depth (the depth-averaged velocity of
 * shallow-water flow), the foam particles of the diffuse pool deposit into the texels around
 * them (bilinear: a particle's mass and centre are kept exactly), and the density is carried
 * semi-Lagrangian by that velocity, spread by an explicit 5-point diffusion and faded by
 * exp(-dt / lifetime). The shading samples it at the surface's world x and z and draws it as a
 * white, lit, bubbly foam. Nothing runs while no foam particle was seen and the layer has faded. */
#ifndef VOLFX_WATER_FOAM_H
#define VOLFX_WATER_FOAM_H

#include <stdbool.h>

#include "gpu/gl.h"
#include "effect.h"

/* vfx_water_foam resolved: checked, defaults applied, the preset's switch folded in. */
typedef struct volfx_water_foam_params {
    bool layer;            /* the layer runs (else the per-particle foam of the diffuse splat) */
    bool impacts;          /* spray is thrown up where a beam strikes the water */
    float lifetime;        /* seconds (1/e) */
    float cell;            /* texel, units of h */
    float diffusion;       /* h^2 / s */
    float deposit;         /* density x h^2 a foam particle adds per second */
    float impact_rate;     /* drops / s an impact */
    float impact_speed;    /* units of sqrt(|g| h) */
} volfx_water_foam_params;

/* Reads the vfx_water_foam chained into `in` (none: every default), checks its ranges and
 * resolves it; `preset_layer` is the preset's switch for the layer. A bad field fails with
 * VFX_ERR_INVALID_ARGUMENT naming it. */
vfx_result volfx_water_foam_params_resolve(vfx_context *ctx, const vfx_water_params *in, bool preset_layer,
                                           volfx_water_foam_params *out);

typedef struct volfx_water_foam_layer volfx_water_foam_layer;

/* Makes the (empty) layer; NULL on allocation failure. */
volfx_water_foam_layer *volfx_water_foam_create(vfx_context *ctx);
/* Frees it; NULL allowed. */
void volfx_water_foam_destroy(vfx_context *ctx, volfx_water_foam_layer *f);

/* What one update needs (borrowed). */
typedef struct volfx_water_foam_input {
    const GLuint *cols;          /* x, y, z position columns of the fluid */
    uint32_t count;              /* fluid particles, non-finite included */
    GLuint vel;                  /* vec4 a fluid particle */
    GLuint pool, header;         /* the diffuse pool (2 vec4 a particle) and its header (diffuse.comp) */
    const float *lo, *hi;        /* box of the finite fluid particles */
    double origin[2];            /* the frame's origin (x, z): the layer is anchored in the world */
    float h, dt, vref;           /* kernel radius, seconds since the last update, sqrt(|g| h) */
    const volfx_water_foam_params *fp;
    bool foam_seen;              /* the newest counters read back counted foam particles */
} volfx_water_foam_input;

/* One update of the layer (pass water.foam); skipped (nothing dispatched) while no foam was seen
 * and the layer has faded below 1e-4 of what it held (9.2 lifetimes). Stats water.foam_texels,
 * water.foam_active. */
vfx_result volfx_water_foam_step(vfx_context *ctx, volfx_water_foam_layer *f, const volfx_water_foam_input *in);

/* The layer to draw: its texture (linear filtering, 0 outside) and grid relative to the frame's
 * origin (x, z): (x0, z0, 1 / (cell x nx), 1 / (cell x nz)); 0 when there is nothing to draw. */
GLuint volfx_water_foam_texture(const volfx_water_foam_layer *f, const double origin[2], float grid[4]);
/* Forgets the layer's foam (the next update starts empty). */
void volfx_water_foam_clear(volfx_water_foam_layer *f);

/* The layer's grid (tests). */
typedef struct volfx_water_foam_grid {
    float x0, z0, cell;          /* texel (0, 0)'s corner relative to the last update's origin; texel size */
    uint32_t nx, nz;
} volfx_water_foam_grid;
/* Debug (tests): the grid and the density, nx x nz floats row by row from z0 (NULL: grid only). */
vfx_result volfx_water_foam_debug_read(vfx_context *ctx, volfx_water_foam_layer *f, volfx_water_foam_grid *g,
                                       float *out, size_t cap);
/* Debug (tests): the next update runs as if foam had been seen (it makes the grid). */
void volfx_water_foam_debug_wake(volfx_water_foam_layer *f);
/* Debug (tests): overwrites the density with `in` (nx x nz of the current grid). */
vfx_result volfx_water_foam_debug_write(vfx_context *ctx, volfx_water_foam_layer *f, const float *in, size_t n);

#endif
