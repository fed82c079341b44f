/* scene_beams.c — the beams section of a scene (docs/scene-format.md): beams, their keyframe
 * tracks and settings, and their evaluation at a time. */
#include "scene/scene_parse.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const beam_param_names[RT_BEAM_PARAM_COUNT + 1] = {
    "head", "dir", "length", "radius", "a", "b", "eps", "color", "intensity", "exposure",
    "head_radius", "orb_radius", "orb_strength", "taper", "surge", NULL};
static const int beam_param_dim[RT_BEAM_PARAM_COUNT] = {3, 3, 1, 1, 1, 1, 1, 4, 1, 1, 1, 1, 1, 1, 1};
static const char *const beam_keyframe_names[] = {
    "head", "dir", "length", "radius", "a", "b", "eps", "color", "intensity", "exposure",
    "head_radius", "orb_radius", "orb_strength", "taper", "surge", "joints", NULL};
/* The anatomy's ranges (vfx_beam; the plugin checks the same in beams_effect.c). */
static const range TAPER_RANGE = {0, 0.95, false};
static const range SURGE_RANGE = {0, 4, false};

static range beam_param_range(int k)
{
    switch (k) { /* the plugin's ranges (volfx_ranges.h) */
    case RT_BEAM_PARAM_HEAD:
    case RT_BEAM_PARAM_DIR: return COORD;
    case RT_BEAM_PARAM_LENGTH: return rt_scene_range(VFX_RANGE_BEAM_LENGTH);
    case RT_BEAM_PARAM_RADIUS: return rt_scene_range(VFX_RANGE_BEAM_RADIUS);
    case RT_BEAM_PARAM_A: return rt_scene_range(VFX_RANGE_BEAM_A);
    case RT_BEAM_PARAM_B: return rt_scene_range(VFX_RANGE_BEAM_B);
    case RT_BEAM_PARAM_EPS: return rt_scene_range(VFX_RANGE_BEAM_EPS);
    case RT_BEAM_PARAM_COLOR: return rt_scene_range(VFX_RANGE_BEAM_COLOR);
    case RT_BEAM_PARAM_INTENSITY: return rt_scene_range(VFX_RANGE_BEAM_INTENSITY);
    case RT_BEAM_PARAM_EXPOSURE: return rt_scene_range(VFX_RANGE_BEAM_EXPOSURE);
    case RT_BEAM_PARAM_TAPER: return TAPER_RANGE;
    case RT_BEAM_PARAM_SURGE: return SURGE_RANGE;
    default: return NONNEG;
    }
}

static float *beam_param_ptr(vfx_beam *b, vfx_beam *look, int k)
{
    switch (k) {
    case RT_BEAM_PARAM_INTENSITY: return &look->intensity;
    case RT_BEAM_PARAM_EXPOSURE: return &look->exposure;
    case RT_BEAM_PARAM_HEAD_RADIUS: return &look->head_radius;
    case RT_BEAM_PARAM_ORB_RADIUS: return &look->orb_radius;
    case RT_BEAM_PARAM_ORB_STRENGTH: return &look->orb_strength;
    case RT_BEAM_PARAM_TAPER: return &look->taper;
    case RT_BEAM_PARAM_SURGE: return &look->surge_amount;
    case RT_BEAM_PARAM_HEAD: return b->head;
    case RT_BEAM_PARAM_DIR: return b->dir;
    case RT_BEAM_PARAM_LENGTH: return &b->length;
    case RT_BEAM_PARAM_RADIUS: return &b->radius;
    case RT_BEAM_PARAM_A: return &b->a;
    case RT_BEAM_PARAM_B: return &b->b;
    case RT_BEAM_PARAM_EPS: return &b->eps;
    default: return b->color;
    }
}

/* A joints value: an array of n [x, y, z] (n = *count when given, else 2..RT_SCENE_MAX_JOINTS). */
static vfx_result joints_value(pctx *c, const cJSON *v, const char *P, uint32_t *count, float *dst)
{
    int n = cJSON_IsArray(v) ? cJSON_GetArraySize(v) : -1;
    if (n < 2 || n > RT_SCENE_MAX_JOINTS)
        return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, P, "expected an array of 2 to %d [x, y, z] joints", RT_SCENE_MAX_JOINTS);
    if (*count && (uint32_t)n != *count)
        return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, P, "%d joints; every key of a beam has the same count (%u)", n, *count);
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, ++i) {
        char PI[JPATH];
        rt_scene_join_index(PI, P, i);
        vfx_result r = rt_scene_point_value(c, e, PI, 3, dst + 3 * i); /* positions: relative to the origin */
        if (r)
            return r;
    }
    *count = (uint32_t)n;
    return VFX_OK;
}

/* Keyframes of parameter k (k = RT_BEAM_PARAM_COUNT: the joints, dim 3 * *joints). */
static vfx_result parse_track(pctx *c, const cJSON *v, const char *P, int k, uint32_t *joints, rt_scene_track *tr)
{
    static const char *const keys[] = {"t", "value", NULL};
    if (!cJSON_IsArray(v))
        return rt_scene_failf(c, VFX_ERR_FORMAT, P, "expected an array of {\"t\", \"value\"} keyframes, got %s", rt_scene_type_name(v));
    int n = cJSON_GetArraySize(v);
    if (n < 1 || n > RT_SCENE_MAX_KEYS)
        return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, P, "%d keyframes; must be 1 to %d", n, RT_SCENE_MAX_KEYS);
    int dim = k < RT_BEAM_PARAM_COUNT ? beam_param_dim[k] : 3 * RT_SCENE_MAX_JOINTS;
    tr->dim = (uint32_t)dim;
    tr->times = malloc((size_t)n * sizeof(float));
    tr->values = malloc((size_t)n * (size_t)dim * sizeof(float));
    if (!tr->times || !tr->values)
        return rt_scene_failf(c, VFX_ERR_OUT_OF_MEMORY, P, "out of memory");
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, ++i) {
        char PI[JPATH], PV[JPATH];
        rt_scene_join_index(PI, P, i);
        vfx_result r = rt_scene_expect_object(c, e, PI);
        if (r)
            return r;
        rt_scene_check_keys(c, e, PI, keys);
        if ((r = rt_scene_get_float(c, e, PI, "t", true, COORD, &tr->times[i])))
            return r;
        if (i > 0 && !(tr->times[i] > tr->times[i - 1])) {
            char PT[JPATH];
            rt_scene_join(PT, PI, "t");
            return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, PT, "keyframe times must increase strictly (%g after %g)",
                         tr->times[i], tr->times[i - 1]);
        }
        rt_scene_join(PV, PI, "value");
        const cJSON *val = cJSON_GetObjectItemCaseSensitive(e, "value");
        float *dst = &tr->values[(size_t)i * (size_t)dim];
        if (!val)
            return rt_scene_failf(c, VFX_ERR_FORMAT, PV, "required value missing");
        if (k == RT_BEAM_PARAM_COUNT) {
            if ((r = joints_value(c, val, PV, joints, dst)))
                return r;
        } else if (dim == 1) {
            double d;
            if ((r = rt_scene_number_value(c, val, PV, beam_param_range(k), &d)))
                return r;
            dst[0] = (float)d;
        } else if ((r = k == RT_BEAM_PARAM_HEAD ? rt_scene_point_value(c, val, PV, dim, dst) /* a position */
                                                : rt_scene_vec_value(c, val, PV, dim, beam_param_range(k), dst))) {
            return r;
        }
        if (k == RT_BEAM_PARAM_DIR && rt_scene_is_zero3(dst))
            return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, PV, "direction must not be the zero vector");
        tr->count = (uint32_t)i + 1;
    }
    if (k == RT_BEAM_PARAM_COUNT) { /* pack the keys to the beam's joint count */
        uint32_t d3 = 3 * *joints;
        for (int j = 1; j < n; ++j)
            memmove(&tr->values[(size_t)j * d3], &tr->values[(size_t)j * (size_t)dim], d3 * sizeof(float));
        tr->dim = d3;
    }
    return VFX_OK;
}

/* A beam's joints: the static value and/or the keyframes (the first key is the base). */
static vfx_result parse_joints(pctx *c, const cJSON *e, const cJSON *kf, const char *P, rt_scene_beam *o)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(e, "joints");
    const cJSON *track = kf ? cJSON_GetObjectItemCaseSensitive(kf, "joints") : NULL;
    vfx_result r = VFX_OK;
    if (v) {
        char PJ[JPATH];
        rt_scene_join(PJ, P, "joints");
        if ((r = joints_value(c, v, PJ, &o->joint_count, &o->joints[0][0])))
            return r;
    }
    if (track) {
        char PK[JPATH], PT[JPATH];
        rt_scene_join(PK, P, "keyframes");
        rt_scene_join(PT, PK, "joints");
        if ((r = parse_track(c, track, PT, RT_BEAM_PARAM_COUNT, &o->joint_count, &o->joint_track)))
            return r;
        if (!v)
            memcpy(o->joints, o->joint_track.values, o->joint_track.dim * sizeof(float));
    }
    return r;
}

static const range TWIST_RANGE = {-64, 64, false};
static const range CORE_RANGE = {0, 1, false};

/* The optional object e.name: *obj NULL when absent; else checked to be an object with only
 * the given keys, and its JSON path written to path (the key checks report through c). */
static vfx_result optional_object(pctx *c, const cJSON *e, const char *P, const char *name,
                                  const char *const *keys, const cJSON **obj, char path[JPATH])
{
    *obj = cJSON_GetObjectItemCaseSensitive(e, name);
    if (!*obj)
        return VFX_OK;
    rt_scene_join(path, P, name);
    vfx_result r = rt_scene_expect_object(c, *obj, path);
    if (!r)
        rt_scene_check_keys(c, *obj, path, keys);
    return r;
}

/* orb {pulse, pulse_hz}, surge {wavelength, speed} and core (the keyframable sizes are
 * parameters). Scenes default the core to 0.2: the hue-keeping ramp (0 keeps version 2's). */
static vfx_result parse_anatomy(pctx *c, const cJSON *e, const char *P, vfx_beam *look)
{
    static const char *const orb_keys[] = {"pulse", "pulse_hz", NULL};
    static const char *const surge_keys[] = {"wavelength", "speed", NULL};
    look->core = 0.2f;
    vfx_result r = rt_scene_get_float(c, e, P, "core", false, CORE_RANGE, &look->core);
    const cJSON *orb = NULL, *surge = NULL;
    char PO[JPATH], PS[JPATH];
    if (!r) r = optional_object(c, e, P, "orb", orb_keys, &orb, PO);
    if (!r && orb) {
        r = rt_scene_get_float(c, orb, PO, "pulse", false, UNIT, &look->orb_pulse);
        if (!r) r = rt_scene_get_float(c, orb, PO, "pulse_hz", false, NONNEG, &look->orb_pulse_hz);
    }
    if (!r) r = optional_object(c, e, P, "surges", surge_keys, &surge, PS);
    if (!r && surge) {
        r = rt_scene_get_float(c, surge, PS, "wavelength", false, NONNEG, &look->surge_wavelength);
        /* the plugin's row (vfx_beam.surge_wavelength): 0 or at least 1e-6 (1e-40 made the profile NaN) */
        if (!r && look->surge_wavelength > 0.f && look->surge_wavelength < 1e-6f) {
            char p[JPATH];
            rt_scene_join(p, PS, "wavelength");
            r = rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, p, "must be 0 (8 x radius) or >= 1e-06, got %g",
                               (double)look->surge_wavelength);
        }
        if (!r) r = rt_scene_get_float(c, surge, PS, "speed", false, COORD, &look->surge_speed);
    }
    return r;
}

/* falloff, ramp, flow and the anatomy's settings of one beam (intensity, exposure and the
 * anatomy's sizes are parameters, keyframable). */
static vfx_result parse_look(pctx *c, const cJSON *e, const char *P, vfx_beam *look3)
{
    static const char *const falloffs[] = {"smooth", "hard", NULL};
    static const char *const ramps[] = {"hot", "thesis", NULL};
    static const char *const flow_keys[] = {"amount", "speed", "scale", "kind", "twist", NULL};
    static const char *const kinds[] = {"noise", "spiral", NULL};
    vfx_beam *look = look3;
    uint32_t f = 0, rp = 0;
    vfx_result r = rt_scene_get_enum(c, e, P, "falloff", false, falloffs, &f);
    if (!r)
        r = rt_scene_get_enum(c, e, P, "ramp", false, ramps, &rp);
    if (!r)
        r = parse_anatomy(c, e, P, look3);
    if (r)
        return r;
    look->falloff = f == 1 ? VFX_BEAM_FALLOFF_HARD : VFX_BEAM_FALLOFF_SMOOTH;
    look->ramp = rp == 1 ? VFX_BEAM_RAMP_THESIS : VFX_BEAM_RAMP_HOT;
    if (rp == 1)
        look3->core = 0; /* the thesis ramp has no core */
    const cJSON *flow;
    char PF[JPATH];
    if ((r = optional_object(c, e, P, "flow", flow_keys, &flow, PF)) || !flow)
        return r;
    look->flow_amount = 0.5f;
    if (!r) r = rt_scene_get_float_row(c, flow, PF, "amount", VFX_RANGE_BEAM_FLOW_AMOUNT, &look->flow_amount);
    if (!r) r = rt_scene_get_float_row(c, flow, PF, "speed", VFX_RANGE_BEAM_FLOW_SPEED, &look->flow_speed);
    if (!r) r = rt_scene_get_float_row(c, flow, PF, "scale", VFX_RANGE_BEAM_FLOW_SCALE, &look->flow_scale);
    if (!r) r = rt_scene_get_enum(c, flow, PF, "kind", false, kinds, &look3->flow_kind);
    if (!r) r = rt_scene_get_float(c, flow, PF, "twist", false, TWIST_RANGE, &look3->flow_twist);
    return r;
}

vfx_result rt_scene_parse_beams(pctx *c, const cJSON *v, rt_scene *s)
{
    static const char *const keys[] = {"head", "dir", "length", "radius", "a", "b", "eps", "color",
                                       "intensity", "exposure", "falloff", "ramp", "flow", "joints",
                                       "keyframes", "loop_s", "head_radius", "orb_radius", "orb_strength",
                                       "taper", "surge", "orb", "surges", "core", NULL};
    int n;
    vfx_result ra = rt_scene_alloc_array(c, v, "beams", RT_SCENE_MAX_BEAMS, sizeof *s->beams, (void **)&s->beams, &n);
    if (ra || n == 0)
        return ra;
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, ++i) {
        char P[JPATH];
        rt_scene_join_index(P, "beams", i);
        rt_scene_beam *o = &s->beams[i];
        s->beam_count = (uint32_t)i + 1; /* so that free() sees tracks of a half-parsed beam */
        vfx_beam *b = &o->base;
        *b = (vfx_beam){.type = VFX_TYPE_BEAM, .length = 1.0f, .radius = 0.5f, .a = 0.05f, .b = 0.03f, .eps = 0.02f,
                        .color = {1, 1, 1, 1}};
        o->look = (vfx_beam){.type = VFX_TYPE_BEAM, .falloff = VFX_BEAM_FALLOFF_SMOOTH, .ramp = VFX_BEAM_RAMP_HOT,
                             .intensity = 1.0f};
        vfx_result r = rt_scene_expect_object(c, e, P);
        if (r)
            return r;
        rt_scene_check_keys(c, e, P, keys);
        const cJSON *kf = cJSON_GetObjectItemCaseSensitive(e, "keyframes");
        if (kf) {
            char PK[JPATH];
            rt_scene_join(PK, P, "keyframes");
            if ((r = rt_scene_expect_object(c, kf, PK)))
                return r;
            rt_scene_check_keys(c, kf, PK, beam_keyframe_names);
        }
        if ((r = parse_joints(c, e, kf, P, o)))
            return r;
        for (int k = 0; k < RT_BEAM_PARAM_COUNT; ++k) {
            const char *name = beam_param_names[k];
            const cJSON *track = kf ? cJSON_GetObjectItemCaseSensitive(kf, name) : NULL;
            /* head and dir are required unless animated (then the first key is the base) or the
             * beam bends (its joints give them) */
            bool required = (k == RT_BEAM_PARAM_HEAD || k == RT_BEAM_PARAM_DIR) && !track && !o->joint_count;
            float *dst = beam_param_ptr(b, &o->look, k);
            if (beam_param_dim[k] == 1)
                r = rt_scene_get_float(c, e, P, name, required, beam_param_range(k), dst);
            else if (k == RT_BEAM_PARAM_HEAD)
                r = rt_scene_get_point(c, e, P, name, required, dst);
            else
                r = rt_scene_get_vec(c, e, P, name, beam_param_dim[k], required, beam_param_range(k), dst);
            if (r)
                return r;
            if (track) {
                char PT[JPATH], PK[JPATH];
                rt_scene_join(PK, P, "keyframes");
                rt_scene_join(PT, PK, name);
                if ((r = parse_track(c, track, PT, k, NULL, &o->tracks[k])))
                    return r;
                if (!cJSON_GetObjectItemCaseSensitive(e, name))
                    memcpy(dst, o->tracks[k].values, (size_t)beam_param_dim[k] * sizeof(float));
            }
        }
        if (o->joint_count) { /* a bending beam: its straight part describes the first segment */
            for (int k = 0; k < 3; ++k) {
                b->head[k] = o->joints[0][k];
                b->dir[k] = o->joints[1][k] - o->joints[0][k];
            }
            b->length = sqrtf(b->dir[0] * b->dir[0] + b->dir[1] * b->dir[1] + b->dir[2] * b->dir[2]);
            if (rt_scene_is_zero3(b->dir))
                b->dir[0] = 1.f;
        }
        if (rt_scene_is_zero3(b->dir)) {
            char PD[JPATH];
            rt_scene_join(PD, P, "dir");
            return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, PD, "direction must not be the zero vector");
        }
        if ((r = rt_scene_get_float(c, e, P, "loop_s", false, NONNEG, &o->loop_s)) || (r = parse_look(c, e, P, &o->look)))
            return r;
    }
    return VFX_OK;
}

vfx_result rt_scene_parse_beam_settings(pctx *c, const cJSON *v, vfx_beams_view *bv)
{
    static const char *const keys[] = {"saturation", "c", "far_distance", "bloom", "bloom_strength", "bloom_levels",
                                       NULL};
    static const char *const sat[] = {"clamp", "smooth", NULL};
    const char *P = "beam_settings";
    vfx_result r = rt_scene_expect_object(c, v, P);
    if (r)
        return r;
    rt_scene_check_keys(c, v, P, keys);
    r = rt_scene_get_enum(c, v, P, "saturation", false, sat, &bv->saturation);
    if (!r) r = rt_scene_get_float_row(c, v, P, "c", VFX_RANGE_BEAMS_C, &bv->saturate_c);
    if (!r) r = rt_scene_get_float_row(c, v, P, "far_distance", VFX_RANGE_BEAMS_FAR, &bv->far_distance);
    vfx_beams_view *bv2 = bv;
    bool bloom = true;
    if (!r && cJSON_GetObjectItemCaseSensitive(v, "bloom")) {
        r = rt_scene_get_bool(c, v, P, "bloom", &bloom);
        bv2->bloom = bloom ? VFX_BEAMS_BLOOM_ON : VFX_BEAMS_BLOOM_OFF;
    }
    if (!r) r = rt_scene_get_float_row(c, v, P, "bloom_strength", VFX_RANGE_BEAMS_BLOOM_STRENGTH, &bv2->bloom_strength);
    if (!r) r = rt_scene_get_uint_row(c, v, P, "bloom_levels", VFX_RANGE_BEAMS_BLOOM_LEVELS, &bv2->bloom_levels);
    return r;
}

/* ------------------------------------------------------------------ animation */

/* Index of the last key with time <= t (0 when t is before the first). */
static uint32_t key_before(const rt_scene_track *tr, double t)
{
    uint32_t lo = 0, hi = tr->count - 1;
    if (t <= tr->times[0])
        return 0;
    if (t >= tr->times[hi])
        return hi;
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (tr->times[mid] <= t)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

void rt_scene_track_eval(const rt_scene_track *tr, double t, float *out)
{
    if (!tr || tr->count == 0)
        return;
    uint32_t i = key_before(tr, t), d = tr->dim;
    const float *v0 = &tr->values[(size_t)i * d];
    if (i + 1 >= tr->count || t <= tr->times[0]) {
        memcpy(out, v0, d * sizeof(float));
        return;
    }
    const float *v1 = v0 + d;
    double f = (t - tr->times[i]) / ((double)tr->times[i + 1] - tr->times[i]);
    for (uint32_t k = 0; k < d; ++k)
        out[k] = (float)(v0[k] + f * ((double)v1[k] - v0[k]));
}

/* Time within a beam's loop. */
static double beam_time(const rt_scene_beam *b, double time)
{
    double t = isfinite(time) ? time : 0;
    if (b->loop_s > 0) {
        t = fmod(t, b->loop_s);
        if (t < 0)
            t += b->loop_s;
    }
    return t;
}

/* One beam at `time`: the look with the geometry of base, keyframes interpolated, wrapped by
 * loop_s. */
static void beam_at(const rt_scene_beam *b, double time, vfx_beam *out)
{
    double t = beam_time(b, time);
    *out = b->look;
    out->type = VFX_TYPE_BEAM;
    out->next = NULL;
    memcpy(out->head, b->base.head, sizeof out->head);
    out->length = b->base.length;
    memcpy(out->dir, b->base.dir, sizeof out->dir);
    out->radius = b->base.radius;
    out->a = b->base.a;
    out->b = b->base.b;
    out->eps = b->base.eps;
    memcpy(out->color, b->base.color, sizeof out->color);
    for (int k = 0; k < RT_BEAM_PARAM_COUNT; ++k) {
        const rt_scene_track *tr = &b->tracks[k];
        if (!tr->count)
            continue;
        float *dst = beam_param_ptr(out, out, k);
        rt_scene_track_eval(tr, t, dst);
        /* opposite direction keys pass through zero: hold the earlier key's direction */
        if (k == RT_BEAM_PARAM_DIR && rt_scene_is_zero3(dst))
            memcpy(dst, &tr->values[(size_t)key_before(tr, t) * 3], 3 * sizeof(float));
    }
}

uint32_t rt_scene_beams_at(const rt_scene *scene, double time, vfx_beam *out, uint32_t n, float *joints,
                           uint32_t joint_cap, uint32_t *joint_count)
{
    uint32_t used = 0;
    if (joint_count)
        *joint_count = 0;
    if (!scene || !out)
        return 0;
    uint32_t count = scene->beam_count < n ? scene->beam_count : n;
    for (uint32_t i = 0; i < count; ++i) {
        const rt_scene_beam *b = &scene->beams[i];
        beam_at(b, time, &out[i]);
        if (b->joint_count && joints && joint_cap - used >= b->joint_count) {
            float *dst = joints + 3 * (size_t)used;
            memcpy(dst, b->joints, 3 * b->joint_count * sizeof(float));
            if (b->joint_track.count)
                rt_scene_track_eval(&b->joint_track, beam_time(b, time), dst);
            out[i].joint_first = used;
            out[i].joint_count = b->joint_count;
            used += b->joint_count;
        }
    }
    if (joint_count)
        *joint_count = used;
    return count;
}
