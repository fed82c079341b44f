/* scene_water.c — the water section of a scene (docs/scene-format.md) and the particles it
 * generates or loads. */
#include "scene/scene_parse.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/particle_file.h"

vfx_result rt_scene_parse_box(pctx *c, const cJSON *obj, const char *path, const char *key, float mn[3], float mx[3])
{
    static const char *const keys[] = {"min", "max", NULL};
    char P[JPATH];
    rt_scene_join(P, path, key);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v)
        return rt_scene_failf(c, VFX_ERR_FORMAT, P, "required {\"min\", \"max\"} box missing");
    vfx_result r = rt_scene_expect_object(c, v, P);
    if (r)
        return r;
    rt_scene_check_keys(c, v, P, keys);
    r = rt_scene_get_point(c, v, P, "min", true, mn);
    if (!r) r = rt_scene_get_point(c, v, P, "max", true, mx);
    for (int k = 0; k < 3 && !r; ++k)
        if (!(mx[k] > mn[k])) {
            char PM[JPATH];
            rt_scene_join(PM, P, "max");
            r = rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, PM, "must exceed min on every axis (axis %d: %g <= %g)", k, mx[k], mn[k]);
        }
    return r;
}

/* No "h" given: h = 2 x the particle spacing, the seed's ratio (h = 0.61 at its spacing of 0.3),
 * where h/spacing sets how many neighbours a point's field sums (~33 at 2: a surface without the
 * single spheres showing, a sheet one particle thick still closed). The spacing is the layers'
 * own or the cube root of the volume per particle of the generated box or sphere or of the
 * simulation's initial fluid box; a file gives none (0: the plugin measures the spacing). */
static float water_h_from_spacing(const rt_scene_water *w)
{
    double vol = 0;
    if (w->count == 0)
        return 0;
    if (w->source == RT_SCENE_WATER_GENERATOR && w->generator == RT_SCENE_GEN_LAYERS)
        return w->spacing > 0 ? 2.0f * w->spacing : 0.0f;
    if (w->source == RT_SCENE_WATER_GENERATOR && w->generator == RT_SCENE_GEN_SPHERE)
        vol = 4.0 / 3.0 * 3.14159265358979 * (double)w->radius * w->radius * w->radius;
    else if (w->source != RT_SCENE_WATER_FILE)
        vol = ((double)w->box_max[0] - w->box_min[0]) * ((double)w->box_max[1] - w->box_min[1]) *
              ((double)w->box_max[2] - w->box_min[2]);
    return vol > 0 ? (float)(2.0 * cbrt(vol / w->count)) : 0.0f;
}

/* water.generator: the kind (layers, box, sphere) and its count and shape. */
static vfx_result parse_water_generator(pctx *c, const cJSON *v, rt_scene_water *w)
{
    static const char *const gkeys[] = {"kind", "count", "origin", "spacing", "layer_side", "min", "max",
                                        "center", "radius", NULL};
    static const char *const kinds[] = {"layers", "box", "sphere", NULL};
    vfx_result r;
    const char *PG = "water.generator";
    const cJSON *g = cJSON_GetObjectItemCaseSensitive(v, "generator");
    if (!g)
        return rt_scene_failf(c, VFX_ERR_FORMAT, PG, "required for source \"generator\"");
    if ((r = rt_scene_expect_object(c, g, PG)))
        return r;
    rt_scene_check_keys(c, g, PG, gkeys);
    uint32_t kind = 0;
    r = rt_scene_get_enum(c, g, PG, "kind", true, kinds, &kind);
    if (!r) r = rt_scene_get_uint(c, g, PG, "count", true, 0, RT_SCENE_MAX_PARTICLES, &w->count);
    if (r)
        return r;
    w->generator = (rt_scene_generator)kind;
    if (kind == RT_SCENE_GEN_LAYERS) {
        r = rt_scene_get_point(c, g, PG, "origin", false, w->origin);
        if (!r) r = rt_scene_get_float(c, g, PG, "spacing", false, POSITIVE, &w->spacing);
        if (!r) r = rt_scene_get_uint(c, g, PG, "layer_side", false, 1, 4096, &w->layer_side);
    } else if (kind == RT_SCENE_GEN_BOX) {
        r = rt_scene_get_point(c, g, PG, "min", true, w->box_min);
        if (!r) r = rt_scene_get_point(c, g, PG, "max", true, w->box_max);
        for (int k = 0; k < 3 && !r; ++k)
            if (!(w->box_max[k] > w->box_min[k]))
                r = rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, "water.generator.max",
                          "must exceed min on every axis (axis %d: %g <= %g)", k, w->box_max[k], w->box_min[k]);
    } else {
        r = rt_scene_get_point(c, g, PG, "center", false, w->center);
        if (!r) r = rt_scene_get_float(c, g, PG, "radius", true, POSITIVE, &w->radius);
    }
    return r;
}

/* water.simulation: the tank, the initial fluid box, the particle count, gravity, dt, no-slip
 * walls and the optional paddle. */
static vfx_result parse_water_simulation(pctx *c, const cJSON *v, rt_scene_water *w)
{
    static const char *const skeys[] = {"tank", "fluid", "particle_count", "gravity", "dt", "paddle", "no_slip",
                                        "solver", "settle_steps", "impact_strength", "impact_radius", "device", NULL};
    static const char *const solvers[] = {"wcsph", "pbf", NULL}; /* rt_sph_solver order */
    vfx_result r;
    const char *PS = "water.simulation";
    const cJSON *s = cJSON_GetObjectItemCaseSensitive(v, "simulation");
    if (!s)
        return rt_scene_failf(c, VFX_ERR_FORMAT, PS, "required for source \"simulation\"");
    if ((r = rt_scene_expect_object(c, s, PS)))
        return r;
    rt_scene_check_keys(c, s, PS, skeys);
    r = rt_scene_parse_box(c, s, PS, "tank", w->tank_min, w->tank_max);
    if (!r) r = rt_scene_parse_box(c, s, PS, "fluid", w->box_min, w->box_max);
    for (int k = 0; k < 3 && !r; ++k)
        if (w->box_min[k] < w->tank_min[k] || w->box_max[k] > w->tank_max[k])
            r = rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, "water.simulation.fluid", "must lie inside the tank (axis %d)", k);
    if (!r) r = rt_scene_get_uint(c, s, PS, "particle_count", true, 0, RT_SCENE_MAX_PARTICLES, &w->count);
    if (!r) r = rt_scene_get_vec(c, s, PS, "gravity", 3, false, (range){-1000, 1000, false}, w->gravity);
    if (!r) r = rt_scene_get_float(c, s, PS, "dt", false, (range){0, 0.1, true}, &w->dt);
    if (!r) r = rt_scene_get_bool(c, s, PS, "no_slip", &w->no_slip);
    w->solver = 1; /* "pbf" when the key is absent (issue 22: 5-7x cheaper per frame, calmer at rest) */
    if (!r) r = rt_scene_get_enum(c, s, PS, "solver", false, solvers, &w->solver);
    static const char *const devices[] = {"auto", "cpu", "gpu", NULL}; /* RT_SCENE_SIM_* order */
    w->device = RT_SCENE_SIM_AUTO;
    if (!r) r = rt_scene_get_enum(c, s, PS, "device", false, devices, &w->device);
    if (!r && w->device == RT_SCENE_SIM_GPU && w->solver != 1)
        r = rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, "water.simulation.device",
                           "\"gpu\" runs the PBF solver only: set water.simulation.solver to \"pbf\" (or device \"cpu\")");
    w->settle_steps = 120; /* absent: the block settles before frame 0 (issue 22: it sank at ~1 m/s) */
    if (!r) r = rt_scene_get_uint(c, s, PS, "settle_steps", false, 0, 10000, &w->settle_steps);
    /* a beam striking the water pushes the fluid (docs/simulation.md "Impacts"); 0 switches it off */
    w->impact_strength = 4.f, w->impact_radius = 0.25f;
    if (!r) r = rt_scene_get_float(c, s, PS, "impact_strength", false, (range){0, 50, false}, &w->impact_strength);
    if (!r) r = rt_scene_get_float(c, s, PS, "impact_radius", false, (range){0.01, 10, false}, &w->impact_radius);
    if (r)
        return r;
    const cJSON *pd = cJSON_GetObjectItemCaseSensitive(s, "paddle");
    if (pd) {
        static const char *const pkeys[] = {"axis", "amplitude", "period_s", "ramp_s", NULL};
        static const char *const axes[] = {"x", "y", "z", NULL};
        const char *PP = "water.simulation.paddle";
        if ((r = rt_scene_expect_object(c, pd, PP)))
            return r;
        rt_scene_check_keys(c, pd, PP, pkeys);
        w->paddle = true;
        r = rt_scene_get_enum(c, pd, PP, "axis", false, axes, &w->paddle_axis);
        if (!r) r = rt_scene_get_float(c, pd, PP, "amplitude", false, NONNEG, &w->paddle_amplitude);
        if (!r) r = rt_scene_get_float(c, pd, PP, "period_s", false, (range){0, 1e4, true}, &w->paddle_period_s);
        w->paddle_ramp_s = -1.f; /* absent: one period (issue 22: it started at its peak speed) */
        /* 0 is documented: full amplitude from t = 0 (the solver's motion_ramp_s 0) */
        if (!r) r = rt_scene_get_float(c, pd, PP, "ramp_s", false, (range){0, 1e4, false}, &w->paddle_ramp_s);
        if (r)
            return r;
        if (w->paddle_ramp_s < 0.f)
            w->paddle_ramp_s = w->paddle_period_s;
    }
    return VFX_OK;
}

/* water.quality (present): the method, its sample and step limits, the features switched off and
 * the kernel; writes w->params. The lab's baselines and ablation bits are no scene keys: tests and
 * benches chain vfx_lab_water themselves. */
static vfx_result parse_water_quality(pctx *c, const cJSON *q, rt_scene_water *w)
{
    vfx_water_params *wp = &w->params;
    static const char *const qkeys[] = {"max_samples", "step", "refine_iters", "pyramid_level", "method",
                                        "disable", "kernel", "preset", NULL};
    static const char *const methods[] = {"paper", "tile", NULL};
    static const uint32_t method_ids[] = {VFX_WATER_METHOD_PAPER, VFX_WATER_METHOD_TILE};
    static const char *const presets[] = {"low", "medium", "high", "ultra", NULL};
    static const char *const flags[] = {"spray", "ssr", NULL};
    static const uint32_t bits[] = {VFX_WATER_NO_SPRAY, VFX_WATER_NO_SSR}; /* vfx_water_params.features_off */
    vfx_result r;
    const char *PQ = "water.quality";
    if ((r = rt_scene_expect_object(c, q, PQ)))
        return r;
    rt_scene_check_keys(c, q, PQ, qkeys);
    r = rt_scene_get_uint_row(c, q, PQ, "max_samples", VFX_RANGE_WATER_MAX_SAMPLES, &wp->max_samples);
    if (!r) r = rt_scene_get_float_row(c, q, PQ, "step", VFX_RANGE_WATER_STEP, &wp->step);
    if (!r) r = rt_scene_get_uint_row(c, q, PQ, "refine_iters", VFX_RANGE_WATER_REFINE_ITERS, &wp->refine_iters);
    if (!r) r = rt_scene_get_uint_row(c, q, PQ, "pyramid_level", VFX_RANGE_WATER_PYRAMID_LEVEL, &wp->pyramid_level);
    uint32_t mi = 1;
    if (!r) r = rt_scene_get_enum(c, q, PQ, "method", false, methods, &mi);
    wp->method = method_ids[mi];
    uint32_t method = method_ids[mi];
    if (!r && cJSON_GetObjectItemCaseSensitive(q, "preset")) {
        uint32_t pi = 0;
        r = rt_scene_get_enum(c, q, PQ, "preset", false, presets, &pi);
        wp->preset = VFX_WATER_PRESET_LOW + pi;
    }
    if (!r) r = rt_scene_get_flags(c, q, PQ, "disable", flags, bits, &wp->features_off);
    if (!r && cJSON_GetObjectItemCaseSensitive(q, "kernel")) {
        static const char *const kernels[] = {"isotropic", "anisotropic", NULL};
        uint32_t k = 0;
        r = rt_scene_get_enum(c, q, PQ, "kernel", false, kernels, &k);
        wp->kernel = k == 1 ? VFX_WATER_KERNEL_ANISOTROPIC : VFX_WATER_KERNEL_ISOTROPIC;
        if (!r && wp->kernel == VFX_WATER_KERNEL_ANISOTROPIC && method != VFX_WATER_METHOD_TILE)
            r = rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, "water.quality.kernel",
                            "\"anisotropic\" is drawn by method \"tile\" only (method \"%s\" draws the seed's isotropic kernel)",
                            methods[mi]);
    }
    return r;
}

/* water.diffuse (vfx_water_params' diffuse fields; the plugin checks the ranges' relations). */
static vfx_result parse_diffuse(pctx *c, const cJSON *v, rt_scene_water *w)
{
    static const char *const keys[] = {"max", "gravity", "trapped_air", "wave_crest", "energy", "rate_trapped_air",
                                       "rate_wave_crest", "lifetime", "buoyancy", "drag", "spray_below",
                                       "bubble_above", NULL};
    vfx_water_params *d = &w->params;
    const cJSON *o = cJSON_GetObjectItemCaseSensitive(v, "diffuse");
    const char *P = "water.diffuse";
    vfx_result r = VFX_OK;
    if (o) {
        if ((r = rt_scene_expect_object(c, o, P)))
            return r;
        rt_scene_check_keys(c, o, P, keys);
        const range POS4 = {0, 1e4, true};
        r = rt_scene_get_uint(c, o, P, "max", false, 1, 4194304, &d->diffuse_max);
        if (!r) r = rt_scene_get_vec(c, o, P, "gravity", 3, false, (range){-1e4, 1e4, false}, d->gravity);
        if (!r) r = rt_scene_get_vec(c, o, P, "trapped_air", 2, false, POS4, d->trapped_air);
        if (!r) r = rt_scene_get_vec(c, o, P, "wave_crest", 2, false, POS4, d->wave_crest);
        if (!r) r = rt_scene_get_vec(c, o, P, "energy", 2, false, POS4, d->energy);
        if (!r) r = rt_scene_get_float(c, o, P, "rate_trapped_air", false, (range){0, 1e4, false}, &d->rate_trapped_air);
        if (!r) r = rt_scene_get_float(c, o, P, "rate_wave_crest", false, (range){0, 1e4, false}, &d->rate_wave_crest);
        if (!r) r = rt_scene_get_float(c, o, P, "lifetime", false, (range){0, 60, true}, &d->lifetime);
        if (!r) r = rt_scene_get_float(c, o, P, "buoyancy", false, (range){0, 20, true}, &d->buoyancy);
        if (!r) r = rt_scene_get_float(c, o, P, "drag", false, (range){0, 60, true}, &d->drag);
        if (!r) r = rt_scene_get_uint(c, o, P, "spray_below", false, 1, 10000, &d->spray_below);
        if (!r) r = rt_scene_get_uint(c, o, P, "bubble_above", false, 1, 10000, &d->bubble_above);
        for (int k = 0; !r && k < 3; ++k) {
            const float *pr = k == 0 ? d->trapped_air : k == 1 ? d->wave_crest : d->energy;
            static const char *const names[] = {"trapped_air", "wave_crest", "energy"};
            char PK[JPATH];
            rt_scene_join(PK, P, names[k]);
            if ((pr[0] != 0 || pr[1] != 0) && !(pr[0] < pr[1]))
                r = rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, PK, "[min, max] needs min < max (got [%g, %g])", pr[0], pr[1]);
        }
        if (!r && d->spray_below && d->bubble_above && d->spray_below > d->bubble_above) {
            char PK[JPATH];
            rt_scene_join(PK, P, "spray_below");
            r = rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, PK, "%u is above bubble_above %u", d->spray_below, d->bubble_above);
        }
    }
    /* the spray falls with the simulation's gravity unless the scene says otherwise */
    if (!r && rt_scene_is_zero3(d->gravity) && w->source == RT_SCENE_WATER_SIMULATION)
        memcpy(d->gravity, w->gravity, sizeof d->gravity);
    return r;
}

/* water.foam (vfx_water_foam; each number against its row of volfx_ranges.h). */
static vfx_result parse_foam(pctx *c, const cJSON *v, rt_scene_water *w)
{
    static const char *const keys[] = {"layer", "impacts", "lifetime", "cell", "diffusion", "deposit",
                                       "impact_rate", "impact_speed", NULL};
    static const char *const onoff[] = {"on", "off", NULL};
    vfx_water_foam *f = &w->foam;
    f->type = VFX_TYPE_WATER_FOAM;
    const cJSON *o = cJSON_GetObjectItemCaseSensitive(v, "foam");
    const char *P = "water.foam";
    if (!o)
        return VFX_OK;
    vfx_result r = rt_scene_expect_object(c, o, P);
    if (r)
        return r;
    rt_scene_check_keys(c, o, P, keys);
    uint32_t k = 0;
    if (cJSON_GetObjectItemCaseSensitive(o, "layer") && !(r = rt_scene_get_enum(c, o, P, "layer", false, onoff, &k)))
        f->layer = k == 0 ? VFX_WATER_FOAM_ON : VFX_WATER_FOAM_OFF;
    if (!r && cJSON_GetObjectItemCaseSensitive(o, "impacts") && !(r = rt_scene_get_enum(c, o, P, "impacts", false, onoff, &k)))
        f->impacts = k == 0 ? VFX_WATER_FOAM_ON : VFX_WATER_FOAM_OFF;
    if (!r) r = rt_scene_get_float_row(c, o, P, "lifetime", VFX_RANGE_WATER_FOAM_LIFETIME, &f->lifetime);
    if (!r) r = rt_scene_get_float_row(c, o, P, "cell", VFX_RANGE_WATER_FOAM_CELL, &f->cell);
    if (!r) r = rt_scene_get_float_row(c, o, P, "diffusion", VFX_RANGE_WATER_FOAM_DIFFUSION, &f->diffusion);
    if (!r) r = rt_scene_get_float_row(c, o, P, "deposit", VFX_RANGE_WATER_FOAM_DEPOSIT, &f->deposit);
    if (!r) r = rt_scene_get_float_row(c, o, P, "impact_rate", VFX_RANGE_WATER_FOAM_IMPACT_RATE, &f->impact_rate);
    if (!r) r = rt_scene_get_float_row(c, o, P, "impact_speed", VFX_RANGE_WATER_FOAM_IMPACT_SPEED, &f->impact_speed);
    return r;
}

vfx_result rt_scene_parse_water(pctx *c, const cJSON *v, rt_scene_water *w)
{
    static const char *const keys[] = {"source", "path", "generator", "simulation", "h", "threshold",
                                       "quality", "color", "absorption", "ior", "diffuse", "foam", NULL};
    static const char *const sources[] = {"file", "generator", "simulation", NULL};
    const char *P = "water";
    vfx_result r = rt_scene_expect_object(c, v, P);
    if (r)
        return r;
    rt_scene_check_keys(c, v, P, keys);
    uint32_t src = 0;
    if ((r = rt_scene_get_enum(c, v, P, "source", true, sources, &src)))
        return r;
    w->source = (rt_scene_water_source)src;
    w->layer_side = 24;
    w->spacing = 0.1f;
    w->dt = 1.0f / 60.0f; /* the clock step: one solver call per 60 Hz frame */
    w->gravity[1] = -9.81f;
    w->paddle_amplitude = 0.2f;
    w->paddle_period_s = 2.0f;
    if (w->source == RT_SCENE_WATER_FILE) {
        if ((r = rt_scene_get_path(c, v, P, "path", true, w->path)))
            return r;
    } else if (w->source == RT_SCENE_WATER_GENERATOR) {
        if ((r = parse_water_generator(c, v, w)))
            return r;
    } else if ((r = parse_water_simulation(c, v, w))) {
        return r;
    }
    vfx_water_params *wp = &w->params;
    /* ours (TILE) unless water.quality.method names another */
    *wp = (vfx_water_params){.type = VFX_TYPE_WATER_PARAMS, .method = VFX_WATER_METHOD_TILE};
    /* the plugin's ranges (volfx_ranges.h) */
    r = rt_scene_get_float_row(c, v, P, "h", VFX_RANGE_WATER_H, &wp->h);
    if (!r) r = rt_scene_get_float_row(c, v, P, "threshold", VFX_RANGE_WATER_THRESHOLD, &wp->threshold);
    if (!r) r = rt_scene_get_vec(c, v, P, "color", 3, false, rt_scene_range(VFX_RANGE_WATER_COLOR), wp->color);
    if (!r) r = rt_scene_get_float_row(c, v, P, "absorption", VFX_RANGE_WATER_ABSORPTION, &wp->absorption);
    if (!r) r = rt_scene_get_float_row(c, v, P, "ior", VFX_RANGE_WATER_IOR, &wp->ior);
    if (r)
        return r;
    if (wp->h == 0)
        wp->h = water_h_from_spacing(w);
    const cJSON *q = cJSON_GetObjectItemCaseSensitive(v, "quality");
    if (q)
        r = parse_water_quality(c, q, w);
    if (!r)
        r = parse_diffuse(c, v, w);
    if (!r)
        r = parse_foam(c, v, w);
    /* the default: the preset's, as the plugin resolves it (anisotropic for TILE but at preset
     * "low": flat water flat, sheets stay sheets; docs/water.md "Presets"), the seed's isotropic
     * kernel for the other methods */
    if (!r && wp->kernel == VFX_WATER_KERNEL_DEFAULT)
        wp->kernel = wp->method == VFX_WATER_METHOD_TILE && wp->preset != VFX_WATER_PRESET_LOW
                         ? VFX_WATER_KERNEL_ANISOTROPIC
                         : VFX_WATER_KERNEL_ISOTROPIC;
    return r;
}

/* ------------------------------------------------------------------ water and volume data */

static vfx_result lattice_box(const float mn[3], const float mx[3], uint32_t count, float *xyz)
{
    double e[3] = {(double)mx[0] - mn[0], (double)mx[1] - mn[1], (double)mx[2] - mn[2]};
    double d = cbrt(e[0] * e[1] * e[2] / count);
    uint32_t nk[3];
    for (int iter = 0; iter < 100000; ++iter) {
        double prod = 1;
        for (int k = 0; k < 3; ++k) {
            double q = floor(e[k] / d) + 1;
            nk[k] = q > 1e7 ? 10000000u : (uint32_t)q;
            prod *= nk[k];
        }
        if (prod >= count)
            break;
        d *= 0.99;
    }
    uint32_t i = 0;
    /* bottom layers first, so a partial last layer sits on top like a fluid surface */
    for (uint32_t y = 0; y < nk[1] && i < count; ++y)
        for (uint32_t x = 0; x < nk[0] && i < count; ++x)
            for (uint32_t z = 0; z < nk[2] && i < count; ++z, ++i) {
                xyz[3 * (size_t)i] = (float)(mn[0] + x * d);
                xyz[3 * (size_t)i + 1] = (float)(mn[1] + y * d);
                xyz[3 * (size_t)i + 2] = (float)(mn[2] + z * d);
            }
    return i == count ? VFX_OK : VFX_ERR_NUMERIC;
}

static vfx_result lattice_sphere(const float c[3], float r, uint32_t count, float *xyz)
{
    double d = cbrt(4.0 / 3.0 * M_PI * (double)r * r * r / count);
    long m = 0;
    for (int iter = 0; iter < 10000; ++iter) {
        m = (long)floor(r / d);
        double inside = 0;
        for (long y = -m; y <= m; ++y)
            for (long x = -m; x <= m; ++x) {
                double q = (double)r * r - (x * d) * (x * d) - (y * d) * (y * d);
                if (q >= 0)
                    inside += 2 * floor(sqrt(q) / d) + 1;
            }
        if (inside >= count)
            break;
        d *= 0.98;
    }
    uint32_t i = 0;
    for (long y = -m; y <= m && i < count; ++y)
        for (long x = -m; x <= m && i < count; ++x)
            for (long z = -m; z <= m && i < count; ++z) {
                double q = (x * d) * (x * d) + (y * d) * (y * d) + (z * d) * (z * d);
                if (q > (double)r * r)
                    continue;
                xyz[3 * (size_t)i] = (float)(c[0] + x * d);
                xyz[3 * (size_t)i + 1] = (float)(c[1] + y * d);
                xyz[3 * (size_t)i + 2] = (float)(c[2] + z * d);
                ++i;
            }
    return i == count ? VFX_OK : VFX_ERR_NUMERIC;
}

vfx_result rt_scene_water_particles(const rt_scene_water *w, float **xyz, uint32_t *count, char *err,
                                     size_t errlen)
{
    if (!w || !xyz || !count) {
        if (err && errlen)
            snprintf(err, errlen, "water: NULL argument");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    *xyz = NULL;
    *count = 0;
    if (w->source == RT_SCENE_WATER_FILE) {
        vfx_result r = rt_particle_file_load(w->path, xyz, count, err, errlen);
        if (r == VFX_OK && (w->scene_origin[0] != 0 || w->scene_origin[1] != 0 || w->scene_origin[2] != 0))
            for (uint32_t i = 0; i < *count; ++i) /* in double, as the scene's own positions */
                for (int k = 0; k < 3; ++k)
                    (*xyz)[3 * i + k] = (float)((double)(*xyz)[3 * i + k] - w->scene_origin[k]);
        return r;
    }
    uint32_t n = w->count;
    if (n == 0)
        return VFX_OK;
    if (n > RT_SCENE_MAX_PARTICLES) {
        if (err && errlen)
            snprintf(err, errlen, "water: %u particles, above the cap of %u", n, RT_SCENE_MAX_PARTICLES);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    float *p = malloc((size_t)n * 3 * sizeof(float));
    if (!p) {
        if (err && errlen)
            snprintf(err, errlen, "water: out of memory for %u particles", n);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    vfx_result r = VFX_OK;
    if (w->source == RT_SCENE_WATER_GENERATOR && w->generator == RT_SCENE_GEN_LAYERS) {
        uint32_t side = w->layer_side ? w->layer_side : 24, per = side * side;
        for (uint32_t i = 0; i < n; ++i) {
            uint32_t layer = i / per, q = i % per;
            p[3 * (size_t)i] = w->origin[0] + (float)(q % side) * w->spacing;
            p[3 * (size_t)i + 1] = w->origin[1] + (float)layer * w->spacing;
            p[3 * (size_t)i + 2] = w->origin[2] + (float)(q / side) * w->spacing;
        }
    } else if (w->source == RT_SCENE_WATER_GENERATOR && w->generator == RT_SCENE_GEN_SPHERE) {
        r = lattice_sphere(w->center, w->radius, n, p);
    } else {
        r = lattice_box(w->box_min, w->box_max, n, p);
    }
    for (size_t i = 0; i < 3 * (size_t)n && !r; ++i)
        if (!isfinite(p[i]))
            r = VFX_ERR_NUMERIC;
    if (r) {
        free(p);
        if (err && errlen)
            snprintf(err, errlen, "water.generator: could not place %u finite particles", n);
        return r;
    }
    *xyz = p;
    *count = n;
    return VFX_OK;
}
