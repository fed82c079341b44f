/* scene.c — see scene.h and docs/scene-format.md: the root, camera and mesh sections, load and
 * free. Each other section has its own scene_<section>.c over scene_parse.h. */
#include "scene/scene.h"
#include "scene/scene_parse.h"
#include "core/file.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/particle_file.h"

/* ------------------------------------------------------------------ sections */

/* The camera's eye when the scene has no "origin" key: camera.eye read in double (its checks
 * come with the camera's), or the default eye. */
static void implicit_origin(pctx *c, const cJSON *cam, rt_scene *s)
{
    double eye[3] = {RT_SCENE_DEFAULT_EYE};
    const cJSON *e = cJSON_IsObject(cam) ? cJSON_GetObjectItemCaseSensitive(cam, "eye") : NULL;
    const cJSON *x = cJSON_IsArray(e) && cJSON_GetArraySize(e) == 3 ? e->child : NULL;
    for (int i = 0; x && i < 3; ++i, x = x->next)
        if (cJSON_IsNumber(x) && isfinite(x->valuedouble) && fabs(x->valuedouble) <= COORD_MAX)
            eye[i] = x->valuedouble;
    memcpy(c->origin, eye, sizeof eye);
    memcpy(s->origin, eye, sizeof eye);
    c->defaults_world = true;
}

/* "origin": [x, y, z] or "camera" (the camera's eye), in double: every position the scene holds
 * is stored as its difference to it, so a scene 1e5 units out keeps float32 digits near the
 * camera; the game hands the origin to the plugin in frame view 2. Absent: the camera's eye, as
 * with "camera" (camera-relative by default, as large-world engines render), but the defaults
 * of positions the scene leaves out stay world positions, so the scene means what it meant with
 * the world origin. [0, 0, 0] is the opt-out: float32 world coordinates. */
static vfx_result parse_origin(pctx *c, const cJSON *root, rt_scene *s)
{
    const cJSON *o = cJSON_GetObjectItemCaseSensitive(root, "origin");
    const cJSON *cam = cJSON_GetObjectItemCaseSensitive(root, "camera");
    if (!o) {
        implicit_origin(c, cam, s);
        return VFX_OK;
    }
    const cJSON *src = o;
    const char *P = "origin";
    if (cJSON_IsString(o)) {
        if (strcmp(o->valuestring, "camera") != 0)
            return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, P, "expected [x, y, z] or \"camera\", got \"%s\"", o->valuestring);
        src = cJSON_IsObject(cam) ? cJSON_GetObjectItemCaseSensitive(cam, "eye") : NULL;
        P = "camera.eye";
        if (!src)
            return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, "origin", "\"camera\" needs camera.eye");
    }
    if (!cJSON_IsArray(src) || cJSON_GetArraySize(src) != 3)
        return rt_scene_failf(c, VFX_ERR_FORMAT, P, "expected an array of 3 numbers, got %s", rt_scene_type_name(src));
    int i = 0;
    for (const cJSON *e = src->child; e; e = e->next, ++i) {
        char pi[JPATH];
        rt_scene_join_index(pi, P, i);
        vfx_result r = rt_scene_number_value(c, e, pi, COORD, &c->origin[i]);
        if (r)
            return r;
        s->origin[i] = c->origin[i] = e->valuedouble; /* in double, unrounded */
    }
    return VFX_OK;
}

static vfx_result parse_camera(pctx *c, const cJSON *v, rt_scene_camera *cam)
{
    static const char *const keys[] = {"eye", "target", "up", "fov_y_deg", "width", "height", "near", "far", NULL};
    const char *P = "camera";
    vfx_result r = rt_scene_expect_object(c, v, P);
    if (r)
        return r;
    rt_scene_check_keys(c, v, P, keys);
    if (!r) r = rt_scene_get_point(c, v, P, "eye", false, cam->eye);
    if (!r) r = rt_scene_get_point(c, v, P, "target", false, cam->target);
    if (!r) r = rt_scene_get_vec(c, v, P, "up", 3, false, COORD, cam->up);
    if (!r) r = rt_scene_get_float(c, v, P, "fov_y_deg", false, (range){0, 179, true}, &cam->fov_y_deg);
    if (!r) r = rt_scene_get_uint(c, v, P, "width", false, 1, 16384, &cam->width);
    if (!r) r = rt_scene_get_uint(c, v, P, "height", false, 1, 16384, &cam->height);
    if (!r) r = rt_scene_get_float(c, v, P, "near", false, POSITIVE, &cam->near_plane);
    if (!r) r = rt_scene_get_float(c, v, P, "far", false, POSITIVE, &cam->far_plane);
    if (r)
        return r;
    if (!(cam->far_plane > cam->near_plane))
        return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, "camera.far", "must be > near (%g), got %g",
                     cam->near_plane, cam->far_plane);
    double f[3], fl = 0, ul = 0, cr[3], cl = 0;
    for (int k = 0; k < 3; ++k)
        f[k] = (double)cam->target[k] - cam->eye[k], fl += f[k] * f[k], ul += (double)cam->up[k] * cam->up[k];
    if (fl < 1e-18)
        return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, "camera.target", "equals camera.eye: no view direction");
    cr[0] = f[1] * cam->up[2] - f[2] * cam->up[1];
    cr[1] = f[2] * cam->up[0] - f[0] * cam->up[2];
    cr[2] = f[0] * cam->up[1] - f[1] * cam->up[0];
    for (int k = 0; k < 3; ++k)
        cl += cr[k] * cr[k];
    /* sin^2 of the angle between up and the view direction below 1e-10: no usable right vector */
    if (ul < 1e-18 || cl < 1e-10 * fl * ul)
        return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, "camera.up", "zero or parallel to the view direction");
    return VFX_OK;
}

static vfx_result parse_meshes(pctx *c, const cJSON *v, rt_scene *s)
{
    static const char *const keys[] = {"path", "box", "translate", "rotate_deg", "scale", "matrix", "color", NULL};
    int n;
    vfx_result ra = rt_scene_alloc_array(c, v, "meshes", RT_SCENE_MAX_MESHES, sizeof *s->meshes, (void **)&s->meshes, &n);
    if (ra || n == 0)
        return ra;
    int i = 0;
    for (const cJSON *m = v->child; m; m = m->next, ++i) {
        char P[JPATH];
        rt_scene_join_index(P, "meshes", i);
        rt_scene_mesh *o = &s->meshes[i];
        vfx_result r = rt_scene_expect_object(c, m, P);
        if (r)
            return r;
        rt_scene_check_keys(c, m, P, keys);
        const cJSON *path = cJSON_GetObjectItemCaseSensitive(m, "path"), *box = cJSON_GetObjectItemCaseSensitive(m, "box");
        if (!path == !box)
            return rt_scene_failf(c, VFX_ERR_FORMAT, P, "needs exactly one of \"path\" (a mesh file) or \"box\"");
        if (path) {
            r = rt_scene_get_path(c, m, P, "path", true, o->path);
        } else {
            char PB[JPATH];
            rt_scene_join(PB, P, "box");
            static const char *const bkeys[] = {"min", "max", NULL};
            if ((r = rt_scene_expect_object(c, box, PB)))
                return r;
            rt_scene_check_keys(c, box, PB, bkeys);
            o->is_box = true;
            r = rt_scene_get_vec(c, box, PB, "min", 3, true, COORD, o->box_min); /* model space */
            if (!r) r = rt_scene_get_vec(c, box, PB, "max", 3, true, COORD, o->box_max);
            for (int k = 0; k < 3 && !r; ++k)
                if (!(o->box_max[k] > o->box_min[k])) {
                    char PM[JPATH];
                    rt_scene_join(PM, PB, "max");
                    r = rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, PM, "must exceed min on every axis (axis %d: %g <= %g)",
                              k, o->box_max[k], o->box_min[k]);
                }
        }
        o->color[0] = o->color[1] = o->color[2] = 0.7f;
        if (!r) r = rt_scene_get_vec(c, m, P, "color", 3, false, UNIT, o->color);
        if (!r) r = rt_scene_parse_transform(c, m, P, o->model);
        if (r)
            return r;
        s->mesh_count = (uint32_t)i + 1;
    }
    return VFX_OK;
}


static vfx_result parse_environment(pctx *c, const cJSON *v, rt_scene_environment *env)
{
    static const char *const keys[] = {"sky", "sun_dir", "fog", NULL};
    static const char *const skies[] = {"none", "dusk", NULL};
    vfx_result r = rt_scene_expect_object(c, v, "environment");
    if (r)
        return r;
    rt_scene_check_keys(c, v, "environment", keys);
    uint32_t sky = 1;
    env->sun_dir[0] = -0.45f, env->sun_dir[1] = 0.35f, env->sun_dir[2] = -0.82f;
    if ((r = rt_scene_get_enum(c, v, "environment", "sky", false, skies, &sky)))
        return r;
    env->sky = sky == 1;
    if ((r = rt_scene_get_vec(c, v, "environment", "sun_dir", 3, false, COORD, env->sun_dir)))
        return r;
    if (!(fabsf(env->sun_dir[0]) + fabsf(env->sun_dir[1]) + fabsf(env->sun_dir[2]) > 1e-6f))
        return rt_scene_failf(c, VFX_ERR_INVALID_ARGUMENT, "environment.sun_dir", "must not be the zero vector");
    return rt_scene_get_float(c, v, "environment", "fog", false, (range){0, 10, false}, &env->fog);
}

/* The distance between neighbouring float32 values at magnitude x. */
static double f32_ulp(double x)
{
    float f = (float)fabs(x);
    return (double)nextafterf(f, INFINITY) - (double)f;
}

/* Warns when content the scene stores relative to the origin lies so far from it that float32
 * cannot resolve it (an origin 1e6 away from a pool of spacing 0.05: positions 0.0625 apart,
 * the simulation wrecked and the water drawn as a few pixels): the fluid's tank against 1/64 of
 * its particle spacing, the camera's eye against 1/16 of its near plane. */
static void check_origin_distance(pctx *c, const rt_scene *s)
{
    const double *o = s->origin;
    if (s->has_water && s->water.source == RT_SCENE_WATER_SIMULATION && s->water.count) {
        const rt_scene_water *w = &s->water;
        double far = 0, vol = 1;
        for (int k = 0; k < 3; ++k) {
            far = fmax(far, fmax(fabs(w->tank_min[k]), fabs(w->tank_max[k])));
            vol *= fmax(w->box_max[k] - w->box_min[k], 1e-6);
        }
        double spacing = cbrt(vol / w->count), u = f32_ulp(far);
        if (u > spacing / 64)
            rt_logf(c->log, VFX_LOG_WARN, "origin [%.9g, %.9g, %.9g]: water.simulation.tank reaches %g m from it, "
                    "where float32 positions are %g m apart, more than 1/64 of the particle spacing %g m: the "
                    "simulation cannot resolve the fluid; put the origin near the content (\"camera\", or leave "
                    "the key out)", o[0], o[1], o[2], far, u, spacing);
    }
    double eye = 0;
    for (int k = 0; k < 3; ++k)
        eye = fmax(eye, fabs(s->camera.eye[k]));
    if (f32_ulp(eye) > s->camera.near_plane / 16)
        rt_logf(c->log, VFX_LOG_WARN, "origin [%.9g, %.9g, %.9g]: camera.eye is %g m from it, where float32 "
                "positions are %g m apart, more than 1/16 of camera.near (%g m): the view cannot be placed; put the "
                "origin near the camera (\"camera\", or leave the key out)", o[0], o[1], o[2], eye, f32_ulp(eye),
                (double)s->camera.near_plane);
}

static vfx_result parse_root(pctx *c, const cJSON *root, rt_scene *s)
{
    static const char *const keys[] = {"version", "origin", "name", "description", "camera", "meshes", "beams",
                                       "beam_settings", "water", "volume", "environment", NULL};
    vfx_result r = rt_scene_expect_object(c, root, "");
    if (r)
        return r;
    rt_scene_check_keys(c, root, "", keys);
    const cJSON *ver = cJSON_GetObjectItemCaseSensitive(root, "version");
    if (ver) {
        uint32_t version = 0;
        if ((r = rt_scene_get_uint(c, root, "", "version", false, 0, 1e9, &version)))
            return r;
        if (version != RT_SCENE_FORMAT_VERSION)
            return rt_scene_failf(c, VFX_ERR_UNSUPPORTED, "version", "scene format version %u is not supported (this build reads %d)",
                         version, RT_SCENE_FORMAT_VERSION);
    }
    char desc[512];
    r = rt_scene_get_string(c, root, "", "name", false, s->name, sizeof s->name);
    if (!r) r = rt_scene_get_string(c, root, "", "description", false, desc, sizeof desc);
    if (r)
        return r;
    if ((r = parse_origin(c, root, s)))
        return r;
    s->camera = (rt_scene_camera){.eye = {RT_SCENE_DEFAULT_EYE}, .target = {0, 0.5f, 0}, .up = {0, 1, 0}, .fov_y_deg = 60,
                                   .width = 640, .height = 360, .near_plane = 0.05f, .far_plane = 200};
    if (c->defaults_world && !cJSON_GetObjectItemCaseSensitive(root, "camera"))
        for (int i = 0; i < 3; ++i) { /* no camera object to read: its world defaults made relative here */
            s->camera.eye[i] = (float)((double)s->camera.eye[i] - c->origin[i]);
            s->camera.target[i] = (float)((double)s->camera.target[i] - c->origin[i]);
        }
    s->beams_view = (vfx_beams_view){.type = VFX_TYPE_BEAMS_VIEW, .saturation = VFX_SATURATE_SMOOTH, .saturate_c = 1};
    const cJSON *v;
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "camera")) && (r = parse_camera(c, v, &s->camera)))
        return r;
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "meshes")) && (r = parse_meshes(c, v, s)))
        return r;
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "beams")) && (r = rt_scene_parse_beams(c, v, s)))
        return r;
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "beam_settings")) && (r = rt_scene_parse_beam_settings(c, v, &s->beams_view)))
        return r;
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "water"))) {
        s->has_water = true;
        if ((r = rt_scene_parse_water(c, v, &s->water)))
            return r;
        memcpy(s->water.scene_origin, s->origin, sizeof s->origin);
    }
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "environment")) && (r = parse_environment(c, v, &s->environment)))
        return r;
    if ((v = cJSON_GetObjectItemCaseSensitive(root, "volume"))) {
        s->has_volume = true;
        if ((r = rt_scene_parse_volume(c, v, &s->volume)))
            return r;
    }
    check_origin_distance(c, s);
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
    for (uint32_t i = 0; i < scene->beam_count; ++i) {
        free(scene->beams[i].joint_track.times);
        free(scene->beams[i].joint_track.values);
    }
    free(scene->beams);
    free(scene->meshes);
    free(scene);
}

/* How many arrays and objects are open at byte off (brackets inside strings skipped). */
static size_t json_depth(const char *text, size_t off)
{
    size_t depth = 0;
    bool str = false;
    for (size_t i = 0; i < off && text[i]; ++i) {
        char ch = text[i];
        if (str) {
            if (ch == '\\' && text[i + 1])
                ++i;
            else if (ch == '"')
                str = false;
        } else if (ch == '"') {
            str = true;
        } else if (ch == '[' || ch == '{') {
            ++depth;
        } else if ((ch == ']' || ch == '}') && depth) {
            --depth;
        }
    }
    return depth;
}

static void line_col(const char *text, size_t off, unsigned *line, unsigned *col)
{
    *line = *col = 1;
    for (size_t i = 0; i < off; ++i)
        if (text[i] == '\n')
            ++*line, *col = 1;
        else
            ++*col;
}

vfx_result rt_scene_load_mem(const char *json, size_t len, const char *base_dir, const rt_logger *logger,
                              rt_scene **out, char *err, size_t errlen)
{
    pctx c = {.log = logger, .err = err, .errlen = errlen, .base_dir = base_dir};
    if (err && errlen)
        err[0] = 0;
    if (!out || (!json && len))
        return rt_scene_failf(&c, VFX_ERR_INVALID_ARGUMENT, "scene", "NULL argument");
    *out = NULL;
    if (len > RT_SCENE_MAX_BYTES)
        return rt_scene_failf(&c, VFX_ERR_INVALID_ARGUMENT, "scene", "%zu bytes, above the cap of %u", len, RT_SCENE_MAX_BYTES);
    if (base_dir && strlen(base_dir) >= RT_SCENE_PATH_MAX)
        return rt_scene_failf(&c, VFX_ERR_INVALID_ARGUMENT, "scene", "base directory longer than %d bytes", RT_SCENE_PATH_MAX - 1);
    /* a private NUL-terminated copy: cJSON then never depends on the caller's termination */
    char *text = malloc(len + 1);
    if (!text)
        return rt_scene_failf(&c, VFX_ERR_OUT_OF_MEMORY, "scene", "out of memory");
    if (len)
        memcpy(text, json, len);
    text[len] = 0;
    /* cJSON stops at a NUL and the rest would pass as trailing whitespace */
    const char *nul = memchr(text, 0, len);
    if (nul) {
        unsigned line, col;
        size_t at = (size_t)(nul - text);
        line_col(text, at, &line, &col);
        free(text);
        return rt_scene_failf(&c, VFX_ERR_FORMAT, "scene", "NUL byte at line %u, column %u (byte %zu): not JSON text",
                           line, col, at);
    }
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(text, len + 1, &end, false);
    if (!root) {
        size_t off = end && end >= text && end <= text + len ? (size_t)(end - text) : len;
        if (memchr(text, 0, len))
            off = strlen(text) < off ? strlen(text) : off;
        unsigned line, col;
        line_col(text, off, &line, &col);
        vfx_result r;
        if (json_depth(text, off) >= CJSON_NESTING_LIMIT)
            r = rt_scene_failf(&c, VFX_ERR_FORMAT, "scene", "JSON nested deeper than %d arrays and objects (the "
                               "parser's limit) at line %u, column %u (byte %zu)", CJSON_NESTING_LIMIT, line, col, off);
        else
            r = rt_scene_failf(&c, VFX_ERR_FORMAT, "scene", "JSON syntax error at line %u, column %u (byte %zu)%s",
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
        unsigned line, col;
        line_col(text, off, &line, &col);
        cJSON_Delete(root);
        free(text);
        return rt_scene_failf(&c, VFX_ERR_FORMAT, "scene", "JSON syntax error at line %u, column %u (byte %zu): text after the scene object",
                     line, col, off);
    }
    rt_scene *s = calloc(1, sizeof *s);
    vfx_result r = VFX_OK;
    if (!s) {
        r = rt_scene_failf(&c, VFX_ERR_OUT_OF_MEMORY, "scene", "out of memory");
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
    vfx_result rr = rt_read_file(path, RT_SCENE_MAX_BYTES, "16 MiB for a scene file (RT_SCENE_MAX_BYTES)", &buf, &size, tmp, sizeof tmp);
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
