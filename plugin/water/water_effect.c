/* water_effect.c — metaball water (seed 000, Mishima et al.): the effect's create, resize,
 * upload, per-frame method choice, shading and counter readback. The methods: PAPER
 * (water_paper.c), TILE, ours (water_tile.c, with water_aniso.c's kernels), and the lab's BRUTE
 * and GRID when a lab is attached (lab_hooks.h, plugin/lab); spray, foam and bubbles in
 * water_diffuse.c. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "water/water_effect.h"
#include "gpu/gpu.h"
#include "gpu/pass.h"
#include "effect.h"
#include "context.h"

#include "water_internal.h"
#include "water_params.h"
#include "lab_hooks.h"
#include "param_ranges.h"
#if VFX_WITH_BEAMS
#include "beams/beams_impact.h"
#endif


static void groups_free(vfx_context *ctx, water_state *s)
{
    for (uint32_t g = 0; g < s->group_count; ++g)
        glDeleteBuffers(3, s->groups[g].cols);
    volfx_free(ctx, s->groups);
    s->groups = NULL;
    s->group_count = 0;
    s->capacity = 0;
    s->cols[0] = s->cols[1] = s->cols[2] = 0;
}


/* This frame's parameters: the resolved ones, h from the spacing when the host gave none. */
static vfx_result water_set_params(vfx_context *ctx, water_state *s, volfx_water_resolved *res)
{
    vfx_result r = res->p.h == 0 ? volfx_water_params_set_h(ctx, res, s->auto_h > 0 ? s->auto_h : 0.61f) : VFX_OK;
    if (r == VFX_OK)
        s->params = res->p;
    return r;
}

static bool water_present(vfx_context *ctx)
{
    return ctx->host.particle_chunk_count && ctx->host.particle_chunk_count(ctx->host.user) > 0;
}

static void water_destroy(vfx_context *ctx, void *state);

static vfx_result water_create(vfx_context *ctx, void **out)
{
    water_state *s = volfx_alloc(ctx, sizeof *s);
    if (!s)
        return VFX_ERR_OUT_OF_MEMORY;
    s->active = -1;
    glCreateVertexArrays(1, &s->vao);
    /* one SSBO binding must hold a whole column */
    GLint64 block = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &block);
    uint64_t cap = block > 0 ? (uint64_t)block / sizeof(float) : (1u << 24);
    s->gl_cap = cap > WATER_MAX_PARTICLES ? WATER_MAX_PARTICLES : (uint32_t)cap;
    glCreateBuffers(WATER_COUNTER_RING, s->ring);
    for (int k = 0; k < WATER_COUNTER_RING; ++k)
        glNamedBufferStorage(s->ring[k], WATER_COUNTERS * sizeof(uint32_t), NULL, GL_MAP_READ_BIT);
    *out = s;
    if (!volfx_ubo_create(ctx, &s->frame_ubo, sizeof(water_frame_block), "water.frame")) {
        water_destroy(ctx, s);
        *out = NULL;
        return VFX_ERR_GL;
    }
    return VFX_OK;
}

static void water_destroy(vfx_context *ctx, void *state)
{
    water_state *s = state;
    groups_free(ctx, s);
    volfx_water_views_destroy(ctx, s);
    if (s->lab_state && ctx->lab)
        ctx->lab->water_free(ctx, s->lab_state);
    volfx_water_aniso_destroy(ctx, s->aniso);
    volfx_water_diffuse_destroy(ctx, s->diffuse);
    volfx_water_foam_destroy(ctx, s->foam);
    volfx_water_gather_destroy(ctx, s->gather);
    volfx_water_lights_destroy(&s->effect_lights);
    volfx_free(ctx, s->chunk_rev);
    glDeleteVertexArrays(1, &s->vao);
    volfx_ubo_destroy(&s->frame_ubo);
    for (int k = 0; k < WATER_COUNTER_RING; ++k)
        if (s->fence[k])
            glDeleteSync(s->fence[k]);
    glDeleteBuffers(WATER_COUNTER_RING, s->ring);
    if (s->counters)
        glDeleteBuffers(1, &s->counters);
    volfx_free(ctx, s);
}

/* Targets are per view and made at the size the view is drawn at (water_view.c): a resize of
 * the context allocates nothing here, so a second view at another size costs no reallocation. */
static vfx_result water_resize(vfx_context *ctx, void *state, uint32_t width, uint32_t height)
{
    (void)ctx, (void)state, (void)width, (void)height;
    return VFX_OK;
}

/* Position buffers for `total` particles, at most buffer_cap each (recreated when the count
 * grows past what they hold, or the cap changed). */
static vfx_result ensure_groups(vfx_context *ctx, water_state *s, uint32_t total)
{
    uint32_t cap = s->gl_cap;
    if (ctx->debug.water_buffer_cap && ctx->debug.water_buffer_cap < cap)
        cap = ctx->debug.water_buffer_cap;
    uint32_t need = total ? (uint32_t)(((uint64_t)total + cap - 1) / cap) : 1;
    if (s->groups && total <= s->capacity && need == s->group_count && cap == s->buffer_cap) {
        /* as many particles or fewer: same buffers (each sized for its group at capacity) */
        for (uint32_t g = 0; g < need; ++g) {
            uint32_t first = g * cap;
            s->groups[g].count = total > first ? (total - first < cap ? total - first : cap) : 0;
        }
        return VFX_OK;
    }
    groups_free(ctx, s);
    s->buffer_cap = cap;
    s->groups = volfx_alloc(ctx, need * sizeof *s->groups);
    if (!s->groups)
        return VFX_ERR_OUT_OF_MEMORY;
    s->group_count = need;
    for (uint32_t g = 0; g < need; ++g) {
        water_group *w = &s->groups[g];
        w->first = g * cap;
        w->count = total - w->first < cap ? total - w->first : cap;
        glCreateBuffers(3, w->cols);
        for (int k = 0; k < 3; ++k)
            glNamedBufferStorage(w->cols[k], (GLsizeiptr)(w->count ? w->count : 1) * 4, NULL, GL_DYNAMIC_STORAGE_BIT);
    }
    memcpy(s->cols, s->groups[0].cols, sizeof s->cols);
    s->capacity = total;
    const char *e = volfx_gpu_error_string();
    if (e) {
        groups_free(ctx, s);
        return volfx_fail(ctx, VFX_ERR_OUT_OF_MEMORY, VFX_LOG_ID_GPU_OUT_OF_MEMORY,
                          "water: position buffers for %u particles (%u buffers of at most %u): %s",
                        total, need, cap, e);
    }
    return VFX_OK;
}

/* Asks the host for chunk `c` (a typed, zeroed view) and checks what it names: positions as CPU
 * columns or a GL buffer, not both (the same for velocities and kernels), GL buffer columns that
 * fit their buffers (GL buffer velocities and kernels with GL buffer positions). */
static vfx_result query_chunk(vfx_context *ctx, uint32_t c, water_chunk *out)
{
    vfx_particle_view v;
    memset(&v, 0, sizeof v);
    v.type = VFX_TYPE_PARTICLE_VIEW;
    vfx_result r = ctx->host.particle_chunk(ctx->host.user, c, &v);
    if (r)
        return volfx_fail(ctx, r, VFX_LOG_ID_HOST_CALLBACK,
                          "water: particle chunk %u failed (%d)", c, (int)r);
    char what[64];
    snprintf(what, sizeof what, "water: particle chunk %u (vfx_particle_view)", c);
    if ((r = volfx_check_type(ctx, &v, VFX_TYPE_PARTICLE_VIEW, what)))
        return r;
    memset(out, 0, sizeof *out);
    out->count = v.count;
    out->revision = v.revision;
    memcpy(out->pos, v.pos, sizeof out->pos);
    memcpy(out->vel, v.vel, sizeof out->vel);
    out->radius = v.radius;
    out->kernel = v.kernel;
    out->gpu_pos = v.gpu_pos, out->gpu_vel = v.gpu_vel, out->gpu_kernel = v.gpu_kernel;
    if (!out->count)
        return VFX_OK;
    bool cpu_pos = out->pos[0] || out->pos[1] || out->pos[2], cpu_vel = out->vel[0] || out->vel[1] || out->vel[2];
    if (out->gpu_pos.buffer && cpu_pos)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_GPU_COLUMN,
                             "water: particle chunk %u names both pos[] and gpu_pos (one of them)", c);
    if (out->gpu_vel.buffer && cpu_vel)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_GPU_COLUMN,
                             "water: particle chunk %u names both vel[] and gpu_vel (one of them)", c);
    if (out->gpu_kernel.buffer && out->kernel)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_GPU_COLUMN,
                          "water: particle chunk %u names both kernel and gpu_kernel (one of them)", c);
    if (!out->gpu_pos.buffer && (!out->pos[0] || !out->pos[1] || !out->pos[2]))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_WATER_PARTICLE_CHUNK,
                          "water: particle chunk %u has %u particles but a NULL position column",
                          c, out->count);
    if (out->gpu_pos.buffer && (r = volfx_water_gather_check(ctx, c, "gpu_pos", &out->gpu_pos, out->count, 12)))
        return r;
    if (out->gpu_vel.buffer && !out->gpu_pos.buffer)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_GPU_COLUMN,
                             "water: particle chunk %u names gpu_vel with CPU positions (GL buffer velocities need "
                             "gpu_pos)", c);
    if (out->gpu_vel.buffer && (r = volfx_water_gather_check(ctx, c, "gpu_vel", &out->gpu_vel, out->count, 12)))
        return r;
    if (out->gpu_kernel.buffer && !out->gpu_pos.buffer)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_GPU_COLUMN,
                          "water: particle chunk %u names gpu_kernel with CPU positions (GL buffer kernels need "
                          "gpu_pos)", c);
    if (out->gpu_kernel.buffer
        && (r = volfx_water_gather_check(ctx, c, "gpu_kernel", &out->gpu_kernel, out->count, 24)))
        return r;
    return VFX_OK;
}

/* This update's parameters, resolved and checked, into *res (and the state's kernel, preset and
 * diffuse parameters). */
static vfx_result read_params(vfx_context *ctx, water_state *s, volfx_water_resolved *res)
{
    vfx_water_params wp;
    memset(&wp, 0, sizeof wp);
    wp.type = VFX_TYPE_WATER_PARAMS;
    if (ctx->host.water_params) {
        vfx_result r = ctx->host.water_params(ctx->host.user, &wp);
        if (r != VFX_OK && r != VFX_ERR_NOT_FOUND)
            return volfx_fail(ctx, r, VFX_LOG_ID_HOST_CALLBACK,
                              "water: host water_params failed (%d)", (int)r);
        if (r == VFX_ERR_NOT_FOUND) {
            memset(&wp, 0, sizeof wp);
            wp.type = VFX_TYPE_WATER_PARAMS;
        }
        if ((r = volfx_check_type(ctx, &wp, VFX_TYPE_WATER_PARAMS, "water: host water_params (vfx_water_params)")))
            return r;
    }
    vfx_result kr = volfx_water_params_resolve(ctx, &wp, res);
    if (!kr)
        kr = volfx_water_diffuse_params_check(ctx, &wp, &s->dp);
    if (!kr)
        kr = volfx_water_foam_params_resolve(ctx, &wp, (res->look & WATER_LOOK_FOAM_LAYER) != 0, &s->fp);
    if (kr)
        return kr;
    s->kp = res->kp;
    s->preset = res->preset;
    s->look = res->look;
    return VFX_OK;
}

/* What the upload measures of the positions: the finite particles' box, the non-finite count and
 * every stride-th finite particle for the spacing (cxyz NULL: none). */
typedef struct water_scan {
    float lo[3], hi[3];
    bool seen;
    uint32_t nan_count;
    float *cxyz;
    uint32_t cand, stride;
} water_scan;

/* Scans particles [off, off + n) of the concatenation, columns x, y, z. */
static void scan_positions(water_scan *a, const float *const pos[3], uint32_t n, uint32_t off)
{
    /* NaN/Inf positions are uploaded as they are and skipped by the shaders (a NaN distance fails
     * every `<` test); counted here so the host can see them. */
    for (uint32_t i = 0; i < n; ++i) {
        float q[3] = {pos[0][i], pos[1][i], pos[2][i]};
        if (!isfinite(q[0]) || !isfinite(q[1]) || !isfinite(q[2])) {
            ++a->nan_count;
            continue;
        }
        for (int k = 0; k < 3; ++k) {
            if (!a->seen || q[k] < a->lo[k]) a->lo[k] = q[k];
            if (!a->seen || q[k] > a->hi[k]) a->hi[k] = q[k];
        }
        a->seen = true;
        if (a->cxyz && (off + i) % a->stride == 0) {
            memcpy(a->cxyz + 3 * (size_t)a->cand, q, sizeof q);
            ++a->cand;
        }
    }
}

/* The box the passes use for the GPU chunks when nothing is read back now: the newest box read
 * back, its faces moved outwards by twice the distance they moved per upload between the two
 * newest readbacks times the uploads it lags (a still scene: exactly the box). */
static void late_box(water_state *s, water_scan *box)
{
    volfx_water_gather_box nw, bf;
    uint64_t uploads;
    if (!volfx_water_gather_late(s->gather, &nw, &bf, &uploads))
        return;
    uint64_t lag = uploads + 1u - nw.upload, span = nw.upload > bf.upload ? nw.upload - bf.upload : 0;
    for (int k = 0; k < 3; ++k) {
        float dl = span && bf.lo[k] > nw.lo[k] ? (bf.lo[k] - nw.lo[k]) / (float)span : 0.0f;
        float dh = span && nw.hi[k] > bf.hi[k] ? (nw.hi[k] - bf.hi[k]) / (float)span : 0.0f;
        box->lo[k] = nw.lo[k] - 2.0f * (float)lag * dl;
        box->hi[k] = nw.hi[k] + 2.0f * (float)lag * dh;
    }
    box->seen = true;
    box->nan_count = nw.bad;
    s->gpu_late = (uint32_t)lag;
    s->gpu_outside = nw.outside;
}

/* Positions (and velocities) of a GL-buffer chunk at particle `off`: gathered into the position
 * groups (a chunk may straddle them) and the diffuse velocities; with `a` (the blocking path) the
 * gathered positions are read back and scanned as the CPU path scans its arrays. */
static vfx_result upload_gpu_chunk(vfx_context *ctx, water_state *s, const water_chunk *v, uint32_t off, water_scan *a)
{
    vfx_result r;
    for (uint32_t done = 0; done < v->count;) {
        uint32_t at = off + done, g = at / s->buffer_cap, within = at - s->groups[g].first;
        uint32_t n = s->groups[g].count - within;
        if (n > v->count - done)
            n = v->count - done;
        volfx_gpu_column piece = v->gpu_pos;
        piece.offset += (uint64_t)done * piece.stride;
        if ((r = volfx_water_gather_positions(ctx, s->gather, &piece, n, s->groups[g].cols, within)))
            return r;
        if (a) {
            float *xyz = volfx_alloc(ctx, (size_t)n * 3 * sizeof(float));
            if (!xyz)
                return VFX_ERR_OUT_OF_MEMORY;
            for (int k = 0; k < 3; ++k)
                glGetNamedBufferSubData(s->groups[g].cols[k], (GLintptr)within * 4, (GLsizeiptr)n * 4, xyz + (size_t)k * n);
            const float *cols[3] = {xyz, xyz + n, xyz + 2 * (size_t)n};
            scan_positions(a, cols, n, at);
            volfx_free(ctx, xyz);
        }
        done += n;
    }
    if (!v->gpu_vel.buffer) {
        volfx_water_diffuse_no_velocities(s->diffuse);
        return VFX_OK;
    }
    GLuint vel = volfx_water_diffuse_velocity_target(ctx, s->diffuse, off, v->count);
    return vel ? volfx_water_gather_velocities(ctx, s->gather, &v->gpu_vel, v->count, vel, off) : VFX_ERR_INVALID_ARGUMENT;
}

/* Positions of a CPU chunk at particle `off` into the position groups, scanned into `a`. */
static void upload_cpu_chunk(water_state *s, const water_chunk *v, uint32_t off, water_scan *a)
{
    /* a chunk may straddle buffers: it goes in pieces, each inside one group */
    for (uint32_t done = 0; done < v->count;) {
        uint32_t at = off + done, g = at / s->buffer_cap, within = at - s->groups[g].first;
        uint32_t n = s->groups[g].count - within;
        if (n > v->count - done)
            n = v->count - done;
        for (int k = 0; k < 3; ++k)
            glNamedBufferSubData(s->groups[g].cols[k], (GLintptr)within * 4, (GLsizeiptr)n * 4, v->pos[k] + done);
        done += n;
    }
    scan_positions(a, v->pos, v->count, off);
}

/* Every chunk into the position groups, the kernel columns and the diffuse velocities; the box,
 * the non-finite count and the spacing's candidates into *a (GPU chunks: measured now when
 * `blocking`, else the late box merged in). */
static vfx_result upload_chunks(vfx_context *ctx, water_state *s, uint32_t chunks, uint64_t total, bool any_gpu,
                                bool blocking, water_scan *a)
{
    water_scan gpu_box = {.seen = false};
    vfx_result r;
    if (any_gpu) {
        if (!s->gather && !(s->gather = volfx_water_gather_create(ctx)))
            return VFX_ERR_OUT_OF_MEMORY;
        if (!blocking)
            late_box(s, &gpu_box);
        else
            s->gpu_late = 0, s->gpu_outside = 0;
        float lo[3] = {0, 0, 0}, hi[3] = {-1, -1, -1}; /* blocking: nothing is counted outside */
        if ((r = volfx_water_gather_begin(ctx, s->gather, gpu_box.seen ? gpu_box.lo : lo, gpu_box.seen ? gpu_box.hi : hi)))
            return r;
    }
    uint32_t off = 0, gpu_count = 0;
    for (uint32_t c = 0; c < chunks; ++c) {
        water_chunk v;
        r = query_chunk(ctx, c, &v);
        if (r || off + (uint64_t)v.count > total)
            return r ? r : volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_WATER_PARTICLE_CHUNK,
                                      "water: particle chunk %u changed between the count and the upload", c);
        if (v.gpu_pos.buffer) {
            /* the blocking path scans in the same order as the CPU path (the same candidates) */
            water_scan *sc = blocking ? a : NULL;
            if ((r = upload_gpu_chunk(ctx, s, &v, off, sc)))
                return r;
            gpu_count += v.count;
        } else {
            upload_cpu_chunk(s, &v, off, a);
            if ((r = volfx_water_diffuse_chunk(ctx, s->diffuse, off, v.count, v.vel)))
                return r;
        }
        if (s->aniso && v.gpu_kernel.buffer)
            r = volfx_water_aniso_columns_gpu_chunk(ctx, s->aniso, s->gather, c, off, v.count, v.radius, &v.gpu_kernel);
        else if (s->aniso)
            r = volfx_water_aniso_columns_chunk(ctx, s->aniso, c, off, v.count, v.radius, v.kernel);
        if (r)
            return r;
        off += v.count;
        s->chunk_rev[c] = v.revision;
    }
    if (any_gpu) {
        volfx_water_gather_end(s->gather);
        if (blocking && a->seen)
            volfx_water_gather_set_exact(s->gather, a->lo, a->hi, a->nan_count);
        if (!blocking && gpu_box.seen) {
            for (int k = 0; k < 3; ++k) {
                a->lo[k] = a->seen && a->lo[k] < gpu_box.lo[k] ? a->lo[k] : gpu_box.lo[k];
                a->hi[k] = a->seen && a->hi[k] > gpu_box.hi[k] ? a->hi[k] : gpu_box.hi[k];
            }
            a->seen = true;
            a->nan_count += gpu_box.nan_count;
        }
    }
    s->gpu_count = gpu_count;
    return VFX_OK;
}

/* What the host's particle chunks hold this update: their count and total, whether every
 * chunk has the nonzero revision of the last upload (0: the host tracks none), and whether any
 * gives a radius, a kernel or GL buffers. */
typedef struct water_survey {
    uint32_t chunks;
    uint64_t total;
    int revs_same;
    bool any_radius, any_kernel, any_gpu;
} water_survey;

static vfx_result survey_chunks(vfx_context *ctx, const water_state *s, water_survey *out)
{
    uint32_t chunks = ctx->host.particle_chunk_count(ctx->host.user);
    water_survey sv = {.chunks = chunks, .revs_same = s->chunk_rev != NULL && s->chunk_rev_count == chunks};
    for (uint32_t c = 0; c < chunks; ++c) {
        water_chunk v;
        vfx_result r = query_chunk(ctx, c, &v);
        if (r)
            return r;
        sv.any_radius = sv.any_radius || (v.count && v.radius);
        sv.any_kernel = sv.any_kernel || (v.count && (v.kernel || v.gpu_kernel.buffer));
        sv.any_gpu = sv.any_gpu || (v.count && v.gpu_pos.buffer);
        sv.total += v.count;
        sv.revs_same = sv.revs_same && v.revision != 0 && v.revision == s->chunk_rev[c];
    }
    if (sv.total > WATER_MAX_PARTICLES)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_WATER_PARTICLE_COUNT,
                        "water: %u particle chunks hold %llu particles, more than the limit of %u (2^30)",
                        chunks, (unsigned long long)sv.total, WATER_MAX_PARTICLES);
    *out = sv;
    return VFX_OK;
}

/* h from the particles' spacing (the scan's sample of `total`, freed here): the seed's ratio,
 * refused below the range of vfx_water_params.h; kept with the count it was measured at. */
static vfx_result measure_h(vfx_context *ctx, water_state *s, water_scan *scan, uint32_t total)
{
    double d = volfx_water_spacing(ctx, scan->cxyz, scan->cand, scan->stride);
    volfx_free(ctx, scan->cxyz);
    scan->cxyz = NULL;
    if (d < 0)
        return VFX_ERR_OUT_OF_MEMORY;
    /* the seed's ratio h = 2 x spacing (0.61 at its 0.3); no spacing (one particle, all on
     * one point): the seed's 0.61 */
    double h = d > 0 && isfinite(d) ? 2.0 * d : 0.61;
    /* particles spaced 1e-40 apart gave h = 2e-40 and drew nothing: below the row's end h^3
     * is no normal float32 (the kernels underflow); refused, naming what was measured */
    const volfx_range *hr = volfx_range_row(VFX_RANGE_WATER_H);
    if (h < hr->lo)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_PARAM_RANGE,
                             "water: the particles' spacing %g (the median nearest-neighbour distance of %u "
                             "particles) gives h %g, below vfx_water_params.h's %g: give h, or particles "
                             "spaced at least %g apart", d, scan->cand, h, hr->lo, hr->lo / 2);
    s->auto_h = (float)h;
    s->auto_h_count = total;
    return VFX_OK;
}

static vfx_result water_update(vfx_context *ctx, void *state, double time, float dt)
{
    (void)time;
    water_state *s = state;
    /* a hitch or a bad clock must not throw the diffuse particles across the scene */
    s->dt = isfinite(dt) && dt > 0 ? (dt < 0.1f ? dt : 0.1f) : 0.0f;
    s->diffuse_due = true; /* stepped once, by the first view drawn after this update */
    volfx_water_resolved res;
    vfx_result kr = read_params(ctx, s, &res);
    if (kr)
        return kr;
    water_survey sv = {0};
    if ((kr = survey_chunks(ctx, s, &sv)))
        return kr;
    const uint32_t chunks = sv.chunks;
    const uint64_t total = sv.total;
    const bool any_radius = sv.any_radius, any_kernel = sv.any_kernel, any_gpu = sv.any_gpu;
    const int revs_same = sv.revs_same;
    GLuint before = s->groups ? s->groups[0].cols[0] : 0;
    uint32_t before_groups = s->group_count;
    vfx_result gr = ensure_groups(ctx, s, (uint32_t)total);
    if (gr)
        return gr;
    /* The same revisions, the same total and the same buffers: the columns already hold these
     * positions (the box and the NaN count are still right), so nothing is read or uploaded. */
    int same = revs_same && total == s->count && s->groups[0].cols[0] == before &&
               s->group_count == before_groups;
    /* h from the spacing: measured on the first upload, and again when the count has changed by
     * more than 2x since (an h that moves every frame would make the surface breathe and drop
     * the temporal history each frame) */
    bool spacing = res.p.h == 0 && (!(s->auto_h > 0) || total > 2ull * s->auto_h_count ||
                                    2ull * total < s->auto_h_count);
    same = same && !spacing;
    s->upload_skipped = same;
    if (same)
        return water_set_params(ctx, s, &res);
    /* GL-buffer chunks are read back (blocking) only when the spacing is measured or no box of
     * theirs has been read back yet; otherwise their box comes from a readback a few uploads old */
    volfx_water_gather_box nb, bb;
    uint64_t ups;
    bool blocking = any_gpu && (spacing || !s->gather || !volfx_water_gather_late(s->gather, &nb, &bb, &ups));
    /* every stride-th finite particle, at most 2^20, for the spacing */
    water_scan scan = {.stride = (uint32_t)(total >> 20) + 1u};
    scan.cxyz = spacing ? volfx_alloc(ctx, (((size_t)total + scan.stride - 1) / scan.stride + 1) * 3 * sizeof(float)) : NULL;
    if (spacing && !scan.cxyz)
        return VFX_ERR_OUT_OF_MEMORY;
    if (chunks != s->chunk_rev_count) {
        volfx_free(ctx, s->chunk_rev);
        s->chunk_rev_count = 0;
        s->chunk_rev = chunks ? volfx_alloc(ctx, chunks * sizeof *s->chunk_rev) : NULL;
        if (chunks && !s->chunk_rev) {
            volfx_free(ctx, scan.cxyz);
            return VFX_ERR_OUT_OF_MEMORY;
        }
        s->chunk_rev_count = chunks;
    }
    /* cleared first: an upload that fails half way leaves 0s, so the next frame uploads again */
    if (chunks)
        memset(s->chunk_rev, 0, chunks * sizeof *s->chunk_rev);
    ++s->data_rev;
    if ((any_radius || any_kernel) && !s->aniso && !(s->aniso = volfx_water_aniso_create(ctx)))
        gr = VFX_ERR_OUT_OF_MEMORY;
    if (!gr && s->aniso)
        gr = volfx_water_aniso_columns_begin(ctx, s->aniso, (uint32_t)total, any_radius, any_kernel);
    if (!gr && !s->diffuse && !(s->diffuse = volfx_water_diffuse_create(ctx)))
        gr = VFX_ERR_OUT_OF_MEMORY;
    if (!gr)
        gr = volfx_water_diffuse_begin(ctx, s->diffuse, (uint32_t)total);
    if (!gr)
        gr = upload_chunks(ctx, s, chunks, total, any_gpu, blocking, &scan);
    if (gr) {
        volfx_free(ctx, scan.cxyz);
        return gr;
    }
    s->count = (uint32_t)total;
    s->nan_count = scan.nan_count;
    if (scan.seen)
        for (int k = 0; k < 3; ++k)
            s->lo[k] = scan.lo[k], s->hi[k] = scan.hi[k];
    if (spacing && (kr = measure_h(ctx, s, &scan, (uint32_t)total)))
        return kr;
    if ((kr = water_set_params(ctx, s, &res)))
        return kr;
    const char *e = volfx_gpu_error_string();
    if (e)
        return volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR,
                          "water upload of %u particles: %s", s->count, e);
    return VFX_OK;
}


static void publish_counters(vfx_context *ctx, water_state *s)
{
    const uint32_t *c = s->last;
    const int paper = s->last_method == VFX_WATER_METHOD_PAPER;
    if (paper) {
        volfx_stat_set(ctx, "water.fragments_culled", c[0]);
        volfx_stat_set(ctx, "water.potential_fragments", c[1]);
        volfx_stat_set(ctx, "water.samples", c[2]);
        volfx_stat_set(ctx, "water.pixels_found", c[3]);
        volfx_stat_set(ctx, "water.pixels_sample_cap", c[4]);
        volfx_stat_set(ctx, "water.pixels_left", c[5]);
    }
    const int tile = s->last_method == VFX_WATER_METHOD_TILE;
    if (tile) {
        volfx_stat_set(ctx, "water.samples", c[2]);
        volfx_stat_set(ctx, "water.pixels_found", c[3]);
        volfx_stat_set(ctx, "water.pixels_left", c[5]);
        volfx_stat_set(ctx, "water.pixels_undecided", c[12]);
        volfx_stat_set(ctx, "water.tile_dense_pixels", c[13]);
        volfx_stat_set(ctx, "water.tile_subdivision_samples", c[15]);
        volfx_stat_set(ctx, "water.tile_temporal_reused", c[18]);
        volfx_stat_set(ctx, "water.tile_temporal_fallback", c[19]);
        volfx_stat_set(ctx, "water.tile_temporal_steps_skipped", c[20]);
        volfx_stat_set(ctx, "water.tile_temporal_proof_samples", c[21]);
        volfx_stat_set(ctx, "water.tile_temporal_samples_saved", (double)c[20] - c[21]);
        volfx_stat_set(ctx, "water.tile_half_upsampled", c[22]);
        volfx_stat_set(ctx, "water.tile_half_remarched", c[23]);
        if (c[12] && !s->undecided_warned) {
            /* not drawn: said once, never a silent miss (issue 28) */
            s->undecided_warned = 1;
            volfx_log(ctx, VFX_LOG_WARN, VFX_LOG_ID_WATER_UNDECIDED_PIXELS,
                      "water: %u pixels undecided (not drawn) in frame %llu: the march ran past "
                      "MAX_STEPS or the driver ended its loops (llvmpipe: 65,535 loop iterations a shader invocation; "
                      "%u tile entries this frame); a higher resolution or a larger h draws them",
                      c[12], (unsigned long long)s->last_frame, c[10]);
        }
    }
    volfx_stat_set(ctx, "water.ssr_hits", c[26]);
    volfx_stat_set(ctx, "water.diffuse_spray", c[27]);
    volfx_stat_set(ctx, "water.diffuse_foam", c[28]);
    volfx_stat_set(ctx, "water.diffuse_bubbles", c[29]);
    volfx_stat_set(ctx, "water.diffuse_generated", c[30]);
    volfx_stat_set(ctx, "water.diffuse_steam", c[31]);
    if (paper) {
        /* the cap pixels the finishing pass took (0 with VFX_WATER_NO_FINISH), and what is left
         * undecided: cap pixels not finished plus those the finishing march could not decide */
        volfx_stat_set(ctx, "water.pixels_finished", c[11]);
        volfx_stat_set(ctx, "water.pixels_undecided", (double)c[4] - c[11] + c[12]);
    }
    if (tile || (paper && c[11])) {
        volfx_stat_set(ctx, "water.tile_entries", c[10]);
        volfx_stat_set(ctx, "water.tile_sphere_tests", c[14]);
        volfx_stat_set(ctx, "water.tile_global_particles", c[16]);
        volfx_stat_set(ctx, "water.tile_overflow_pixels", c[17]);
    }
    if (tile && c[24] + c[25] > 0) {
        volfx_stat_set(ctx, "water.aniso_stretched", c[24]);
        volfx_stat_set(ctx, "water.aniso_isotropic", c[25]);
    }
    if (!paper && !tile && ctx->lab) /* a lab method's (GRID's) counters are the lab's */
        ctx->lab->water_counters(ctx, s->last_method, c);
    volfx_stat_set(ctx, "water.normal_fragments_culled", c[6]);
    volfx_stat_set(ctx, "water.normal_fragments", c[7]);
    volfx_stat_set(ctx, "water.counters_age", (double)(s->frame_no - 1 - s->last_frame));
}

/* Counters without a stall: this frame's are copied into a ring slot and fenced; every slot
 * whose fence has signalled is read (the copy is done, so the read does not wait) and the
 * newest is reported, `water.counters_age` frames old. A slot still in flight when its turn
 * comes again (the GPU 3 frames behind) is waited for. debug.sync_counters waits for this
 * frame's at once (tests, benchmarks). */
static void counters_frame_end(vfx_context *ctx, water_state *s, uint32_t method)
{
    const GLuint64 forever = 60ull * 1000000000ull;
    uint32_t slot = (uint32_t)(s->frame_no % WATER_COUNTER_RING);
    if (s->fence[slot])
        glClientWaitSync(s->fence[slot], GL_SYNC_FLUSH_COMMANDS_BIT, forever);
    for (int pass = 0; pass < 2; ++pass) {
        for (uint32_t k = 0; k < WATER_COUNTER_RING; ++k) {
            if (!s->fence[k])
                continue;
            GLenum st = glClientWaitSync(s->fence[k], 0, 0);
            if (st != GL_ALREADY_SIGNALED && st != GL_CONDITION_SATISFIED)
                continue;
            if (!s->have_last || s->ring_frame[k] > s->last_frame) {
                glGetNamedBufferSubData(s->ring[k], 0, sizeof s->last, s->last);
                s->last_frame = s->ring_frame[k];
                s->last_method = s->ring_method[k];
                s->have_last = 1;
            }
            glDeleteSync(s->fence[k]);
            s->fence[k] = 0;
        }
        if (pass == 1)
            break;
        /* this frame's copy after the older slots are read, so the poll sees them first */
        glCopyNamedBufferSubData(s->counters, s->ring[slot], 0, 0, sizeof s->last);
        s->fence[slot] = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
        s->ring_frame[slot] = s->frame_no;
        s->ring_method[slot] = method;
        /* the first frame's are waited for too (one stall, once): a warning about them (pixels
         * undecided) then comes with frame 1, not frame 2, and a one-frame run says it */
        if (ctx->debug.sync_counters || !s->have_last)
            glClientWaitSync(s->fence[slot], GL_SYNC_FLUSH_COMMANDS_BIT, forever);
        else
            break;
    }
    ++s->frame_no;
    if (s->have_last)
        publish_counters(ctx, s);
}

/* BRUTE and GRID, the lab's baselines (lab_hooks.h): a method only a vfx_lab_water asks for,
 * which a context without the lab refuses (water_params.c). */
static vfx_result lab_march(vfx_context *ctx, water_state *s, const volfx_frame_targets *targets)
{
    if (!ctx->lab)
        return volfx_fail(ctx, VFX_ERR_UNSUPPORTED, VFX_LOG_ID_WATER_METHOD,
                          "water: method %u is a lab method; this plugin has no lab attached", s->params.method);
    volfx_lab_water_input in = {s->cols, s->count, s->count - s->nan_count, s->lo, s->hi, &s->params,
                                s->width, s->height, ctx->water_dist_tex, s->counters, s->data_rev};
    return ctx->lab->water_march(ctx, &s->lab_state, s->params.method, &in, targets);
}

static vfx_result tile_lists(vfx_context *ctx, water_state *s, volfx_water_tile_input *in,
                             const volfx_frame_targets *targets)
{
    if (!s->tile && !(s->tile = volfx_water_tile_create(ctx)))
        return VFX_ERR_OUT_OF_MEMORY;
    *in = (volfx_water_tile_input){s->cols, s->count, &s->params, s->width, s->height, ctx->water_dist_tex,
                                   s->counters, s->have_last ? s->last[10] : 0, s->view_proj, s->lo, s->hi,
                                   targets->eye, fabsf(targets->proj[5]) * 0.5f * (float)s->height, volfx_water_view_frames(s), 0, 0.0f,
                                   targets->inv_view_proj, targets->host_depth != 0};
    /* per-particle kernels: the anisotropic ones, or the host's radius / kernel columns */
    if (s->params.method == VFX_WATER_METHOD_TILE &&
        (s->kp.kernel == VFX_WATER_KERNEL_ANISOTROPIC || volfx_water_aniso_has_columns(s->aniso))) {
        if (!s->aniso && !(s->aniso = volfx_water_aniso_create(ctx)))
            return VFX_ERR_OUT_OF_MEMORY;
        volfx_water_aniso_input ai = {s->cols, s->count, s->lo, s->hi, s->params.h, &s->kp, s->counters, s->data_rev,
                                      /* a running simulation only: a paused frame (dt 0) or a host
                                       * that steps without time keeps every shape exact */
                                      (s->look & WATER_LOOK_ANISO_HALF_RATE) != 0 && s->dt > 0};
        vfx_result r = volfx_water_aniso_compute(ctx, s->aniso, &ai);
        if (r)
            return r;
        in->kernels = volfx_water_aniso_kernels(s->aniso);
        in->rbound = s->params.h * volfx_water_aniso_sigma_bound(s->aniso);
    }
    return volfx_water_tile_bin(ctx, s->tile, in);
}

static vfx_result tile_march(vfx_context *ctx, water_state *s, const volfx_frame_targets *targets)
{
    volfx_water_tile_input in;
    vfx_result r = tile_lists(ctx, s, &in, targets);
    return r ? r : volfx_water_tile_march(ctx, s->tile, &in, targets, s->grad, s->back);
}

/* The paper method's sample-cap pixels, finished by TILE's march from where they stopped. */
static vfx_result paper_finish(vfx_context *ctx, water_state *s, const volfx_frame_targets *targets)
{
    volfx_water_tile_input in;
    vfx_result r = tile_lists(ctx, s, &in, targets);
    return r ? r : volfx_water_tile_finish(ctx, s->tile, &in, targets, s->st, s->cur);
}

/* Whether this frame has diffuse particles: the host's velocities, not switched off, one
 * position buffer (the grid reads one) and the shading on. */
static bool diffuse_on(const water_state *s)
{
    return !(s->params.disable & (VFX_WATER_NO_SPRAY | VFX_WATER_NO_SHADING)) && s->group_count == 1 &&
           volfx_water_diffuse_ready(s->diffuse);
}

/* the froth's cellular noise repeats every this many of its large cells (shade.frag) */
#define WATER_FOAM_NOISE_PERIOD 4096.0

/* Where beams strike the water this frame (the newest read-back), for the spray thrown there:
 * point and normal each, at most VOLFX_WATER_DIFFUSE_IMPACTS; none without beams or with
 * vfx_water_foam.impacts off. */
static uint32_t water_impacts(vfx_context *ctx, const water_state *s, float (*out)[6])
{
    uint32_t n = 0;
#if VFX_WITH_BEAMS
    volfx_beams_impact *im = s->fp.impacts ? volfx_beams_impact_of(ctx) : NULL;
    volfx_impact_event ev[VOLFX_WATER_DIFFUSE_IMPACTS];
    n = im ? volfx_beams_impact_water_events(im, ev, VOLFX_WATER_DIFFUSE_IMPACTS) : 0;
    n = n > VOLFX_WATER_DIFFUSE_IMPACTS ? VOLFX_WATER_DIFFUSE_IMPACTS : n;
    for (uint32_t e = 0; e < n; ++e) {
        memcpy(out[e], ev[e].position, 3 * sizeof(float));
        memcpy(out[e] + 3, ev[e].normal, 3 * sizeof(float));
    }
#else
    (void)ctx, (void)s, (void)out;
#endif
    return n;
}

/* The foam layer's update after the diffuse step (its foam particles deposit into it); with the
 * layer off, it is forgotten. */
static vfx_result foam_update(vfx_context *ctx, water_state *s, const volfx_frame_targets *targets)
{
    if (!s->fp.layer) {
        volfx_water_foam_clear(s->foam);
        return VFX_OK;
    }
    if (!s->foam && !(s->foam = volfx_water_foam_create(ctx)))
        return VFX_ERR_OUT_OF_MEMORY;
    const float *g = s->dp.gravity;
    float gl = sqrtf(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    volfx_water_foam_input in = {.cols = s->cols, .count = s->count, .lo = s->lo, .hi = s->hi, .h = s->params.h,
                                 .dt = s->dt, .vref = sqrtf((gl > 0 ? gl : 9.81f) * s->params.h), .fp = &s->fp,
                                 /* slot 28: the foam particles of the newest counters read back */
                                 .foam_seen = s->have_last && s->last[28] > 0,
                                 .origin = {targets->origin[0], targets->origin[2]}};
    volfx_water_diffuse_buffers(s->diffuse, &in.vel, &in.pool, &in.header);
    return volfx_water_foam_step(ctx, s->foam, &in);
}

/* The diffuse particles' step over this update's fluid (once per update: the first view drawn
 * steps them, the others draw the same pool), the foam layer's update, and their foam and bubble
 * layer in this view (*layer, 0: none). */
static vfx_result diffuse_frame(vfx_context *ctx, water_state *s, const volfx_frame_targets *targets, GLuint *layer)
{
    *layer = 0;
    if (!diffuse_on(s)) {
        if (s->diffuse)
            volfx_water_diffuse_clear(s->diffuse);
        volfx_water_foam_clear(s->foam);
        return VFX_OK;
    }
    vfx_result r;
    if (s->diffuse_due) {
        if (!s->aniso && !(s->aniso = volfx_water_aniso_create(ctx)))
            return VFX_ERR_OUT_OF_MEMORY;
        volfx_water_aniso_input ai = {s->cols, s->count, s->lo, s->hi, s->params.h, &s->kp, s->counters, s->data_rev, false};
        volfx_water_aniso_grid grid;
        if ((r = volfx_water_aniso_grid_build(ctx, s->aniso, &ai, &grid)))
            return r;
        float imp[VOLFX_WATER_DIFFUSE_IMPACTS][6];
        volfx_water_diffuse_input in = {s->cols, s->count, s->lo, s->hi, s->params.h, s->dt, &s->dp, &grid,
                                        s->counters, s->frame_no, imp, water_impacts(ctx, s, imp),
                                        s->fp.impact_rate, s->fp.impact_speed,
                                        (s->look & WATER_LOOK_STEAM) != 0};
        if ((r = volfx_water_diffuse_step(ctx, s->diffuse, &in)))
            return r;
        if ((r = foam_update(ctx, s, targets)))
            return r;
        s->diffuse_due = false;
    }
    volfx_water_diffuse_draw dd = {s->params.h, s->params.absorption, ctx->water_dist_tex, s->vao, WATER_SHUTTER_S, false};
    return volfx_water_diffuse_splat(ctx, s->diffuse, &dd, targets, layer);
}

/* The frame's set-up before any pass: one position buffer unless the method draws several, the
 * view-projection kept for the next frame's reprojection, the frame block, the cleared counters
 * and the frame's stats. */
static vfx_result view_setup(vfx_context *ctx, water_state *s, volfx_frame_targets *targets)
{
    const volfx_water_core *p = &s->params;
    targets->water_dist = ctx->water_dist_tex;
    volfx_stat_set(ctx, "water.position_buffers", s->group_count);
    if (s->group_count > 1 && (p->method != VFX_WATER_METHOD_PAPER || (p->disable & VFX_WATER_NO_BLEND)))
        return volfx_fail(ctx, VFX_ERR_UNSUPPORTED, VFX_LOG_ID_WATER_METHOD,
                        "water: %u particles span %u position buffers of at most %u; method %u%s reads one "
                        "buffer (only the paper method's billboard passes draw several)",
                        s->count, s->group_count, s->buffer_cap, p->method,
                        (p->disable & VFX_WATER_NO_BLEND) ? " with NO_BLEND" : "");
    /* the frame gate's product (the same proj * view, made once a frame), kept for next frame's reprojection */
    memcpy(s->view_proj, targets->view_proj, sizeof s->view_proj);
    if (p->method != VFX_WATER_METHOD_TILE) /* TILE's passes set their own uniforms */
        volfx_water_frame_upload(s, targets);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, s->counters);
    glClearNamedBufferData(s->counters, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
    volfx_stat_set(ctx, "water.particles", s->count);
    volfx_stat_set(ctx, "water.h", p->h);
    volfx_stat_set(ctx, "water.preset", s->preset);
    volfx_stat_set(ctx, "water.nan_skipped", s->nan_count);
    volfx_stat_set(ctx, "water.upload_skipped", s->upload_skipped);
    volfx_stat_set(ctx, "water.gpu_particles", s->gpu_count);
    volfx_stat_set(ctx, "water.gpu_box_lag", s->gpu_late);
    volfx_stat_set(ctx, "water.gpu_box_outside", s->gpu_outside);
    s->last_method_drawn = UINT32_MAX; /* until this frame completes: nothing for debug_pixel_class */
    return VFX_OK;
}

/* The surface: the chosen method's march into the distance texture, then (all but TILE, which
 * writes them from its own lists) the gradient and back-distance passes the shading reads. */
static vfx_result march_surface(vfx_context *ctx, water_state *s, volfx_frame_targets *targets)
{
    const volfx_water_core *p = &s->params;
    vfx_result r;
    /* the seed's method and the baselines draw the isotropic kernel of radius h only */
    if (p->method != VFX_WATER_METHOD_TILE &&
        (s->kp.kernel == VFX_WATER_KERNEL_ANISOTROPIC || volfx_water_aniso_has_columns(s->aniso)))
        return volfx_fail(ctx, VFX_ERR_UNSUPPORTED, VFX_LOG_ID_WATER_METHOD,
                          "water: %s is drawn by method TILE (3) only; method %u draws the isotropic kernel of radius h "
                          "(scene key water.quality.kernel / method)",
                          s->kp.kernel == VFX_WATER_KERNEL_ANISOTROPIC ? "the anisotropic kernel (vfx_water_params.kernel)"
                                                                        : "a per-particle radius or kernel column (vfx_particle_view.radius, kernel)",
                          p->method);
    if (p->method == VFX_WATER_METHOD_PAPER) {
        r = volfx_water_paper_march(ctx, s, targets);
        /* the tile lists read one position buffer: with several, the cap pixels stay holes
         * (counted in water.pixels_undecided) */
        if (r == VFX_OK && !(p->disable & VFX_WATER_NO_FINISH) && s->group_count == 1)
            r = paper_finish(ctx, s, targets);
    } else if (p->method == VFX_WATER_METHOD_TILE)
        r = tile_march(ctx, s, targets);
    else if (p->method == VFX_WATER_METHOD_BRUTE || p->method == VFX_WATER_METHOD_GRID)
        r = lab_march(ctx, s, targets);
    else
        r = volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_WATER_METHOD,
                       "water: unknown method %u in vfx_water_params (0 paper, 1 brute, 2 grid, 3 tile)", p->method);
    if (r != VFX_OK)
        return r;
    /* TILE wrote the gradient and back distance from its own lists */
    if (!(p->disable & VFX_WATER_NO_SHADING) && p->method != VFX_WATER_METHOD_TILE &&
        (r = volfx_water_surface_passes(ctx, s, targets)) != VFX_OK)
        return r;
    return VFX_OK;
}

/* The shading pass (water.shade) over the frame gate's framebuffer: refraction, reflection, the
 * diffuse layer and foam, the beams' light split at the surface and their lights when `nlights`. */
static vfx_result shade_pass(vfx_context *ctx, water_state *s, const volfx_frame_targets *targets, GLuint layer,
                             bool beams, uint32_t nlights)
{
    const volfx_water_core *p = &s->params;
    GLuint shade = nlights ? volfx_gpu_program(ctx, "common/fullscreen.vert", "water/shade.frag",
                                               "#define WATER_BEAMS 1\n#define WATER_EFFECT_LIGHTS 1\n"
                                               "#define WATER_MAX_LIGHTS 32\n")
                   : beams ? volfx_gpu_program(ctx, "common/fullscreen.vert", "water/shade.frag", "#define WATER_BEAMS 1\n")
                           : volfx_gpu_program(ctx, "common/fullscreen.vert", "water/shade.frag", NULL);
    if (!shade)
        return VFX_ERR_GL;
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.shade", .framebuffer = targets->framebuffer,
                                             .width = targets->width, .height = targets->height});
    glUseProgram(shade);
    glBindTextureUnit(0, ctx->water_dist_tex);
    glBindTextureUnit(1, targets->scene_color);
    glBindTextureUnit(2, s->grad);
    glBindTextureUnit(3, s->back);
    glBindTextureUnit(4, targets->host_depth);
    glUniformMatrix4fv(volfx_gpu_uniform(ctx, shade, "u_inv_view_proj"), 1, GL_FALSE, targets->inv_view_proj);
    glUniformMatrix4fv(volfx_gpu_uniform(ctx, shade, "u_view_proj"), 1, GL_FALSE, targets->view_proj);
    glUniform3fv(volfx_gpu_uniform(ctx, shade, "u_eye"), 1, targets->eye);
    glUniform1f(volfx_gpu_uniform(ctx, shade, "u_h"), p->h);
    glUniform1i(volfx_gpu_uniform(ctx, shade, "u_refract_view"), (p->disable & VFX_WATER_NO_REFRACT_TRACE) != 0);
    glUniform1f(volfx_gpu_uniform(ctx, shade, "u_absorption"), p->absorption);
    glUniform1f(volfx_gpu_uniform(ctx, shade, "u_ior"), p->ior);
    glUniform3fv(volfx_gpu_uniform(ctx, shade, "u_tint"), 1, p->color);
    glUniform1i(volfx_gpu_uniform(ctx, shade, "u_flat"), (p->disable & VFX_WATER_NO_SHADING) != 0);
    glUniform1i(volfx_gpu_uniform(ctx, shade, "u_has_color"), targets->scene_color != 0);
    glUniform1i(volfx_gpu_uniform(ctx, shade, "u_has_depth"), targets->host_depth != 0);
    if (targets->environment_cubemap)
        glBindTextureUnit(5, targets->environment_cubemap);
    glUniform1i(volfx_gpu_uniform(ctx, shade, "u_has_env"), targets->environment_cubemap != 0);
    glUniform1i(volfx_gpu_uniform(ctx, shade, "u_hdr"), targets->color_hdr);
    glUniform1i(volfx_gpu_uniform(ctx, shade, "u_ssr"), !(p->disable & VFX_WATER_NO_SSR));
    glUniform1i(volfx_gpu_uniform(ctx, shade, "u_host_light"), (s->look & WATER_LOOK_HOST_LIGHT) != 0);
    glUniform1i(volfx_gpu_uniform(ctx, shade, "u_ggx"), (s->look & WATER_LOOK_GGX) != 0);
    if (layer)
        glBindTextureUnit(6, layer);
    if (beams) {
        glBindTextureUnit(7, targets->beams_light);
        glBindTextureUnit(8, targets->beams_behind);
    }
    glUniform1i(volfx_gpu_uniform(ctx, shade, "u_has_diffuse"), layer != 0);
    float fgrid[4] = {0, 0, 0, 0};
    const double at[2] = {targets->origin[0], targets->origin[2]};
    GLuint foam = layer ? volfx_water_foam_texture(s->foam, at, fgrid) : 0;
    if (foam)
        glBindTextureUnit(9, foam);
    glUniform1i(volfx_gpu_uniform(ctx, shade, "u_has_foam"), foam != 0);
    glUniform4fv(volfx_gpu_uniform(ctx, shade, "u_foam_grid"), 1, fgrid);
    glUniform1i(volfx_gpu_uniform(ctx, shade, "u_foam_layer"), s->fp.layer);
    /* the froth's noise is fixed in the world: the origin, modulo the noise's period */
    double period = WATER_FOAM_NOISE_PERIOD * 0.33 * p->h;
    glUniform2f(volfx_gpu_uniform(ctx, shade, "u_foam_offset"), period > 0 ? (float)fmod(at[0], period) : 0.0f,
                period > 0 ? (float)fmod(at[1], period) : 0.0f);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, s->counters);
    volfx_gpu_fullscreen(ctx);
    /* the SSR hits counted by the fragments reach the counter copy */
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    volfx_pass_end(ctx);
    return VFX_OK;
}

/* One view's frame: set-up, the surface, the diffuse particles, the beams' prepare step, the
 * shading, the spray and the steam over it, then the counters. */
static vfx_result render_view(vfx_context *ctx, water_state *s, volfx_frame_targets *targets)
{
    const volfx_water_core *p = &s->params;
    vfx_result r = view_setup(ctx, s, targets);
    if (r || (r = march_surface(ctx, s, targets)))
        return r;
    GLuint layer = 0;
    if ((r = diffuse_frame(ctx, s, targets, &layer)))
        return r;
    /* the beams' light split at this surface (their prepare step) before the shading reads it */
    if ((r = volfx_effects_prepare(ctx, targets)))
        return r;
    /* the beams' light and the light loop are compiled in only for a frame that has them (the
     * lights are the beams': none when the beams are not drawn) */
    bool beams = targets->beams_light && targets->beams_behind;
    uint32_t nlights = 0;
    if (beams && (s->look & WATER_LOOK_FX_LIGHTS) && !(p->disable & VFX_WATER_NO_SHADING) &&
        (r = volfx_water_lights_frame(ctx, &s->effect_lights, &nlights)))
        return r;
    if ((r = shade_pass(ctx, s, targets, layer, beams, nlights)))
        return r;
    if (layer) {
        volfx_water_diffuse_draw dd = {p->h, p->absorption, ctx->water_dist_tex, s->vao, WATER_SHUTTER_S, nlights > 0};
        if (nlights)
            glBindBufferBase(GL_UNIFORM_BUFFER, 7, s->effect_lights.buffer);
        if ((r = volfx_water_diffuse_spray(ctx, s->diffuse, &dd, targets)) ||
            (r = volfx_water_diffuse_steam(ctx, s->diffuse, &dd, targets)))
            return r;
    }
    counters_frame_end(ctx, s, p->method);
    s->last_method_drawn = p->method;
    const char *e = volfx_gpu_error_string();
    if (e)
        return volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR, "water render: %s", e);
    return VFX_OK;
}

static vfx_result water_render(vfx_context *ctx, void *state, volfx_frame_targets *targets)
{
    water_state *s = state;
    if (s->counters == 0) {
        glCreateBuffers(1, &s->counters);
        glNamedBufferStorage(s->counters, WATER_COUNTERS * sizeof(uint32_t), NULL, GL_DYNAMIC_STORAGE_BIT);
    }
    vfx_result r = volfx_water_view_begin(ctx, s, targets->view_id, targets->width, targets->height,
                                          s->params.method != VFX_WATER_METHOD_TILE);
    if (r == VFX_OK)
        r = render_view(ctx, s, targets);
    volfx_water_view_end(s, r == VFX_OK);
    return r;
}

vfx_result volfx_water_debug_gradient(vfx_context *ctx, float *out, size_t count)
{
    water_state *s = ctx->effect_state[VFX_EFFECT_WATER];
    if (!s || !s->grad)
        return volfx_fail(ctx, VFX_ERR_NOT_FOUND, VFX_LOG_ID_EFFECT_NOT_RENDERED,
                          "water debug gradient: no water effect or no render yet");
    size_t n = (size_t)s->width * s->height * 4;
    if (!out || count < n)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_READ_BUFFER_SIZE,
                          "water debug gradient: %zu floats, need %zu", count, n);
    return volfx_gpu_read_top_first(ctx, s->grad, GL_RGBA, 4, -1, s->width, s->height, out);
}

vfx_result volfx_water_debug_pixel_class(vfx_context *ctx, uint8_t *out, size_t count)
{
    water_state *s = ctx->effect_state[VFX_EFFECT_WATER];
    if (!s || !s->st || s->frame_no == 0 || s->last_method_drawn != VFX_WATER_METHOD_PAPER)
        return volfx_fail(ctx, VFX_ERR_NOT_FOUND, VFX_LOG_ID_EFFECT_NOT_RENDERED,
                          "water debug pixel class: no paper-method frame rendered yet");
    size_t n = (size_t)s->width * s->height;
    if (!out || count < n)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_READ_BUFFER_SIZE,
                          "water debug pixel class: %zu bytes, need %zu", count, n);
    float *cls = volfx_alloc(ctx, n * sizeof *cls);
    if (!cls)
        return VFX_ERR_OUT_OF_MEMORY;
    vfx_result r = volfx_gpu_read_top_first(ctx, s->st, GL_RGBA, 4, 0, s->width, s->height, cls);
    for (size_t p = 0; r == VFX_OK && p < n; ++p)
        out[p] = (uint8_t)cls[p];
    volfx_free(ctx, cls);
    return r;
}

vfx_result volfx_water_debug_kernels(vfx_context *ctx, float *out, uint32_t *nbrs, size_t particles)
{
    water_state *s = ctx->effect_state[VFX_EFFECT_WATER];
    GLuint kern = s ? volfx_water_aniso_kernels(s->aniso) : 0, nb = s ? volfx_water_aniso_neighbours(s->aniso) : 0;
    if (!kern)
        return volfx_fail(ctx, VFX_ERR_NOT_FOUND, VFX_LOG_ID_EFFECT_NOT_RENDERED,
                          "water debug kernels: no per-particle kernels computed yet");
    if (!out || particles < s->count)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_READ_BUFFER_SIZE,
                          "water debug kernels: room for %zu particles, need %u", particles, s->count);
    glGetNamedBufferSubData(kern, 0, (GLsizeiptr)s->count * VOLFX_WATER_KERNEL_STRIDE, out);
    if (nbrs && nb)
        glGetNamedBufferSubData(nb, 0, (GLsizeiptr)s->count * 4, nbrs);
    else if (nbrs)
        memset(nbrs, 0, (size_t)s->count * 4); /* no neighbour search ran */
    const char *e = volfx_gpu_error_string();
    return e ? volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR, "water debug kernels: %s", e) : VFX_OK;
}

vfx_result volfx_water_debug_diffuse(vfx_context *ctx, float *pot, size_t fluid, float *pool, size_t pool_cap,
                                     uint32_t *alive)
{
    water_state *s = ctx->effect_state[VFX_EFFECT_WATER];
    if (!s || !s->diffuse)
        return volfx_fail(ctx, VFX_ERR_NOT_FOUND, VFX_LOG_ID_EFFECT_NOT_RENDERED,
                          "water debug diffuse: no water effect or no upload yet");
    return volfx_water_diffuse_debug(ctx, s->diffuse, pot, fluid, pool, pool_cap, alive);
}

vfx_result volfx_water_debug_foam(vfx_context *ctx, volfx_water_foam_grid *g, float *out, size_t cap)
{
    water_state *s = ctx->effect_state[VFX_EFFECT_WATER];
    if (!s || !s->foam)
        return volfx_fail(ctx, VFX_ERR_NOT_FOUND, VFX_LOG_ID_EFFECT_NOT_RENDERED, "water debug foam: no foam layer yet");
    return volfx_water_foam_debug_read(ctx, s->foam, g, out, cap);
}

vfx_result volfx_water_debug_foam_write(vfx_context *ctx, const float *in, size_t n)
{
    water_state *s = ctx->effect_state[VFX_EFFECT_WATER];
    if (!s)
        return volfx_fail(ctx, VFX_ERR_NOT_FOUND, VFX_LOG_ID_EFFECT_NOT_RENDERED, "water debug foam: no water effect");
    if (!s->foam && !(s->foam = volfx_water_foam_create(ctx)))
        return VFX_ERR_OUT_OF_MEMORY;
    if (!in) {
        volfx_water_foam_debug_wake(s->foam);
        return VFX_OK;
    }
    return volfx_water_foam_debug_write(ctx, s->foam, in, n);
}

static vfx_result water_read_raw(vfx_context *ctx, void *state, float *out, size_t count)
{
    water_state *s = state;
    size_t n = (size_t)s->width * s->height;
    if (!ctx->water_dist_tex || s->last_method_drawn == UINT32_MAX || s->frame_no == 0)
        return volfx_fail(ctx, VFX_ERR_NOT_FOUND, VFX_LOG_ID_EFFECT_NOT_RENDERED,
                          "water read_raw: no water frame drawn yet");
    if (count < n)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_READ_BUFFER_SIZE,
                          "water read_raw: %zu floats, need %zu", count, n);
    return volfx_gpu_read_top_first(ctx, ctx->water_dist_tex, GL_RED, 1, -1, s->width, s->height, out);
}

const volfx_effect_ops volfx_water_ops = {
    .name = "water",
    .kind = VFX_EFFECT_WATER,
    .present = water_present,
    .create = water_create,
    .destroy = water_destroy,
    .resize = water_resize,
    .update = water_update,
    .render = water_render,
    .read_raw = water_read_raw,
};
