/* water_params.c — presets, parameter checks and h from the particles' spacing for the water
 * effect (docs/water.md "Presets"). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "context.h"
#include "param_ranges.h"
#include "water_params.h"
#include "lab_hooks.h"

/* What each preset sets in the fields the host left 0. The measured cost and error of each are in
 * docs/water.md ("Presets"); MEDIUM is the recommended default. */
typedef struct preset_def {
    const char *name;
    uint32_t kernel;    /* for TILE; the other methods draw the isotropic kernel only */
    uint32_t disable;   /* added to the host's bits */
    float step_div;     /* step = h / step_div */
    uint32_t refine_iters;
    uint32_t look;      /* WATER_LOOK_* */
} preset_def;

static const preset_def PRESETS[] = {
#define LOOK_ALL (WATER_LOOK_HOST_LIGHT | WATER_LOOK_GGX | WATER_LOOK_FX_LIGHTS | WATER_LOOK_FOAM_LAYER | WATER_LOOK_STEAM)
    /* low keeps the cheap GGX lobe and drops the host-light reads (16 texel reads a water pixel),
     * the loop over the plugin's lights (up to 32 a water pixel), the foam layer (its pass and
     * one texture read a water pixel: the foam particles are splatted one by one instead) and the
     * steam at a beam's impact (its puffs and their draw; the strike's spray stays) */
    [VFX_WATER_PRESET_LOW] = {"low", VFX_WATER_KERNEL_ISOTROPIC, 0, 6.0f, 2, WATER_LOOK_GGX | WATER_LOOK_ANISO_HALF_RATE},
    /* medium: the anisotropic shapes every other upload (high and ultra every upload) */
    [VFX_WATER_PRESET_MEDIUM] = {"medium", VFX_WATER_KERNEL_ANISOTROPIC, 0, 8.0f, 3, LOOK_ALL | WATER_LOOK_ANISO_HALF_RATE},
    [VFX_WATER_PRESET_HIGH] = {"high", VFX_WATER_KERNEL_ANISOTROPIC, VFX_WATER_NO_HALF_RES, 8.0f, 3, LOOK_ALL},
    [VFX_WATER_PRESET_ULTRA] = {"ultra", VFX_WATER_KERNEL_ANISOTROPIC, VFX_WATER_NO_HALF_RES, 16.0f, 5, LOOK_ALL},
};

/* The step's range, relative to h (docs/water.md "Presets"): below h/1024 a pixel's march through
 * a few h of water takes more steps than TILE's bound of 2^15 (and llvmpipe ends every loop of an
 * invocation after 65535 iterations in all: the frame came out empty); above h a step jumps
 * over whole drops of radius h(1 - T) that the subdivision (nodes to h/128 at depth 7) has to
 * open one by one, and a drop is no finer than that. */
#define STEP_MIN_H (1.0f / 1024.0f)
#define STEP_MAX_H 1.0f

vfx_result volfx_water_params_resolve(vfx_context *ctx, const vfx_water_params *in, volfx_water_resolved *out)
{
    memset(out, 0, sizeof *out);
    /* every number against its documented range first (plugin/param_ranges.c): a negative or
     * NaN h, threshold, step, absorption or ior, a colour of NaN or 1e30, an ior of Inf were
     * silently replaced by defaults or gave NaN pixels */
    vfx_result rr = volfx_water_params_check_ranges(ctx, in);
    if (rr)
        return rr;
    if (in->features_off & ~(uint32_t)(VFX_WATER_NO_SPRAY | VFX_WATER_NO_SSR))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_WATER_PARAM,
                          "water: vfx_water_params.features_off 0x%x has bits other "
                          "than VFX_WATER_NO_SPRAY | VFX_WATER_NO_SSR (0x%x)", in->features_off,
                          (unsigned)(VFX_WATER_NO_SPRAY | VFX_WATER_NO_SSR));
    if (in->method != VFX_WATER_METHOD_DEFAULT && in->method != VFX_WATER_METHOD_TILE
        && in->method != VFX_WATER_METHOD_PAPER)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_WATER_PARAM,
                          "water: vfx_water_params.method %u unknown (0 default = tile, 3 tile, 4 paper)", in->method);
    /* the lab's struct (ablation bits, baseline methods): read by the lab library only */
    uint32_t lab_disable = 0, lab_method = 0;
    const void *lab = volfx_chain_find(in->next, VFX_TYPE_LAB_WATER);
    if (lab && !ctx->lab)
        return volfx_fail(ctx, VFX_ERR_UNSUPPORTED, VFX_LOG_ID_WATER_PARAM,
                          "water: a vfx_lab_water (type 0x%x) is chained into vfx_water_params: lab structs are read "
                          "only with the lab library attached (volfx_lab_attach: tests and benches), not by libvolfx",
                          (unsigned)VFX_TYPE_LAB_WATER);
    if (lab && (rr = ctx->lab->water_struct(ctx, lab, &lab_disable, &lab_method)))
        return rr;
    volfx_water_core p = {in->h, in->threshold, in->max_samples, in->step, in->refine_iters, in->pyramid_level,
                          in->features_off | lab_disable, in->method,
                          {in->color[0], in->color[1], in->color[2]}, in->absorption, in->ior};
    if (lab_method)
        p.method = lab_method;
    uint32_t preset = in->preset;
    if (preset > VFX_WATER_PRESET_ULTRA)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_WATER_PARAM,
                          "water: vfx_water_params.preset %u unknown (0 default, 1 low, 2 medium, 3 high, 4 ultra)", preset);
    if (preset == VFX_WATER_PRESET_DEFAULT)
        preset = VFX_WATER_PRESET_MEDIUM;
    const preset_def *d = &PRESETS[preset];
    if (p.method > VFX_WATER_METHOD_PAPER)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_WATER_PARAM,
                          "water: vfx_lab_water.method %u unknown (0 default = tile, 1 brute, 2 grid, 3 tile, 4 paper)",
                          p.method);
    if (p.method == VFX_WATER_METHOD_DEFAULT)
        p.method = VFX_WATER_METHOD_TILE;
    vfx_water_params k2 = *in;
    if (k2.kernel == VFX_WATER_KERNEL_DEFAULT)
        k2.kernel = p.method == VFX_WATER_METHOD_TILE ? d->kernel : VFX_WATER_KERNEL_ISOTROPIC;
    vfx_result r = volfx_water_kernel_params_check(ctx, &k2, &out->kp);
    if (r)
        return r;
    if (p.method == VFX_WATER_METHOD_TILE)
        p.disable |= d->disable;
    /* only 0 means the default here: the range check refused every other value outside */
    if (p.threshold == 0) p.threshold = 0.765625f;
    if (p.max_samples == 0) p.max_samples = 64;
    if (p.refine_iters == 0) p.refine_iters = d->refine_iters;
    if (p.pyramid_level == 0) p.pyramid_level = 3;
    if (p.color[0] == 0 && p.color[1] == 0 && p.color[2] == 0) {
        p.color[0] = 0.15f; p.color[1] = 0.55f; p.color[2] = 0.6f;
    }
    /* no absorption: one relative to h (set_h), so that any scene's water, whatever its units,
     * is clear where it is thin and coloured where it is several h deep */
    out->absorption_per_h = p.absorption == 0;
    if (p.ior == 0) p.ior = 1.333f;
    out->step_div = d->step_div;
    out->preset = preset;
    out->look = d->look;
    float step = p.step;
    p.step = 0;
    if (step > 0) {
        p.step = step;
        out->step_div = -1.0f; /* explicit: set_h checks it against h */
    }
    out->p = p;
    return p.h > 0 ? volfx_water_params_set_h(ctx, out, p.h) : VFX_OK;
}

vfx_result volfx_water_params_set_h(vfx_context *ctx, volfx_water_resolved *r, float h)
{
    r->p.h = h;
    if (r->absorption_per_h)
        r->p.absorption = WATER_ABSORPTION_H / h;
    if (r->step_div > 0) {
        r->p.step = h / r->step_div;
        return VFX_OK;
    }
    if (!(r->p.step >= STEP_MIN_H * h && r->p.step <= STEP_MAX_H * h))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_PARAM_RANGE,
                          "water: vfx_water_params.step %g outside [h/1024, h] = [%g, %g] (h %g): a smaller step "
                          "takes more than 2^15 steps a pixel, a larger one passes whole drops",
                          (double)r->p.step, (double)(STEP_MIN_H * h), (double)(STEP_MAX_H * h), (double)h);
    return VFX_OK;
}

static uint32_t cell_hash(int64_t x, int64_t y, int64_t z, uint32_t mask)
{
    uint64_t k = (uint64_t)x * 73856093u ^ (uint64_t)y * 19349663u ^ (uint64_t)z * 83492791u;
    return (uint32_t)(k ^ (k >> 29)) & mask;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

double volfx_water_spacing(vfx_context *ctx, const float *xyz, uint32_t m, uint32_t stride)
{
    if (m < 2)
        return 0;
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k)
        lo[k] = hi[k] = xyz[k];
    for (uint32_t i = 1; i < m; ++i)
        for (int k = 0; k < 3; ++k) {
            double v = xyz[3 * (size_t)i + k];
            lo[k] = v < lo[k] ? v : lo[k];
            hi[k] = v > hi[k] ? v : hi[k];
        }
    double maxe = 0, vol = 1;
    int dims = 0;
    for (int k = 0; k < 3; ++k)
        maxe = hi[k] - lo[k] > maxe ? hi[k] - lo[k] : maxe;
    if (!(maxe > 0))
        return 0; /* all on one point */
    for (int k = 0; k < 3; ++k)
        if (hi[k] - lo[k] > 1e-4 * maxe) {
            vol *= hi[k] - lo[k];
            ++dims;
        }
    /* cells of the mean spacing over the dimensions the particles span (a layer is 2D): about one
     * particle a cell where they are spread evenly, more where they cluster */
    double cell = pow(vol / m, 1.0 / dims);
    if (cell < 1e-6 * maxe)
        cell = 1e-6 * maxe;
    uint32_t buckets = 1;
    while (buckets < 2u * m && buckets < (1u << 22))
        buckets <<= 1;
    uint32_t *start = volfx_alloc(ctx, ((size_t)buckets + 1 + m) * sizeof *start);
    if (!start)
        return -1;
    uint32_t *order = start + buckets + 1;
    memset(start, 0, ((size_t)buckets + 1) * sizeof *start);
    uint32_t mask = buckets - 1;
#define CELL(i, k) ((int64_t)floor((xyz[3 * (size_t)(i) + (k)] - lo[k]) / cell))
    for (uint32_t i = 0; i < m; ++i)
        ++start[cell_hash(CELL(i, 0), CELL(i, 1), CELL(i, 2), mask) + 1];
    for (uint32_t b = 0; b < buckets; ++b)
        start[b + 1] += start[b];
    uint32_t *fill = volfx_alloc(ctx, (size_t)buckets * sizeof *fill);
    if (!fill) {
        volfx_free(ctx, start);
        return -1;
    }
    memcpy(fill, start, (size_t)buckets * sizeof *fill);
    for (uint32_t i = 0; i < m; ++i)
        order[fill[cell_hash(CELL(i, 0), CELL(i, 1), CELL(i, 2), mask)]++] = i;
    volfx_free(ctx, fill);
    enum { SAMPLES = 512 };
    double nn[SAMPLES];
    uint32_t found = 0, samples = m < SAMPLES ? m : SAMPLES;
    for (uint32_t s = 0; s < samples; ++s) {
        uint32_t i = (uint32_t)((uint64_t)s * m / samples);
        int64_t c[3] = {CELL(i, 0), CELL(i, 1), CELL(i, 2)};
        double best = INFINITY;
        /* the 27 cells around it hold every particle within one cell; a farther nearest
         * neighbour (sparse regions) is found when it falls in them, an upper bound otherwise */
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    uint32_t b = cell_hash(c[0] + dx, c[1] + dy, c[2] + dz, mask);
                    for (uint32_t q = start[b]; q < start[b + 1]; ++q) {
                        uint32_t j = order[q];
                        double d2 = 0;
                        for (int k = 0; k < 3; ++k) {
                            double e = (double)xyz[3 * (size_t)j + k] - xyz[3 * (size_t)i + k];
                            d2 += e * e;
                        }
                        if (d2 > 0 && d2 < best)
                            best = d2;
                    }
                }
        if (isfinite(best))
            nn[found++] = sqrt(best);
    }
#undef CELL
    volfx_free(ctx, start);
    if (!found)
        return 0;
    qsort(nn, found, sizeof nn[0], cmp_double);
    return nn[found / 2] * cbrt((double)stride);
}
