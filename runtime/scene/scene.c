/* scene.c — see scene.h and docs/scene-format.md. Every value is validated where it is read, so
 * the message can carry its JSON path; ranges are checked on the double before any cast, so a
 * huge value is refused rather than turned into Inf or a wrapped integer. */
#include "scene/scene.h"
#include "core/file.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/particle_file.h"

#define JPATH 256
#define COORD_MAX 1e6 /* metres: beyond this float precision is gone anyway */

typedef struct pctx {
    const rt_logger *log;
    char *err;
    size_t errlen;
    const char *base_dir;
} pctx;

static vfx_result failf(pctx *c, vfx_result r, const char *path, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static vfx_result failf(pctx *c, vfx_result r, const char *path, const char *fmt, ...)
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
static void join(char *out, const char *parent, const char *key)
{
    int n = parent && *parent ? snprintf(out, JPATH, "%s.%s", parent, key) : snprintf(out, JPATH, "%s", key);
    if (n < 0)
        out[0] = 0;
}

static void join_index(char *out, const char *parent, int i)
{
    if (snprintf(out, JPATH, "%s[%d]", parent, i) < 0)
        out[0] = 0;
}

static const char *type_name(const cJSON *v)
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
static void check_keys(pctx *c, const cJSON *obj, const char *path, const char *const *allowed)
{
    int index = 0;
    for (const cJSON *it = obj->child; it; it = it->next, ++index) {
        const char *k = it->string ? it->string : "";
        bool known = false;
        for (const char *const *a = allowed; *a; ++a)
            if (strcmp(*a, k) == 0)
                known = true;
        char p[JPATH];
        join(p, path, k);
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

static vfx_result expect_object(pctx *c, const cJSON *v, const char *path)
{
    if (!cJSON_IsObject(v))
        return failf(c, VFX_ERR_FORMAT, path, "expected an object, got %s", type_name(v));
    return VFX_OK;
}

typedef struct range {
    double lo, hi;
    bool lo_open; /* value must be > lo rather than >= lo */
} range;

static vfx_result check_range(pctx *c, const char *path, double v, range rg)
{
    if (!isfinite(v))
        return failf(c, VFX_ERR_INVALID_ARGUMENT, path, "must be finite, got %.9g", v);
    if (rg.lo_open ? !(v > rg.lo) : !(v >= rg.lo))
        return failf(c, VFX_ERR_INVALID_ARGUMENT, path, "must be %s %.9g, got %.9g", rg.lo_open ? ">" : ">=",
                     rg.lo, v);
    if (v > rg.hi)
        return failf(c, VFX_ERR_INVALID_ARGUMENT, path, "must be <= %.9g, got %.9g", rg.hi, v);
    return VFX_OK;
}

static vfx_result number_value(pctx *c, const cJSON *v, const char *path, range rg, double *out)
{
    if (!cJSON_IsNumber(v))
        return failf(c, VFX_ERR_FORMAT, path, "expected a number, got %s", type_name(v));
    vfx_result r = check_range(c, path, v->valuedouble, rg);
    if (!r)
        *out = v->valuedouble;
    return r;
}

/* Optional number `key` of `obj`: *out keeps its default when absent. */
static vfx_result get_float(pctx *c, const cJSON *obj, const char *path, const char *key, bool required,
                            range rg, float *out)
{
    char p[JPATH];
    join(p, path, key);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v)
        return required ? failf(c, VFX_ERR_FORMAT, p, "required number missing") : VFX_OK;
    double d = 0; /* set by number_value on success; -O3 cannot see that */
    vfx_result r = number_value(c, v, p, rg, &d);
    if (!r)
        *out = (float)d;
    return r;
}

static vfx_result get_uint(pctx *c, const cJSON *obj, const char *path, const char *key, bool required,
                           double lo, double hi, uint32_t *out)
{
    char p[JPATH];
    join(p, path, key);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v)
        return required ? failf(c, VFX_ERR_FORMAT, p, "required integer missing") : VFX_OK;
    double d = 0; /* set by number_value on success; -O3 cannot see that */
    vfx_result r = number_value(c, v, p, (range){lo, hi, false}, &d);
    if (r)
        return r;
    if (d != floor(d))
        return failf(c, VFX_ERR_INVALID_ARGUMENT, p, "must be an integer, got %g", d);
    *out = (uint32_t)d;
    return VFX_OK;
}

static vfx_result vec_value(pctx *c, const cJSON *v, const char *p, int n, range rg, float *out)
{
    if (!cJSON_IsArray(v))
        return failf(c, VFX_ERR_FORMAT, p, "expected an array of %d numbers, got %s", n, type_name(v));
    int size = cJSON_GetArraySize(v);
    if (size != n)
        return failf(c, VFX_ERR_FORMAT, p, "expected %d numbers, got %d", n, size);
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, ++i) {
        char pi[JPATH];
        join_index(pi, p, i);
        double d = 0;
        vfx_result r = number_value(c, e, pi, rg, &d);
        if (r)
            return r;
        out[i] = (float)d;
    }
    return VFX_OK;
}

static vfx_result get_vec(pctx *c, const cJSON *obj, const char *path, const char *key, int n,
                          bool required, range rg, float *out)
{
    char p[JPATH];
    join(p, path, key);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v)
        return required ? failf(c, VFX_ERR_FORMAT, p, "required array of %d numbers missing", n) : VFX_OK;
    return vec_value(c, v, p, n, rg, out);
}

static vfx_result get_bool(pctx *c, const cJSON *obj, const char *path, const char *key, bool *out)
{
    char p[JPATH];
    join(p, path, key);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v)
        return VFX_OK;
    if (!cJSON_IsBool(v))
        return failf(c, VFX_ERR_FORMAT, p, "expected true or false, got %s", type_name(v));
    *out = cJSON_IsTrue(v);
    return VFX_OK;
}

static vfx_result get_string(pctx *c, const cJSON *obj, const char *path, const char *key, bool required,
                             char *out, size_t outlen)
{
    char p[JPATH];
    join(p, path, key);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v)
        return required ? failf(c, VFX_ERR_FORMAT, p, "required string missing") : VFX_OK;
    if (!cJSON_IsString(v) || !v->valuestring)
        return failf(c, VFX_ERR_FORMAT, p, "expected a string, got %s", type_name(v));
    size_t len = strlen(v->valuestring);
    if (len >= outlen)
        return failf(c, VFX_ERR_INVALID_ARGUMENT, p, "string of %zu bytes is longer than %zu", len, outlen - 1);
    memcpy(out, v->valuestring, len + 1);
    return VFX_OK;
}

/* A string that must be one of `names` (NULL-terminated); *out gets its index. */
static vfx_result get_enum(pctx *c, const cJSON *obj, const char *path, const char *key, bool required,
                           const char *const *names, uint32_t *out)
{
    char buf[64] = "";
    vfx_result r = get_string(c, obj, path, key, required, buf, sizeof buf);
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
    join(p, path, key);
    for (uint32_t i = 0; names[i]; ++i) {
        size_t l = strlen(list);
        snprintf(list + l, sizeof list - l, "%s\"%s\"", i ? ", " : "", names[i]);
    }
    return failf(c, VFX_ERR_INVALID_ARGUMENT, p, "unknown value \"%s\"; expected one of %s", buf, list);
}

/* An array of flag names -> bit mask. */
static vfx_result get_flags(pctx *c, const cJSON *obj, const char *path, const char *key,
                            const char *const *names, const uint32_t *bits, uint32_t *out)
{
    char p[JPATH];
    join(p, path, key);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v)
        return VFX_OK;
    if (!cJSON_IsArray(v))
        return failf(c, VFX_ERR_FORMAT, p, "expected an array of strings, got %s", type_name(v));
    uint32_t mask = 0;
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, ++i) {
        char pi[JPATH];
        join_index(pi, p, i);
        if (!cJSON_IsString(e))
            return failf(c, VFX_ERR_FORMAT, pi, "expected a string, got %s", type_name(e));
        bool found = false;
        for (uint32_t k = 0; names[k]; ++k)
            if (strcmp(names[k], e->valuestring) == 0)
                mask |= bits[k], found = true;
        if (!found)
            return failf(c, VFX_ERR_INVALID_ARGUMENT, pi, "unknown flag \"%.64s\"", e->valuestring);
    }
    *out = mask;
    return VFX_OK;
}

static vfx_result resolve_path(pctx *c, const char *p, const char *rel, char *out)
{
    if (!*rel)
        return failf(c, VFX_ERR_INVALID_ARGUMENT, p, "empty path");
    int n;
    if (rel[0] == '/' || !c->base_dir || !*c->base_dir)
        n = snprintf(out, RT_SCENE_PATH_MAX, "%s", rel);
    else
        n = snprintf(out, RT_SCENE_PATH_MAX, "%s/%s", c->base_dir, rel);
    if (n < 0 || n >= RT_SCENE_PATH_MAX)
        return failf(c, VFX_ERR_INVALID_ARGUMENT, p, "resolved path longer than %d bytes", RT_SCENE_PATH_MAX - 1);
    return VFX_OK;
}

static vfx_result get_path(pctx *c, const cJSON *obj, const char *path, const char *key, bool required,
                           char *out)
{
    char raw[RT_SCENE_PATH_MAX] = "", p[JPATH];
    vfx_result r = get_string(c, obj, path, key, required, raw, sizeof raw);
    if (r || !cJSON_GetObjectItemCaseSensitive(obj, key))
        return r;
    join(p, path, key);
    return resolve_path(c, p, raw, out);
}

static const range COORD = {-COORD_MAX, COORD_MAX, false};
static const range POSITIVE = {0, COORD_MAX, true};
static const range NONNEG = {0, COORD_MAX, false};
static const range UNIT = {0, 1, false};

/* ------------------------------------------------------------------ transforms */

static void mat_identity(float m[16])
{
    memset(m, 0, 16 * sizeof(float));
    m[0] = m[5] = m[10] = m[15] = 1;
}

/* M = T * Rz * Ry * Rx * S, column-major; computed in double for the trig. */
static void mat_trs(const float t[3], const float rdeg[3], const float s[3], float m[16])
{
    double rx = rdeg[0] * M_PI / 180, ry = rdeg[1] * M_PI / 180, rz = rdeg[2] * M_PI / 180;
    double cx = cos(rx), sx = sin(rx), cy = cos(ry), sy = sin(ry), cz = cos(rz), sz = sin(rz);
    /* rows of Rz*Ry*Rx */
    double r[3][3] = {
        {cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx},
        {sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx},
        {-sy, cy * sx, cy * cx},
    };
    mat_identity(m);
    for (int col = 0; col < 3; ++col)
        for (int row = 0; row < 3; ++row)
            m[col * 4 + row] = (float)(r[row][col] * s[col]);
    m[12] = t[0], m[13] = t[1], m[14] = t[2];
}

static vfx_result parse_transform(pctx *c, const cJSON *obj, const char *path, float model[16])
{
    const cJSON *mv = cJSON_GetObjectItemCaseSensitive(obj, "matrix");
    bool trs = cJSON_GetObjectItemCaseSensitive(obj, "translate") || cJSON_GetObjectItemCaseSensitive(obj, "rotate_deg") ||
               cJSON_GetObjectItemCaseSensitive(obj, "scale");
    if (mv) {
        char p[JPATH];
        join(p, path, "matrix");
        if (trs)
            return failf(c, VFX_ERR_INVALID_ARGUMENT, p, "give either matrix or translate/rotate_deg/scale, not both");
        return vec_value(c, mv, p, 16, COORD, model);
    }
    float t[3] = {0, 0, 0}, rdeg[3] = {0, 0, 0}, s[3] = {1, 1, 1};
    vfx_result r = get_vec(c, obj, path, "translate", 3, false, COORD, t);
    if (!r) r = get_vec(c, obj, path, "rotate_deg", 3, false, (range){-36000, 36000, false}, rdeg);
    if (r)
        return r;
    const cJSON *sv = cJSON_GetObjectItemCaseSensitive(obj, "scale");
    if (sv) {
        char p[JPATH];
        join(p, path, "scale");
        const range sr = {0, COORD_MAX, true};
        if (cJSON_IsNumber(sv)) {
            double d;
            if ((r = number_value(c, sv, p, sr, &d)))
                return r;
            s[0] = s[1] = s[2] = (float)d;
        } else if ((r = vec_value(c, sv, p, 3, sr, s))) {
            return r;
        }
    }
    mat_trs(t, rdeg, s, model);
    return VFX_OK;
}

/* ------------------------------------------------------------------ sections */

static vfx_result parse_camera(pctx *c, const cJSON *v, rt_scene_camera *cam)
{
    static const char *const keys[] = {"eye", "target", "up", "fov_y_deg", "width", "height", "near", "far", NULL};
    const char *P = "camera";
    vfx_result r = expect_object(c, v, P);
    if (r)
        return r;
    check_keys(c, v, P, keys);
    if (!r) r = get_vec(c, v, P, "eye", 3, false, COORD, cam->eye);
    if (!r) r = get_vec(c, v, P, "target", 3, false, COORD, cam->target);
    if (!r) r = get_vec(c, v, P, "up", 3, false, COORD, cam->up);
    if (!r) r = get_float(c, v, P, "fov_y_deg", false, (range){0, 179, true}, &cam->fov_y_deg);
    if (!r) r = get_uint(c, v, P, "width", false, 1, 16384, &cam->width);
    if (!r) r = get_uint(c, v, P, "height", false, 1, 16384, &cam->height);
    if (!r) r = get_float(c, v, P, "near", false, POSITIVE, &cam->near_plane);
    if (!r) r = get_float(c, v, P, "far", false, POSITIVE, &cam->far_plane);
    if (r)
        return r;
    if (!(cam->far_plane > cam->near_plane))
        return failf(c, VFX_ERR_INVALID_ARGUMENT, "camera.far", "must be > near (%g), got %g",
                     cam->near_plane, cam->far_plane);
    double f[3], fl = 0, ul = 0, cr[3], cl = 0;
    for (int k = 0; k < 3; ++k)
        f[k] = (double)cam->target[k] - cam->eye[k], fl += f[k] * f[k], ul += (double)cam->up[k] * cam->up[k];
    if (fl < 1e-18)
        return failf(c, VFX_ERR_INVALID_ARGUMENT, "camera.target", "equals camera.eye: no view direction");
    cr[0] = f[1] * cam->up[2] - f[2] * cam->up[1];
    cr[1] = f[2] * cam->up[0] - f[0] * cam->up[2];
    cr[2] = f[0] * cam->up[1] - f[1] * cam->up[0];
    for (int k = 0; k < 3; ++k)
        cl += cr[k] * cr[k];
    /* sin^2 of the angle between up and the view direction below 1e-10: no usable right vector */
    if (ul < 1e-18 || cl < 1e-10 * fl * ul)
        return failf(c, VFX_ERR_INVALID_ARGUMENT, "camera.up", "zero or parallel to the view direction");
    return VFX_OK;
}

/* The prologue every array of objects shares: `v` must be an array of at most `cap` items;
 * *out gets calloc'd room for them (NULL when empty). */
static vfx_result alloc_array(pctx *c, const cJSON *v, const char *name, int cap, size_t elem,
                              void **out, int *count)
{
    *out = NULL;
    *count = 0;
    if (!cJSON_IsArray(v))
        return failf(c, VFX_ERR_FORMAT, name, "expected an array, got %s", type_name(v));
    int n = cJSON_GetArraySize(v);
    if (n > cap)
        return failf(c, VFX_ERR_INVALID_ARGUMENT, name, "%d %s, above the cap of %d", n, name, cap);
    if (n == 0)
        return VFX_OK;
    if (!(*out = calloc((size_t)n, elem)))
        return failf(c, VFX_ERR_OUT_OF_MEMORY, name, "out of memory");
    *count = n;
    return VFX_OK;
}

static vfx_result parse_meshes(pctx *c, const cJSON *v, rt_scene *s)
{
    static const char *const keys[] = {"path", "box", "translate", "rotate_deg", "scale", "matrix", "color", NULL};
    int n;
    vfx_result ra = alloc_array(c, v, "meshes", RT_SCENE_MAX_MESHES, sizeof *s->meshes, (void **)&s->meshes, &n);
    if (ra || n == 0)
        return ra;
    int i = 0;
    for (const cJSON *m = v->child; m; m = m->next, ++i) {
        char P[JPATH];
        join_index(P, "meshes", i);
        rt_scene_mesh *o = &s->meshes[i];
        vfx_result r = expect_object(c, m, P);
        if (r)
            return r;
        check_keys(c, m, P, keys);
        const cJSON *path = cJSON_GetObjectItemCaseSensitive(m, "path"), *box = cJSON_GetObjectItemCaseSensitive(m, "box");
        if (!path == !box)
            return failf(c, VFX_ERR_FORMAT, P, "needs exactly one of \"path\" (a mesh file) or \"box\"");
        if (path) {
            r = get_path(c, m, P, "path", true, o->path);
        } else {
            char PB[JPATH];
            join(PB, P, "box");
            static const char *const bkeys[] = {"min", "max", NULL};
            if ((r = expect_object(c, box, PB)))
                return r;
            check_keys(c, box, PB, bkeys);
            o->is_box = true;
            r = get_vec(c, box, PB, "min", 3, true, COORD, o->box_min);
            if (!r) r = get_vec(c, box, PB, "max", 3, true, COORD, o->box_max);
            for (int k = 0; k < 3 && !r; ++k)
                if (!(o->box_max[k] > o->box_min[k])) {
                    char PM[JPATH];
                    join(PM, PB, "max");
                    r = failf(c, VFX_ERR_INVALID_ARGUMENT, PM, "must exceed min on every axis (axis %d: %g <= %g)",
                              k, o->box_max[k], o->box_min[k]);
                }
        }
        o->color[0] = o->color[1] = o->color[2] = 0.7f;
        if (!r) r = get_vec(c, m, P, "color", 3, false, UNIT, o->color);
        if (!r) r = parse_transform(c, m, P, o->model);
        if (r)
            return r;
        s->mesh_count = (uint32_t)i + 1;
    }
    return VFX_OK;
}

static const char *const beam_param_names[RT_BEAM_PARAM_COUNT + 1] = {
    "head", "dir", "length", "radius", "a", "b", "eps", "color", NULL};
static const int beam_param_dim[RT_BEAM_PARAM_COUNT] = {3, 3, 1, 1, 1, 1, 1, 4};

static range beam_param_range(int k)
{
    switch (k) {
    case RT_BEAM_PARAM_HEAD:
    case RT_BEAM_PARAM_DIR: return COORD;
    case RT_BEAM_PARAM_RADIUS: return POSITIVE;
    case RT_BEAM_PARAM_COLOR: return (range){0, 1000, false};
    default: return NONNEG;
    }
}

static float *beam_param_ptr(vfx_beam *b, int k)
{
    switch (k) {
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

static bool is_zero3(const float *v)
{
    return (double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2] < 1e-24;
}

static vfx_result parse_track(pctx *c, const cJSON *v, const char *P, int k, rt_scene_track *tr)
{
    static const char *const keys[] = {"t", "value", NULL};
    if (!cJSON_IsArray(v))
        return failf(c, VFX_ERR_FORMAT, P, "expected an array of {\"t\", \"value\"} keyframes, got %s", type_name(v));
    int n = cJSON_GetArraySize(v);
    if (n < 1 || n > RT_SCENE_MAX_KEYS)
        return failf(c, VFX_ERR_INVALID_ARGUMENT, P, "%d keyframes; must be 1 to %d", n, RT_SCENE_MAX_KEYS);
    int dim = beam_param_dim[k];
    tr->dim = (uint32_t)dim;
    tr->times = malloc((size_t)n * sizeof(float));
    tr->values = malloc((size_t)n * (size_t)dim * sizeof(float));
    if (!tr->times || !tr->values)
        return failf(c, VFX_ERR_OUT_OF_MEMORY, P, "out of memory");
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, ++i) {
        char PI[JPATH], PV[JPATH];
        join_index(PI, P, i);
        vfx_result r = expect_object(c, e, PI);
        if (r)
            return r;
        check_keys(c, e, PI, keys);
        if ((r = get_float(c, e, PI, "t", true, COORD, &tr->times[i])))
            return r;
        if (i > 0 && !(tr->times[i] > tr->times[i - 1])) {
            char PT[JPATH];
            join(PT, PI, "t");
            return failf(c, VFX_ERR_INVALID_ARGUMENT, PT, "keyframe times must increase strictly (%g after %g)",
                         tr->times[i], tr->times[i - 1]);
        }
        join(PV, PI, "value");
        const cJSON *val = cJSON_GetObjectItemCaseSensitive(e, "value");
        float *dst = &tr->values[(size_t)i * (size_t)dim];
        if (!val)
            return failf(c, VFX_ERR_FORMAT, PV, "required value missing");
        if (dim == 1) {
            double d;
            if ((r = number_value(c, val, PV, beam_param_range(k), &d)))
                return r;
            dst[0] = (float)d;
        } else if ((r = vec_value(c, val, PV, dim, beam_param_range(k), dst))) {
            return r;
        }
        if (k == RT_BEAM_PARAM_DIR && is_zero3(dst))
            return failf(c, VFX_ERR_INVALID_ARGUMENT, PV, "direction must not be the zero vector");
        tr->count = (uint32_t)i + 1;
    }
    return VFX_OK;
}

static vfx_result parse_beams(pctx *c, const cJSON *v, rt_scene *s)
{
    static const char *const keys[] = {"head", "dir", "length", "radius", "a", "b", "eps", "color",
                                       "keyframes", "loop_s", NULL};
    int n;
    vfx_result ra = alloc_array(c, v, "beams", RT_SCENE_MAX_BEAMS, sizeof *s->beams, (void **)&s->beams, &n);
    if (ra || n == 0)
        return ra;
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, ++i) {
        char P[JPATH];
        join_index(P, "beams", i);
        rt_scene_beam *o = &s->beams[i];
        s->beam_count = (uint32_t)i + 1; /* so that free() sees tracks of a half-parsed beam */
        vfx_beam *b = &o->base;
        *b = (vfx_beam){.length = 1.0f, .radius = 0.5f, .a = 0.05f, .b = 0.03f, .eps = 0.02f, .color = {1, 1, 1, 1}};
        vfx_result r = expect_object(c, e, P);
        if (r)
            return r;
        check_keys(c, e, P, keys);
        const cJSON *kf = cJSON_GetObjectItemCaseSensitive(e, "keyframes");
        if (kf) {
            char PK[JPATH];
            join(PK, P, "keyframes");
            if ((r = expect_object(c, kf, PK)))
                return r;
            check_keys(c, kf, PK, beam_param_names);
        }
        for (int k = 0; k < RT_BEAM_PARAM_COUNT; ++k) {
            const char *name = beam_param_names[k];
            const cJSON *track = kf ? cJSON_GetObjectItemCaseSensitive(kf, name) : NULL;
            /* head and dir are required unless animated (then the first key is the base) */
            bool required = (k == RT_BEAM_PARAM_HEAD || k == RT_BEAM_PARAM_DIR) && !track;
            float *dst = beam_param_ptr(b, k);
            if (beam_param_dim[k] == 1)
                r = get_float(c, e, P, name, required, beam_param_range(k), dst);
            else
                r = get_vec(c, e, P, name, beam_param_dim[k], required, beam_param_range(k), dst);
            if (r)
                return r;
            if (track) {
                char PT[JPATH], PK[JPATH];
                join(PK, P, "keyframes");
                join(PT, PK, name);
                if ((r = parse_track(c, track, PT, k, &o->tracks[k])))
                    return r;
                if (!cJSON_GetObjectItemCaseSensitive(e, name))
                    memcpy(dst, o->tracks[k].values, (size_t)beam_param_dim[k] * sizeof(float));
            }
        }
        if (is_zero3(b->dir)) {
            char PD[JPATH];
            join(PD, P, "dir");
            return failf(c, VFX_ERR_INVALID_ARGUMENT, PD, "direction must not be the zero vector");
        }
        if ((r = get_float(c, e, P, "loop_s", false, NONNEG, &o->loop_s)))
            return r;
    }
    return VFX_OK;
}

static vfx_result parse_beam_settings(pctx *c, const cJSON *v, vfx_beams_view *bv)
{
    static const char *const keys[] = {"saturation", "c", "far_distance", "method", "march_samples", NULL};
    static const char *const sat[] = {"clamp", "smooth", NULL};
    static const char *const meth[] = {"closed_form", "march", NULL};
    const char *P = "beam_settings";
    vfx_result r = expect_object(c, v, P);
    if (r)
        return r;
    check_keys(c, v, P, keys);
    r = get_enum(c, v, P, "saturation", false, sat, &bv->saturation);
    if (!r) r = get_float(c, v, P, "c", false, POSITIVE, &bv->saturate_c);
    if (!r) r = get_float(c, v, P, "far_distance", false, NONNEG, &bv->far_distance);
    if (!r) r = get_enum(c, v, P, "method", false, meth, &bv->method);
    if (!r) r = get_uint(c, v, P, "march_samples", false, 1, 4096, &bv->march_samples);
    return r;
}

static vfx_result parse_box(pctx *c, const cJSON *obj, const char *path, const char *key, float mn[3], float mx[3])
{
    static const char *const keys[] = {"min", "max", NULL};
    char P[JPATH];
    join(P, path, key);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v)
        return failf(c, VFX_ERR_FORMAT, P, "required {\"min\", \"max\"} box missing");
    vfx_result r = expect_object(c, v, P);
    if (r)
        return r;
    check_keys(c, v, P, keys);
    r = get_vec(c, v, P, "min", 3, true, COORD, mn);
    if (!r) r = get_vec(c, v, P, "max", 3, true, COORD, mx);
    for (int k = 0; k < 3 && !r; ++k)
        if (!(mx[k] > mn[k])) {
            char PM[JPATH];
            join(PM, P, "max");
            r = failf(c, VFX_ERR_INVALID_ARGUMENT, PM, "must exceed min on every axis (axis %d: %g <= %g)", k, mx[k], mn[k]);
        }
    return r;
}

static vfx_result parse_water(pctx *c, const cJSON *v, rt_scene_water *w)
{
    static const char *const keys[] = {"source", "path", "generator", "simulation", "h", "threshold",
                                       "quality", "color", "absorption", "ior", NULL};
    static const char *const sources[] = {"file", "generator", "simulation", NULL};
    const char *P = "water";
    vfx_result r = expect_object(c, v, P);
    if (r)
        return r;
    check_keys(c, v, P, keys);
    uint32_t src = 0;
    if ((r = get_enum(c, v, P, "source", true, sources, &src)))
        return r;
    w->source = (rt_scene_water_source)src;
    w->layer_side = 24;
    w->spacing = 0.1f;
    w->dt = 0.004f;
    w->gravity[1] = -9.81f;
    w->paddle_amplitude = 0.2f;
    w->paddle_period_s = 2.0f;
    if (w->source == RT_SCENE_WATER_FILE) {
        if ((r = get_path(c, v, P, "path", true, w->path)))
            return r;
    } else if (w->source == RT_SCENE_WATER_GENERATOR) {
        static const char *const gkeys[] = {"kind", "count", "origin", "spacing", "layer_side", "min", "max",
                                            "center", "radius", NULL};
        static const char *const kinds[] = {"layers", "box", "sphere", NULL};
        const char *PG = "water.generator";
        const cJSON *g = cJSON_GetObjectItemCaseSensitive(v, "generator");
        if (!g)
            return failf(c, VFX_ERR_FORMAT, PG, "required for source \"generator\"");
        if ((r = expect_object(c, g, PG)))
            return r;
        check_keys(c, g, PG, gkeys);
        uint32_t kind = 0;
        r = get_enum(c, g, PG, "kind", true, kinds, &kind);
        if (!r) r = get_uint(c, g, PG, "count", true, 0, RT_SCENE_MAX_PARTICLES, &w->count);
        if (r)
            return r;
        w->generator = (rt_scene_generator)kind;
        if (kind == RT_SCENE_GEN_LAYERS) {
            r = get_vec(c, g, PG, "origin", 3, false, COORD, w->origin);
            if (!r) r = get_float(c, g, PG, "spacing", false, POSITIVE, &w->spacing);
            if (!r) r = get_uint(c, g, PG, "layer_side", false, 1, 4096, &w->layer_side);
        } else if (kind == RT_SCENE_GEN_BOX) {
            r = get_vec(c, g, PG, "min", 3, true, COORD, w->box_min);
            if (!r) r = get_vec(c, g, PG, "max", 3, true, COORD, w->box_max);
            for (int k = 0; k < 3 && !r; ++k)
                if (!(w->box_max[k] > w->box_min[k]))
                    r = failf(c, VFX_ERR_INVALID_ARGUMENT, "water.generator.max",
                              "must exceed min on every axis (axis %d: %g <= %g)", k, w->box_max[k], w->box_min[k]);
        } else {
            r = get_vec(c, g, PG, "center", 3, false, COORD, w->center);
            if (!r) r = get_float(c, g, PG, "radius", true, POSITIVE, &w->radius);
        }
        if (r)
            return r;
    } else {
        static const char *const skeys[] = {"tank", "fluid", "particle_count", "gravity", "dt", "paddle", "no_slip", NULL};
        const char *PS = "water.simulation";
        const cJSON *s = cJSON_GetObjectItemCaseSensitive(v, "simulation");
        if (!s)
            return failf(c, VFX_ERR_FORMAT, PS, "required for source \"simulation\"");
        if ((r = expect_object(c, s, PS)))
            return r;
        check_keys(c, s, PS, skeys);
        r = parse_box(c, s, PS, "tank", w->tank_min, w->tank_max);
        if (!r) r = parse_box(c, s, PS, "fluid", w->box_min, w->box_max);
        for (int k = 0; k < 3 && !r; ++k)
            if (w->box_min[k] < w->tank_min[k] || w->box_max[k] > w->tank_max[k])
                r = failf(c, VFX_ERR_INVALID_ARGUMENT, "water.simulation.fluid", "must lie inside the tank (axis %d)", k);
        if (!r) r = get_uint(c, s, PS, "particle_count", true, 0, RT_SCENE_MAX_PARTICLES, &w->count);
        if (!r) r = get_vec(c, s, PS, "gravity", 3, false, (range){-1000, 1000, false}, w->gravity);
        if (!r) r = get_float(c, s, PS, "dt", false, (range){0, 0.1, true}, &w->dt);
        if (!r) r = get_bool(c, s, PS, "no_slip", &w->no_slip);
        if (r)
            return r;
        const cJSON *pd = cJSON_GetObjectItemCaseSensitive(s, "paddle");
        if (pd) {
            static const char *const pkeys[] = {"axis", "amplitude", "period_s", NULL};
            static const char *const axes[] = {"x", "y", "z", NULL};
            const char *PP = "water.simulation.paddle";
            if ((r = expect_object(c, pd, PP)))
                return r;
            check_keys(c, pd, PP, pkeys);
            w->paddle = true;
            r = get_enum(c, pd, PP, "axis", false, axes, &w->paddle_axis);
            if (!r) r = get_float(c, pd, PP, "amplitude", false, NONNEG, &w->paddle_amplitude);
            if (!r) r = get_float(c, pd, PP, "period_s", false, (range){0, 1e4, true}, &w->paddle_period_s);
            if (r)
                return r;
        }
    }
    vfx_water_params *wp = &w->params;
    *wp = (vfx_water_params){.size = sizeof *wp, .version = VFX_WATER_PARAMS_VERSION};
    r = get_float(c, v, P, "h", false, (range){0, 1e3, true}, &wp->h);
    if (!r) r = get_float(c, v, P, "threshold", false, (range){0, 1e3, true}, &wp->threshold);
    if (!r) r = get_vec(c, v, P, "color", 3, false, UNIT, wp->color);
    if (!r) r = get_float(c, v, P, "absorption", false, (range){0, 1e3, false}, &wp->absorption);
    if (!r) r = get_float(c, v, P, "ior", false, (range){1, 3, false}, &wp->ior);
    if (r)
        return r;
    const cJSON *q = cJSON_GetObjectItemCaseSensitive(v, "quality");
    if (q) {
        static const char *const qkeys[] = {"max_samples", "step", "refine_iters", "pyramid_level", "method",
                                            "disable", NULL};
        static const char *const methods[] = {"paper", "brute", "grid", NULL};
        static const char *const flags[] = {"billboard_init", "skip", "blend", "pack4", "pyramid", "refine",
                                            "shading", NULL};
        static const uint32_t bits[] = {VFX_WATER_NO_BILLBOARD_INIT, VFX_WATER_NO_SKIP, VFX_WATER_NO_BLEND,
                                        VFX_WATER_NO_PACK4, VFX_WATER_NO_PYRAMID, VFX_WATER_NO_REFINE,
                                        VFX_WATER_NO_SHADING};
        const char *PQ = "water.quality";
        if ((r = expect_object(c, q, PQ)))
            return r;
        check_keys(c, q, PQ, qkeys);
        r = get_uint(c, q, PQ, "max_samples", false, 1, 4096, &wp->max_samples);
        if (!r) r = get_float(c, q, PQ, "step", false, (range){0, 1e3, true}, &wp->step);
        if (!r) r = get_uint(c, q, PQ, "refine_iters", false, 1, 64, &wp->refine_iters);
        if (!r) r = get_uint(c, q, PQ, "pyramid_level", false, 1, 12, &wp->pyramid_level);
        if (!r) r = get_enum(c, q, PQ, "method", false, methods, &wp->method);
        if (!r) r = get_flags(c, q, PQ, "disable", flags, bits, &wp->disable);
    }
    return r;
}

static bool ends_with(const char *s, const char *suffix)
{
    size_t a = strlen(s), b = strlen(suffix);
    return a >= b && strcmp(s + a - b, suffix) == 0;
}

static vfx_result parse_volume(pctx *c, const cJSON *v, rt_scene_volume *vol)
{
    static const char *const keys[] = {"path", "generator", "scalar", "transfer", "transfer_normalized",
                                       "ert_threshold", "tiles", "update_c", "workers", "disable",
                                       "translate", "rotate_deg", "scale", "matrix", NULL};
    const char *P = "volume";
    vfx_result r = expect_object(c, v, P);
    if (r)
        return r;
    check_keys(c, v, P, keys);
    const cJSON *path = cJSON_GetObjectItemCaseSensitive(v, "path"), *gen = cJSON_GetObjectItemCaseSensitive(v, "generator");
    if (!path == !gen)
        return failf(c, VFX_ERR_FORMAT, P, "needs exactly one of \"path\" (.vtu or .node) or \"generator\"");
    if (path) {
        if ((r = get_path(c, v, P, "path", true, vol->path)))
            return r;
        if (!ends_with(vol->path, ".vtu") && !ends_with(vol->path, ".node"))
            return failf(c, VFX_ERR_INVALID_ARGUMENT, "volume.path",
                         "\"%.200s\" is neither a .vtu nor a TetGen .node file", vol->path);
    } else {
        static const char *const gkeys[] = {"cells", "min", "max", NULL};
        const char *PG = "volume.generator";
        if ((r = expect_object(c, gen, PG)))
            return r;
        check_keys(c, gen, PG, gkeys);
        vol->generated = true;
        vol->gen_cells = 8;
        vol->gen_min[0] = vol->gen_min[1] = vol->gen_min[2] = -1;
        vol->gen_max[0] = vol->gen_max[1] = vol->gen_max[2] = 1;
        r = get_uint(c, gen, PG, "cells", false, 1, RT_SCENE_MAX_VOLUME_CELLS, &vol->gen_cells);
        if (!r) r = get_vec(c, gen, PG, "min", 3, false, COORD, vol->gen_min);
        if (!r) r = get_vec(c, gen, PG, "max", 3, false, COORD, vol->gen_max);
        for (int k = 0; k < 3 && !r; ++k)
            if (!(vol->gen_max[k] > vol->gen_min[k]))
                r = failf(c, VFX_ERR_INVALID_ARGUMENT, "volume.generator.max",
                          "must exceed min on every axis (axis %d: %g <= %g)", k, vol->gen_max[k], vol->gen_min[k]);
        if (r)
            return r;
    }
    r = get_string(c, v, P, "scalar", false, vol->scalar, sizeof vol->scalar);
    if (!r) r = get_bool(c, v, P, "transfer_normalized", &vol->transfer_normalized);
    if (!r) r = get_float(c, v, P, "ert_threshold", false, (range){0, 1, true}, &vol->ert_threshold);
    if (!r) r = get_uint(c, v, P, "tiles", false, 1, 1024, &vol->tiles);
    if (!r) r = get_uint(c, v, P, "update_c", false, 1, 1u << 20, &vol->update_c);
    if (!r) r = get_uint(c, v, P, "workers", false, 0, 256, &vol->workers);
    if (!r) {
        static const char *const flags[] = {"ert", "share", "dlb", NULL};
        static const uint32_t bits[] = {VFX_VOLUME_NO_ERT, VFX_VOLUME_NO_SHARE, VFX_VOLUME_NO_DLB};
        r = get_flags(c, v, P, "disable", flags, bits, &vol->disable);
    }
    if (!r) r = parse_transform(c, v, P, vol->model);
    if (r)
        return r;
    const cJSON *tf = cJSON_GetObjectItemCaseSensitive(v, "transfer");
    if (!tf)
        return VFX_OK;
    const char *PT = "volume.transfer";
    if (!cJSON_IsArray(tf))
        return failf(c, VFX_ERR_FORMAT, PT, "expected an array of {\"scalar\", \"rgba\"}, got %s", type_name(tf));
    int n = cJSON_GetArraySize(tf);
    if (n < 1 || n > RT_SCENE_MAX_TRANSFER)
        return failf(c, VFX_ERR_INVALID_ARGUMENT, PT, "%d control points; must be 1 to %d", n, RT_SCENE_MAX_TRANSFER);
    int i = 0;
    for (const cJSON *e = tf->child; e; e = e->next, ++i) {
        static const char *const tkeys[] = {"scalar", "rgba", NULL};
        char PI[JPATH];
        join_index(PI, PT, i);
        rt_scene_transfer_point *tp = &vol->transfer[i];
        if ((r = expect_object(c, e, PI)))
            return r;
        check_keys(c, e, PI, tkeys);
        r = get_float(c, e, PI, "scalar", true, vol->transfer_normalized ? UNIT : (range){-1e30, 1e30, false}, &tp->scalar);
        if (!r) r = get_vec(c, e, PI, "rgba", 4, true, (range){0, 1e3, false}, tp->rgba);
        if (r)
            return r;
        if (i > 0 && !(tp->scalar > vol->transfer[i - 1].scalar)) {
            char PS[JPATH];
            join(PS, PI, "scalar");
            return failf(c, VFX_ERR_INVALID_ARGUMENT, PS, "control points must increase strictly (%g after %g)",
                         tp->scalar, vol->transfer[i - 1].scalar);
        }
        vol->transfer_count = (uint32_t)i + 1;
    }
    return VFX_OK;
}

static vfx_result parse_root(pctx *c, const cJSON *root, rt_scene *s)
{
    static const char *const keys[] = {"version", "name", "description", "camera", "meshes", "beams",
                                       "beam_settings", "water", "volume", NULL};
    vfx_result r = expect_object(c, root, "");
    if (r)
        return r;
    check_keys(c, root, "", keys);
    const cJSON *ver = cJSON_GetObjectItemCaseSensitive(root, "version");
    if (ver) {
        uint32_t version = 0;
        if ((r = get_uint(c, root, "", "version", false, 0, 1e9, &version)))
            return r;
        if (version != RT_SCENE_FORMAT_VERSION)
            return failf(c, VFX_ERR_UNSUPPORTED, "version", "scene format version %u is not supported (this build reads %d)",
                         version, RT_SCENE_FORMAT_VERSION);
    }
    char desc[512];
    r = get_string(c, root, "", "name", false, s->name, sizeof s->name);
    if (!r) r = get_string(c, root, "", "description", false, desc, sizeof desc);
    if (r)
        return r;
    s->camera = (rt_scene_camera){.eye = {0, 2, 6}, .target = {0, 0.5f, 0}, .up = {0, 1, 0}, .fov_y_deg = 60,
                                   .width = 640, .height = 360, .near_plane = 0.05f, .far_plane = 200};
    s->beams_view = (vfx_beams_view){.size = sizeof s->beams_view, .version = VFX_BEAMS_VIEW_VERSION,
                                     .saturation = VFX_SATURATE_SMOOTH, .saturate_c = 1};
    const cJSON *v;
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "camera")) && (r = parse_camera(c, v, &s->camera)))
        return r;
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "meshes")) && (r = parse_meshes(c, v, s)))
        return r;
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "beams")) && (r = parse_beams(c, v, s)))
        return r;
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "beam_settings")) && (r = parse_beam_settings(c, v, &s->beams_view)))
        return r;
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "water"))) {
        s->has_water = true;
        if ((r = parse_water(c, v, &s->water)))
            return r;
    }
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "volume"))) {
        s->has_volume = true;
        if ((r = parse_volume(c, v, &s->volume)))
            return r;
    }
    return VFX_OK;
}

/* ------------------------------------------------------------------ load / free */

void rt_scene_free(rt_scene *scene)
{
    if (!scene)
        return;
    for (uint32_t i = 0; i < scene->beam_count; ++i)
        for (int k = 0; k < RT_BEAM_PARAM_COUNT; ++k) {
            free(scene->beams[i].tracks[k].times);
            free(scene->beams[i].tracks[k].values);
        }
    free(scene->beams);
    free(scene->meshes);
    free(scene);
}

vfx_result rt_scene_load_mem(const char *json, size_t len, const char *base_dir, const rt_logger *logger,
                              rt_scene **out, char *err, size_t errlen)
{
    pctx c = {.log = logger, .err = err, .errlen = errlen, .base_dir = base_dir};
    if (err && errlen)
        err[0] = 0;
    if (!out || (!json && len))
        return failf(&c, VFX_ERR_INVALID_ARGUMENT, "scene", "NULL argument");
    *out = NULL;
    if (len > RT_SCENE_MAX_BYTES)
        return failf(&c, VFX_ERR_INVALID_ARGUMENT, "scene", "%zu bytes, above the cap of %u", len, RT_SCENE_MAX_BYTES);
    if (base_dir && strlen(base_dir) >= RT_SCENE_PATH_MAX)
        return failf(&c, VFX_ERR_INVALID_ARGUMENT, "scene", "base directory longer than %d bytes", RT_SCENE_PATH_MAX - 1);
    /* a private NUL-terminated copy: cJSON then never depends on the caller's termination */
    char *text = malloc(len + 1);
    if (!text)
        return failf(&c, VFX_ERR_OUT_OF_MEMORY, "scene", "out of memory");
    if (len)
        memcpy(text, json, len);
    text[len] = 0;
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(text, len + 1, &end, false);
    if (!root) {
        size_t off = end && end >= text && end <= text + len ? (size_t)(end - text) : len;
        if (memchr(text, 0, len))
            off = strlen(text) < off ? strlen(text) : off;
        unsigned line = 1, col = 1;
        for (size_t i = 0; i < off; ++i)
            if (text[i] == '\n')
                line++, col = 1;
            else
                col++;
        vfx_result r = failf(&c, VFX_ERR_FORMAT, "scene", "JSON syntax error at line %u, column %u (byte %zu)%s",
                             line, col, off, off >= len ? ": unexpected end of input" : "");
        free(text);
        return r;
    }
    /* trailing non-space after the value is an error too (a truncated edit, two objects) */
    const char *p = end;
    while (p && p < text + len && (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r'))
        ++p;
    if (p && p < text + len) {
        size_t off = (size_t)(p - text);
        unsigned line = 1, col = 1;
        for (size_t i = 0; i < off; ++i)
            if (text[i] == '\n')
                line++, col = 1;
            else
                col++;
        cJSON_Delete(root);
        free(text);
        return failf(&c, VFX_ERR_FORMAT, "scene", "JSON syntax error at line %u, column %u (byte %zu): text after the scene object",
                     line, col, off);
    }
    rt_scene *s = calloc(1, sizeof *s);
    vfx_result r = VFX_OK;
    if (!s) {
        r = failf(&c, VFX_ERR_OUT_OF_MEMORY, "scene", "out of memory");
    } else {
        if (base_dir)
            snprintf(s->base_dir, sizeof s->base_dir, "%s", base_dir);
        r = parse_root(&c, root, s);
    }
    cJSON_Delete(root);
    free(text);
    if (r) {
        rt_scene_free(s);
        return r;
    }
    *out = s;
    return VFX_OK;
}

vfx_result rt_scene_load_file(const char *path, const rt_logger *logger, rt_scene **out, char *err, size_t errlen)
{
    if (err && errlen)
        err[0] = 0;
    if (!path || !out) {
        if (err && errlen)
            snprintf(err, errlen, "scene: NULL argument");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    *out = NULL;
    char *buf, tmp[512];
    size_t size;
    vfx_result rr = rt_read_file(path, RT_SCENE_MAX_BYTES, "16 MiB for a scene", &buf, &size, tmp, sizeof tmp);
    if (rr) {
        if (err && errlen)
            snprintf(err, errlen, "%s", tmp);
        return rr;
    }
    char dir[RT_SCENE_PATH_MAX];
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else if (slash == path)
        snprintf(dir, sizeof dir, "/");
    else
        snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    char msg[512] = "";
    vfx_result r = rt_scene_load_mem(buf, size, dir, logger, out, msg, sizeof msg);
    free(buf);
    if (r && err && errlen)
        snprintf(err, errlen, "%s: %s", path, msg);
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

uint32_t rt_scene_beams_at(const rt_scene *scene, double time, vfx_beam *out, uint32_t n)
{
    if (!scene || !out)
        return 0;
    uint32_t count = scene->beam_count < n ? scene->beam_count : n;
    if (!isfinite(time))
        time = 0;
    for (uint32_t i = 0; i < count; ++i) {
        const rt_scene_beam *b = &scene->beams[i];
        double t = time;
        if (b->loop_s > 0) {
            t = fmod(t, b->loop_s);
            if (t < 0)
                t += b->loop_s;
        }
        out[i] = b->base;
        for (int k = 0; k < RT_BEAM_PARAM_COUNT; ++k) {
            const rt_scene_track *tr = &b->tracks[k];
            if (!tr->count)
                continue;
            float *dst = beam_param_ptr(&out[i], k);
            rt_scene_track_eval(tr, t, dst);
            /* opposite direction keys pass through zero: hold the earlier key's direction */
            if (k == RT_BEAM_PARAM_DIR && is_zero3(dst))
                memcpy(dst, &tr->values[(size_t)key_before(tr, t) * 3], 3 * sizeof(float));
        }
    }
    return count;
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
    if (w->source == RT_SCENE_WATER_FILE)
        return rt_particle_file_load(w->path, xyz, count, err, errlen);
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
