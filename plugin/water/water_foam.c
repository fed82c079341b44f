/* water_foam.c — the foam layer (water_foam.h): the parameters, the grid that follows the
 * water's box, the three dispatches of shaders/water/foam.comp over a ping-pong pair of R32F
 * textures, and the rule that leaves a scene without foam paying nothing. */
#include <math.h>
#include <string.h>

#include "context.h"
#include "gpu/gpu.h"
#include "gpu/pass.h"
#include "param_ranges.h"
#include "water_foam.h"

/* texels a side at most (4 MiB a texture); a wider box gets coarser texels */
#define FOAM_MAX_SIDE 1024u
/* the grid reaches this many h past the water's box (waves and spray that land outside it) */
#define FOAM_MARGIN_H 4.0f
/* the explicit diffusion's coefficient D dt / cell^2 per update is held below this (the 5-point
 * stencil is stable below 1/4); a larger one is spread over the next updates */
#define FOAM_KDIFF_MAX 0.2f
/* the layer counts as faded after this many lifetimes without foam: e^-9.2 = 1e-4 */
#define FOAM_FADED_LIFETIMES 9.2f

struct volfx_water_foam_layer {
    GLuint tex[2];         /* R32F density; tex[cur] holds the newest */
    int cur;
    volfx_water_foam_grid grid;  /* of tex[cur]; x0, z0 relative to `at` */
    double wx0, wz0;       /* texel (0, 0)'s corner in the world (the frame's origin added) */
    double at[2];          /* the origin of the last update */
    GLuint vsum, dep;      /* 3 ints and 1 uint a texel */
    bool live;             /* tex[cur] may hold foam */
    float quiet_s;         /* seconds since foam was last seen */
};

vfx_result volfx_water_foam_params_resolve(vfx_context *ctx, const vfx_water_params *in, bool preset_layer,
                                           volfx_water_foam_params *out)
{
    vfx_water_foam zero;
    memset(&zero, 0, sizeof zero);
    const vfx_water_foam *f = volfx_chain_find(in->next, VFX_TYPE_WATER_FOAM);
    if (!f)
        f = &zero;
    vfx_result r = volfx_water_foam_check_ranges(ctx, f);
    if (r)
        return r;
    out->layer = f->layer == VFX_WATER_FOAM_ON || (f->layer == VFX_WATER_FOAM_DEFAULT && preset_layer);
    out->impacts = f->impacts != VFX_WATER_FOAM_OFF;
    out->lifetime = f->lifetime ? f->lifetime : 3.0f;
    out->cell = f->cell ? f->cell : 0.5f;
    out->diffusion = f->diffusion ? f->diffusion : 0.5f;
    out->deposit = f->deposit ? f->deposit : 0.1f;
    out->impact_rate = f->impact_rate ? f->impact_rate : 600.0f;
    out->impact_speed = f->impact_speed ? f->impact_speed : 4.0f;
    return VFX_OK;
}

volfx_water_foam_layer *volfx_water_foam_create(vfx_context *ctx)
{
    volfx_water_foam_layer *f = volfx_alloc(ctx, sizeof *f);
    if (f)
        memset(f, 0, sizeof *f);
    return f;
}

static void free_grid(volfx_water_foam_layer *f)
{
    for (int k = 0; k < 2; ++k)
        if (f->tex[k])
            glDeleteTextures(1, &f->tex[k]);
    if (f->vsum)
        glDeleteBuffers(1, &f->vsum);
    if (f->dep)
        glDeleteBuffers(1, &f->dep);
    f->tex[0] = f->tex[1] = f->vsum = f->dep = 0;
}

void volfx_water_foam_destroy(vfx_context *ctx, volfx_water_foam_layer *f)
{
    if (!f)
        return;
    free_grid(f);
    volfx_free(ctx, f);
}

void volfx_water_foam_clear(volfx_water_foam_layer *f)
{
    if (f && f->live && f->tex[f->cur])
        glClearTexImage(f->tex[f->cur], 0, GL_RED, GL_FLOAT, NULL);
    if (f) {
        f->live = false;
        f->quiet_s = 0;
    }
}

static GLuint make_tex(uint32_t nx, uint32_t nz, const char *label)
{
    GLuint t;
    glCreateTextures(GL_TEXTURE_2D, 1, &t);
    glTextureStorage2D(t, 1, GL_R32F, (GLsizei)nx, (GLsizei)nz);
    glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(t, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    glTextureParameteri(t, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    const float zero[4] = {0, 0, 0, 0};
    glTextureParameterfv(t, GL_TEXTURE_BORDER_COLOR, zero);
    glClearTexImage(t, 0, GL_RED, GL_FLOAT, NULL);
    volfx_gpu_label(GL_TEXTURE, t, label);
    return t;
}

/* The grid this update wants: the box (x, z) and FOAM_MARGIN_H h around it, texels of cell x h
 * snapped to multiples of the cell (a box that moves a little keeps the same texels). */
static volfx_water_foam_grid want_grid(const volfx_water_foam_input *in, double *wx0, double *wz0)
{
    volfx_water_foam_grid g;
    float m = FOAM_MARGIN_H * in->h, ex = in->hi[0] - in->lo[0] + 2 * m, ez = in->hi[2] - in->lo[2] + 2 * m;
    float cell = in->fp->cell * in->h, side = ex > ez ? ex : ez;
    if (side / cell > (float)(FOAM_MAX_SIDE - 2))
        cell = side / (float)(FOAM_MAX_SIDE - 2);
    g.cell = cell;
    /* snapped in the world: a host that moves its origin keeps the same texels */
    *wx0 = floor((in->origin[0] + in->lo[0] - m) / cell) * cell;
    *wz0 = floor((in->origin[1] + in->lo[2] - m) / cell) * cell;
    g.x0 = (float)(*wx0 - in->origin[0]);
    g.z0 = (float)(*wz0 - in->origin[1]);
    g.nx = (uint32_t)ceilf((in->hi[0] + m - g.x0) / cell) + 1;
    g.nz = (uint32_t)ceilf((in->hi[2] + m - g.z0) / cell) + 1;
    g.nx = g.nx > FOAM_MAX_SIDE ? FOAM_MAX_SIDE : g.nx;
    g.nz = g.nz > FOAM_MAX_SIDE ? FOAM_MAX_SIDE : g.nz;
    return g;
}

/* Keeps the grid while the box (with h to spare) lies inside it at the same cell; else a new
 * grid: tex[1 - cur] and the sums at its size, tex[cur] (the old grid) is read by the step. */
static vfx_result ensure_grid(vfx_context *ctx, volfx_water_foam_layer *f, const volfx_water_foam_input *in,
                              volfx_water_foam_grid *old)
{
    double wx0, wz0;
    volfx_water_foam_grid g = want_grid(in, &wx0, &wz0), *c = &f->grid;
    /* the current grid relative to this update's origin */
    c->x0 = (float)(f->wx0 - in->origin[0]);
    c->z0 = (float)(f->wz0 - in->origin[1]);
    f->at[0] = in->origin[0], f->at[1] = in->origin[1];
    *old = *c;
    float m = in->h;
    bool inside = f->tex[f->cur] && fabsf(g.cell - c->cell) <= 1e-6f * g.cell && in->lo[0] - m >= c->x0 &&
                  in->lo[2] - m >= c->z0 && in->hi[0] + m <= c->x0 + c->cell * (float)c->nx &&
                  in->hi[2] + m <= c->z0 + c->cell * (float)c->nz;
    if (inside)
        return VFX_OK;
    /* a new grid: the old texture stays readable as tex[cur]; everything else is remade */
    GLuint keep = f->tex[f->cur];
    f->tex[f->cur] = 0;
    free_grid(f);
    if (!keep) {
        keep = make_tex(1, 1, "water.foam_a");
        old->x0 = g.x0, old->z0 = g.z0, old->cell = g.cell, old->nx = old->nz = 1;
    }
    f->tex[f->cur] = keep;
    f->tex[1 - f->cur] = make_tex(g.nx, g.nz, f->cur ? "water.foam_a" : "water.foam_b");
    size_t texels = (size_t)g.nx * g.nz;
    f->vsum = volfx_gpu_storage((GLsizeiptr)(texels * 12), "water.foam_velocity");
    f->dep = volfx_gpu_storage((GLsizeiptr)(texels * 4), "water.foam_deposit");
    if (f->vsum)
        glClearNamedBufferData(f->vsum, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
    if (f->dep)
        glClearNamedBufferData(f->dep, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
    *c = g;
    f->wx0 = wx0, f->wz0 = wz0;
    const char *e = volfx_gpu_error_string();
    if (e || !f->vsum || !f->dep)
        return volfx_fail(ctx, VFX_ERR_OUT_OF_MEMORY, VFX_LOG_ID_GPU_OUT_OF_MEMORY, "water foam: a %u x %u layer: %s",
                             g.nx, g.nz, e ? e : "no buffer");
    return VFX_OK;
}

/* The uniforms of every mode: the grid, the previous grid the step reads, the rates. */
static void uniforms(vfx_context *ctx, GLuint prog, const volfx_water_foam_layer *f, const volfx_water_foam_grid *old,
                     const volfx_water_foam_input *in)
{
    const volfx_water_foam_grid *g = &f->grid;
    const volfx_water_foam_params *fp = in->fp;
    glUseProgram(prog);
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_count"), in->count);
    glUniform2f(volfx_gpu_uniform(ctx, prog, "u_grid"), g->x0, g->z0);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_cell"), g->cell);
    glUniform2i(volfx_gpu_uniform(ctx, prog, "u_size"), (GLint)g->nx, (GLint)g->nz);
    glUniform4f(volfx_gpu_uniform(ctx, prog, "u_prev_grid"), old->x0, old->z0, 1.0f / (old->cell * (float)old->nx),
                1.0f / (old->cell * (float)old->nz));
    glUniform2f(volfx_gpu_uniform(ctx, prog, "u_prev_texel"), 1.0f / (float)old->nx, 1.0f / (float)old->nz);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_dt"), in->dt);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_vref"), in->vref);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_decay"), expf(-in->dt / fp->lifetime));
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_dry_decay"), expf(-10.0f * in->dt / fp->lifetime));
    /* D dt / cell^2 in the old grid's texels (the stencil's taps are the old grid's) */
    float k = fp->diffusion * in->h * in->h * in->dt / (old->cell * old->cell);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_kdiff"), k < FOAM_KDIFF_MAX ? k : FOAM_KDIFF_MAX);
    /* density a foam particle adds this update over its texels: deposit dt h^2 / cell^2 */
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_deposit"), fp->deposit * in->dt * in->h * in->h / (g->cell * g->cell));
}

vfx_result volfx_water_foam_step(vfx_context *ctx, volfx_water_foam_layer *f, const volfx_water_foam_input *in)
{
    if (in->foam_seen)
        f->quiet_s = 0;
    else
        f->quiet_s += in->dt;
    bool faded = f->quiet_s > FOAM_FADED_LIFETIMES * in->fp->lifetime;
    if (!in->foam_seen && (!f->live || faded)) {
        volfx_water_foam_clear(f); /* nothing runs: a still pool without foam pays nothing */
        volfx_stat_set(ctx, "water.foam_active", 0);
        return VFX_OK;
    }
    if (!(in->dt > 0)) { /* paused: the layer stays as it is */
        volfx_stat_set(ctx, "water.foam_active", 0);
        return VFX_OK;
    }
    volfx_water_foam_grid old;
    vfx_result r = ensure_grid(ctx, f, in, &old);
    if (r)
        return r;
    GLuint velp = volfx_gpu_compute(ctx, "water/foam.comp", "#define MODE_VELOCITY\n");
    GLuint depp = volfx_gpu_compute(ctx, "water/foam.comp", "#define MODE_DEPOSIT\n");
    GLuint stepp = volfx_gpu_compute(ctx, "water/foam.comp", "#define MODE_STEP\n");
    if (!velp || !depp || !stepp)
        return VFX_ERR_GL;
    GLuint bind[] = {in->cols[0], in->cols[1], in->cols[2], in->vel, f->vsum, f->dep, in->header, in->pool};
    for (GLuint k = 0; k < sizeof bind / sizeof bind[0]; ++k)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, k, bind[k]);
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.foam", .compute = true});
    GLuint groups = (in->count + 63u) / 64u;
    GLuint gx = groups < 65535u ? groups : 65535u, gy = gx ? (groups + gx - 1) / gx : 0;
    if (gx) {
        uniforms(ctx, velp, f, &old, in);
        glDispatchCompute(gx, gy, 1);
    }
    /* the diffuse step left the advection's dispatch in the header: an upper bound of the pool */
    uniforms(ctx, depp, f, &old, in);
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, in->header);
    glDispatchComputeIndirect(0);
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, 0);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    uniforms(ctx, stepp, f, &old, in);
    glBindTextureUnit(0, f->tex[f->cur]);
    glBindImageTexture(0, f->tex[1 - f->cur], 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    glDispatchCompute((f->grid.nx + 7) / 8, (f->grid.nz + 7) / 8, 1);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    glBindImageTexture(0, 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    glClearNamedBufferData(f->vsum, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
    glClearNamedBufferData(f->dep, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
    volfx_pass_end(ctx);
    /* a regrid's old texture is the 1x1 placeholder or the old size: remade at the grid's size */
    if (old.nx != f->grid.nx || old.nz != f->grid.nz) {
        glDeleteTextures(1, &f->tex[f->cur]);
        f->tex[f->cur] = make_tex(f->grid.nx, f->grid.nz, f->cur ? "water.foam_b" : "water.foam_a");
    }
    f->cur = 1 - f->cur;
    f->live = true;
    volfx_stat_set(ctx, "water.foam_active", 1);
    volfx_stat_set(ctx, "water.foam_texels", (double)f->grid.nx * f->grid.nz);
    const char *e = volfx_gpu_error_string();
    return e ? volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR, "water foam: the layer's step (%u x %u texels): %s", f->grid.nx,
                          f->grid.nz, e)
             : VFX_OK;
}

GLuint volfx_water_foam_texture(const volfx_water_foam_layer *f, const double origin[2], float grid[4])
{
    if (!f || !f->live || !f->tex[f->cur])
        return 0;
    const volfx_water_foam_grid *g = &f->grid;
    grid[0] = (float)(f->wx0 - origin[0]), grid[1] = (float)(f->wz0 - origin[1]);
    grid[2] = 1.0f / (g->cell * (float)g->nx), grid[3] = 1.0f / (g->cell * (float)g->nz);
    return f->tex[f->cur];
}

vfx_result volfx_water_foam_debug_read(vfx_context *ctx, volfx_water_foam_layer *f, volfx_water_foam_grid *g,
                                       float *out, size_t cap)
{
    if (!f || !f->tex[f->cur])
        return volfx_fail(ctx, VFX_ERR_NOT_FOUND, VFX_LOG_ID_EFFECT_NOT_RENDERED, "water foam debug: no foam layer yet");
    *g = f->grid;
    size_t n = (size_t)g->nx * g->nz;
    if (!out)
        return VFX_OK;
    if (cap < n)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_READ_BUFFER_SIZE, "water foam debug: room for %zu texels, the layer has %zu", cap, n);
    glGetTextureImage(f->tex[f->cur], 0, GL_RED, GL_FLOAT, (GLsizei)(n * sizeof(float)), out);
    const char *e = volfx_gpu_error_string();
    return e ? volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR, "water foam debug: %s", e) : VFX_OK;
}

void volfx_water_foam_debug_wake(volfx_water_foam_layer *f)
{
    f->live = true;
    f->quiet_s = 0;
}

vfx_result volfx_water_foam_debug_write(vfx_context *ctx, volfx_water_foam_layer *f, const float *in, size_t n)
{
    if (!f || !f->tex[f->cur])
        return volfx_fail(ctx, VFX_ERR_NOT_FOUND, VFX_LOG_ID_EFFECT_NOT_RENDERED, "water foam debug: no foam layer yet");
    if (n != (size_t)f->grid.nx * f->grid.nz)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_API_ARGUMENT, "water foam debug: %zu texels, the layer has %u x %u", n,
                          f->grid.nx, f->grid.nz);
    glTextureSubImage2D(f->tex[f->cur], 0, 0, 0, (GLsizei)f->grid.nx, (GLsizei)f->grid.nz, GL_RED, GL_FLOAT, in);
    f->live = true;
    f->quiet_s = 0;
    return VFX_OK;
}
