/* lab.c — volfx_lab_attach: the lab's hook table (lab_hooks.h), one constant table shared by
 * every context it is attached to. */
#include "lab_beams.h"
#include "lab_volume.h"
#include "lab_water.h"
#include "volfx_shaders.h"

static const volfx_lab_hooks LAB_HOOKS = {
    .shaders = &volfx_lab_shaders,
    .water_struct = volfx_lab_water_struct,
    .water_march = volfx_lab_water_march,
    .water_free = volfx_lab_water_free,
    .water_counters = volfx_lab_water_counters,
    .volume_struct = volfx_lab_volume_struct,
    .beams_struct = volfx_lab_beams_struct,
    .beams_program = volfx_lab_beams_program,
};

vfx_result volfx_lab_attach(vfx_context *ctx)
{
    if (!ctx)
        return VFX_ERR_INVALID_ARGUMENT;
    ctx->lab = &LAB_HOOKS;
    return VFX_OK;
}
