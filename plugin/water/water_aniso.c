/* water_aniso.c — per-particle kernels for method TILE (see water_aniso.h): the host columns'
 * checks and upload, and the GPU pass of shaders/water/aniso.comp (hashed grid by counting sort
 * with the plugin's GPU scan, gpu/scan.h, then one kernel per particle). */
#include <math.h>
#include <string.h>

#include "gpu/gpu.h"
#include "gpu/pass.h"
#include "gpu/scan.h"
#include "water_aniso.h"

/* a power of two with buckets + 1 within the scan's VOLFX_SCAN_MAX */
#define ANISO_MAX_BUCKETS (VOLFX_SCAN_MAX / 2u)
/* the columns a host may give: radius and kernel eigenvalues in this range */
#define COLUMN_MIN 1e-3
#define COLUMN_MAX 1e3

struct volfx_water_aniso {
    GLuint count, start, sorted, kern, nbr, radius, hostg;
    uint32_t bucket_cap, particle_cap, column_cap;
    bool has_radius, has_kernel;
    float radius_max;      /* largest radius column value (1 without one) */
    float host_sigma_max;  /* largest 1 / eigenvalue of the host kernels */
    /* what the last pass computed from: skip it when nothing changed */
    uint64_t done_rev;
    uint32_t done_count;
    float done_h;
    volfx_water_kernel_params done_kp;
    bool done_radius, done_kernel, done;
    bool searched;         /* the last pass counted neighbours (the anisotropic kernel, computed) */
    bool shape_fresh;      /* the last pass computed the shapes (the half rate's next one moves centres) */
    /* the hashed grid in sorted/start: built from data_rev grid_rev (0: none), these cells */
    uint64_t grid_rev;
    uint32_t grid_count, grid_buckets;
    float grid_cs, grid_lo[3];
};

vfx_result volfx_water_kernel_params_check(vfx_context *ctx, const vfx_water_params *in,
                                           volfx_water_kernel_params *out)
{
    if (in->kernel > VFX_WATER_KERNEL_ANISOTROPIC)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_WATER_PARAM,
                          "water: vfx_water_params.kernel %u unknown (0 default, 1 isotropic, 2 anisotropic)", in->kernel);
    struct { const char *name; float v, lo, hi, def; float *dst; } f[] = {
        {"aniso_radius", in->aniso_radius, 0.5f, 4.0f, 1.5f, &out->radius},
        {"aniso_max_stretch", in->aniso_max_stretch, 1.0f, 64.0f, 2.0f, &out->max_stretch},
        {"aniso_scale", in->aniso_scale, 0.25f, 4.0f, 1.15f, &out->scale},
        {"aniso_smoothing", in->aniso_smoothing, 0.0f, 1.0f, 0.0f, &out->smoothing},
    };
    for (size_t k = 0; k < sizeof f / sizeof f[0]; ++k) {
        float v = f[k].v;
        if (v == 0.0f) {
            *f[k].dst = f[k].def;
            continue;
        }
        if (!(v >= f[k].lo && v <= f[k].hi))
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_PARAM_RANGE,
                              "water: vfx_water_params.%s %g outside [%g, %g] (0: default %g)",
                              f[k].name, v, f[k].lo, f[k].hi, f[k].def);
        *f[k].dst = v;
    }
    if (in->aniso_min_neighbours > 10000)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_PARAM_RANGE,
                          "water: vfx_water_params.aniso_min_neighbours %u above 10000",
                          in->aniso_min_neighbours);
    out->min_neighbours = in->aniso_min_neighbours ? in->aniso_min_neighbours : 16;
    out->kernel = in->kernel == VFX_WATER_KERNEL_ANISOTROPIC ? VFX_WATER_KERNEL_ANISOTROPIC : VFX_WATER_KERNEL_ISOTROPIC;
    return VFX_OK;
}

volfx_water_aniso *volfx_water_aniso_create(vfx_context *ctx)
{
    volfx_water_aniso *a = volfx_alloc(ctx, sizeof *a);
    if (!a)
        return NULL;
    a->radius_max = 1.0f;
    return a;
}

void volfx_water_aniso_destroy(vfx_context *ctx, volfx_water_aniso *a)
{
    if (!a)
        return;
    GLuint b[] = {a->count, a->start, a->sorted, a->kern, a->nbr, a->radius, a->hostg};
    for (size_t k = 0; k < sizeof b / sizeof b[0]; ++k)
        if (b[k])
            glDeleteBuffers(1, &b[k]);
    volfx_free(ctx, a);
}

/* Eigenvalues of the symmetric 3x3 (xx xy xz yy yz zz) by cyclic Jacobi in double. */
static void eigen_sym3(const double g[6], double ev[3])
{
    double A[3][3] = {{g[0], g[1], g[2]}, {g[1], g[3], g[4]}, {g[2], g[4], g[5]}};
    for (int sweep = 0; sweep < 32; ++sweep) {
        double off = fabs(A[0][1]) + fabs(A[0][2]) + fabs(A[1][2]);
        if (!(off > 1e-300))
            break;
        for (int p = 0; p < 2; ++p)
            for (int q = p + 1; q < 3; ++q) {
                if (A[p][q] == 0.0)
                    continue;
                double th = (A[q][q] - A[p][p]) / (2.0 * A[p][q]);
                double t = (th >= 0 ? 1.0 : -1.0) / (fabs(th) + sqrt(th * th + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 3; ++k) { /* A J */
                    double akp = A[k][p], akq = A[k][q];
                    A[k][p] = c * akp - s * akq;
                    A[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; ++k) { /* J^T (A J) */
                    double apk = A[p][k], aqk = A[q][k];
                    A[p][k] = c * apk - s * aqk;
                    A[q][k] = s * apk + c * aqk;
                }
            }
    }
    for (int k = 0; k < 3; ++k)
        ev[k] = A[k][k];
}

static GLuint regrow(GLuint b, GLsizeiptr bytes, const char *label)
{
    if (b)
        glDeleteBuffers(1, &b);
    return volfx_gpu_storage(bytes, label);
}

vfx_result volfx_water_aniso_columns_begin(vfx_context *ctx, volfx_water_aniso *a, uint32_t total, bool radius,
                                           bool kernel)
{
    a->has_radius = radius;
    a->has_kernel = kernel;
    a->radius_max = 1.0f;
    a->host_sigma_max = 0.0f;
    if (!radius && !kernel)
        return VFX_OK;
    uint32_t n = total ? total : 1;
    if (n > a->column_cap || !a->radius || !a->hostg) {
        a->radius = regrow(a->radius, (GLsizeiptr)n * 4, "water.aniso_radius");
        a->hostg = regrow(a->hostg, (GLsizeiptr)n * 24, "water.aniso_host_kernel");
        a->column_cap = n;
    }
    const char *e = volfx_gpu_error_string();
    if (e)
        return volfx_fail(ctx, VFX_ERR_OUT_OF_MEMORY, VFX_LOG_ID_GPU_OUT_OF_MEMORY,
                          "water: kernel columns for %u particles: %s", total, e);
    return VFX_OK;
}

/* One chunk's columns checked and uploaded; `field` names the kernel column in messages
 * ("kernel", "gpu_kernel"); `kernel_there`: the kernels are in hostg already (gathered), `kernel`
 * their copy read back for the checks. */
static vfx_result columns_chunk(vfx_context *ctx, volfx_water_aniso *a, uint32_t chunk, uint32_t first, uint32_t count,
                                const float *radius, const float *kernel, const char *field, bool kernel_there)
{
    for (uint32_t i = 0; radius && i < count; ++i)
        if (!(radius[i] >= COLUMN_MIN && radius[i] <= COLUMN_MAX))
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_WATER_PARTICLE_VALUE,
                              "water: particle chunk %u, particle %u: radius %g (vfx_particle_view.radius) must be finite and in [%g, %g]",
                              chunk, i, radius[i], COLUMN_MIN, COLUMN_MAX);
    for (uint32_t i = 0; kernel && i < count; ++i) {
        double g[6], ev[3];
        for (int k = 0; k < 6; ++k) {
            g[k] = kernel[6 * (size_t)i + k];
            if (!isfinite(g[k]))
                return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_WATER_PARTICLE_VALUE,
                                  "water: particle chunk %u, particle %u: kernel (vfx_particle_view.%s) entry %d is %g",
                                  chunk, i, field, k, g[k]);
        }
        eigen_sym3(g, ev);
        for (int k = 0; k < 3; ++k) {
            if (!(ev[k] >= COLUMN_MIN && ev[k] <= COLUMN_MAX))
                return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_WATER_PARTICLE_VALUE,
                                  "water: particle chunk %u, particle %u: kernel (vfx_particle_view.%s) has eigenvalue %g, "
                                  "outside [%g, %g] (symmetric positive definite, xx xy xz yy yz zz)",
                                  chunk, i, field, ev[k], COLUMN_MIN, COLUMN_MAX);
            double s = (radius ? radius[i] : 1.0) / ev[k];
            if (s > a->host_sigma_max)
                a->host_sigma_max = (float)s;
        }
    }
    for (uint32_t i = 0; radius && i < count; ++i)
        if (radius[i] > a->radius_max)
            a->radius_max = radius[i];
    if (radius) {
        glNamedBufferSubData(a->radius, (GLintptr)first * 4, (GLsizeiptr)count * 4, radius);
    } else {
        float one = 1.0f;
        glClearNamedBufferSubData(a->radius, GL_R32F, (GLintptr)first * 4, (GLsizeiptr)count * 4, GL_RED, GL_FLOAT, &one);
    }
    if (kernel) {
        if (!kernel_there)
            glNamedBufferSubData(a->hostg, (GLintptr)first * 24, (GLsizeiptr)count * 24, kernel);
    } else if (a->has_kernel) {
        /* this chunk gives none: the identity (the isotropic kernel) */
        float *id = volfx_alloc(ctx, (size_t)count * 24);
        if (!id)
            return volfx_fail(ctx, VFX_ERR_OUT_OF_MEMORY, VFX_LOG_ID_OUT_OF_MEMORY,
                              "water: identity kernels for chunk %u (%u particles)", chunk, count);
        for (uint32_t i = 0; i < count; ++i) {
            float *g = id + 6 * (size_t)i;
            g[0] = g[3] = g[5] = 1.0f;
            g[1] = g[2] = g[4] = 0.0f;
            float s = radius ? radius[i] : 1.0f;
            if (s > a->host_sigma_max)
                a->host_sigma_max = s;
        }
        glNamedBufferSubData(a->hostg, (GLintptr)first * 24, (GLsizeiptr)count * 24, id);
        volfx_free(ctx, id);
    }
    return VFX_OK;
}

vfx_result volfx_water_aniso_columns_chunk(vfx_context *ctx, volfx_water_aniso *a, uint32_t chunk, uint32_t first,
                                           uint32_t count, const float *radius, const float *kernel)
{
    if ((!a->has_radius && !a->has_kernel) || count == 0)
        return VFX_OK;
    return columns_chunk(ctx, a, chunk, first, count, radius, kernel, "kernel", false);
}

vfx_result volfx_water_aniso_columns_gpu_chunk(vfx_context *ctx, volfx_water_aniso *a, volfx_water_gather *g,
                                               uint32_t chunk, uint32_t first, uint32_t count, const float *radius,
                                               const volfx_gpu_column *kernel)
{
    if (count == 0)
        return VFX_OK;
    vfx_result r = volfx_water_gather_kernels(ctx, g, kernel, count, a->hostg, first);
    if (r)
        return r;
    /* the same checks as the CPU column's, on the gathered floats read back: a kernel outside
     * [1e-3, 1e3] is refused naming the particle, and the largest 1 / eigenvalue bounds TILE's
     * binning this upload (a GPU reduction read late could not: the bound must hold now) */
    float *copy = volfx_alloc(ctx, (size_t)count * 24);
    if (!copy)
        return VFX_ERR_OUT_OF_MEMORY;
    glGetNamedBufferSubData(a->hostg, (GLintptr)first * 24, (GLsizeiptr)count * 24, copy);
    r = columns_chunk(ctx, a, chunk, first, count, radius, copy, "gpu_kernel", true);
    volfx_free(ctx, copy);
    return r;
}

bool volfx_water_aniso_has_columns(const volfx_water_aniso *a)
{
    return a && (a->has_radius || a->has_kernel);
}

GLuint volfx_water_aniso_kernels(const volfx_water_aniso *a) { return a ? a->kern : 0; }
GLuint volfx_water_aniso_neighbours(const volfx_water_aniso *a) { return a && a->searched ? a->nbr : 0; }

static float sigma_bound_of(const volfx_water_aniso *a, const volfx_water_kernel_params *kp)
{
    if (a->has_kernel)
        return a->host_sigma_max > 0 ? a->host_sigma_max : 1.0f;
    float s = 1.0f;
    if (kp && kp->kernel == VFX_WATER_KERNEL_ANISOTROPIC) {
        /* axes with s1 s2 s3 = 1 and each >= s_max / kr: s_max^3 / kr^2 <= 1, then times ks */
        float stretch = cbrtf(kp->max_stretch * kp->max_stretch) * kp->scale;
        if (stretch > s) s = stretch;
    }
    /* rounding of the normalisation in float: a little room */
    return s * a->radius_max * 1.001f;
}

float volfx_water_aniso_sigma_bound(const volfx_water_aniso *a)
{
    return a ? sigma_bound_of(a, a->done ? &a->done_kp : NULL) : 1.0f;
}

static void aniso_uniforms(vfx_context *ctx, GLuint prog, const volfx_water_aniso_input *in, uint32_t buckets,
                           float cs, uint32_t n)
{
    const volfx_water_kernel_params *kp = in->kp;
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_count"), in->count);
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_n"), n);
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_buckets"), buckets);
    glUniform3fv(volfx_gpu_uniform(ctx, prog, "u_g0"), 1, in->lo);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_cs"), cs);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_h"), in->h);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_kr"), kp->max_stretch);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_ks"), kp->scale);
    glUniform1f(volfx_gpu_uniform(ctx, prog, "u_lambda"), kp->smoothing);
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_ne"), kp->min_neighbours);
}

/* One step of the grid build: the program with the pass's uniforms, gx x gy groups (none when
 * gx is 0: no particles), then `barrier`. */
static void aniso_step(vfx_context *ctx, GLuint prog, const volfx_water_aniso_input *in, uint32_t buckets, float cs,
                       uint32_t n, GLuint gx, GLuint gy, GLbitfield barrier)
{
    glUseProgram(prog);
    aniso_uniforms(ctx, prog, in, buckets, cs, n);
    if (gx)
        glDispatchCompute(gx, gy, 1);
    glMemoryBarrier(barrier);
}

/* The buckets of a grid over n particles (a power of two, about 2 n) and the scan's length. */
static uint32_t grid_buckets(uint32_t count, uint32_t *need)
{
    uint32_t n = count ? count : 1;
    uint32_t buckets = 1024;
    while (buckets < 2u * n && buckets < ANISO_MAX_BUCKETS)
        buckets *= 2;
    *need = (buckets + 1 + 1023u) & ~1023u;
    return buckets;
}

/* The grid build's buffers for in->count particles; an error when GL could not make them. */
static vfx_result ensure_buffers(vfx_context *ctx, volfx_water_aniso *a, const volfx_water_aniso_input *in)
{
    uint32_t n = in->count ? in->count : 1, need;
    grid_buckets(in->count, &need);
    if (need > a->bucket_cap) {
        a->count = regrow(a->count, (GLsizeiptr)need * 4, "water.aniso_count");
        a->start = regrow(a->start, (GLsizeiptr)need * 4, "water.aniso_start");
        a->bucket_cap = need;
        a->grid_rev = 0;
    }
    if (n > a->particle_cap || !a->kern) {
        a->sorted = regrow(a->sorted, (GLsizeiptr)n * 16, "water.aniso_sorted");
        a->kern = regrow(a->kern, (GLsizeiptr)n * VOLFX_WATER_KERNEL_STRIDE, "water.aniso_kernels");
        a->nbr = regrow(a->nbr, (GLsizeiptr)n * 4, "water.aniso_neighbours");
        a->particle_cap = n;
        a->grid_rev = 0;
    }
    if (!a->radius) /* bound even when unused */
        a->radius = regrow(a->radius, 4, "water.aniso_radius");
    if (!a->hostg)
        a->hostg = regrow(a->hostg, 24, "water.aniso_host_kernel");
    const char *e = volfx_gpu_error_string();
    if (e)
        return volfx_fail(ctx, VFX_ERR_OUT_OF_MEMORY, VFX_LOG_ID_GPU_OUT_OF_MEMORY,
                          "water aniso: buffers for %u particles: %s", in->count, e);
    return VFX_OK;
}

static void bind_all(const volfx_water_aniso *a, const volfx_water_aniso_input *in)
{
    GLuint bind[] = {in->cols[0], in->cols[1], in->cols[2], a->count, in->counters, a->start, 0, a->sorted,
                     a->kern, a->nbr, a->radius, a->hostg};
    for (GLuint k = 0; k < sizeof bind / sizeof bind[0]; ++k)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, k, bind[k]);
}

/* The hashed grid of cell kp->radius h over the positions: counts, prefix sum, scatter into
 * `sorted` (the buffers bound by bind_all). */
static vfx_result grid_steps(vfx_context *ctx, volfx_water_aniso *a, const volfx_water_aniso_input *in)
{
    GLuint count = volfx_gpu_compute(ctx, "water/aniso.comp", "#define MODE_COUNT\n");
    GLuint scatter = volfx_gpu_compute(ctx, "water/aniso.comp", "#define MODE_SCATTER\n");
    if (!count || !scatter)
        return VFX_ERR_GL;
    uint32_t need, buckets = grid_buckets(in->count, &need), nscan = buckets + 1;
    float cs = in->kp->radius * in->h;
    GLuint groups = (in->count + 63u) / 64u;
    GLuint gx = groups < 65535u ? groups : 65535u, gy = gx ? (groups + gx - 1) / gx : 0;
    glClearNamedBufferSubData(a->count, GL_R32UI, 0, (GLsizeiptr)need * 4, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
    aniso_step(ctx, count, in, buckets, cs, nscan, gx, gy, GL_SHADER_STORAGE_BARRIER_BIT);
    vfx_result r = volfx_gpu_scan(ctx, a->count, a->start, nscan, "water aniso grid");
    if (r)
        return r;
    bind_all(a, in);
    glClearNamedBufferSubData(a->count, GL_R32UI, 0, (GLsizeiptr)need * 4, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
    aniso_step(ctx, scatter, in, buckets, cs, nscan, gx, gy, GL_SHADER_STORAGE_BARRIER_BIT);
    a->grid_rev = in->data_rev;
    a->grid_count = in->count;
    a->grid_buckets = buckets;
    a->grid_cs = cs;
    memcpy(a->grid_lo, in->lo, sizeof a->grid_lo);
    return VFX_OK;
}

vfx_result volfx_water_aniso_grid_build(vfx_context *ctx, volfx_water_aniso *a, const volfx_water_aniso_input *in,
                                        volfx_water_aniso_grid *out)
{
    float cs = in->kp->radius * in->h;
    if (!(a->grid_rev && a->grid_rev == in->data_rev && a->grid_count == in->count && a->grid_cs == cs &&
          !memcmp(a->grid_lo, in->lo, sizeof a->grid_lo))) {
        vfx_result r = ensure_buffers(ctx, a, in);
        if (r)
            return r;
        bind_all(a, in);
        volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.aniso_grid", .compute = true});
        r = grid_steps(ctx, a, in);
        volfx_pass_end(ctx);
        if (r)
            return r;
    }
    *out = (volfx_water_aniso_grid){a->sorted, a->start, a->grid_buckets, a->grid_cs,
                                    {a->grid_lo[0], a->grid_lo[1], a->grid_lo[2]}};
    return VFX_OK;
}

/* One invocation a particle (groups of 64, rows of at most 65535 groups) of the bound program,
 * then the barrier, the end of the open pass's timer and the GL error check (`what` names the
 * pass in the message). */
static vfx_result particle_dispatch_end(vfx_context *ctx, uint32_t count, const char *what)
{
    GLuint groups = (count + 63u) / 64u;
    GLuint gx = groups < 65535u ? groups : 65535u, gy = gx ? (groups + gx - 1) / gx : 0;
    if (groups)
        glDispatchCompute(gx, gy, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    volfx_pass_end(ctx);
    const char *e = volfx_gpu_error_string();
    if (e)
        return volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR, "water aniso %s over %u particles: %s", what, count, e);
    return VFX_OK;
}

/* The half rate's other upload: the centres to the new positions, the shapes (and the neighbour
 * counts the spray reads) kept from the last full pass. */
static vfx_result centre_pass(vfx_context *ctx, volfx_water_aniso *a, const volfx_water_aniso_input *in)
{
    GLuint prog = volfx_gpu_compute(ctx, "water/aniso.comp", "#define MODE_CENTRE\n");
    if (!prog)
        return VFX_ERR_GL;
    bind_all(a, in);
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.aniso_centre", .compute = true});
    glUseProgram(prog);
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_count"), in->count);
    vfx_result r = particle_dispatch_end(ctx, in->count, "centre pass");
    if (r)
        return r;
    a->shape_fresh = false;
    a->done_rev = in->data_rev;
    volfx_stat_set(ctx, "water.aniso_half_skipped", 1);
    return VFX_OK;
}

vfx_result volfx_water_aniso_compute(vfx_context *ctx, volfx_water_aniso *a, const volfx_water_aniso_input *in)
{
    const volfx_water_kernel_params *kp = in->kp;
    bool aniso = kp->kernel == VFX_WATER_KERNEL_ANISOTROPIC && !a->has_kernel;
    bool same_setup = a->done && a->done_count == in->count && a->done_h == in->h && !memcmp(&a->done_kp, kp, sizeof *kp) &&
                      a->done_radius == a->has_radius && a->done_kernel == a->has_kernel;
    if (same_setup && in->data_rev && a->done_rev == in->data_rev) {
        volfx_stat_set(ctx, "water.aniso_skipped", 1);
        return VFX_OK;
    }
    volfx_stat_set(ctx, "water.aniso_skipped", 0);
    vfx_result r = ensure_buffers(ctx, a, in);
    if (r)
        return r;
    if (in->half_rate && aniso && a->searched && a->shape_fresh && same_setup && kp->smoothing == 0)
        return centre_pass(ctx, a, in);
    volfx_stat_set(ctx, "water.aniso_half_skipped", 0);
    uint32_t need, buckets = grid_buckets(in->count, &need), nscan = buckets + 1;
    GLuint kern = volfx_gpu_compute(ctx, "water/aniso.comp", "#define MODE_KERNEL\n");
    if (!kern)
        return VFX_ERR_GL;
    bind_all(a, in);
    float cs = kp->radius * in->h;
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.aniso", .compute = true});
    if (aniso && (r = grid_steps(ctx, a, in))) {
        volfx_pass_end(ctx);
        return r;
    }
    glUseProgram(kern);
    aniso_uniforms(ctx, kern, in, buckets, cs, nscan);
    glUniform1i(volfx_gpu_uniform(ctx, kern, "u_radius"), a->has_radius);
    glUniform1i(volfx_gpu_uniform(ctx, kern, "u_host"), a->has_kernel);
    glUniform1i(volfx_gpu_uniform(ctx, kern, "u_aniso"), aniso);
    if ((r = particle_dispatch_end(ctx, in->count, "pass")))
        return r;
    a->done = true;
    a->done_rev = in->data_rev;
    a->done_count = in->count;
    a->done_h = in->h;
    a->done_kp = *kp;
    a->done_radius = a->has_radius;
    a->done_kernel = a->has_kernel;
    a->searched = aniso;
    a->shape_fresh = true;
    volfx_stat_set(ctx, "water.aniso_buckets", aniso ? buckets : 0);
    return VFX_OK;
}
