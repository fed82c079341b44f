/* lab_ranges.h — the documented range of each numeric field of the lab structs (volfx_lab.h) that
 * the lab reads as a number, one row each, in the form of the ABI's table (volfx_ranges.h:
 * X(ID, field, scene key or "-", lo, hi, flags, note)). Not installed: a host never sees a lab
 * field. The lab checks its structs against these rows (volfx_lab_range_check); test
 * unit/abi_ranges requires every row to name a field of volfx_lab.h and none in the installed
 * table, and unit/param_ranges walks each row through the lab's check. */
#ifndef VOLFX_LAB_RANGES_H
#define VOLFX_LAB_RANGES_H

#include "param_ranges.h"

#define VOLFX_LAB_RANGE_TABLE(X) \
    X(BEAMS_MARCH_SAMPLES, "vfx_lab_beams.march_samples", "-", 1, 4096, VFX_RANGE_INT | VFX_RANGE_ZERO, "")

typedef enum volfx_lab_range_id {
#define VOLFX_LAB_RANGE_ENUM_(id, field, key, lo, hi, flags, note) VOLFX_LAB_RANGE_##id,
    VOLFX_LAB_RANGE_TABLE(VOLFX_LAB_RANGE_ENUM_)
#undef VOLFX_LAB_RANGE_ENUM_
    VOLFX_LAB_RANGE_COUNT
} volfx_lab_range_id;

/* The row of `id` (id < VOLFX_LAB_RANGE_COUNT). */
const volfx_range *volfx_lab_range_row(volfx_lab_range_id id);
/* VFX_OK when v fits the row; else fails ctx as volfx_range_check does, naming the field. */
vfx_result volfx_lab_range_check(vfx_context *ctx, const char *what, volfx_lab_range_id id, double v);

#endif
