/* water_diffuse.c — diffuse particles (see water_diffuse.h): the parameters' checks, the
 * velocity upload, the step's dispatches (shaders/water/diffuse.comp) over a ping-pong pool
 * whose count never leaves the GPU (indirect dispatch and draw), and the two draws
 * (shaders/water/diffuse.vert, diffuse.frag). The plugin generates them rather than the host:
 * it already holds the positions and the neighbour grid on the GPU, so a host only hands over
 * its velocity columns (no new ABI beyond the parameters) and any engine gets them. */
#include <math.h>
#include <string.h>

#include "gpu/gpu.h"
#include "gpu/pass.h"
#include "water_diffuse.h"

/* the pool's cap at most: 2 vec4 a particle, 32 bytes, twice (ping-pong): 256 MiB */
#define DIFFUSE_MAX_CAP (1u << 22)
#define HEADER_UINTS 16
/* a spray streak's half-width and a foam / bubble splat's radius, in units of h */
#define SPRAY_RADIUS_H 0.12f
#define FOAM_RADIUS_H 0.8f
/* Steam at a beam's impact: puffs a second an impact, their lifetime (s), terminal rise speed
 * (units of v_ref = sqrt(|g| h)) and drag (1/s: how fast buoyancy and drag bring a puff to that
 * speed and damp its outward drift); a puff's radius at birth and at the end of its life (h).
 * In the default scene (h 0.106 m, v_ref 1.02 m/s) a puff rises at up to 0.71 m/s, about 1.1 m
 * over its life (a body height), and grows from 0.13 to 0.85 m across. */
#define STEAM_RATE 150.0
#define STEAM_LIFE_S 2.0f
#define STEAM_RISE 0.7f
#define STEAM_DRAG 4.0f
#define STEAM_RADIUS0_H 0.6f
#define STEAM_RADIUS1_H 4.0f

struct volfx_water_diffuse {
    GLuint vel;           /* vec4 a fluid particle */
    uint32_t vel_cap;
    float *staging;       /* one chunk's velocities, 4 floats each */
    uint32_t staging_cap;
    bool has_vel;         /* every chunk of the last upload gave velocities */
    GLuint nrm, pot;      /* vec4 a fluid particle */
    uint32_t fluid_cap;
    GLuint pool[2];       /* 2 vec4 a diffuse particle; pool[cur] holds the live ones */
    uint32_t pool_cap;
    int cur;
    GLuint header;        /* HEADER_UINTS: see diffuse.comp */
    GLuint layer, fbo;    /* RG16F foam thickness, bubbles */
    uint32_t layer_w, layer_h;
    bool stepped;         /* a step ran since the pool was made or cleared */
    float steam_left;     /* seconds a steam puff may still live (0: none in the pool) */
};

vfx_result volfx_water_diffuse_params_check(vfx_context *ctx, const vfx_water_params *in,
                                            volfx_water_diffuse_params *out)
{
    if (in->diffuse_max > DIFFUSE_MAX_CAP)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_PARAM_RANGE,
                          "water: vfx_water_params.diffuse_max %u above %u",
                          in->diffuse_max, DIFFUSE_MAX_CAP);
    out->max = in->diffuse_max ? in->diffuse_max : 32768;
    for (int k = 0; k < 3; ++k)
        if (!isfinite(in->gravity[k]) || fabsf(in->gravity[k]) > 1e4f)
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_PARAM_RANGE,
                              "water: vfx_water_params.gravity[%d] %g not finite or above 1e4",
                              k, in->gravity[k]);
    if (in->gravity[0] == 0 && in->gravity[1] == 0 && in->gravity[2] == 0) {
        out->gravity[0] = 0; out->gravity[1] = -9.81f; out->gravity[2] = 0;
    } else {
        memcpy(out->gravity, in->gravity, sizeof out->gravity);
    }
    struct { const char *name; const float *v; float def[2]; float *dst; } pairs[] = {
        /* retuned for a pool that starts calm (issue 24): with the former [6, 18], [0.5, 2],
         * [1, 6] the default scene's paddle waves (|v| up to 1.3 v_ref) made no particle in 400
         * frames; these show foam along the paddle's wave and at the walls at frame 90 (106
         * foam, 5 bubbles) without the grey sheet that [0.1, 1], [0.5, 3], [0.1, 0.6] laid over
         * the whole pool (3,504 foam), docs/water-whitewater.md "Diffuse particles" */
        {"trapped_air", in->trapped_air, {1.5f, 6.0f}, out->ta},
        {"wave_crest", in->wave_crest, {0.2f, 1.0f}, out->wc},
        {"energy", in->energy, {0.3f, 2.0f}, out->ek},
    };
    for (size_t k = 0; k < sizeof pairs / sizeof pairs[0]; ++k) {
        for (int e = 0; e < 2; ++e) {
            float v = pairs[k].v[e];
            if (!(v >= 0 && v <= 1e4f))
                return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_PARAM_RANGE,
                                  "water: vfx_water_params.%s[%d] %g outside [0, 1e4]",
                                  pairs[k].name, e, v);
            pairs[k].dst[e] = v == 0 ? pairs[k].def[e] : v;
        }
        if (!(pairs[k].dst[0] < pairs[k].dst[1]))
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_WATER_PARAM,
                              "water: vfx_water_params.%s [%g, %g]: min must be below max",
                              pairs[k].name, pairs[k].dst[0], pairs[k].dst[1]);
    }
    struct { const char *name; float v, hi, def; float *dst; } f[] = {
        {"rate_trapped_air", in->rate_trapped_air, 1e4f, 10.0f, &out->rate_ta},
        {"rate_wave_crest", in->rate_wave_crest, 1e4f, 25.0f, &out->rate_wc},
        {"lifetime", in->lifetime, 60.0f, 1.5f, &out->lifetime},
        {"buoyancy", in->buoyancy, 20.0f, 2.0f, &out->buoyancy},
        {"drag", in->drag, 60.0f, 8.0f, &out->drag},
    };
    for (size_t k = 0; k < sizeof f / sizeof f[0]; ++k) {
        if (!(f[k].v >= 0 && f[k].v <= f[k].hi))
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_PARAM_RANGE,
                              "water: vfx_water_params.%s %g outside [0, %g] (0: default %g)",
                              f[k].name, f[k].v, f[k].hi, f[k].def);
        *f[k].dst = f[k].v == 0 ? f[k].def : f[k].v;
    }
    out->spray_below = in->spray_below ? in->spray_below : 6;
    out->bubble_above = in->bubble_above ? in->bubble_above : 20;
    if (out->spray_below > 10000 || out->bubble_above > 10000 || out->spray_below > out->bubble_above)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_WATER_PARAM,
                          "water: vfx_water_params.spray_below %u and bubble_above %u: each <= 10000, spray_below <= bubble_above",
                          out->spray_below, out->bubble_above);
    return VFX_OK;
}

/* An empty pool: the header's counts all 0. */
static void header_zero(volfx_water_diffuse *d)
{
    if (d->header)
        glClearNamedBufferData(d->header, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
}

volfx_water_diffuse *volfx_water_diffuse_create(vfx_context *ctx)
{
    volfx_water_diffuse *d = volfx_alloc(ctx, sizeof *d);
    if (!d)
        return NULL;
    memset(d, 0, sizeof *d);
    d->header = volfx_gpu_storage(HEADER_UINTS * sizeof(uint32_t), "water.diffuse_header");
    header_zero(d);
    return d;
}

static void del_buffer(GLuint *b)
{
    if (*b)
        glDeleteBuffers(1, b);
    *b = 0;
}

void volfx_water_diffuse_destroy(vfx_context *ctx, volfx_water_diffuse *d)
{
    if (!d)
        return;
    GLuint *b[] = {&d->vel, &d->nrm, &d->pot, &d->pool[0], &d->pool[1], &d->header};
    for (size_t k = 0; k < sizeof b / sizeof b[0]; ++k)
        del_buffer(b[k]);
    if (d->layer)
        glDeleteTextures(1, &d->layer);
    if (d->fbo)
        glDeleteFramebuffers(1, &d->fbo);
    volfx_free(ctx, d->staging);
    volfx_free(ctx, d);
}

void volfx_water_diffuse_clear(volfx_water_diffuse *d)
{
    if (d->stepped) /* nothing to forget otherwise: no GL call on frames without particles */
        header_zero(d);
    d->stepped = false;
    d->steam_left = 0;
}

vfx_result volfx_water_diffuse_begin(vfx_context *ctx, volfx_water_diffuse *d, uint32_t total)
{
    d->has_vel = total > 0;
    if (total <= d->vel_cap && d->vel)
        return VFX_OK;
    del_buffer(&d->vel);
    d->vel = volfx_gpu_storage((GLsizeiptr)total * 16, "water.diffuse_fluid_velocity");
    d->vel_cap = d->vel ? total : 0;
    if (!d->vel || volfx_gpu_error_string())
        return volfx_fail(ctx, VFX_ERR_OUT_OF_MEMORY, VFX_LOG_ID_GPU_OUT_OF_MEMORY,
                          "water diffuse: velocities of %u particles", total);
    return VFX_OK;
}

vfx_result volfx_water_diffuse_chunk(vfx_context *ctx, volfx_water_diffuse *d, uint32_t first, uint32_t count,
                                     const float *const vel[3])
{
    if (!count)
        return VFX_OK;
    if (first + (uint64_t)count > d->vel_cap)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_WATER_PARTICLE_CHUNK,
                          "water diffuse: chunk at %u of %u particles passes the %u uploaded",
                          first, count, d->vel_cap);
    if (!vel[0] || !vel[1] || !vel[2]) {
        d->has_vel = false; /* a chunk without velocities: no diffuse particles this frame */
        return VFX_OK;
    }
    if (count > d->staging_cap) {
        volfx_free(ctx, d->staging);
        d->staging = volfx_alloc(ctx, (size_t)count * 4 * sizeof *d->staging);
        d->staging_cap = d->staging ? count : 0;
        if (!d->staging)
            return volfx_fail(ctx, VFX_ERR_OUT_OF_MEMORY, VFX_LOG_ID_OUT_OF_MEMORY,
                              "water diffuse: staging for %u velocities", count);
    }
    for (uint32_t i = 0; i < count; ++i) {
        float q[3] = {vel[0][i], vel[1][i], vel[2][i]};
        bool ok = isfinite(q[0]) && isfinite(q[1]) && isfinite(q[2]);
        for (int k = 0; k < 3; ++k) /* non-finite: at rest (generates nothing) */
            d->staging[4 * (size_t)i + k] = ok ? q[k] : 0.0f;
        d->staging[4 * (size_t)i + 3] = 0.0f;
    }
    glNamedBufferSubData(d->vel, (GLintptr)first * 16, (GLsizeiptr)count * 16, d->staging);
    return VFX_OK;
}

GLuint volfx_water_diffuse_velocity_target(vfx_context *ctx, volfx_water_diffuse *d, uint32_t first, uint32_t count)
{
    if (first + (uint64_t)count > d->vel_cap) {
        volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_WATER_PARTICLE_CHUNK,
                   "water diffuse: chunk at %u of %u particles passes the %u uploaded",
                   first, count, d->vel_cap);
        return 0;
    }
    return d->vel;
}

void volfx_water_diffuse_no_velocities(volfx_water_diffuse *d)
{
    d->has_vel = false;
}

bool volfx_water_diffuse_ready(const volfx_water_diffuse *d)
{
    return d && d->has_vel && d->vel;
}

/* Buffers for `fluid` particles and a pool of `cap`; a new pool starts empty. */
static vfx_result ensure_step_buffers(vfx_context *ctx, volfx_water_diffuse *d, uint32_t fluid, uint32_t cap)
{
    uint32_t n = fluid ? fluid : 1;
    if (n > d->fluid_cap || !d->nrm) {
        del_buffer(&d->nrm);
        del_buffer(&d->pot);
        d->nrm = volfx_gpu_storage((GLsizeiptr)n * 16, "water.diffuse_normals");
        d->pot = volfx_gpu_storage((GLsizeiptr)n * 16, "water.diffuse_potentials");
        d->fluid_cap = n;
    }
    if (cap != d->pool_cap || !d->pool[0]) {
        for (int k = 0; k < 2; ++k) {
            del_buffer(&d->pool[k]);
            d->pool[k] = volfx_gpu_storage((GLsizeiptr)cap * 32, k ? "water.diffuse_pool_b" : "water.diffuse_pool_a");
        }
        d->pool_cap = cap;
        d->cur = 0;
        d->steam_left = 0;
        header_zero(d);
    }
    const char *e = volfx_gpu_error_string();
    if (e)
        return volfx_fail(ctx, VFX_ERR_OUT_OF_MEMORY, VFX_LOG_ID_GPU_OUT_OF_MEMORY,
                          "water diffuse: buffers for %u fluid and %u diffuse particles: %s",
                          fluid, cap, e);
    return VFX_OK;
}

static void step_uniforms(vfx_context *ctx, GLuint prog, const volfx_water_diffuse_input *in)
{
    const volfx_water_diffuse_params *dp = in->dp;
    float g = sqrtf(dp->gravity[0] * dp->gravity[0] + dp->gravity[1] * dp->gravity[1] + dp->gravity[2] * dp->gravity[2]);
    /* v_ref = sqrt(|g| h); a host without gravity still gets a speed unit (that of 9.81) */
    float vref = sqrtf((g > 0 ? g : 9.81f) * in->h);
    glUseProgram(prog);
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_count"), in->count);
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_cap"), dp->max);
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_buckets"), in->grid->buckets);
    glUniform3fv(volfx_gpu_uniform(ctx, prog, "u_g0"), 1, in->grid->origin);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_cs"), in->grid->cell);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_h"), in->h);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_dt"), in->dt);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_vref"), vref);
    glUniform3fv(volfx_gpu_uniform(ctx, prog, "u_gravity"), 1, dp->gravity);
    glUniform2fv(volfx_gpu_uniform(ctx, prog, "u_ta"), 1, dp->ta);
    glUniform2fv(volfx_gpu_uniform(ctx, prog, "u_wc"), 1, dp->wc);
    glUniform2fv(volfx_gpu_uniform(ctx, prog, "u_ek"), 1, dp->ek);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_rate_ta"), dp->rate_ta);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_rate_wc"), dp->rate_wc);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_life"), dp->lifetime);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_buoy"), dp->buoyancy);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_drag"), dp->drag);
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_spray_below"), dp->spray_below);
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_bubble_above"), dp->bubble_above);
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_seed"), (uint32_t)(in->frame * 2654435761u));
    glUniform3fv(volfx_gpu_uniform(ctx, prog, "u_lo"), 1, in->lo);
    glUniform3fv(volfx_gpu_uniform(ctx, prog, "u_hi"), 1, in->hi);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_steam_life"), STEAM_LIFE_S);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_steam_rise"), STEAM_RISE);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_steam_drag"), STEAM_DRAG);
}

/* Drops each impact throws this step: impact_rate x dt, the fraction carried by a hash of the
 * frame (a rate below one a step still throws some), at most IMPACT_DROPS_MAX. */
#define IMPACT_DROPS_MAX 256u
static uint32_t per_step(double rate, float dt, uint64_t frame)
{
    double want = rate * dt;
    uint32_t x = (uint32_t)(frame * 2654435761u);
    x ^= x >> 15, x *= 2246822519u, x ^= x >> 13;
    double n = floor(want + (double)(x >> 8) / 16777216.0);
    return n > IMPACT_DROPS_MAX ? IMPACT_DROPS_MAX : (uint32_t)n;
}

static uint32_t impact_drops(const volfx_water_diffuse_input *in)
{
    if (!in->impact_count || !(in->impact_rate > 0))
        return 0;
    return per_step(in->impact_rate, in->dt, in->frame);
}

/* Steam puffs each impact makes this step: STEAM_RATE x dt (the fraction carried like the
 * drops', by another hash); none with the steam off or no impact. */
static uint32_t steam_puffs(const volfx_water_diffuse_input *in)
{
    if (!in->impact_count || !in->steam)
        return 0;
    return per_step(STEAM_RATE, in->dt, in->frame ^ 0x5bd1e995u);
}

vfx_result volfx_water_diffuse_step(vfx_context *ctx, volfx_water_diffuse *d, const volfx_water_diffuse_input *in)
{
    vfx_result r = ensure_step_buffers(ctx, d, in->count, in->dp->max);
    if (r)
        return r;
    GLuint normal = volfx_gpu_compute(ctx, "water/diffuse.comp", "#define MODE_NORMAL\n");
    GLuint gen = volfx_gpu_compute(ctx, "water/diffuse.comp", "#define MODE_GENERATE\n");
    GLuint prep = volfx_gpu_compute(ctx, "water/diffuse.comp", "#define MODE_PREP\n");
    GLuint adv = volfx_gpu_compute(ctx, "water/diffuse.comp", "#define MODE_ADVECT\n");
    GLuint fin = volfx_gpu_compute(ctx, "water/diffuse.comp", "#define MODE_FINAL\n");
    GLuint emit = in->impact_count ? volfx_gpu_compute(ctx, "water/diffuse.comp", "#define MODE_EMIT\n") : 0;
    if (!normal || !gen || !prep || !adv || !fin || (in->impact_count && !emit))
        return VFX_ERR_GL;
    GLuint bind[] = {in->cols[0], in->cols[1], in->cols[2], d->vel, in->counters, in->grid->start, d->header,
                     in->grid->sorted, d->nrm, d->pot, d->pool[d->cur], d->pool[1 - d->cur]};
    for (GLuint k = 0; k < sizeof bind / sizeof bind[0]; ++k)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, k, bind[k]);
    GLuint groups = (in->count + 63u) / 64u;
    GLuint gx = groups < 65535u ? groups : 65535u, gy = gx ? (groups + gx - 1) / gx : 0;
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.diffuse", .compute = true});
    /* paused (dt 0): nothing is generated; the pool is still classified (the stats) */
    if (gx && in->dt > 0) {
        step_uniforms(ctx, normal, in);
        glDispatchCompute(gx, gy, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        step_uniforms(ctx, gen, in);
        glDispatchCompute(gx, gy, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
    uint32_t per = in->dt > 0 ? impact_drops(in) : 0, puffs = in->dt > 0 ? steam_puffs(in) : 0;
    d->steam_left = puffs ? STEAM_LIFE_S : (d->steam_left > in->dt ? d->steam_left - in->dt : 0);
    if (per || puffs) {
        step_uniforms(ctx, emit, in);
        float imp[VOLFX_WATER_DIFFUSE_IMPACTS][8];
        memset(imp, 0, sizeof imp);
        for (uint32_t e = 0; e < in->impact_count; ++e) {
            memcpy(imp[e], in->impacts[e], 3 * sizeof(float));
            memcpy(imp[e] + 4, in->impacts[e] + 3, 3 * sizeof(float));
        }
        glUniform4fv(volfx_gpu_uniform(ctx, emit, "u_imp"), (GLsizei)(2 * in->impact_count), imp[0]);
        glUniform1ui(volfx_gpu_uniform(ctx, emit, "u_imp_n"), in->impact_count);
        glUniform1ui(volfx_gpu_uniform(ctx, emit, "u_imp_per"), per);
        glUniform1f(volfx_gpu_uniform(ctx, emit, "u_imp_speed"), in->impact_speed);
        glUniform1ui(volfx_gpu_uniform(ctx, emit, "u_steam_per"), puffs);
        glDispatchCompute((in->impact_count * (per + puffs) + 63u) / 64u, 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
    step_uniforms(ctx, prep, in);
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
    step_uniforms(ctx, adv, in);
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, d->header);
    glDispatchComputeIndirect(0);
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, 0);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    step_uniforms(ctx, fin, in);
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
    volfx_pass_end(ctx);
    d->cur = 1 - d->cur;
    d->stepped = true;
    const char *e = volfx_gpu_error_string();
    if (e)
        return volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR,
                          "water diffuse step over %u fluid particles: %s", in->count, e);
    return VFX_OK;
}

void volfx_water_diffuse_buffers(const volfx_water_diffuse *d, GLuint *vel, GLuint *pool, GLuint *header)
{
    *vel = d->vel;
    *pool = d->pool[d->cur];
    *header = d->header;
}

/* The uniforms both draws read; binds the live pool at SSBO 0. */
static void draw_uniforms(vfx_context *ctx, GLuint prog, volfx_water_diffuse *d, const volfx_water_diffuse_draw *dd,
                          const volfx_frame_targets *targets, float radius)
{
    glUseProgram(prog);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, d->pool[d->cur]);
    glBindTextureUnit(0, dd->dist_tex);
    glBindTextureUnit(1, targets->host_depth);
    glUniformMatrix4fv(volfx_gpu_uniform(ctx, prog, "u_view_proj"), 1, GL_FALSE, targets->view_proj);
    glUniformMatrix4fv(volfx_gpu_uniform(ctx, prog, "u_inv_view_proj"), 1, GL_FALSE, targets->inv_view_proj);
    glUniform3fv(volfx_gpu_uniform(ctx, prog, "u_eye"), 1, targets->eye);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_radius"), radius * dd->h);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_h"), dd->h);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_absorption"), dd->absorption);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_shutter"), dd->shutter);
    glUniform1i(volfx_gpu_uniform(ctx, prog, "u_has_depth"), targets->host_depth != 0);
    glUniform1i(volfx_gpu_uniform(ctx, prog, "u_hdr"), targets->color_hdr);
    glBindVertexArray(dd->vao);
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, d->header);
}

vfx_result volfx_water_diffuse_splat(vfx_context *ctx, volfx_water_diffuse *d, const volfx_water_diffuse_draw *dd,
                                     const volfx_frame_targets *targets, GLuint *layer)
{
    *layer = 0;
    if (!d->stepped)
        return VFX_OK;
    if (!d->layer || d->layer_w != targets->width || d->layer_h != targets->height) {
        if (d->layer)
            glDeleteTextures(1, &d->layer);
        if (d->fbo)
            glDeleteFramebuffers(1, &d->fbo);
        glCreateTextures(GL_TEXTURE_2D, 1, &d->layer);
        glTextureStorage2D(d->layer, 1, GL_RG16F, (GLsizei)targets->width, (GLsizei)targets->height);
        glTextureParameteri(d->layer, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(d->layer, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        volfx_gpu_label(GL_TEXTURE, d->layer, "water.diffuse_layer");
        glCreateFramebuffers(1, &d->fbo);
        glNamedFramebufferTexture(d->fbo, GL_COLOR_ATTACHMENT0, d->layer, 0);
        d->layer_w = targets->width;
        d->layer_h = targets->height;
        vfx_result r = volfx_gpu_check_target(ctx, d->fbo, "water diffuse: layer", targets->width, targets->height);
        if (r)
            return r;
    }
    GLuint prog = volfx_gpu_program(ctx, "water/diffuse.vert", "water/diffuse.frag", "#define SPLAT\n");
    if (!prog)
        return VFX_ERR_GL;
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.diffuse_splat", .framebuffer = d->fbo,
                                             .width = targets->width, .height = targets->height, .clear_color = true,
                                             .blend = VOLFX_BLEND_ADD});
    draw_uniforms(ctx, prog, d, dd, targets, FOAM_RADIUS_H);
    glDrawArraysIndirect(GL_TRIANGLE_STRIP, (const void *)(uintptr_t)(4 * sizeof(uint32_t)));
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
    volfx_pass_end(ctx);
    *layer = d->layer;
    return VFX_OK;
}

vfx_result volfx_water_diffuse_spray(vfx_context *ctx, volfx_water_diffuse *d, const volfx_water_diffuse_draw *dd,
                                     const volfx_frame_targets *targets)
{
    if (!d->stepped)
        return VFX_OK;
    GLuint prog = volfx_gpu_program(ctx, "water/diffuse.vert", "water/diffuse.frag",
                                    dd->lights ? "#define STREAK\n#define WATER_EFFECT_LIGHTS 1\n#define WATER_MAX_LIGHTS 32\n"
                                               : "#define STREAK\n");
    if (!prog)
        return VFX_ERR_GL;
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.spray", .framebuffer = targets->framebuffer,
                                             .width = targets->width, .height = targets->height,
                                             .blend = VOLFX_BLEND_OVER_PREMUL});
    draw_uniforms(ctx, prog, d, dd, targets, SPRAY_RADIUS_H);
    glDrawArraysIndirect(GL_TRIANGLE_STRIP, (const void *)(uintptr_t)(4 * sizeof(uint32_t)));
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
    volfx_pass_end(ctx);
    return VFX_OK;
}

vfx_result volfx_water_diffuse_steam(vfx_context *ctx, volfx_water_diffuse *d, const volfx_water_diffuse_draw *dd,
                                     const volfx_frame_targets *targets)
{
    if (!d->stepped || !(d->steam_left > 0))
        return VFX_OK;
    GLuint prog = volfx_gpu_program(ctx, "water/steam.vert", "water/steam.frag",
                                    dd->lights ? "#define WATER_EFFECT_LIGHTS 1\n#define WATER_MAX_LIGHTS 32\n" : "");
    if (!prog)
        return VFX_ERR_GL;
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.steam", .framebuffer = targets->framebuffer,
                                             .width = targets->width, .height = targets->height,
                                             .blend = VOLFX_BLEND_OVER_PREMUL});
    draw_uniforms(ctx, prog, d, dd, targets, STEAM_RADIUS0_H);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_radius1"), STEAM_RADIUS1_H * dd->h);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_steam_life"), STEAM_LIFE_S);
    glDrawArraysIndirect(GL_TRIANGLE_STRIP, (const void *)(uintptr_t)(4 * sizeof(uint32_t)));
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
    volfx_pass_end(ctx);
    return VFX_OK;
}

vfx_result volfx_water_diffuse_debug(vfx_context *ctx, volfx_water_diffuse *d, float *pot, size_t fluid,
                                     float *pool, size_t pool_cap, uint32_t *alive)
{
    if (!d || !d->stepped)
        return volfx_fail(ctx, VFX_ERR_NOT_FOUND, VFX_LOG_ID_EFFECT_NOT_RENDERED,
                          "water diffuse debug: no diffuse step ran yet");
    uint32_t hdr[HEADER_UINTS];
    glGetNamedBufferSubData(d->header, 0, sizeof hdr, hdr);
    uint32_t n = hdr[3] < d->pool_cap ? hdr[3] : d->pool_cap;
    if (alive)
        *alive = n;
    if (pot) {
        if (fluid > d->fluid_cap)
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_READ_BUFFER_SIZE,
                              "water diffuse debug: %zu fluid particles, %u computed", fluid,
                              d->fluid_cap);
        glGetNamedBufferSubData(d->pot, 0, (GLsizeiptr)fluid * 16, pot);
    }
    if (pool) {
        if (pool_cap < n)
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_READ_BUFFER_SIZE,
                              "water diffuse debug: room for %zu, %u alive", pool_cap, n);
        if (n)
            glGetNamedBufferSubData(d->pool[d->cur], 0, (GLsizeiptr)n * 32, pool);
    }
    const char *e = volfx_gpu_error_string();
    return e ? volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR, "water diffuse debug: %s", e) : VFX_OK;
}
