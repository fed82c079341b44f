/* lab_ranges.c — see lab_ranges.h. */
#include "lab_ranges.h"

static const volfx_range LAB_ROWS[VOLFX_LAB_RANGE_COUNT] = {
#define ROW_(id, field, key, lo, hi, flags, note) [VOLFX_LAB_RANGE_##id] = {field, key, lo, hi, flags, note},
    VOLFX_LAB_RANGE_TABLE(ROW_)
#undef ROW_
};

const volfx_range *volfx_lab_range_row(volfx_lab_range_id id)
{
    return &LAB_ROWS[id];
}

vfx_result volfx_lab_range_check(vfx_context *ctx, const char *what, volfx_lab_range_id id, double v)
{
    return volfx_range_check_row(ctx, what, &LAB_ROWS[id], v);
}
