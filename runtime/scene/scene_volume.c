/* scene_volume.c — the volume section of a scene (docs/scene-format.md), its transfer function
 * and generated volumes. */
#include "scene/scene_parse.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool rt_scene_ends_with(const char *s, const char *suffix)
{
    size_t a = strlen(s), b = strlen(suffix);
    return a >= b && strcmp(s + a - b, suffix) == 0;
}

/* volume.animate.rim {gain, power} and .hit_ripple {gain, wavelength, speed, reach}: the
 * energy-shield terms the game adds to the scalar (sample_game/volume_shield.c). */
static vfx_result parse_shield(pctx *c, const cJSON *a, rt_scene_volume_animation *an)
{
    vfx_result r = VFX_OK;
    const cJSON *rim = cJSON_GetObjectItemCaseSensitive(a, "rim");
    if (rim) {
        static const char *const k[] = {"gain", "power", NULL};
        const char *PR = "volume.animate.rim";
        if ((r = rt_scene_expect_object(c, rim, PR)))
            return r;
        rt_scene_check_keys(c, rim, PR, k);
        an->rim_power = 3.0f;
        r = rt_scene_get_float(c, rim, PR, "gain", true, (range){0, 1e3, false}, &an->rim_gain);
        if (!r) r = rt_scene_get_float(c, rim, PR, "power", false, (range){0.1, 64, false}, &an->rim_power);
        if (r)
            return r;
    }
    const cJSON *hit = cJSON_GetObjectItemCaseSensitive(a, "hit_ripple");
    if (hit) {
        static const char *const k[] = {"gain", "wavelength", "speed", "reach", NULL};
        const char *PH = "volume.animate.hit_ripple";
        if ((r = rt_scene_expect_object(c, hit, PH)))
            return r;
        rt_scene_check_keys(c, hit, PH, k);
        an->hit_wavelength = 0.5f, an->hit_speed = 1.0f, an->hit_reach = 1.0f;
        r = rt_scene_get_float(c, hit, PH, "gain", true, (range){0, 1e3, false}, &an->hit_gain);
        if (!r) r = rt_scene_get_float(c, hit, PH, "wavelength", false, POSITIVE, &an->hit_wavelength);
        if (!r) r = rt_scene_get_float(c, hit, PH, "speed", false, (range){0, 1e3, false}, &an->hit_speed);
        if (!r) r = rt_scene_get_float(c, hit, PH, "reach", false, POSITIVE, &an->hit_reach);
    }
    return r;
}

/* volume.animate: {"ripple": {amplitude, wavelength, period_s}, "beam_glow": {gain, reach},
 * "transfer_pulse": {rgba, width, period_s}, "rim": {gain, power}, "hit_ripple": {gain,
 * wavelength, speed, reach}}; absent parts stay 0 (off). */
static vfx_result parse_animation(pctx *c, const cJSON *a, rt_scene_volume_animation *an)
{
    if (!a)
        return VFX_OK;
    static const char *const keys[] = {"ripple", "beam_glow", "transfer_pulse", "rim", "hit_ripple", NULL};
    const char *P = "volume.animate";
    vfx_result r = rt_scene_expect_object(c, a, P);
    if (r)
        return r;
    rt_scene_check_keys(c, a, P, keys);
    const cJSON *rp = cJSON_GetObjectItemCaseSensitive(a, "ripple");
    if (rp) {
        static const char *const k[] = {"amplitude", "wavelength", "period_s", NULL};
        const char *PR = "volume.animate.ripple";
        if ((r = rt_scene_expect_object(c, rp, PR)))
            return r;
        rt_scene_check_keys(c, rp, PR, k);
        an->ripple_wavelength = 0.5f, an->ripple_period_s = 1.5f;
        r = rt_scene_get_float(c, rp, PR, "amplitude", true, (range){0, 0.5, false}, &an->ripple_amplitude);
        if (!r) r = rt_scene_get_float(c, rp, PR, "wavelength", false, POSITIVE, &an->ripple_wavelength);
        if (!r) r = rt_scene_get_float(c, rp, PR, "period_s", false, POSITIVE, &an->ripple_period_s);
        if (r)
            return r;
    }
    const cJSON *g = cJSON_GetObjectItemCaseSensitive(a, "beam_glow");
    if (g) {
        static const char *const k[] = {"gain", "reach", NULL};
        const char *PG = "volume.animate.beam_glow";
        if ((r = rt_scene_expect_object(c, g, PG)))
            return r;
        rt_scene_check_keys(c, g, PG, k);
        an->glow_reach = 2.0f;
        r = rt_scene_get_float(c, g, PG, "gain", true, (range){0, 1e3, false}, &an->glow_gain);
        if (!r) r = rt_scene_get_float(c, g, PG, "reach", false, (range){0, 100, true}, &an->glow_reach);
        if (r)
            return r;
    }
    const cJSON *tp = cJSON_GetObjectItemCaseSensitive(a, "transfer_pulse");
    if (tp) {
        static const char *const k[] = {"rgba", "width", "period_s", NULL};
        const char *PT = "volume.animate.transfer_pulse";
        if ((r = rt_scene_expect_object(c, tp, PT)))
            return r;
        rt_scene_check_keys(c, tp, PT, k);
        an->pulse_width = 0.03f, an->pulse_period_s = 3.0f;
        r = rt_scene_get_vec(c, tp, PT, "rgba", 4, true, (range){0, 1e3, false}, an->pulse_rgba);
        if (!r) r = rt_scene_get_float(c, tp, PT, "width", false, (range){0, 0.25, true}, &an->pulse_width);
        if (!r) r = rt_scene_get_float(c, tp, PT, "period_s", false, POSITIVE, &an->pulse_period_s);
        if (r)
            return r;
    }
    return parse_shield(c, a, an);
}

vfx_result rt_scene_parse_volume(pctx *c, const cJSON *v, rt_scene_volume *vol)
{
    static const char *const keys[] = {"path", "generator", "scalar", "transfer", "transfer_normalized",
                                       "ert_threshold", "tiles", "update_c", "workers",
                                       "translate", "rotate_deg", "scale", "matrix", "transfer_method", "animate", NULL};
    const char *P = "volume";
    vfx_result r = rt_scene_expect_object(c, v, P);
    if (r)
        return r;
    rt_scene_check_keys(c, v, P, keys);
    const cJSON *path = cJSON_GetObjectItemCaseSensitive(v, "path"), *gen = cJSON_GetObjectItemCaseSensitive(v, "generator");
    if (!path == !gen)
        return rt_scene_failf(c, VFX_ERR_FORMAT, P, "needs exactly one of \"path\" (.vtu or .node) or \"generator\"");
    if (path) {
        if ((r = rt_scene_get_path(c, v, P, "path", true, vol->path)))
            return r;
        if (!rt_scene_ends_with(vol->path, ".vtu") && !rt_scene_ends_with(vol->path, ".node"))
            return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, "volume.path",
                         "\"%.200s\" is neither a .vtu nor a TetGen .node file", vol->path);
    } else {
        static const char *const gkeys[] = {"cells", "min", "max", NULL};
        const char *PG = "volume.generator";
        if ((r = rt_scene_expect_object(c, gen, PG)))
            return r;
        rt_scene_check_keys(c, gen, PG, gkeys);
        vol->generated = true;
        vol->gen_cells = 8;
        vol->gen_min[0] = vol->gen_min[1] = vol->gen_min[2] = -1;
        vol->gen_max[0] = vol->gen_max[1] = vol->gen_max[2] = 1;
        r = rt_scene_get_uint(c, gen, PG, "cells", false, 1, RT_SCENE_MAX_VOLUME_CELLS, &vol->gen_cells);
        if (!r) r = rt_scene_get_vec(c, gen, PG, "min", 3, false, COORD, vol->gen_min); /* model space */
        if (!r) r = rt_scene_get_vec(c, gen, PG, "max", 3, false, COORD, vol->gen_max);
        for (int k = 0; k < 3 && !r; ++k)
            if (!(vol->gen_max[k] > vol->gen_min[k]))
                r = rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, "volume.generator.max",
                          "must exceed min on every axis (axis %d: %g <= %g)", k, vol->gen_max[k], vol->gen_min[k]);
        if (r)
            return r;
    }
    r = rt_scene_get_string(c, v, P, "scalar", false, vol->scalar, sizeof vol->scalar);
    if (!r) r = rt_scene_get_bool(c, v, P, "transfer_normalized", &vol->transfer_normalized);
    /* the plugin's ranges (volfx_ranges.h) */
    if (!r) r = rt_scene_get_float_row(c, v, P, "ert_threshold", VFX_RANGE_VOLUME_ERT_THRESHOLD, &vol->ert_threshold);
    if (!r) r = rt_scene_get_uint_row(c, v, P, "tiles", VFX_RANGE_VOLUME_TILES, &vol->tiles);
    if (!r) r = rt_scene_get_uint_row(c, v, P, "update_c", VFX_RANGE_VOLUME_UPDATE_C, &vol->update_c);
    if (!r) r = rt_scene_get_uint_row(c, v, P, "workers", VFX_RANGE_VOLUME_WORKERS, &vol->workers);
    if (!r) {
        char method[32] = "exact";
        r = rt_scene_get_string(c, v, P, "transfer_method", false, method, sizeof method);
        if (!r && !strcmp(method, "preintegrated"))
            vol->transfer_method = VFX_VOLUME_TRANSFER_PREINTEGRATED;
        else if (!r && strcmp(method, "exact"))
            r = rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, "volume.transfer_method",
                            "\"%.40s\" is neither \"exact\" nor \"preintegrated\"", method);
    }
    if (!r) r = parse_animation(c, cJSON_GetObjectItemCaseSensitive(v, "animate"), &vol->anim);
    if (!r) r = rt_scene_parse_transform(c, v, P, vol->model);
    if (r)
        return r;
    const cJSON *tf = cJSON_GetObjectItemCaseSensitive(v, "transfer");
    if (!tf)
        return VFX_OK;
    const char *PT = "volume.transfer";
    if (!cJSON_IsArray(tf))
        return rt_scene_failf(c, VFX_ERR_FORMAT, PT, "expected an array of {\"scalar\", \"rgba\"}, got %s", rt_scene_type_name(tf));
    int n = cJSON_GetArraySize(tf);
    if (n < 1 || n > RT_SCENE_MAX_TRANSFER)
        return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, PT, "%d control points; must be 1 to %d", n, RT_SCENE_MAX_TRANSFER);
    int i = 0;
    for (const cJSON *e = tf->child; e; e = e->next, ++i) {
        static const char *const tkeys[] = {"scalar", "rgba", NULL};
        char PI[JPATH];
        rt_scene_join_index(PI, PT, i);
        rt_scene_transfer_point *tp = &vol->transfer[i];
        if ((r = rt_scene_expect_object(c, e, PI)))
            return r;
        rt_scene_check_keys(c, e, PI, tkeys);
        r = rt_scene_get_float(c, e, PI, "scalar", true, vol->transfer_normalized ? UNIT : (range){-1e30, 1e30, false}, &tp->scalar);
        if (!r) r = rt_scene_get_vec(c, e, PI, "rgba", 4, true, (range){0, 1e3, false}, tp->rgba);
        if (r)
            return r;
        if (i > 0 && !(tp->scalar > vol->transfer[i - 1].scalar)) {
            char PS[JPATH];
            rt_scene_join(PS, PI, "scalar");
            return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, PS, "control points must increase strictly (%g after %g)",
                         tp->scalar, vol->transfer[i - 1].scalar);
        }
        vol->transfer_count = (uint32_t)i + 1;
    }
    return VFX_OK;
}

void rt_scene_transfer_sample(const rt_scene_volume *v, uint32_t n, float *rgba, float *smin, float *smax)
{
    if (!v || !rgba || n < 2)
        return;
    uint32_t m = v->transfer_count;
    const rt_scene_transfer_point *tp = v->transfer;
    if (smin) *smin = 0;
    if (smax) *smax = 0;
    if (m == 0) { /* grey ramp, opacity rising with the scalar */
        for (uint32_t j = 0; j < n; ++j) {
            float f = (float)j / (float)(n - 1);
            rgba[4 * j] = rgba[4 * j + 1] = rgba[4 * j + 2] = f, rgba[4 * j + 3] = f;
        }
        return;
    }
    double lo = tp[0].scalar, hi = tp[m - 1].scalar;
    if (!v->transfer_normalized) {
        if (smin) *smin = (float)lo;
        if (smax) *smax = (float)hi;
    }
    uint32_t seg = 0;
    for (uint32_t j = 0; j < n; ++j) {
        double s = lo + (hi - lo) * j / (n - 1);
        while (seg + 1 < m - 1 && s > tp[seg + 1].scalar)
            ++seg;
        float *o = &rgba[4 * j];
        if (m == 1 || s <= tp[0].scalar) {
            memcpy(o, tp[0].rgba, 4 * sizeof(float));
        } else if (s >= tp[m - 1].scalar) {
            memcpy(o, tp[m - 1].rgba, 4 * sizeof(float));
        } else {
            double f = (s - tp[seg].scalar) / ((double)tp[seg + 1].scalar - tp[seg].scalar);
            for (int k = 0; k < 4; ++k)
                o[k] = (float)(tp[seg].rgba[k] + f * ((double)tp[seg + 1].rgba[k] - tp[seg].rgba[k]));
        }
    }
}

vfx_result rt_scene_volume_generate(const rt_scene_volume *v, float **points, uint32_t *point_count,
                                     uint32_t **tets, uint32_t *tet_count, float **scalar, char *err, size_t errlen)
{
    if (!v || !points || !point_count || !tets || !tet_count || !scalar || !v->generated || v->gen_cells == 0 ||
        v->gen_cells > RT_SCENE_MAX_VOLUME_CELLS) {
        if (err && errlen)
            snprintf(err, errlen, "volume.generator: NULL argument, not a generated volume or cells out of range");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    uint32_t n = v->gen_cells, np1 = n + 1;
    size_t np = (size_t)np1 * np1 * np1, nt = (size_t)6 * n * n * n;
    float *P = malloc(np * 3 * sizeof(float)), *S = malloc(np * sizeof(float));
    uint32_t *T = malloc(nt * 4 * sizeof(uint32_t));
    if (!P || !S || !T) {
        free(P), free(S), free(T);
        if (err && errlen)
            snprintf(err, errlen, "volume.generator: out of memory");
        return VFX_ERR_OUT_OF_MEMORY;
    }
    double c[3], half = 0;
    for (int k = 0; k < 3; ++k) {
        c[k] = 0.5 * ((double)v->gen_min[k] + v->gen_max[k]);
        half += 0.25 * ((double)v->gen_max[k] - v->gen_min[k]) * ((double)v->gen_max[k] - v->gen_min[k]);
    }
    half = sqrt(half);
    for (uint32_t z = 0, i = 0; z < np1; ++z)
        for (uint32_t y = 0; y < np1; ++y)
            for (uint32_t x = 0; x < np1; ++x, ++i) {
                uint32_t q[3] = {x, y, z};
                double d2 = 0;
                for (int k = 0; k < 3; ++k) {
                    double p = v->gen_min[k] + ((double)v->gen_max[k] - v->gen_min[k]) * q[k] / n;
                    P[3 * (size_t)i + k] = (float)p;
                    d2 += (p - c[k]) * (p - c[k]);
                }
                S[i] = (float)(1.0 - sqrt(d2) / half);
            }
    /* Kuhn (Freudenthal) subdivision: 6 tets along the cube's main diagonal, one per axis order;
     * neighbouring cubes then share their face triangulations (a conforming mesh). */
    static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    size_t t = 0;
    for (uint32_t z = 0; z < n; ++z)
        for (uint32_t y = 0; y < n; ++y)
            for (uint32_t x = 0; x < n; ++x)
                for (int pi = 0; pi < 6; ++pi, ++t) {
                    uint32_t q[3] = {x, y, z}, *o = &T[4 * t];
                    for (int s = 0; s < 4; ++s) {
                        if (s > 0)
                            q[perms[pi][s - 1]]++;
                        o[s] = (q[2] * np1 + q[1]) * np1 + q[0];
                    }
                    const float *a = &P[3 * (size_t)o[0]], *b = &P[3 * (size_t)o[1]], *cc = &P[3 * (size_t)o[2]],
                                *d = &P[3 * (size_t)o[3]];
                    double u[3], w[3], e[3];
                    for (int k = 0; k < 3; ++k)
                        u[k] = (double)b[k] - a[k], w[k] = (double)cc[k] - a[k], e[k] = (double)d[k] - a[k];
                    double vol = u[0] * (w[1] * e[2] - w[2] * e[1]) - u[1] * (w[0] * e[2] - w[2] * e[0]) +
                                 u[2] * (w[0] * e[1] - w[1] * e[0]);
                    if (vol < 0) {
                        uint32_t tmp = o[2];
                        o[2] = o[3], o[3] = tmp;
                    }
                }
    *points = P, *point_count = (uint32_t)np, *tets = T, *tet_count = (uint32_t)nt, *scalar = S;
    return VFX_OK;
}
