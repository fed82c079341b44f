/* lab_types.h — the type values of the lab structs (vfx_lab_water, vfx_lab_beams,
 * vfx_lab_volume: plugin/lab/volfx_lab.h). The product knows only these numbers: it finds a lab
 * struct in a chain to hand it to the lab (lab_hooks.h) or, without one, to refuse it by name;
 * the structs' layouts are the lab's. Far from the public values (volfx.h). */
#ifndef VOLFX_LAB_TYPES_H
#define VOLFX_LAB_TYPES_H

#include <volfx/volfx.h>

#define VFX_TYPE_LAB_WATER ((vfx_struct_type)0x4c414201)
#define VFX_TYPE_LAB_BEAMS ((vfx_struct_type)0x4c414202)
#define VFX_TYPE_LAB_VOLUME ((vfx_struct_type)0x4c414203)

#endif
