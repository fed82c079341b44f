/* lab_volume.c — the volume's laboratory (lab_hooks.h): the vfx_lab_volume struct, whose bits
 * switch the tet renderer's techniques off for the ablations (docs/tetvol-method.md). */
#include "lab_volume.h"

#define VOLUME_DISABLE_ALL (VFX_VOLUME_NO_ERT | VFX_VOLUME_NO_SHARE | VFX_VOLUME_NO_DLB)

vfx_result volfx_lab_volume_struct(vfx_context *ctx, const void *lab, volfx_lab_volume_off *off)
{
    const vfx_lab_volume *l = lab;
    if (l->disable & ~(uint32_t)VOLUME_DISABLE_ALL)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_PARAM_RANGE,
                          "volume[0]: vfx_lab_volume.disable 0x%x has unknown bits (known: 0x%x)", l->disable,
                          (unsigned)VOLUME_DISABLE_ALL);
    *off = (volfx_lab_volume_off){.ert = (l->disable & VFX_VOLUME_NO_ERT) != 0,
                                  .share = (l->disable & VFX_VOLUME_NO_SHARE) != 0,
                                  .dlb = (l->disable & VFX_VOLUME_NO_DLB) != 0};
    return VFX_OK;
}
