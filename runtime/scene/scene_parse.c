/* scene_parse.c — see scene_parse.h: every value is validated where it is read, so the message can
 * carry its JSON path; ranges are checked on the double before any cast. */
#include "scene/scene_parse.h"

#include <cglm/cglm.h>

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/file.h"
vfx_result rt_scene_failf(pctx *c, vfx_result r, const char *path, const char *fmt, ...)
{
    if (c->err && c->errlen) {
        char msg[512];
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, sizeof msg, fmt, ap);
        va_end(ap);
        snprintf(c->err, c->errlen, "%s: %s", path && *path ? path : "(root)", msg);
    }
    return r;
}

/* JSON paths longer than JPATH are cut: the message stays readable, the check unaffected. */
void rt_scene_join(char *out, const char *parent, const char *key)
{
    int n = parent && *parent ? snprintf(out, JPATH, "%s.%s", parent, key) : snprintf(out, JPATH, "%s", key);
    if (n < 0)
        out[0] = 0;
}

void rt_scene_join_index(char *out, const char *parent, int i)
{
    if (snprintf(out, JPATH, "%s[%d]", parent, i) < 0)
        out[0] = 0;
}

const char *rt_scene_type_name(const cJSON *v)
{
    if (!v) return "nothing";
    if (cJSON_IsNumber(v)) return "a number";
    if (cJSON_IsString(v)) return "a string";
    if (cJSON_IsBool(v)) return "a boolean";
    if (cJSON_IsNull(v)) return "null";
    if (cJSON_IsArray(v)) return "an array";
    if (cJSON_IsObject(v)) return "an object";
    return "an invalid value";
}

/* Unknown keys are warnings (a typo should be visible, a newer file should still load);
 * a duplicated key is a warning too because cJSON would silently take the first. */
void rt_scene_check_keys(pctx *c, const cJSON *obj, const char *path, const char *const *allowed)
{
    int index = 0;
    for (const cJSON *it = obj->child; it; it = it->next, ++index) {
        const char *k = it->string ? it->string : "";
        bool known = false;
        for (const char *const *a = allowed; *a; ++a)
            if (strcmp(*a, k) == 0)
                known = true;
        char p[JPATH];
        rt_scene_join(p, path, k);
        if (!known)
            rt_logf(c->log, VFX_LOG_WARN, "%s: unknown key ignored", p);
        /* duplicates: quadratic, but only for the first 64 keys of an object */
        if (index < 64)
            for (const cJSON *prev = obj->child; prev != it; prev = prev->next)
                if (prev->string && strcmp(prev->string, k) == 0) {
                    rt_logf(c->log, VFX_LOG_WARN, "%s: duplicate key, the first one is used", p);
                    break;
                }
    }
}

vfx_result rt_scene_expect_object(pctx *c, const cJSON *v, const char *path)
{
    if (!cJSON_IsObject(v))
        return rt_scene_failf(c, VFX_ERR_FORMAT, path, "expected an object, got %s", rt_scene_type_name(v));
    return VFX_OK;
}


vfx_result rt_scene_check_range(pctx *c, const char *path, double v, range rg)
{
    if (!isfinite(v))
        return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, path, "must be finite, got %.9g", v);
    if (rg.lo_open ? !(v > rg.lo) : !(v >= rg.lo))
        return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, path, "must be %s %.9g, got %.9g", rg.lo_open ? ">" : ">=",
                     rg.lo, v);
    if (v > rg.hi)
        return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, path, "must be <= %.9g, got %.9g", rg.hi, v);
    return VFX_OK;
}

/* Every number a scene gives is stored as float32, so the range is checked on that float, not
 * on the double JSON gave: 1e-320 is > 0 as a double and 0 as a float, 1e39 is finite as a
 * double and Inf as a float. A float32 subnormal is refused too: it keeps almost no digits and
 * its reciprocal or cube is Inf or 0 in the float code that uses it. */
vfx_result rt_scene_number_value(pctx *c, const cJSON *v, const char *path, range rg, double *out)
{
    if (!cJSON_IsNumber(v))
        return rt_scene_failf(c, VFX_ERR_FORMAT, path, "expected a number, got %s", rt_scene_type_name(v));
    double d = v->valuedouble;
    vfx_result r = rt_scene_check_range(c, path, d, rg);
    if (r)
        return r;
    if (fabs(d) > FLT_MAX)
        return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, path, "must be finite as float32, got %.9g", d);
    float f = (float)d;
    if (f != 0 && fabsf(f) < FLT_MIN) {
        /* advise 0 only where the range takes it */
        const bool zero_ok = (rg.lo_open ? 0 > rg.lo : 0 >= rg.lo) && 0 <= rg.hi;
        return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, path, "%g is subnormal as float32 (magnitude "
                           "below %.9g): give %sa value of magnitude %.9g or more", d, (double)FLT_MIN,
                           zero_ok ? "0 or " : "", (double)FLT_MIN);
    }
    if (d != 0 && f == 0) /* only reached with d below FLT_MIN/2 */
        return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, path, "%.3g is 0 as float32", d);
    /* the float against the bounds as floats: a documented end such as 0.1 is the float nearest
     * it (0.100000001), which is above the double 0.1 (dt 0.1 was refused) */
    volatile float flo = (float)rg.lo, fhi = (float)rg.hi; /* rounded here, not folded away */
    range rf = {(double)flo, (double)fhi, rg.lo_open};
    r = rt_scene_check_range(c, path, (double)f, rf);
    if (!r)
        *out = (double)f;
    return r;
}

/* Optional number `key` of `obj`: *out keeps its default when absent. */
vfx_result rt_scene_get_float(pctx *c, const cJSON *obj, const char *path, const char *key, bool required,
                            range rg, float *out)
{
    char p[JPATH];
    rt_scene_join(p, path, key);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v)
        return required ? rt_scene_failf(c, VFX_ERR_FORMAT, p, "required number missing") : VFX_OK;
    double d = 0; /* set by number_value on success; -O3 cannot see that */
    vfx_result r = rt_scene_number_value(c, v, p, rg, &d);
    if (!r)
        *out = (float)d;
    return r;
}

vfx_result rt_scene_get_uint(pctx *c, const cJSON *obj, const char *path, const char *key, bool required,
                           double lo, double hi, uint32_t *out)
{
    char p[JPATH];
    rt_scene_join(p, path, key);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v)
        return required ? rt_scene_failf(c, VFX_ERR_FORMAT, p, "required integer missing") : VFX_OK;
    /* integers stay doubles: as a float 16777217 would round to a different integer */
    if (!cJSON_IsNumber(v))
        return rt_scene_failf(c, VFX_ERR_FORMAT, p, "expected a number, got %s", rt_scene_type_name(v));
    double d = v->valuedouble;
    vfx_result r = rt_scene_check_range(c, p, d, (range){lo, hi, false});
    if (r)
        return r;
    if (d != floor(d))
        return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, p, "must be an integer, got %g", d);
    *out = (uint32_t)d;
    return VFX_OK;
}

vfx_result rt_scene_vec_value(pctx *c, const cJSON *v, const char *p, int n, range rg, float *out)
{
    if (!cJSON_IsArray(v))
        return rt_scene_failf(c, VFX_ERR_FORMAT, p, "expected an array of %d numbers, got %s", n, rt_scene_type_name(v));
    int size = cJSON_GetArraySize(v);
    if (size != n)
        return rt_scene_failf(c, VFX_ERR_FORMAT, p, "expected %d numbers, got %d", n, size);
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, ++i) {
        char pi[JPATH];
        rt_scene_join_index(pi, p, i);
        double d = 0;
        vfx_result r = rt_scene_number_value(c, e, pi, rg, &d);
        if (r)
            return r;
        out[i] = (float)d;
    }
    return VFX_OK;
}

vfx_result rt_scene_point_value(pctx *c, const cJSON *v, const char *p, int n, float *out)
{
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != n)
        return rt_scene_vec_value(c, v, p, n, COORD, out); /* its message names what is wrong */
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, ++i) {
        char pi[JPATH];
        rt_scene_join_index(pi, p, i);
        double d = 0;
        vfx_result r = rt_scene_number_value(c, e, pi, COORD, &d); /* checks it as float32 too */
        if (r)
            return r;
        d = e->valuedouble; /* but keeps the digits: the difference is what becomes float32 */
        if (n == 3)
            d -= c->origin[i];
        else if (i >= 12 && i < 15)
            d -= c->origin[i - 12];
        out[i] = (float)d;
    }
    return VFX_OK;
}

vfx_result rt_scene_get_point(pctx *c, const cJSON *obj, const char *path, const char *key, bool required,
                            float out[3])
{
    char p[JPATH];
    rt_scene_join(p, path, key);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v && required)
        return rt_scene_failf(c, VFX_ERR_FORMAT, p, "required array of 3 numbers missing");
    if (!v && c->defaults_world) /* the default is a world position: relative to the origin too */
        for (int i = 0; i < 3; ++i)
            out[i] = (float)((double)out[i] - c->origin[i]);
    return v ? rt_scene_point_value(c, v, p, 3, out) : VFX_OK;
}

vfx_result rt_scene_get_vec(pctx *c, const cJSON *obj, const char *path, const char *key, int n,
                          bool required, range rg, float *out)
{
    char p[JPATH];
    rt_scene_join(p, path, key);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v)
        return required ? rt_scene_failf(c, VFX_ERR_FORMAT, p, "required array of %d numbers missing", n) : VFX_OK;
    return rt_scene_vec_value(c, v, p, n, rg, out);
}

vfx_result rt_scene_get_bool(pctx *c, const cJSON *obj, const char *path, const char *key, bool *out)
{
    char p[JPATH];
    rt_scene_join(p, path, key);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v)
        return VFX_OK;
    if (!cJSON_IsBool(v))
        return rt_scene_failf(c, VFX_ERR_FORMAT, p, "expected true or false, got %s", rt_scene_type_name(v));
    *out = cJSON_IsTrue(v);
    return VFX_OK;
}

vfx_result rt_scene_get_string(pctx *c, const cJSON *obj, const char *path, const char *key, bool required,
                             char *out, size_t outlen)
{
    char p[JPATH];
    rt_scene_join(p, path, key);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v)
        return required ? rt_scene_failf(c, VFX_ERR_FORMAT, p, "required string missing") : VFX_OK;
    if (!cJSON_IsString(v) || !v->valuestring)
        return rt_scene_failf(c, VFX_ERR_FORMAT, p, "expected a string, got %s", rt_scene_type_name(v));
    size_t len = strlen(v->valuestring);
    if (len >= outlen)
        return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, p, "string of %zu bytes is longer than %zu", len, outlen - 1);
    memcpy(out, v->valuestring, len + 1);
    return VFX_OK;
}

/* A string that must be one of `names` (NULL-terminated); *out gets its index. */
vfx_result rt_scene_get_enum(pctx *c, const cJSON *obj, const char *path, const char *key, bool required,
                           const char *const *names, uint32_t *out)
{
    char buf[64] = "";
    vfx_result r = rt_scene_get_string(c, obj, path, key, required, buf, sizeof buf);
    if (r)
        return r;
    if (!cJSON_GetObjectItemCaseSensitive(obj, key))
        return VFX_OK;
    for (uint32_t i = 0; names[i]; ++i)
        if (strcmp(names[i], buf) == 0) {
            *out = i;
            return VFX_OK;
        }
    char p[JPATH], list[256] = "";
    rt_scene_join(p, path, key);
    for (uint32_t i = 0; names[i]; ++i) {
        size_t l = strlen(list);
        snprintf(list + l, sizeof list - l, "%s\"%s\"", i ? ", " : "", names[i]);
    }
    return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, p, "unknown value \"%s\"; expected one of %s", buf, list);
}

/* An array of flag names -> bit mask. */
vfx_result rt_scene_get_flags(pctx *c, const cJSON *obj, const char *path, const char *key,
                            const char *const *names, const uint32_t *bits, uint32_t *out)
{
    char p[JPATH];
    rt_scene_join(p, path, key);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v)
        return VFX_OK;
    if (!cJSON_IsArray(v))
        return rt_scene_failf(c, VFX_ERR_FORMAT, p, "expected an array of strings, got %s", rt_scene_type_name(v));
    uint32_t mask = 0;
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, ++i) {
        char pi[JPATH];
        rt_scene_join_index(pi, p, i);
        if (!cJSON_IsString(e))
            return rt_scene_failf(c, VFX_ERR_FORMAT, pi, "expected a string, got %s", rt_scene_type_name(e));
        bool found = false;
        for (uint32_t k = 0; names[k]; ++k)
            if (strcmp(names[k], e->valuestring) == 0)
                mask |= bits[k], found = true;
        if (!found)
            return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, pi, "unknown flag \"%.64s\"", e->valuestring);
    }
    *out = mask;
    return VFX_OK;
}

vfx_result rt_scene_resolve_path(pctx *c, const char *p, const char *rel, char *out)
{
    if (!*rel)
        return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, p, "empty path");
    int n;
    if (rel[0] == '/' || !c->base_dir || !*c->base_dir)
        n = snprintf(out, RT_SCENE_PATH_MAX, "%s", rel);
    else
        n = snprintf(out, RT_SCENE_PATH_MAX, "%s/%s", c->base_dir, rel);
    if (n < 0 || n >= RT_SCENE_PATH_MAX)
        return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, p, "resolved path longer than %d bytes", RT_SCENE_PATH_MAX - 1);
    return VFX_OK;
}

vfx_result rt_scene_get_path(pctx *c, const cJSON *obj, const char *path, const char *key, bool required,
                           char *out)
{
    char raw[RT_SCENE_PATH_MAX] = "", p[JPATH];
    vfx_result r = rt_scene_get_string(c, obj, path, key, required, raw, sizeof raw);
    if (r || !cJSON_GetObjectItemCaseSensitive(obj, key))
        return r;
    rt_scene_join(p, path, key);
    return rt_scene_resolve_path(c, p, raw, out);
}


/* ------------------------------------------------------------------ transforms */

/* M = T * Rz * Ry * Rx * S, column-major, with cglm. */
void rt_scene_mat_trs(const float t[3], const float rdeg[3], const float s[3], float m[16])
{
    mat4 M;
    glm_translate_make(M, (vec3){t[0], t[1], t[2]});
    glm_rotate_z(M, glm_rad(rdeg[2]), M);
    glm_rotate_y(M, glm_rad(rdeg[1]), M);
    glm_rotate_x(M, glm_rad(rdeg[0]), M);
    glm_scale(M, (vec3){s[0], s[1], s[2]});
    memcpy(m, M, sizeof M);
}

vfx_result rt_scene_parse_transform(pctx *c, const cJSON *obj, const char *path, float model[16])
{
    const cJSON *mv = cJSON_GetObjectItemCaseSensitive(obj, "matrix");
    bool trs = cJSON_GetObjectItemCaseSensitive(obj, "translate") || cJSON_GetObjectItemCaseSensitive(obj, "rotate_deg") ||
               cJSON_GetObjectItemCaseSensitive(obj, "scale");
    if (mv) {
        char p[JPATH];
        rt_scene_join(p, path, "matrix");
        if (trs)
            return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, p, "give either matrix or translate/rotate_deg/scale, not both");
        return rt_scene_point_value(c, mv, p, 16, model);
    }
    /* no translate: at the world origin, which is -origin from the scene's origin (with
     * defaults_world rt_scene_get_point makes the world default 0 that) */
    float t[3] = {0, 0, 0};
    if (!c->defaults_world)
        for (int i = 0; i < 3; ++i)
            t[i] = (float)-c->origin[i];
    float rdeg[3] = {0, 0, 0}, s[3] = {1, 1, 1};
    vfx_result r = rt_scene_get_point(c, obj, path, "translate", false, t);
    if (!r) r = rt_scene_get_vec(c, obj, path, "rotate_deg", 3, false, (range){-36000, 36000, false}, rdeg);
    if (r)
        return r;
    const cJSON *sv = cJSON_GetObjectItemCaseSensitive(obj, "scale");
    if (sv) {
        char p[JPATH];
        rt_scene_join(p, path, "scale");
        const range sr = {0, COORD_MAX, true};
        if (cJSON_IsNumber(sv)) {
            double d;
            if ((r = rt_scene_number_value(c, sv, p, sr, &d)))
                return r;
            s[0] = s[1] = s[2] = (float)d;
        } else if ((r = rt_scene_vec_value(c, sv, p, 3, sr, s))) {
            return r;
        }
    }
    rt_scene_mat_trs(t, rdeg, s, model);
    return VFX_OK;
}

static const struct {
    double lo, hi;
    uint32_t flags;
} range_rows[VFX_RANGE_COUNT] = {
#define ROW_(id, field, key, lo, hi, flags, note) [VFX_RANGE_##id] = {lo, hi, flags},
    VFX_RANGE_TABLE(ROW_)
#undef ROW_
};

range rt_scene_range(vfx_range_id id)
{
    return (range){range_rows[id].lo, range_rows[id].hi, (range_rows[id].flags & VFX_RANGE_LO_OPEN) != 0};
}

vfx_result rt_scene_get_float_row(pctx *c, const cJSON *obj, const char *path, const char *key, vfx_range_id id,
                                  float *out)
{
    return rt_scene_get_float(c, obj, path, key, false, rt_scene_range(id), out);
}

vfx_result rt_scene_get_uint_row(pctx *c, const cJSON *obj, const char *path, const char *key, vfx_range_id id,
                                 uint32_t *out)
{
    return rt_scene_get_uint(c, obj, path, key, false, range_rows[id].lo, range_rows[id].hi, out);
}

/* The prologue every array of objects shares (meshes, beams, transfer points). */
vfx_result rt_scene_alloc_array(pctx *c, const cJSON *v, const char *name, int cap, size_t elem,
                              void **out, int *count)
{
    *out = NULL;
    *count = 0;
    if (!cJSON_IsArray(v))
        return rt_scene_failf(c, VFX_ERR_FORMAT, name, "expected an array, got %s", rt_scene_type_name(v));
    int n = cJSON_GetArraySize(v);
    if (n > cap)
        return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, name, "%d %s, above the cap of %d", n, name, cap);
    if (n == 0)
        return VFX_OK;
    if (!(*out = calloc((size_t)n, elem)))
        return rt_scene_failf(c, VFX_ERR_OUT_OF_MEMORY, name, "out of memory");
    *count = n;
    return VFX_OK;
}

bool rt_scene_is_zero3(const float *v)
{
    return (double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2] < 1e-24;
}
