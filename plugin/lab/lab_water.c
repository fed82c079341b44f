/* lab_water.c — the water's laboratory (lab_hooks.h): the vfx_lab_water struct (ablation bits and
 * the baseline methods), and the two baselines' marches: BRUTE, every pixel over every particle
 * (shaders/water/brute.comp), and GRID (water_grid.c). */
#include "lab_water.h"

#include "gpu/gpu.h"
#include "gpu/pass.h"
#include "water_grid.h"

/* The lab's state in the water effect: the GRID's, made the first time GRID is drawn. */
typedef struct lab_water_state {
    volfx_water_grid *grid;
} lab_water_state;

vfx_result volfx_lab_water_struct(vfx_context *ctx, const void *lab, uint32_t *disable, uint32_t *method)
{
    const vfx_lab_water *l = lab;
    if (l->disable & ~VFX_WATER_DISABLE_ALL)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_WATER_PARAM,
                          "water: vfx_lab_water.disable 0x%x has unknown bits", l->disable);
    *disable = l->disable;
    *method = l->method;
    return VFX_OK;
}

/* BRUTE: the per-pixel march over every particle (pass water.brute). */
static vfx_result brute_march(vfx_context *ctx, const volfx_lab_water_input *in, const volfx_frame_targets *targets)
{
    GLuint prog = volfx_gpu_compute(ctx, "water/brute.comp", NULL);
    if (!prog)
        return VFX_ERR_GL;
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.brute", .compute = true});
    glUseProgram(prog);
    for (int k = 0; k < 3; ++k)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)k, in->cols[k]);
    volfx_water_march_bind(ctx, prog, in->dist_tex, in->params, targets);
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_count"), in->count);
    glDispatchCompute((in->width + 7) / 8, (in->height + 7) / 8, 1);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
    volfx_pass_end(ctx);
    return VFX_OK;
}

vfx_result volfx_lab_water_march(vfx_context *ctx, void **state, uint32_t method, const volfx_lab_water_input *in,
                                 const volfx_frame_targets *targets)
{
    if (method == VFX_WATER_METHOD_BRUTE)
        return brute_march(ctx, in, targets);
    if (method != VFX_WATER_METHOD_GRID)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_WATER_METHOD,
                          "water: lab method %u unknown (1 brute, 2 grid)", method);
    lab_water_state *s = *state;
    if (!s) {
        if (!(s = volfx_alloc(ctx, sizeof *s)))
            return VFX_ERR_OUT_OF_MEMORY;
        *state = s;
    }
    if (!s->grid && !(s->grid = volfx_water_grid_create(ctx)))
        return VFX_ERR_OUT_OF_MEMORY;
    return volfx_water_grid_render(ctx, s->grid, in, targets);
}

/* GRID counts samples and pixel classes in march.comp's slots (2-5) and its walk in 8 and 9
 * (shaders/water/grid.comp); BRUTE counts nothing. */
void volfx_lab_water_counters(vfx_context *ctx, uint32_t method, const uint32_t *c)
{
    if (method != VFX_WATER_METHOD_GRID)
        return;
    volfx_stat_set(ctx, "water.samples", c[2]);
    volfx_stat_set(ctx, "water.pixels_found", c[3]);
    volfx_stat_set(ctx, "water.pixels_sample_cap", c[4]);
    volfx_stat_set(ctx, "water.pixels_left", c[5]);
    volfx_stat_set(ctx, "water.grid_cells_visited", c[8]);
    volfx_stat_set(ctx, "water.grid_sphere_tests", c[9]);
}

void volfx_lab_water_free(vfx_context *ctx, void *state)
{
    lab_water_state *s = state;
    if (!s)
        return;
    volfx_water_grid_destroy(ctx, s->grid);
    volfx_free(ctx, s);
}
