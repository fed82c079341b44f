/* lab_hooks.h — the product's one door to the laboratory (plugin/lab: the research baselines
 * and ablation switches, a library that tests and benches link and libvolfx does not contain).
 * A context holds a table of the lab's functions in ctx->lab: NULL in the product, filled by
 * volfx_lab_attach (volfx_lab.h). Without it a lab struct or method is refused by name. */
#ifndef VOLFX_LAB_HOOKS_H
#define VOLFX_LAB_HOOKS_H

#include <stdbool.h>
#include <stdint.h>

#include "gpu/gl.h"
#include "effect.h"
#include "lab_types.h"

struct volfx_water_core;    /* water/water_params.h */
struct volfx_shader_table;  /* volfx_shaders.h */

/* What a lab method of the water draws from: the water's state, borrowed for the call. */
typedef struct volfx_lab_water_input {
    const GLuint *cols;              /* x, y, z position columns (SSBOs of `count` floats) */
    uint32_t count;                  /* particles in the columns, non-finite ones included */
    uint32_t finite;                 /* of which finite (0: nothing to draw) */
    const float *lo, *hi;            /* box of the finite particles */
    const struct volfx_water_core *params; /* defaults already applied */
    uint32_t width, height;
    GLuint dist_tex;                 /* R32F target: distance along the ray or -1 */
    GLuint counters;                 /* the effect's counter buffer (fenced readback ring) */
    uint64_t data_rev;               /* changes whenever the columns were uploaded again */
} volfx_lab_water_input;

/* What a vfx_lab_volume switches off in the volume's renderer (tetra/tet_render.h tet_options):
 * early ray termination, the workers' shared ERT tables, dynamic load balancing. */
typedef struct volfx_lab_volume_off {
    bool ert, share, dlb;
} volfx_lab_volume_off;

struct volfx_lab_hooks {
    /* The lab's embedded GLSL (volfx_lab_shaders): the program cache (gpu/gpu.c) builds a path
     * the product's table lacks from it. */
    const struct volfx_shader_table *shaders;
    /* Reads the vfx_lab_water at `lab` (its type already matched): *disable gets its VFX_WATER_NO_*
     * bits, *method its method (0: the host's); unknown bits fail with VFX_ERR_INVALID_ARGUMENT
     * naming the field. */
    vfx_result (*water_struct)(vfx_context *ctx, const void *lab, uint32_t *disable, uint32_t *method);
    /* Draws lab method `method` (VFX_WATER_METHOD_BRUTE or _GRID) into in->dist_tex, adding its
     * counts into in->counters; *state is the lab's own, NULL until its first call. */
    vfx_result (*water_march)(vfx_context *ctx, void **state, uint32_t method, const volfx_lab_water_input *in,
                              const volfx_frame_targets *targets);
    /* Frees what water_march made in *state (NULL allowed). */
    void (*water_free)(vfx_context *ctx, void *state);
    /* Publishes the stats of lab method `method` from the counter slots `c` of one frame (the
     * water's fenced readback, WATER_COUNTERS words). */
    void (*water_counters)(vfx_context *ctx, uint32_t method, const uint32_t *c);
    /* Reads the vfx_lab_volume at `lab` (its type already matched) into *off: what it switches
     * off in the volume's renderer; unknown bits fail with VFX_ERR_INVALID_ARGUMENT naming the
     * field. */
    vfx_result (*volume_struct)(vfx_context *ctx, const void *lab, volfx_lab_volume_off *off);
    /* Reads the vfx_lab_beams at `lab` (its type already matched) into *method: 0 for the
     * product's closed form, else a lab method for beams_program; a value outside its range
     * (lab_ranges.h) fails with VFX_ERR_INVALID_ARGUMENT naming the field. */
    vfx_result (*beams_struct)(vfx_context *ctx, const void *lab, uint32_t *method);
    /* The beams' integrate program of lab method `method` (nonzero, from beams_struct) in the
     * product's variant `defines` (its VOLFX_BEAMS_* lines; NULL: none), the pass's name in
     * *pass; 0 on failure (logged). The product binds and draws it as its own integrate pass. */
    GLuint (*beams_program)(vfx_context *ctx, uint32_t method, const char *defines, const char **pass);
};

#endif
