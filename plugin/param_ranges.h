/* param_ranges.h — the plugin's one check of the host's numbers against their documented ranges
 * (include/volfx/volfx_ranges.h, VFX_RANGE_TABLE): each effect calls its function below before
 * it reads a field, so a value outside is refused naming the field, never defaulted. */
#ifndef VOLFX_PARAM_RANGES_H
#define VOLFX_PARAM_RANGES_H

#include <stddef.h>
#include <stdint.h>
#include <volfx/volfx.h>
#include <volfx/volfx_ranges.h>

#include "context.h"

/* One row of VFX_RANGE_TABLE. */
typedef struct volfx_range {
    const char *field, *scene_key;
    double lo, hi;
    uint32_t flags; /* VFX_RANGE_* */
    const char *note;
} volfx_range;

/* The row of `id` (id < VFX_RANGE_COUNT). */
const volfx_range *volfx_range_row(vfx_range_id id);
/* Writes the row's range as the docs show it ("(0, 1000]", "1..4096", with "or 0" where 0 is
 * the default); returns out. */
char *volfx_range_text(const volfx_range *r, char *out, size_t n);
/* VFX_OK when v fits the row (0 too where 0 is the default); else fails ctx with
 * VFX_ERR_INVALID_ARGUMENT "WHAT: FIELD V outside RANGE". NaN and Inf never fit. */
vfx_result volfx_range_check(vfx_context *ctx, const char *what, vfx_range_id id, double v);
/* The same against a row of another table (the lab's, plugin/lab/lab_ranges.h). */
vfx_result volfx_range_check_row(vfx_context *ctx, const char *what, const volfx_range *row, double v);
/* Every one of v[0..n) (all 0 allowed where 0 is the default). */
vfx_result volfx_range_check_vec(vfx_context *ctx, const char *what, vfx_range_id id, const float *v, int n);

/* The water parameters. */
vfx_result volfx_water_params_check_ranges(vfx_context *ctx, const vfx_water_params *p);
/* The diffuse particles' fields alone (volfx_water_params_check_ranges includes them). */
vfx_result volfx_water_diffuse_check_ranges(vfx_context *ctx, const vfx_water_params *p);
/* The water's foam struct (chained into the water parameters). */
vfx_result volfx_water_foam_check_ranges(vfx_context *ctx, const vfx_water_foam *f);
/* Beam i. */
vfx_result volfx_beam_check_ranges(vfx_context *ctx, uint32_t i, const vfx_beam *b);
/* The beams view's own numbers. */
vfx_result volfx_beams_view_check_ranges(vfx_context *ctx, const vfx_beams_view *v);
/* The volume view's renderer options. */
vfx_result volfx_volume_view_check_ranges(vfx_context *ctx, const vfx_volume_view *v);
/* The frame view's numbers, each against its row alone (the frame gate checks the relations:
 * near against proj, eye against view, the GL names). */
vfx_result volfx_frame_view_check_ranges(vfx_context *ctx, const vfx_frame_view *v);
/* A chained vfx_frame_depth's numbers against their rows. */
vfx_result volfx_frame_depth_check_ranges(vfx_context *ctx, const vfx_frame_depth *d);

#endif
