/* water_grid.c — the lab's GRID baseline of the water: uniform grid of cell h (grown when it would exceed
 * GRID_MAX_CELLS), built on the GPU from the position columns whenever they were uploaded
 * again or h changed (a static scene keeps its grid): count per cell,
 * exclusive prefix sum (gpu/scan.h), scatter of the positions into cell order. The
 * march (grid.comp MODE_MARCH) then sums each sample's potential over the cells its h-ball
 * touches and jumps over empty space. Cell size and origin come from the box the CPU already
 * computes while counting NaNs in water_update, so the only CPU work here is a few uniforms. */
#include <math.h>
#include <string.h>

#include "gpu/gpu.h"
#include "gpu/pass.h"
#include "gpu/scan.h"
#include "water_grid.h"

/* cells + 1 entries must fit the scan */
#define GRID_MAX_CELLS (VOLFX_SCAN_MAX - 1u)

struct volfx_water_grid {
    GLuint count, start, sorted;
    uint32_t cell_cap;     /* entries count/start hold (ncells + 1, rounded up to 1024) */
    uint32_t sorted_cap;   /* particles `sorted` holds */
    /* what the grid in the buffers was built from: the same, and it is still right */
    int built;
    uint64_t built_rev;
    uint32_t built_count;
    float built_h;
};

volfx_water_grid *volfx_water_grid_create(vfx_context *ctx)
{
    volfx_water_grid *g = volfx_alloc(ctx, sizeof *g);
    if (!g)
        return NULL;
    return g;
}

void volfx_water_grid_destroy(vfx_context *ctx, volfx_water_grid *g)
{
    if (!g)
        return;
    GLuint b[] = {g->count, g->start, g->sorted};
    for (int k = 0; k < 3; ++k)
        if (b[k])
            glDeleteBuffers(1, &b[k]);
    volfx_free(ctx, g);
}

/* Grid geometry: origin one cell below the box, cell >= h (times 1 + 1e-4 so that rounding in
 * floor() never puts a particle within h of a sample two cells away), grown by the cube root of
 * the excess when the box would need more than GRID_MAX_CELLS cells (h tiny against the extent). */
static void grid_layout(const volfx_lab_water_input *in, float g0[3], float *cs_out, int dims[3])
{
    double cs = (double)in->params->h * (1.0 + 1e-4);
    double lo[3] = {0, 0, 0}, ext[3] = {0, 0, 0};
    if (in->finite)
        for (int k = 0; k < 3; ++k) {
            lo[k] = in->lo[k];
            ext[k] = (double)in->hi[k] - in->lo[k];
        }
    for (int tries = 0; tries < 64; ++tries) {
        double cells = 1;
        for (int k = 0; k < 3; ++k)
            cells *= floor(ext[k] / cs) + 3;
        if (cells <= GRID_MAX_CELLS)
            break;
        cs *= cbrt(cells / GRID_MAX_CELLS) * 1.01;
    }
    for (int k = 0; k < 3; ++k) {
        dims[k] = (int)(floor(ext[k] / cs) + 3);
        g0[k] = (float)(lo[k] - cs);
    }
    *cs_out = (float)cs;
}

/* The storage buffers of every grid.comp mode. */
static void grid_bind(const volfx_water_grid *g, const volfx_lab_water_input *in)
{
    for (int k = 0; k < 3; ++k)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)k, in->cols[k]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, g->count);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, in->counters);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, g->start);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 7, g->sorted);
}

static void grid_uniforms(vfx_context *ctx, GLuint prog, const volfx_lab_water_input *in, const float g0[3], float cs,
                          const int dims[3])
{
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_count"), in->count);
    glUniform3fv(volfx_gpu_uniform(ctx, prog, "u_g0"), 1, g0);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_cs"), cs);
    glUniform3iv(volfx_gpu_uniform(ctx, prog, "u_dims"), 1, dims);
}

void volfx_water_march_bind(vfx_context *ctx, GLuint prog, GLuint dist_tex, const volfx_water_core *p,
                          const volfx_frame_targets *targets)
{
    glBindImageTexture(0, dist_tex, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    glBindTextureUnit(1, targets->host_depth);
    glUniformMatrix4fv(volfx_gpu_uniform(ctx, prog, "u_inv_view_proj"), 1, GL_FALSE, targets->inv_view_proj);
    glUniform3fv(volfx_gpu_uniform(ctx, prog, "u_eye"), 1, targets->eye);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_h"), p->h);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_T"), p->threshold);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_step"), p->step);
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_max_samples"), p->max_samples);
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_refine_iters"), (p->disable & VFX_WATER_NO_REFINE) ? 0u : p->refine_iters);
    glUniform1i(volfx_gpu_uniform(ctx, prog, "u_has_depth"), targets->host_depth != 0);
}

vfx_result volfx_water_grid_render(vfx_context *ctx, volfx_water_grid *g, const volfx_lab_water_input *in,
                                 const volfx_frame_targets *targets)
{
    const volfx_water_core *p = in->params;
    float g0[3], cs;
    int dims[3];
    grid_layout(in, g0, &cs, dims);
    uint32_t ncells = (uint32_t)dims[0] * (uint32_t)dims[1] * (uint32_t)dims[2];
    uint32_t nscan = ncells + 1; /* start[ncells] = number of finite particles */
    uint32_t need = (nscan + 1023u) & ~1023u;
    if (need > g->cell_cap) {
        if (g->count) glDeleteBuffers(1, &g->count);
        if (g->start) glDeleteBuffers(1, &g->start);
        g->count = volfx_gpu_storage((GLsizeiptr)need * 4, "water.grid_count");
        g->start = volfx_gpu_storage((GLsizeiptr)need * 4, "water.grid_start");
        g->cell_cap = need;
        g->built = 0;
    }
    uint32_t np = in->count ? in->count : 1;
    if (np > g->sorted_cap) {
        if (g->sorted) glDeleteBuffers(1, &g->sorted);
        g->sorted = volfx_gpu_storage((GLsizeiptr)np * 16, "water.grid_sorted");
        g->sorted_cap = np;
        g->built = 0;
    }
    /* The box, hence the layout, comes from the same upload as the positions: a grid built
     * from this upload with this h is the one this frame would build (bit for bit but for the
     * order within a cell, which the atomics may change: skipping keeps the image identical). */
    int rebuild = !g->built || g->built_rev != in->data_rev || g->built_count != in->count ||
                  memcmp(&g->built_h, &p->h, sizeof p->h) != 0;
    GLuint count = volfx_gpu_compute(ctx, "water/grid.comp", "#define MODE_COUNT\n");
    GLuint scatter = volfx_gpu_compute(ctx, "water/grid.comp", "#define MODE_SCATTER\n");
    GLuint march = volfx_gpu_compute(ctx, "water/grid.comp", "#define MODE_MARCH\n");
    if (!count || !scatter || !march)
        return VFX_ERR_GL;
    grid_bind(g, in);
    /* per-particle passes as 2D dispatches: GL promises only 65535 groups per dimension */
    GLuint groups = (in->count + 63u) / 64u;
    GLuint gx = groups < 65535u ? groups : 65535u, gy = gx ? (groups + gx - 1) / gx : 0;

    if (rebuild) {
        volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.grid_build", .compute = true});
        glClearNamedBufferSubData(g->count, GL_R32UI, 0, (GLsizeiptr)need * 4, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
        glUseProgram(count);
        grid_uniforms(ctx, count, in, g0, cs, dims);
        if (groups)
            glDispatchCompute(gx, gy, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        vfx_result r = volfx_gpu_scan(ctx, g->count, g->start, nscan, "water grid");
        if (r) {
            volfx_pass_end(ctx);
            return r;
        }
        grid_bind(g, in);
        /* the counts are spent: the same buffer becomes the per-cell fill cursor of the scatter */
        glClearNamedBufferSubData(g->count, GL_R32UI, 0, (GLsizeiptr)need * 4, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
        glUseProgram(scatter);
        grid_uniforms(ctx, scatter, in, g0, cs, dims);
        if (groups)
            glDispatchCompute(gx, gy, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        volfx_pass_end(ctx);
        g->built = 1;
        g->built_rev = in->data_rev;
        g->built_count = in->count;
        g->built_h = p->h;
    }

    /* the counters were cleared by the effect at the start of the frame */
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.grid_march", .compute = true});
    glUseProgram(march);
    grid_uniforms(ctx, march, in, g0, cs, dims);
    float blo[3], bhi[3];
    for (int k = 0; k < 3; ++k) {
        blo[k] = in->finite ? in->lo[k] - p->h : 0.0f;
        bhi[k] = in->finite ? in->hi[k] + p->h : -1.0f; /* empty box: every ray misses */
    }
    glUniform3fv(volfx_gpu_uniform(ctx, march, "u_blo"), 1, blo);
    glUniform3fv(volfx_gpu_uniform(ctx, march, "u_bhi"), 1, bhi);
    volfx_water_march_bind(ctx, march, in->dist_tex, p, targets);
    /* the paper's technique bits mean the same here: 1 = start at the box entry instead of the
     * first sphere entry, 2 = fixed steps after the start (no jump over empty space) */
    glUniform1i(volfx_gpu_uniform(ctx, march, "u_seek_init"), !(p->disable & VFX_WATER_NO_BILLBOARD_INIT));
    glUniform1i(volfx_gpu_uniform(ctx, march, "u_seek_gaps"), !(p->disable & VFX_WATER_NO_SKIP));
    glDispatchCompute((in->width + 7) / 8, (in->height + 7) / 8, 1);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                    GL_TEXTURE_UPDATE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    volfx_pass_end(ctx);

    volfx_stat_set(ctx, "water.grid_rebuilt", rebuild);
    volfx_stat_set(ctx, "water.grid_cells", ncells);
    volfx_stat_set(ctx, "water.grid_cell_size", cs);
    const char *e = volfx_gpu_error_string();
    if (e)
        return volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR,
                          "water grid (%dx%dx%d cells of %g): %s", dims[0], dims[1], dims[2], (double)cs, e);
    return VFX_OK;
}
