/* lab_volume.h — the volume's entry of the lab's hook table (lab_hooks.h): the vfx_lab_volume
 * struct. */
#ifndef VOLFX_LAB_VOLUME_H
#define VOLFX_LAB_VOLUME_H

#include "lab_hooks.h"
#include "volfx_lab.h"

/* lab_hooks.h volume_struct: what the disable bits switch off (unknown bits refused). */
vfx_result volfx_lab_volume_struct(vfx_context *ctx, const void *lab, volfx_lab_volume_off *off);

#endif
