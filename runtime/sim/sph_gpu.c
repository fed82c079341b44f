/* sph_gpu.c — see sph_gpu.h: the host side of the GPU PBF solver (programs, buffers, the pass
 * sequence of a step, the fenced stats ring). The passes are shaders/sim/pbf_*.comp. */
#include "sim/sph_gpu.h"
#include "sim/sph_collide.h"
#include "sim/sph_internal.h"
#include "core/error.h"

#include <epoxy/gl.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "shader_text.h"

#define GPU_GROUP 128u   /* local_size_x of the particle passes (pbf_common.glsl) */
#define GPU_SLOTS 3u     /* frames of stats in flight */
#define GPU_SLOT_BYTES 256u
#define GPU_MAX_COLLIDERS 64u

enum { P_PREDICT, P_SCAN, P_SCATTER, P_LAMBDA, P_DELTA, P_FINISH, P_VISC, P_REDUCE, P_VELOCITY, P_COUNT };
static const char *const gpu_shader_path[P_COUNT] = {
    "sim/pbf_predict.comp", "sim/pbf_scan.comp",   "sim/pbf_scatter.comp", "sim/pbf_lambda.comp",
    "sim/pbf_delta.comp",   "sim/pbf_finish.comp", "sim/pbf_visc.comp",    "sim/pbf_reduce.comp",
    "sim/pbf_velocity.comp"};

/* the stats slot as the shaders write it */
typedef struct gpu_stats {
    uint32_t v2max, errmax, clamped, bad;
    float errsum, ke, pe;
} gpu_stats;

/* Params of pbf_common.glsl (std140) */
typedef struct gpu_params {
    float lo[4], hi[4], grav[4], k0[4], k1[4], k2[4], k3[4];
    int32_t grid[4];
    uint32_t counts[4];
} gpu_params;

struct rt_sph_gpu {
    rt_sph *s;
    bool sync;
    GLuint prog[P_COUNT];
    GLint u_iter, u_omega, u_scan_len, u_scan_mode, u_groups, u_vel_mode, u_vel_scale, u_vel_centre, u_vel_dir;
    uint32_t n, ncells, nblocks, groups;
    int dims[3];
    /* state: positions alternate between pos[0] and pos[1] every step (pc is current), velocities
     * stay in vel[0] (vel[1] holds the sorted predicted ones during a step), ids alternate */
    GLuint pos[2], vel[2], id[2];
    uint32_t pc;
    GLuint x0, qa, qb, key, count, start, blocks, lam, wallc, rho, partial, params, colliders;
    GLuint stats;                 /* GPU_SLOTS slots, persistently mapped */
    const volatile uint8_t *stats_map;
    GLsync fence[GPU_SLOTS];
    uint64_t slot_frame[GPU_SLOTS];
    uint64_t frame, known_frame;  /* frames stepped; the frame of the newest figures read */
    gpu_stats known;              /* the newest figures read back */
    float vmax_known;             /* the largest speed the step count assumes [m/s] */
    size_t bytes;
};

/* ---- programs and buffers --------------------------------------------------------------------- */

static GLuint gpu_compile(const char *path, char *err, size_t errlen)
{
    char e[256], raw[4096], pretty[8192];
    char *src = volfx_shader_expand(&rt_host_shaders, path, NULL, e, sizeof e);
    if (!src) {
        rt_errf(err, errlen, VFX_ERR_GL, "GPU fluid solver: %s", e);
        return 0;
    }
    GLuint sh = glCreateShader(GL_COMPUTE_SHADER);
    glShaderSource(sh, 1, (const char *const *)&src, NULL);
    glCompileShader(sh);
    free(src);
    GLint ok = 0;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        glGetShaderInfoLog(sh, sizeof raw, NULL, raw);
        volfx_shader_rewrite_log(&rt_host_shaders, raw, pretty, sizeof pretty, path);
        rt_errf(err, errlen, VFX_ERR_GL, "GPU fluid solver: %s did not compile: %s", path, pretty);
        glDeleteShader(sh);
        return 0;
    }
    GLuint p = glCreateProgram();
    glAttachShader(p, sh);
    glLinkProgram(p);
    glDeleteShader(sh);
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        glGetProgramInfoLog(p, sizeof raw, NULL, raw);
        rt_errf(err, errlen, VFX_ERR_GL, "GPU fluid solver: %s did not link: %s", path, raw);
        glDeleteProgram(p);
        return 0;
    }
    return p;
}

static GLuint gpu_buffer(rt_sph_gpu *g, size_t bytes, const void *data, GLbitfield flags)
{
    GLuint b = 0;
    glCreateBuffers(1, &b);
    glNamedBufferStorage(b, (GLsizeiptr)(bytes ? bytes : 16), data, flags | GL_DYNAMIC_STORAGE_BIT);
    g->bytes += bytes ? bytes : 16;
    return b;
}

static vfx_result gpu_programs(rt_sph_gpu *g, char *err, size_t errlen)
{
    for (int k = 0; k < P_COUNT; ++k)
        if (!(g->prog[k] = gpu_compile(gpu_shader_path[k], err, errlen)))
            return VFX_ERR_GL;
    g->u_iter = glGetUniformLocation(g->prog[P_LAMBDA], "u_iter");
    g->u_omega = glGetUniformLocation(g->prog[P_DELTA], "u_omega");
    g->u_scan_len = glGetUniformLocation(g->prog[P_SCAN], "u_len");
    g->u_scan_mode = glGetUniformLocation(g->prog[P_SCAN], "u_mode");
    g->u_groups = glGetUniformLocation(g->prog[P_REDUCE], "u_groups");
    g->u_vel_mode = glGetUniformLocation(g->prog[P_VELOCITY], "u_mode");
    g->u_vel_scale = glGetUniformLocation(g->prog[P_VELOCITY], "u_scale");
    g->u_vel_centre = glGetUniformLocation(g->prog[P_VELOCITY], "u_centre");
    g->u_vel_dir = glGetUniformLocation(g->prog[P_VELOCITY], "u_dir");
    return VFX_OK;
}

/* The particles of the CPU solver, interleaved into the state buffers. */
static vfx_result gpu_upload(rt_sph_gpu *g, char *err, size_t errlen)
{
    rt_sph_columns c = rt_sph_get_columns(g->s);
    size_t n = c.count ? c.count : 1;
    float *p = calloc(n * 4, sizeof *p), *v = calloc(n * 4, sizeof *v);
    uint32_t *id = calloc(n, sizeof *id);
    if (!p || !v || !id) {
        free(p), free(v), free(id);
        return rt_errf(err, errlen, VFX_ERR_OUT_OF_MEMORY, "GPU fluid solver: out of memory for the upload of %u "
                       "particles", c.count);
    }
    for (uint32_t i = 0; i < c.count; ++i) {
        p[4 * i] = c.x[i], p[4 * i + 1] = c.y[i], p[4 * i + 2] = c.z[i], p[4 * i + 3] = 1.f;
        v[4 * i] = c.vx[i], v[4 * i + 1] = c.vy[i], v[4 * i + 2] = c.vz[i];
        id[i] = c.id ? c.id[i] : i;
    }
    const size_t v4 = n * 16;
    g->pos[0] = gpu_buffer(g, v4, p, 0);
    g->pos[1] = gpu_buffer(g, v4, NULL, 0);
    g->vel[0] = gpu_buffer(g, v4, v, 0);
    g->vel[1] = gpu_buffer(g, v4, NULL, 0);
    g->id[0] = gpu_buffer(g, n * 4, id, 0);
    g->id[1] = gpu_buffer(g, n * 4, NULL, 0);
    free(p), free(v), free(id);
    g->x0 = gpu_buffer(g, v4, NULL, 0);
    g->qa = gpu_buffer(g, v4, NULL, 0);
    g->qb = gpu_buffer(g, v4, NULL, 0);
    g->wallc = gpu_buffer(g, v4, NULL, 0);
    g->key = gpu_buffer(g, n * 8, NULL, 0);
    g->lam = gpu_buffer(g, n * 4, NULL, 0);
    g->rho = gpu_buffer(g, n * 4, NULL, 0);
    g->partial = gpu_buffer(g, (size_t)g->groups * 16, NULL, 0);
    g->count = gpu_buffer(g, ((size_t)g->ncells + 1) * 4, NULL, 0);
    g->start = gpu_buffer(g, ((size_t)g->ncells + 1) * 4, NULL, 0);
    g->blocks = gpu_buffer(g, (size_t)g->nblocks * 4, NULL, 0);
    g->params = gpu_buffer(g, sizeof(gpu_params), NULL, 0);
    g->colliders = gpu_buffer(g, GPU_MAX_COLLIDERS * 64, NULL, 0);
    const GLbitfield map = GL_MAP_READ_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
    g->stats = gpu_buffer(g, GPU_SLOTS * GPU_SLOT_BYTES, NULL, map);
    g->stats_map = glMapNamedBufferRange(g->stats, 0, GPU_SLOTS * GPU_SLOT_BYTES, map);
    if (glGetError() != GL_NO_ERROR || !g->stats_map)
        return rt_errf(err, errlen, VFX_ERR_GL, "GPU fluid solver: GL buffers for %u particles and %u cells could "
                       "not be made (%zu bytes)", c.count, g->ncells, g->bytes);
    return VFX_OK;
}

/* What the GPU solver cannot do, by name; VFX_OK when sim is within it. */
static vfx_result gpu_supported(const rt_sph *s, char *err, size_t errlen)
{
    const char *what = NULL;
    if (s->p.solver != RT_SPH_SOLVER_PBF)
        what = "a solver other than PBF (the GPU solver is PBF only)";
    else if (s->nem)
        what = "emitters";
    else if (s->p.pbf_vorticity > 0.f)
        what = "vorticity confinement (pbf_vorticity > 0)";
    else if (s->p.flags & RT_SPH_PBF_WARM_START)
        what = "the warm-start experiment";
    for (uint32_t c = 0; !what && c < s->ncol; ++c)
        if (s->col[c].sdf)
            what = "mesh colliders";
    if (what)
        return rt_errf(err, errlen, VFX_ERR_UNSUPPORTED, "GPU fluid solver: %s not supported; use the cpu device", what);
    return VFX_OK;
}

vfx_result rt_sph_gpu_create(rt_sph *s, const rt_sph_gpu_desc *desc, rt_sph_gpu **out, char *err, size_t errlen)
{
    if (!s || !out)
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_gpu_create: sim and out are required");
    *out = NULL;
    vfx_result r = gpu_supported(s, err, errlen);
    if (r)
        return r;
    rt_sph_gpu *g = calloc(1, sizeof *g);
    if (!g)
        return rt_errf(err, errlen, VFX_ERR_OUT_OF_MEMORY, "rt_sph_gpu_create: out of memory");
    g->s = s;
    g->sync = desc && desc->sync_stats;
    g->n = s->n;
    g->groups = (g->n + GPU_GROUP - 1) / GPU_GROUP;
    uint64_t cells = 1;
    for (int a = 0; a < 3; ++a) {
        double d = ceil((double)(s->p.domain_max[a] - s->p.domain_min[a]) * s->inv_cell);
        g->dims[a] = d < 1 ? 1 : (int)fmin(d, 1e9);
        cells *= (uint64_t)g->dims[a];
    }
    if (cells > SPH_MAX_CELLS) {
        r = rt_errf(err, errlen, VFX_ERR_UNSUPPORTED, "GPU fluid solver: the tank holds %llu cells of H/2 "
                    "(%d x %d x %d), above %u: a larger spacing or a smaller tank", (unsigned long long)cells,
                    g->dims[0], g->dims[1], g->dims[2], SPH_MAX_CELLS);
        free(g);
        return r;
    }
    g->ncells = (uint32_t)cells;
    g->nblocks = (g->ncells + 1 + 1023) / 1024;
    if ((r = gpu_programs(g, err, errlen)) || (r = gpu_upload(g, err, errlen))) {
        rt_sph_gpu_destroy(g);
        return r;
    }
    float v2 = 0.f;
    for (uint32_t i = 0; i < s->n; ++i)
        v2 = fmaxf(v2, s->vx[i] * s->vx[i] + s->vy[i] * s->vy[i] + s->vz[i] * s->vz[i]);
    g->vmax_known = sqrtf(v2);
    *out = g;
    return VFX_OK;
}

void rt_sph_gpu_destroy(rt_sph_gpu *g)
{
    if (!g)
        return;
    for (int k = 0; k < P_COUNT; ++k)
        glDeleteProgram(g->prog[k]);
    for (uint32_t k = 0; k < GPU_SLOTS; ++k)
        if (g->fence[k])
            glDeleteSync(g->fence[k]);
    if (g->stats_map)
        glUnmapNamedBuffer(g->stats);
    GLuint b[] = {g->pos[0], g->pos[1], g->vel[0], g->vel[1], g->id[0], g->id[1], g->x0, g->qa, g->qb, g->key,
                  g->count, g->start, g->blocks, g->lam, g->wallc, g->rho, g->partial, g->params, g->colliders,
                  g->stats};
    glDeleteBuffers((GLsizei)(sizeof b / sizeof b[0]), b);
    free(g);
}

/* ---- a step --------------------------------------------------------------------------------- */

/* The parameters of a step of dt in a call of frame_dt, and the colliders at the step's end. */
static void gpu_set_params(rt_sph_gpu *g, float dt, float frame_dt)
{
    rt_sph *s = g->s;
    float D0, eps, wdq;
    rt_sph_pbf_constants(s, frame_dt, &D0, &eps, &wdq);
    const bool scorr = !(s->p.flags & RT_SPH_PBF_NO_SCORR) && s->p.pbf_scorr_k > 0.f;
    const float xsph = (s->p.flags & RT_SPH_PBF_NO_XSPH) ? 0.f : s->p.pbf_xsph;
    gpu_params P = {
        .lo = {s->p.domain_min[0], s->p.domain_min[1], s->p.domain_min[2], s->H},
        .hi = {s->p.domain_max[0], s->p.domain_max[1], s->p.domain_max[2], s->H2},
        .grav = {s->p.gravity[0], s->p.gravity[1], s->p.gravity[2], dt},
        .k0 = {s->mass, s->p.rest_density, s->k_poly6, s->k_spiky},
        .k1 = {s->wall_scale, s->fric_scale, eps, s->p.velocity_limit},
        .k2 = {s->inv_cell, s->p.spacing, xsph, s->p.kinematic_viscosity},
        .k3 = {scorr ? s->p.pbf_scorr_k / D0 : 0.f, 1.f / wdq, 0.5f * s->H, 0.f},
        .grid = {g->dims[0], g->dims[1], g->dims[2], (int32_t)g->ncells},
        .counts = {g->n, s->ncol, s->p.no_slip_faces, s->friction ? 1u : 0u}};
    glNamedBufferSubData(g->params, 0, sizeof P, &P);
    rt_sph_update_colliders(s, s->time + dt); /* the constraints hold at the end of the step */
    float C[GPU_MAX_COLLIDERS][16];
    memset(C, 0, sizeof C);
    for (uint32_t c = 0; c < s->ncol && c < GPU_MAX_COLLIDERS; ++c) {
        const sph_collider_state *st = &s->col[c];
        float *o = C[c];
        for (int a = 0; a < 3; ++a) {
            o[a] = st->pos[a], o[4 + a] = st->c.normal[a], o[8 + a] = st->c.half[a], o[12 + a] = st->vel[a];
        }
        o[3] = (float)st->c.kind, o[7] = st->c.radius, o[11] = st->c.no_slip ? 1.f : 0.f;
    }
    if (s->ncol)
        glNamedBufferSubData(g->colliders, 0, (GLsizeiptr)(s->ncol * 64), C);
}

static void gpu_bind(GLuint binding, GLuint buffer) { glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, buffer); }

static void gpu_dispatch(GLuint groups)
{
    glDispatchCompute(groups, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

/* Counting sort of the predicted positions by cell: count (in predict), scan, scatter. */
static void gpu_sort(rt_sph_gpu *g, GLuint slot_off)
{
    const uint32_t len = g->ncells + 1, sg = (len + 1023) / 1024;
    glUseProgram(g->prog[P_SCAN]);
    gpu_bind(0, g->count), gpu_bind(1, g->start), gpu_bind(2, g->blocks);
    glUniform1ui(g->u_scan_len, len), glUniform1i(g->u_scan_mode, 0);
    gpu_dispatch(sg);
    glUniform1ui(g->u_scan_len, g->nblocks), glUniform1i(g->u_scan_mode, 1);
    gpu_dispatch(1);
    glUniform1ui(g->u_scan_len, len), glUniform1i(g->u_scan_mode, 2);
    gpu_dispatch(sg);
    (void)slot_off;
    glUseProgram(g->prog[P_SCATTER]);
    gpu_bind(0, g->pos[g->pc]), gpu_bind(1, g->start), gpu_bind(2, g->vel[0]), gpu_bind(3, g->key);
    gpu_bind(4, g->id[g->pc]), gpu_bind(5, g->x0), gpu_bind(6, g->vel[1]), gpu_bind(7, g->id[1 - g->pc]);
    gpu_dispatch(g->groups);
}

/* The Jacobi iterations with the Chebyshev weights of sph_pbf.c; the final iterate's buffer. */
static GLuint gpu_iterate(rt_sph_gpu *g, uint32_t *iterations)
{
    const rt_sph *s = g->s;
    const float rho = (s->p.flags & RT_SPH_PBF_NO_CHEBYSHEV) ? 0.f : s->p.pbf_chebyshev_rho;
    GLuint cur = g->x0, prev = g->x0, bufs[2] = {g->qa, g->qb};
    const GLuint ids = g->id[1 - g->pc];
    for (uint32_t it = 0; it < s->p.pbf_iterations; ++it) {
        GLuint next = bufs[it & 1u];
        glUseProgram(g->prog[P_LAMBDA]);
        glUniform1ui(g->u_iter, it);
        gpu_bind(0, cur), gpu_bind(1, g->start), gpu_bind(2, ids), gpu_bind(3, g->x0), gpu_bind(4, g->wallc);
        gpu_bind(5, g->lam);
        gpu_dispatch(g->groups);
        glUseProgram(g->prog[P_DELTA]);
        /* omega_1 = 1, omega_2 = 2 / (2 - rho^2), ...: the CPU solver's recurrence */
        glUniform1f(g->u_omega, rho == 0.f ? 1.f : rt_sph_chebyshev_weight(rho, it + 1));
        gpu_bind(0, cur), gpu_bind(1, g->start), gpu_bind(2, ids), gpu_bind(3, g->x0), gpu_bind(4, g->wallc);
        gpu_bind(5, g->lam), gpu_bind(6, prev), gpu_bind(7, next);
        gpu_dispatch(g->groups);
        prev = cur, cur = next;
        (*iterations)++;
    }
    return cur;
}

/* One PBF step of dt; its counters and end-state figures go to stats slot `slot`. */
static void gpu_substep(rt_sph_gpu *g, float dt, float frame_dt, uint32_t slot, uint32_t *iterations)
{
    const GLintptr off = (GLintptr)slot * GPU_SLOT_BYTES;
    gpu_set_params(g, dt, frame_dt);
    glBindBufferBase(GL_UNIFORM_BUFFER, 0, g->params);
    glBindBufferBase(GL_UNIFORM_BUFFER, 1, g->colliders);
    glClearNamedBufferData(g->count, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
    glUseProgram(g->prog[P_PREDICT]);
    gpu_bind(0, g->pos[g->pc]), gpu_bind(2, g->vel[0]), gpu_bind(3, g->key), gpu_bind(4, g->count);
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 5, g->stats, off, 16);
    gpu_dispatch(g->groups);
    gpu_sort(g, (GLuint)off);
    GLuint fin = gpu_iterate(g, iterations);
    const GLuint out_pos = g->pos[1 - g->pc];
    glUseProgram(g->prog[P_FINISH]);
    gpu_bind(0, fin), gpu_bind(2, g->x0), gpu_bind(3, g->vel[1]), gpu_bind(4, out_pos);
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 5, g->stats, off, 16);
    gpu_dispatch(g->groups);
    /* the end state's maxima are this step's alone */
    glClearNamedBufferSubData(g->stats, GL_R32UI, off, 8, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
    glUseProgram(g->prog[P_VISC]);
    gpu_bind(0, out_pos), gpu_bind(1, g->start), gpu_bind(2, g->vel[1]), gpu_bind(3, g->vel[0]), gpu_bind(4, g->rho);
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 5, g->stats, off, 16);
    gpu_bind(6, g->partial);
    gpu_dispatch(g->groups);
    glUseProgram(g->prog[P_REDUCE]);
    glUniform1ui(g->u_groups, g->groups);
    gpu_bind(0, g->partial);
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 1, g->stats, off, 32);
    gpu_dispatch(1);
    g->pc = 1 - g->pc;
}

/* Copies slot k's figures once its fence has passed (wait: block until it has). */
static void gpu_poll_slot(rt_sph_gpu *g, uint32_t k, bool wait)
{
    if (!g->fence[k])
        return;
    GLenum st = glClientWaitSync(g->fence[k], wait ? GL_SYNC_FLUSH_COMMANDS_BIT : 0,
                                 wait ? (GLuint64)60 * 1000000000ull : 0);
    if (st != GL_ALREADY_SIGNALED && st != GL_CONDITION_SATISFIED)
        return;
    glDeleteSync(g->fence[k]);
    g->fence[k] = 0;
    if (g->slot_frame[k] >= g->known_frame) {
        memcpy(&g->known, (const void *)(g->stats_map + k * GPU_SLOT_BYTES), sizeof g->known);
        g->known_frame = g->slot_frame[k];
        float v2;
        memcpy(&v2, &g->known.v2max, sizeof v2);
        g->vmax_known = sqrtf(v2);
    }
}

static float gpu_bits_float(uint32_t u)
{
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

/* The report's state figures from the newest figures read back. */
static void gpu_fill_report(const rt_sph_gpu *g, rt_sph_report *rep)
{
    const gpu_stats *k = &g->known;
    rep->max_speed = sqrtf(gpu_bits_float(k->v2max));
    rep->max_density_error = gpu_bits_float(k->errmax);
    rep->mean_density_error = g->n ? k->errsum / (float)g->n : 0.f;
    rep->kinetic_energy = k->ke;
    rep->potential_energy = k->pe;
    rep->internal_energy = 0.0;
    rep->speed_clamped = k->clamped;
}

vfx_result rt_sph_gpu_step(rt_sph_gpu *g, float frame_dt, rt_sph_report *rep, char *err, size_t errlen)
{
    rt_sph_report dummy;
    if (!rep)
        rep = &dummy;
    memset(rep, 0, sizeof *rep);
    if (!g || !(frame_dt >= 0.f) || !isfinite(frame_dt))
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_gpu_step: frame_dt %g must be finite and >= 0",
                       (double)frame_dt);
    rt_sph *s = g->s;
    for (uint32_t k = 0; k < GPU_SLOTS; ++k)
        gpu_poll_slot(g, k, false);
    /* the step count of rt_sph_pbf_step, from the newest known max speed */
    const float *gr = s->p.gravity;
    float gl = sqrtf(gr[0] * gr[0] + gr[1] * gr[1] + gr[2] * gr[2]);
    double steps = ceil((double)frame_dt / s->p.pbf_max_step - 1e-6);
    double cfl = ceil((double)frame_dt * (g->vmax_known + gl * frame_dt) / (s->p.pbf_cfl * s->H) - 1e-6);
    if (cfl > steps)
        steps = cfl;
    if (steps > s->p.max_substeps)
        steps = s->p.max_substeps, rep->cap_hit = true;
    uint32_t n = frame_dt > 0.f && g->n ? (uint32_t)(steps > 1 ? steps : 1) : 0;
    float dt = n ? frame_dt / (float)n : 0.f;
    rep->dt_min = rep->dt_max = rep->dt_last = n ? dt : 0.0;
    rep->dt_limit = cfl > ceil((double)frame_dt / s->p.pbf_max_step - 1e-6) ? RT_SPH_DT_CFL : RT_SPH_DT_FRAME;
    if (!n) {
        gpu_fill_report(g, rep);
        return VFX_OK;
    }
    const uint32_t slot = (uint32_t)(g->frame % GPU_SLOTS);
    gpu_poll_slot(g, slot, true); /* the GPU is GPU_SLOTS frames behind: wait for the oldest */
    GLint prev_prog = 0;
    glGetIntegerv(GL_CURRENT_PROGRAM, &prev_prog);
    glClearNamedBufferSubData(g->stats, GL_R32UI, (GLintptr)slot * GPU_SLOT_BYTES, GPU_SLOT_BYTES, GL_RED_INTEGER,
                              GL_UNSIGNED_INT, NULL);
    for (uint32_t k = 0; k < n; ++k) {
        gpu_substep(g, dt, frame_dt, slot, &rep->iterations);
        s->time += dt;
        rep->substeps++;
        rep->simulated_time += dt;
        rep->neighbor_rebuilds++;
    }
    glMemoryBarrier(GL_ALL_BARRIER_BITS); /* the renderer reads the state next */
    glUseProgram((GLuint)prev_prog);
    g->frame++;
    g->slot_frame[slot] = g->frame;
    g->fence[slot] = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    glFlush();
    if (g->sync)
        gpu_poll_slot(g, slot, true);
    gpu_fill_report(g, rep);
    if (g->known.bad)
        return rt_errf(err, errlen, VFX_ERR_NUMERIC, "rt_sph_gpu_step: %u particle updates went non-finite by frame "
                       "%llu (t=%.6g s, PBF step %.3g s); they were left at their predicted positions, at rest. The "
                       "projection overflowed: particles closer than float32 resolves or a step far above the "
                       "spacing's (pbf_cfl)", g->known.bad, (unsigned long long)g->known_frame, s->time, (double)dt);
    return VFX_OK;
}


/* ---- velocity edits, settle, access ------------------------------------------------------------ */

static void gpu_velocity_pass(rt_sph_gpu *g, int mode, float scale, const float centre[4], const float dir[4])
{
    if (!g->n)
        return;
    GLint prev_prog = 0;
    glGetIntegerv(GL_CURRENT_PROGRAM, &prev_prog);
    gpu_set_params(g, 1.f / 60.f, 1.f / 60.f);
    glBindBufferBase(GL_UNIFORM_BUFFER, 0, g->params);
    glBindBufferBase(GL_UNIFORM_BUFFER, 1, g->colliders);
    glUseProgram(g->prog[P_VELOCITY]);
    glUniform1i(g->u_vel_mode, mode);
    glUniform1f(g->u_vel_scale, scale);
    if (centre)
        glUniform4fv(g->u_vel_centre, 1, centre), glUniform4fv(g->u_vel_dir, 1, dir);
    gpu_bind(0, g->pos[g->pc]), gpu_bind(2, g->vel[0]);
    gpu_dispatch(g->groups);
    glUseProgram((GLuint)prev_prog);
}

void rt_sph_gpu_impulse(rt_sph_gpu *g, const float centre[3], const float dir[3], float radius, float speed)
{
    if (!g || !centre || !(radius > 0) || !(speed > 0) || !isfinite(radius) || !isfinite(speed) ||
        !isfinite(centre[0]) || !isfinite(centre[1]) || !isfinite(centre[2]))
        return;
    float d[4] = {0, 0, 0, speed}, c[4] = {centre[0], centre[1], centre[2], radius};
    float dl = dir ? sqrtf(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]) : 0.f;
    if (dl > 0 && isfinite(dl))
        for (int k = 0; k < 3; ++k)
            d[k] = dir[k] / dl;
    gpu_velocity_pass(g, 1, 1.f, c, d);
    g->vmax_known += speed; /* an impulse adds at most speed to a particle's */
}

static vfx_result gpu_settle_step(void *g, float dt, rt_sph_report *rep, char *err, size_t errlen)
{
    return rt_sph_gpu_step(g, dt, rep, err, errlen);
}

static void gpu_settle_damp(void *solver, float factor, const rt_sph_report *rep)
{
    rt_sph_gpu *g = solver;
    gpu_velocity_pass(g, 0, factor, NULL, NULL);
    g->vmax_known = rep->max_speed * factor;
}

vfx_result rt_sph_gpu_settle(rt_sph_gpu *g, const rt_sph_settle_desc *desc, rt_sph_settle_report *rep, char *err,
                             size_t errlen)
{
    if (rep)
        *rep = (rt_sph_settle_report){0};
    if (!g)
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_gpu_settle: NULL solver");
    /* rt_sph_settle's checks, defaults, steps and stopping rule; each step waits for its figures */
    const bool sync = g->sync;
    g->sync = true;
    const rt_sph_settle_ops ops = {gpu_settle_step, gpu_settle_damp, g, &g->n};
    vfx_result r = rt_sph_settle_run(g->s, "rt_sph_gpu_settle", desc, &ops, rep, err, errlen);
    g->sync = sync;
    return r;
}

void rt_sph_gpu_columns(const rt_sph_gpu *g, vfx_gpu_column *pos, vfx_gpu_column *vel, uint32_t *count)
{
    if (pos)
        *pos = g ? (vfx_gpu_column){g->pos[g->pc], 16, 0} : (vfx_gpu_column){0};
    if (vel)
        *vel = g ? (vfx_gpu_column){g->vel[0], 16, 0} : (vfx_gpu_column){0};
    if (count)
        *count = g ? g->n : 0;
}

vfx_result rt_sph_gpu_download(rt_sph_gpu *g, float *x, float *y, float *z, float *vx, float *vy, float *vz,
                               float *density, uint32_t *id, char *err, size_t errlen)
{
    if (!g)
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_gpu_download: NULL solver");
    size_t n = g->n ? g->n : 1;
    float *p = malloc(n * 16), *v = malloc(n * 16), *rho = malloc(n * 4);
    uint32_t *ids = malloc(n * 4);
    if (!p || !v || !rho || !ids) {
        free(p), free(v), free(rho), free(ids);
        return rt_errf(err, errlen, VFX_ERR_OUT_OF_MEMORY, "rt_sph_gpu_download: out of memory for %u particles", g->n);
    }
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    if (g->n) {
        glGetNamedBufferSubData(g->pos[g->pc], 0, (GLsizeiptr)g->n * 16, p);
        glGetNamedBufferSubData(g->vel[0], 0, (GLsizeiptr)g->n * 16, v);
        glGetNamedBufferSubData(g->rho, 0, (GLsizeiptr)g->n * 4, rho);
        glGetNamedBufferSubData(g->id[g->pc], 0, (GLsizeiptr)g->n * 4, ids);
    }
    for (uint32_t i = 0; i < g->n; ++i) {
        if (x)
            x[i] = p[4 * i], y[i] = p[4 * i + 1], z[i] = p[4 * i + 2];
        if (vx)
            vx[i] = v[4 * i], vy[i] = v[4 * i + 1], vz[i] = v[4 * i + 2];
        if (density)
            density[i] = g->frame ? rho[i] : g->s->p.rest_density;
        if (id)
            id[i] = ids[i];
    }
    free(p), free(v), free(rho), free(ids);
    return VFX_OK;
}

size_t rt_sph_gpu_memory_bytes(const rt_sph_gpu *g) { return g ? g->bytes : 0; }

bool rt_sph_gpu_software_renderer(void)
{
    const char *r = (const char *)glGetString(GL_RENDERER);
    if (!r)
        return true; /* no answer: the safe choice is the CPU */
    return strstr(r, "llvmpipe") || strstr(r, "softpipe") || strstr(r, "swrast") || strstr(r, "Software Rasterizer");
}
