/* lab_beams.h — the beams' entries of the lab's hook table (lab_hooks.h): the vfx_lab_beams
 * struct and the ray-marching baseline's integrate program (shaders/beams/march.frag). */
#ifndef VOLFX_LAB_BEAMS_H
#define VOLFX_LAB_BEAMS_H

#include "lab_hooks.h"

/* lab_hooks.h beams_struct: the method (unknown ones refused) and the march samples (against
 * lab_ranges.h; 0 -> 32). *method: 0 for the closed form, else the samples per ray. */
vfx_result volfx_lab_beams_struct(vfx_context *ctx, const void *lab, uint32_t *method);
/* lab_hooks.h beams_program: march.frag in the variant `defines`, marching `method` samples. */
GLuint volfx_lab_beams_program(vfx_context *ctx, uint32_t method, const char *defines, const char **pass);

#endif
