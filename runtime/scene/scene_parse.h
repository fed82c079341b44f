/* scene_parse.h — internal to runtime/scene: the parse context, JSON-path errors, typed getters
 * with ranges, transforms, and the section parsers each scene_<section>.c defines. Not for hosts:
 * they use scene.h. */
#ifndef RT_SCENE_PARSE_H
#define RT_SCENE_PARSE_H

#include <cjson/cJSON.h>
#include <stdbool.h>
#include <stddef.h>

#include "scene/scene.h"
#include <volfx/volfx_ranges.h>

#define JPATH 256
#define COORD_MAX 1e6 /* metres: beyond this float precision is gone anyway */
typedef struct pctx {
    const rt_logger *log;
    char *err;
    size_t errlen;
    const char *base_dir;
    double origin[3]; /* the scene's origin: positions are stored relative to it (scene.h) */
    bool defaults_world; /* no "origin" key: the origin is the camera's eye, and a position the
                            scene leaves out keeps its world-space default (stored relative too) */
} pctx;
typedef struct range {
    double lo, hi;
    bool lo_open; /* value must be > lo rather than >= lo */
} range;

/* The array v, named name, of at most cap elements: *out calloc'd with *count of elem bytes
 * (NULL and 0 for an empty array); an error naming it when v is no array or holds too many. */
vfx_result rt_scene_alloc_array(pctx *c, const cJSON *v, const char *name, int cap, size_t elem,
                              void **out, int *count);
void rt_scene_check_keys(pctx *c, const cJSON *obj, const char *path, const char *const *allowed);
vfx_result rt_scene_check_range(pctx *c, const char *path, double v, range rg);
vfx_result rt_scene_expect_object(pctx *c, const cJSON *v, const char *path);
/* The ranges most keys use. */
static const range COORD = {-COORD_MAX, COORD_MAX, false};
static const range POSITIVE = {0, COORD_MAX, true};
static const range NONNEG = {0, COORD_MAX, false};
static const range UNIT = {0, 1, false};

/* A VFX_RANGE_TABLE row (plugin/include/volfx/volfx_ranges.h) as the scene checks it: the
 * plugin's own range, so a key and the ABI field it fills cannot drift apart (a scene leaves a
 * key out for the default instead of writing the ABI's 0). */
range rt_scene_range(vfx_range_id id);
/* rt_scene_get_float / rt_scene_get_uint with the range of row `id`. */
vfx_result rt_scene_get_float_row(pctx *c, const cJSON *obj, const char *path, const char *key, vfx_range_id id,
                                  float *out);
vfx_result rt_scene_get_uint_row(pctx *c, const cJSON *obj, const char *path, const char *key, vfx_range_id id,
                                 uint32_t *out);

vfx_result rt_scene_failf(pctx *c, vfx_result r, const char *path, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
vfx_result rt_scene_get_bool(pctx *c, const cJSON *obj, const char *path, const char *key, bool *out);
vfx_result rt_scene_get_enum(pctx *c, const cJSON *obj, const char *path, const char *key, bool required,
                           const char *const *names, uint32_t *out);
vfx_result rt_scene_get_flags(pctx *c, const cJSON *obj, const char *path, const char *key,
                            const char *const *names, const uint32_t *bits, uint32_t *out);
vfx_result rt_scene_get_float(pctx *c, const cJSON *obj, const char *path, const char *key, bool required,
                            range rg, float *out);
vfx_result rt_scene_get_path(pctx *c, const cJSON *obj, const char *path, const char *key, bool required,
                           char *out);
vfx_result rt_scene_get_string(pctx *c, const cJSON *obj, const char *path, const char *key, bool required,
                             char *out, size_t outlen);
vfx_result rt_scene_get_uint(pctx *c, const cJSON *obj, const char *path, const char *key, bool required,
                           double lo, double hi, uint32_t *out);
vfx_result rt_scene_get_vec(pctx *c, const cJSON *obj, const char *path, const char *key, int n,
                          bool required, range rg, float *out);
/* True when the vector's length is below 1e-12 (a direction that names none). */
bool rt_scene_is_zero3(const float *v);
void rt_scene_join(char *out, const char *parent, const char *key);
void rt_scene_join_index(char *out, const char *parent, int i);
void rt_scene_mat_trs(const float t[3], const float rdeg[3], const float s[3], float m[16]);
vfx_result rt_scene_number_value(pctx *c, const cJSON *v, const char *path, range rg, double *out);
vfx_result rt_scene_parse_transform(pctx *c, const cJSON *obj, const char *path, float model[16]);
vfx_result rt_scene_resolve_path(pctx *c, const char *p, const char *rel, char *out);
const char *rt_scene_type_name(const cJSON *v);
vfx_result rt_scene_vec_value(pctx *c, const cJSON *v, const char *p, int n, range rg, float *out);
/* A world position (n = 3), or a model matrix (n = 16) whose translation is one: read in double
 * and stored as the difference to the scene's origin, so far-out scenes keep float32 digits. */
vfx_result rt_scene_point_value(pctx *c, const cJSON *v, const char *p, int n, float *out);
vfx_result rt_scene_get_point(pctx *c, const cJSON *obj, const char *path, const char *key, bool required,
                            float out[3]);
vfx_result rt_scene_parse_beams(pctx *c, const cJSON *v, rt_scene *s);
vfx_result rt_scene_parse_beam_settings(pctx *c, const cJSON *v, vfx_beams_view *bv);
vfx_result rt_scene_parse_water(pctx *c, const cJSON *v, rt_scene_water *w);
vfx_result rt_scene_parse_volume(pctx *c, const cJSON *v, rt_scene_volume *vol);
bool rt_scene_ends_with(const char *s, const char *suffix);
vfx_result rt_scene_parse_box(pctx *c, const cJSON *obj, const char *path, const char *key, float mn[3], float mx[3]);

#endif
