/* lab_beams.c — the beams' ray-marching baseline (vfx_lab_beams): midpoint samples of the raw
 * density instead of the closed form, the thesis' comparison (docs/beams-method.md), run as the
 * product's integrate pass with the lab's fragment shader (shaders/beams/march.frag). */
#include "lab_beams.h"

#include "gpu/gpu.h"
#include "gpu/pass.h"
#include "lab_ranges.h"
#include "volfx_lab.h"

#define MARCH_DEFAULT_SAMPLES 32u

/* The baseline's pass as the product opens it: its name, the timer's stat (docs/stats.md). */
static const volfx_pass_desc MARCH_PASS = {.name = "beams.march"};

vfx_result volfx_lab_beams_struct(vfx_context *ctx, const void *lab, uint32_t *method)
{
    const vfx_lab_beams *b = lab;
    if (b->method > VFX_BEAMS_METHOD_MARCH)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_BEAMS_VIEW_FIELD,
                          "beams: vfx_lab_beams.method %u unknown (0 closed form, 1 march)", b->method);
    vfx_result r = volfx_lab_range_check(ctx, "beams", VOLFX_LAB_RANGE_BEAMS_MARCH_SAMPLES, b->march_samples);
    if (r)
        return r;
    *method = b->method == VFX_BEAMS_METHOD_MARCH ? (b->march_samples ? b->march_samples : MARCH_DEFAULT_SAMPLES) : 0;
    return VFX_OK;
}

GLuint volfx_lab_beams_program(vfx_context *ctx, uint32_t method, const char *defines, const char **pass)
{
    *pass = MARCH_PASS.name;
    GLuint prog = volfx_gpu_program(ctx, "common/fullscreen.vert", "beams/march.frag", defines);
    if (prog)
        glProgramUniform1i(prog, volfx_gpu_uniform(ctx, prog, "u_march_samples"), (GLint)method);
    return prog;
}
