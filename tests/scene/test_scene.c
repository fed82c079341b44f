/* test_scene.c — scene files: every field read back, the sample scenes, bad input (error code
 * and the JSON path in the message), syntax-error locations, keyframe interpolation against
 * hand-computed values, generators against independent checks. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "scene/particle_file.h"
#include "scene/scene.h"
#include "test_util.h"

extern const char game_default_scene_json[];
extern const unsigned long game_default_scene_json_len;

static vfx_result load(const char *json, test_log *log, rt_scene **s, char *err, size_t errlen)
{
    rt_logger lg = {test_log_fn, log};
    return rt_scene_load_mem(json, strlen(json), "/base", &lg, s, err, errlen);
}

/* float parameters are stored as float: compare with a float-epsilon-relative tolerance */
#define assert_close(a, b) assert_true(fabs((double)(a) - (double)(b)) <= 1e-6 * (1 + fabs((double)(b))))

static void test_every_field(void **state)
{
    (void)state;
    const char *json =
        "{\"version\":1,\"origin\":[0,0,0],\"name\":\"full\",\"description\":\"d\"," /* world values */
        "\"camera\":{\"eye\":[1,2,3],\"target\":[0,1,0],\"up\":[0,0,1],\"fov_y_deg\":45,\"width\":320,"
        "\"height\":200,\"near\":0.1,\"far\":50},"
        "\"meshes\":[{\"path\":\"m/arena.obj\",\"translate\":[1,2,3],\"rotate_deg\":[0,90,0],\"scale\":2,"
        "\"color\":[0.1,0.2,0.3]},"
        "{\"box\":{\"min\":[0,0,0],\"max\":[1,2,3]},\"matrix\":[1,0,0,0,0,1,0,0,0,0,1,0,5,6,7,1]},"
        "{\"path\":\"/abs/x.ply\"}],"
        "\"beam_settings\":{\"saturation\":\"clamp\",\"c\":2.5,\"far_distance\":30},"
        "\"beams\":[{\"head\":[1,2,3],\"dir\":[0,0,-1],\"length\":4,\"radius\":0.7,\"a\":0.1,\"b\":0.2,"
        "\"eps\":0.03,\"color\":[1,0.5,0.25,1],\"loop_s\":2}],"
        "\"water\":{\"source\":\"file\",\"path\":\"p.bin\",\"h\":0.3,\"threshold\":0.5,"
        "\"quality\":{\"max_samples\":32,\"step\":0.01,\"refine_iters\":5,\"pyramid_level\":2,"
        "\"method\":\"paper\",\"disable\":[\"ssr\"]},\"color\":[0.2,0.4,0.6],"
        "\"absorption\":1.5,\"ior\":1.2},"
        "\"volume\":{\"path\":\"v/pipe.vtu\",\"scalar\":\"Velocity\",\"transfer\":[{\"scalar\":-1,"
        "\"rgba\":[0,0,0,0]},{\"scalar\":3,\"rgba\":[1,1,1,2]}],\"ert_threshold\":0.8,\"tiles\":8,"
        "\"update_c\":4,\"workers\":2,\"translate\":[0,0,-2]}}";
    test_log log = {0};
    rt_scene *s = NULL;
    char err[256];
    assert_int_equal(load(json, &log, &s, err, sizeof err), VFX_OK);
    assert_int_equal(log.warnings, 0);
    assert_string_equal(s->name, "full");
    assert_close(s->camera.eye[2], 3);
    assert_close(s->camera.up[2], 1);
    assert_close(s->camera.fov_y_deg, 45);
    assert_int_equal(s->camera.width, 320);
    assert_int_equal(s->camera.height, 200);
    assert_close(s->camera.near_plane, 0.1);
    assert_close(s->camera.far_plane, 50);
    assert_int_equal(s->mesh_count, 3);
    assert_string_equal(s->meshes[0].path, "/base/m/arena.obj");
    assert_string_equal(s->meshes[2].path, "/abs/x.ply");
    /* rotate 90 deg about y then scale 2: x axis -> -z (column 0 = (0,0,-2)), translate last */
    assert_close(s->meshes[0].model[0], 0);
    assert_close(s->meshes[0].model[2], -2);
    assert_close(s->meshes[0].model[8], 2);
    assert_close(s->meshes[0].model[5], 2);
    assert_close(s->meshes[0].model[12], 1);
    assert_close(s->meshes[0].model[14], 3);
    assert_close(s->meshes[0].color[2], 0.3);
    assert_true(s->meshes[1].is_box);
    assert_close(s->meshes[1].box_max[2], 3);
    assert_close(s->meshes[1].model[13], 6);
    assert_int_equal(s->beams_view.saturation, VFX_SATURATE_CLAMP);
    assert_close(s->beams_view.saturate_c, 2.5);
    assert_close(s->beams_view.far_distance, 30);
    assert_int_equal(s->beams_view.type, VFX_TYPE_BEAMS_VIEW);
    assert_int_equal(s->beam_count, 1);
    const vfx_beam *b = &s->beams[0].base;
    assert_close(b->head[1], 2);
    assert_close(b->dir[2], -1);
    assert_close(b->length, 4);
    assert_close(b->radius, 0.7);
    assert_close(b->a, 0.1);
    assert_close(b->b, 0.2);
    assert_close(b->eps, 0.03);
    assert_close(b->color[2], 0.25);
    assert_close(s->beams[0].loop_s, 2);
    assert_true(s->has_water);
    assert_int_equal(s->water.source, RT_SCENE_WATER_FILE);
    assert_string_equal(s->water.path, "/base/p.bin");
    const vfx_water_params *wp = &s->water.params;
    assert_int_equal(wp->type, VFX_TYPE_WATER_PARAMS);
    assert_close(wp->h, 0.3);
    assert_close(wp->threshold, 0.5);
    assert_int_equal(wp->max_samples, 32);
    assert_close(wp->step, 0.01);
    assert_int_equal(wp->refine_iters, 5);
    assert_int_equal(wp->pyramid_level, 2);
    assert_int_equal(wp->method, VFX_WATER_METHOD_PAPER);
    assert_int_equal(wp->features_off, VFX_WATER_NO_SSR);
    assert_close(wp->color[1], 0.4);
    assert_close(wp->absorption, 1.5);
    assert_close(wp->ior, 1.2);
    assert_true(s->has_volume);
    assert_false(s->volume.generated);
    assert_string_equal(s->volume.path, "/base/v/pipe.vtu");
    assert_string_equal(s->volume.scalar, "Velocity");
    assert_int_equal(s->volume.transfer_count, 2);
    assert_close(s->volume.transfer[1].rgba[3], 2);
    assert_close(s->volume.ert_threshold, 0.8);
    assert_int_equal(s->volume.tiles, 8);
    assert_int_equal(s->volume.update_c, 4);
    assert_int_equal(s->volume.workers, 2);
    assert_close(s->volume.model[14], -2);
    rt_scene_free(s);
}

static void test_defaults(void **state)
{
    (void)state;
    test_log log = {0};
    rt_scene *s = NULL;
    char err[256];
    assert_int_equal(load("{}", &log, &s, err, sizeof err), VFX_OK);
    assert_int_equal(s->camera.width, 640);
    assert_int_equal(s->camera.height, 360);
    assert_close(s->camera.fov_y_deg, 60);
    assert_int_equal(s->mesh_count, 0);
    assert_int_equal(s->beam_count, 0);
    assert_false(s->has_water);
    assert_false(s->has_volume);
    assert_int_equal(s->beams_view.saturation, VFX_SATURATE_SMOOTH);
    rt_scene_free(s);
    /* water.quality.kernel: anisotropic for TILE (the default method), isotropic for the others */
    static const struct { const char *json; uint32_t kernel; } kcases[] = {
        {"{\"water\":{\"source\":\"file\",\"path\":\"p\"}}", VFX_WATER_KERNEL_ANISOTROPIC},
        {"{\"water\":{\"source\":\"file\",\"path\":\"p\",\"quality\":{\"kernel\":\"anisotropic\"}}}", VFX_WATER_KERNEL_ANISOTROPIC},
        {"{\"water\":{\"source\":\"file\",\"path\":\"p\",\"quality\":{\"kernel\":\"isotropic\"}}}", VFX_WATER_KERNEL_ISOTROPIC},
        {"{\"water\":{\"source\":\"file\",\"path\":\"p\",\"quality\":{\"method\":\"paper\"}}}", VFX_WATER_KERNEL_ISOTROPIC},
        {"{\"water\":{\"source\":\"file\",\"path\":\"p\",\"quality\":{\"method\":\"paper\",\"kernel\":\"isotropic\"}}}",
         VFX_WATER_KERNEL_ISOTROPIC},
    };
    for (size_t k = 0; k < sizeof kcases / sizeof kcases[0]; ++k) {
        assert_int_equal(load(kcases[k].json, &log, &s, err, sizeof err), VFX_OK);
        assert_int_equal(s->water.params.kernel, kcases[k].kernel);
        rt_scene_free(s);
    }
    /* water.simulation.solver: "pbf" when absent (issue 22), "wcsph" when asked for */
    static const char *const solver_cases[] = {"", ",\"solver\":\"wcsph\"", ",\"solver\":\"pbf\""};
    for (int k = 0; k < 3; ++k) {
        char json[512];
        snprintf(json, sizeof json, "{\"water\":{\"source\":\"simulation\",\"simulation\":{\"tank\":{\"min\":[0,0,0],"
                 "\"max\":[1,1,1]},\"fluid\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"particle_count\":10%s}}}",
                 solver_cases[k]);
        assert_int_equal(load(json, &log, &s, err, sizeof err), VFX_OK);
        assert_int_equal(s->water.solver, k == 1 ? 0u : 1u); /* rt_sph_solver: 0 WCSPH, 1 PBF */
        rt_scene_free(s);
    }
    /* water.simulation.device: "auto" when absent */
    static const char *const device_cases[] = {"", ",\"device\":\"cpu\"", ",\"device\":\"gpu\"", ",\"device\":\"auto\""};
    static const uint32_t device_ids[] = {RT_SCENE_SIM_AUTO, RT_SCENE_SIM_CPU, RT_SCENE_SIM_GPU, RT_SCENE_SIM_AUTO};
    for (int k = 0; k < 4; ++k) {
        char json[512];
        snprintf(json, sizeof json, "{\"water\":{\"source\":\"simulation\",\"simulation\":{\"tank\":{\"min\":[0,0,0],"
                 "\"max\":[1,1,1]},\"fluid\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"particle_count\":10%s}}}",
                 device_cases[k]);
        assert_int_equal(load(json, &log, &s, err, sizeof err), VFX_OK);
        assert_int_equal(s->water.device, device_ids[k]);
        rt_scene_free(s);
    }
    /* beam defaults: only head and dir given */
    assert_int_equal(load("{\"beams\":[{\"head\":[0,0,0],\"dir\":[1,0,0]}]}", &log, &s, err, sizeof err), VFX_OK);
    assert_close(s->beams[0].base.radius, 0.5);
    assert_close(s->beams[0].base.length, 1);
    assert_close(s->beams[0].base.color[3], 1);
    rt_scene_free(s);
}

typedef struct bad_case {
    const char *json;
    vfx_result code;
    const char *needle; /* must appear in the message: the JSON path and the reason */
} bad_case;

static const bad_case bad_cases[] = {
    {"[]", VFX_ERR_FORMAT, "(root): expected an object"},
    {"{\"version\":2}", VFX_ERR_UNSUPPORTED, "version: scene format version 2"},
    {"{\"camera\":{\"fov_y_deg\":\"wide\"}}", VFX_ERR_FORMAT, "camera.fov_y_deg: expected a number, got a string"},
    {"{\"camera\":{\"fov_y_deg\":180}}", VFX_ERR_INVALID_ARGUMENT, "camera.fov_y_deg: must be <= 179"},
    {"{\"camera\":{\"width\":0}}", VFX_ERR_INVALID_ARGUMENT, "camera.width: must be >= 1, got 0"},
    {"{\"camera\":{\"width\":64.5}}", VFX_ERR_INVALID_ARGUMENT, "camera.width: must be an integer"},
    {"{\"camera\":{\"height\":1e12}}", VFX_ERR_INVALID_ARGUMENT, "camera.height: must be <= 16384"},
    {"{\"camera\":{\"near\":1,\"far\":0.5}}", VFX_ERR_INVALID_ARGUMENT, "camera.far: must be > near"},
    {"{\"camera\":{\"eye\":[0,0,0],\"target\":[0,0,0]}}", VFX_ERR_INVALID_ARGUMENT, "camera.target: equals camera.eye"},
    {"{\"camera\":{\"eye\":[0,5,0],\"target\":[0,0,0],\"up\":[0,1,0]}}", VFX_ERR_INVALID_ARGUMENT, "camera.up: zero or parallel"},
    {"{\"camera\":{\"eye\":[1,2]}}", VFX_ERR_FORMAT, "camera.eye: expected 3 numbers, got 2"},
    {"{\"camera\":{\"eye\":[1,2,1e999]}}", VFX_ERR_INVALID_ARGUMENT, "camera.eye[2]: must be finite, got inf"},
    {"{\"camera\":{\"eye\":[1,-1e300,0]}}", VFX_ERR_INVALID_ARGUMENT, "camera.eye[1]: must be >= -1000000, got -1e+300"},
    {"{\"camera\":[]}", VFX_ERR_FORMAT, "camera: expected an object, got an array"},
    {"{\"meshes\":{}}", VFX_ERR_FORMAT, "meshes: expected an array"},
    {"{\"meshes\":[{}]}", VFX_ERR_FORMAT, "meshes[0]: needs exactly one of"},
    {"{\"meshes\":[{\"path\":\"a.obj\",\"box\":{}}]}", VFX_ERR_FORMAT, "meshes[0]: needs exactly one of"},
    {"{\"meshes\":[{\"path\":\"\"}]}", VFX_ERR_INVALID_ARGUMENT, "meshes[0].path: empty path"},
    {"{\"meshes\":[{\"path\":7}]}", VFX_ERR_FORMAT, "meshes[0].path: expected a string, got a number"},
    {"{\"meshes\":[{\"path\":\"a\"},{\"box\":{\"min\":[0,0,0],\"max\":[1,0,1]}}]}", VFX_ERR_INVALID_ARGUMENT,
     "meshes[1].box.max: must exceed min on every axis (axis 1"},
    {"{\"meshes\":[{\"path\":\"a\",\"scale\":0}]}", VFX_ERR_INVALID_ARGUMENT, "meshes[0].scale: must be > 0, got 0"},
    {"{\"meshes\":[{\"path\":\"a\",\"scale\":[1,-1,1]}]}", VFX_ERR_INVALID_ARGUMENT, "meshes[0].scale[1]: must be > 0"},
    {"{\"meshes\":[{\"path\":\"a\",\"matrix\":[1,0,0,0],\"scale\":1}]}", VFX_ERR_INVALID_ARGUMENT,
     "meshes[0].matrix: give either matrix"},
    {"{\"meshes\":[{\"path\":\"a\",\"matrix\":[1,0,0,0]}]}", VFX_ERR_FORMAT, "meshes[0].matrix: expected 16 numbers, got 4"},
    {"{\"meshes\":[{\"path\":\"a\",\"color\":[1,2,0]}]}", VFX_ERR_INVALID_ARGUMENT, "meshes[0].color[1]: must be <= 1, got 2"},
    {"{\"beams\":[{\"head\":[0,0,0],\"dir\":[1,0,0]},{\"head\":[0,0,0],\"dir\":[1,0,0]},"
     "{\"head\":[0,0,0],\"dir\":[1,0,0],\"radius\":-1}]}",
     VFX_ERR_INVALID_ARGUMENT, "beams[2].radius: must be > 0, got -1"},
    {"{\"beams\":[{\"dir\":[1,0,0]}]}", VFX_ERR_FORMAT, "beams[0].head: required array of 3 numbers missing"},
    {"{\"beams\":[{\"head\":[0,0,0],\"dir\":[0,0,0]}]}", VFX_ERR_INVALID_ARGUMENT, "beams[0].dir: direction must not be the zero vector"},
    {"{\"beams\":[{\"head\":[0,0,0],\"dir\":[1,0,0],\"a\":-0.5}]}", VFX_ERR_INVALID_ARGUMENT, "beams[0].a: must be >= 0, got -0.5"},
    {"{\"beams\":[{\"head\":[0,0,0],\"dir\":[1,0,0],\"length\":1e40}]}", VFX_ERR_INVALID_ARGUMENT, "beams[0].length: must be <= 1000000"},
    {"{\"beams\":[{\"head\":[0,0,0],\"dir\":[1,0,0],\"eps\":null}]}", VFX_ERR_FORMAT, "beams[0].eps: expected a number, got null"},
    {"{\"beams\":[{\"head\":[0,0,0],\"dir\":[1,0,0],\"keyframes\":{\"length\":[]}}]}", VFX_ERR_INVALID_ARGUMENT,
     "beams[0].keyframes.length: 0 keyframes; must be 1 to"},
    {"{\"beams\":[{\"head\":[0,0,0],\"dir\":[1,0,0],\"keyframes\":{\"length\":[{\"t\":1,\"value\":1},"
     "{\"t\":1,\"value\":2}]}}]}",
     VFX_ERR_INVALID_ARGUMENT, "beams[0].keyframes.length[1].t: keyframe times must increase strictly"},
    {"{\"beams\":[{\"head\":[0,0,0],\"dir\":[1,0,0],\"keyframes\":{\"radius\":[{\"t\":0,\"value\":0}]}}]}",
     VFX_ERR_INVALID_ARGUMENT, "beams[0].keyframes.radius[0].value: must be > 0, got 0"},
    {"{\"beams\":[{\"head\":[0,0,0],\"dir\":[1,0,0],\"keyframes\":{\"head\":[{\"t\":0,\"value\":1}]}}]}",
     VFX_ERR_FORMAT, "beams[0].keyframes.head[0].value: expected an array of 3 numbers"},
    {"{\"beams\":[{\"head\":[0,0,0],\"dir\":[1,0,0],\"keyframes\":{\"dir\":[{\"t\":0,\"value\":[0,0,0]}]}}]}",
     VFX_ERR_INVALID_ARGUMENT, "beams[0].keyframes.dir[0].value: direction must not be the zero vector"},
    {"{\"beams\":[{\"head\":[0,0,0],\"dir\":[1,0,0],\"keyframes\":{\"a\":[{\"value\":1}]}}]}",
     VFX_ERR_FORMAT, "beams[0].keyframes.a[0].t: required number missing"},
    {"{\"beam_settings\":{\"saturation\":\"soft\"}}", VFX_ERR_INVALID_ARGUMENT,
     "beam_settings.saturation: unknown value \"soft\"; expected one of \"clamp\", \"smooth\""},
    {"{\"beam_settings\":{\"c\":0}}", VFX_ERR_INVALID_ARGUMENT, "beam_settings.c: must be > 0"},
    {"{\"water\":{}}", VFX_ERR_FORMAT, "water.source: required string missing"},
    {"{\"water\":{\"source\":\"rain\"}}", VFX_ERR_INVALID_ARGUMENT, "water.source: unknown value \"rain\""},
    {"{\"water\":{\"source\":\"file\"}}", VFX_ERR_FORMAT, "water.path: required string missing"},
    {"{\"water\":{\"source\":\"generator\"}}", VFX_ERR_FORMAT, "water.generator: required for source"},
    {"{\"water\":{\"source\":\"generator\",\"generator\":{\"kind\":\"layers\",\"count\":-5}}}", VFX_ERR_INVALID_ARGUMENT,
     "water.generator.count: must be >= 0, got -5"},
    {"{\"water\":{\"source\":\"generator\",\"generator\":{\"kind\":\"layers\",\"count\":1e9}}}", VFX_ERR_INVALID_ARGUMENT,
     "water.generator.count: must be <= 4194304"},
    {"{\"water\":{\"source\":\"generator\",\"generator\":{\"kind\":\"sphere\",\"count\":10}}}", VFX_ERR_FORMAT,
     "water.generator.radius: required number missing"},
    {"{\"water\":{\"source\":\"simulation\",\"simulation\":{\"tank\":{\"min\":[0,0,0],\"max\":[1,1,1]},"
     "\"fluid\":{\"min\":[0,0,0],\"max\":[2,1,1]},\"particle_count\":10}}}",
     VFX_ERR_INVALID_ARGUMENT, "water.simulation.fluid: must lie inside the tank (axis 0)"},
    {"{\"water\":{\"source\":\"simulation\",\"simulation\":{\"tank\":{\"min\":[0,0,0],\"max\":[1,1,1]},"
     "\"fluid\":{\"min\":[0,0,0],\"max\":[1,1,1]}}}}",
     VFX_ERR_FORMAT, "water.simulation.particle_count: required integer missing"},
    {"{\"water\":{\"source\":\"simulation\",\"simulation\":{\"tank\":{\"min\":[0,0,0],\"max\":[1,1,1]},"
     "\"fluid\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"particle_count\":10,\"paddle\":{\"axis\":\"w\"}}}}",
     VFX_ERR_INVALID_ARGUMENT, "water.simulation.paddle.axis: unknown value \"w\""},
    {"{\"water\":{\"source\":\"simulation\",\"simulation\":{\"tank\":{\"min\":[0,0,0],\"max\":[1,1,1]},"
     "\"fluid\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"particle_count\":10,\"paddle\":{\"ramp_s\":-1}}}}",
     VFX_ERR_INVALID_ARGUMENT, "water.simulation.paddle.ramp_s"},
    {"{\"water\":{\"source\":\"simulation\",\"simulation\":{\"tank\":{\"min\":[0,0,0],\"max\":[1,1,1]},"
     "\"fluid\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"particle_count\":10,\"settle_steps\":-3}}}",
     VFX_ERR_INVALID_ARGUMENT, "water.simulation.settle_steps"},
    {"{\"water\":{\"source\":\"simulation\",\"simulation\":{\"tank\":{\"min\":[0,0,0],\"max\":[1,1,1]},"
     "\"fluid\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"particle_count\":10,\"no_slip\":3}}}",
     VFX_ERR_FORMAT, "water.simulation.no_slip: expected true or false, got a number"},
    {"{\"water\":{\"source\":\"simulation\",\"simulation\":{\"tank\":{\"min\":[0,0,0],\"max\":[1,1,1]},"
     "\"fluid\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"particle_count\":10,\"solver\":\"sph\"}}}",
     VFX_ERR_INVALID_ARGUMENT, "water.simulation.solver: unknown value \"sph\"; expected one of \"wcsph\", \"pbf\""},
    {"{\"water\":{\"source\":\"simulation\",\"simulation\":{\"tank\":{\"min\":[0,0,0],\"max\":[1,1,1]},"
     "\"fluid\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"particle_count\":10,\"device\":\"tpu\"}}}",
     VFX_ERR_INVALID_ARGUMENT, "water.simulation.device: unknown value \"tpu\"; expected one of \"auto\", \"cpu\", \"gpu\""},
    {"{\"water\":{\"source\":\"simulation\",\"simulation\":{\"tank\":{\"min\":[0,0,0],\"max\":[1,1,1]},"
     "\"fluid\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"particle_count\":10,\"solver\":\"wcsph\",\"device\":\"gpu\"}}}",
     VFX_ERR_INVALID_ARGUMENT, "water.simulation.device: \"gpu\" runs the PBF solver only"},
    {"{\"water\":{\"source\":\"file\",\"path\":\"p\",\"h\":0}}", VFX_ERR_INVALID_ARGUMENT, "water.h: must be >= 1e-12, got 0"},
    {"{\"water\":{\"source\":\"file\",\"path\":\"p\",\"quality\":{\"disable\":[\"spray\",\"magic\"]}}}",
     VFX_ERR_INVALID_ARGUMENT, "water.quality.disable[1]: unknown flag \"magic\""},
    /* the lab's baselines and ablation bits are no scene keys (tests and benches chain the lab) */
    {"{\"water\":{\"source\":\"file\",\"path\":\"p\",\"quality\":{\"method\":\"grid\"}}}",
     VFX_ERR_INVALID_ARGUMENT, "water.quality.method: unknown value \"grid\"; expected one of \"paper\", \"tile\""},
    {"{\"water\":{\"source\":\"file\",\"path\":\"p\",\"quality\":{\"disable\":[\"pyramid\"]}}}",
     VFX_ERR_INVALID_ARGUMENT, "water.quality.disable[0]: unknown flag \"pyramid\""},
    {"{\"water\":{\"source\":\"file\",\"path\":\"p\",\"quality\":{\"max_samples\":0}}}", VFX_ERR_INVALID_ARGUMENT,
     "water.quality.max_samples: must be >= 1"},
    {"{\"volume\":{}}", VFX_ERR_FORMAT, "volume: needs exactly one of"},
    {"{\"volume\":{\"path\":\"mesh.stl\"}}", VFX_ERR_INVALID_ARGUMENT, "volume.path: \"/base/mesh.stl\" is neither"},
    {"{\"volume\":{\"generator\":{\"cells\":1000}}}", VFX_ERR_INVALID_ARGUMENT, "volume.generator.cells: must be <= 64"},
    {"{\"volume\":{\"path\":\"a.vtu\",\"transfer\":[{\"scalar\":1,\"rgba\":[0,0,0,0]},{\"scalar\":0,\"rgba\":[1,1,1,1]}]}}",
     VFX_ERR_INVALID_ARGUMENT, "volume.transfer[1].scalar: control points must increase strictly"},
    {"{\"volume\":{\"path\":\"a.vtu\",\"transfer\":[{\"scalar\":0,\"rgba\":[0,0,-1,0]}]}}", VFX_ERR_INVALID_ARGUMENT,
     "volume.transfer[0].rgba[2]: must be >= 0, got -1"},
    {"{\"volume\":{\"path\":\"a.vtu\",\"ert_threshold\":1.5}}", VFX_ERR_INVALID_ARGUMENT, "volume.ert_threshold: must be <= 1"},
    {"{\"volume\":{\"path\":\"a.vtu\",\"tiles\":0}}", VFX_ERR_INVALID_ARGUMENT, "volume.tiles: must be >= 1, got 0"},
    /* issue 18, defect 6: ranges are checked on the float32 the scene stores, not the double */
    {"{\"water\":{\"source\":\"generator\",\"generator\":{\"kind\":\"sphere\",\"count\":10,\"radius\":1e-320}}}",
     VFX_ERR_INVALID_ARGUMENT, "water.generator.radius: 1e-320 is 0 as float32"},
    {"{\"water\":{\"source\":\"generator\",\"generator\":{\"kind\":\"layers\",\"count\":10,\"spacing\":1e-320}}}",
     VFX_ERR_INVALID_ARGUMENT, "water.generator.spacing: 1e-320 is 0 as float32"},
    {"{\"water\":{\"source\":\"file\",\"path\":\"p\",\"h\":1e-320}}", VFX_ERR_INVALID_ARGUMENT, "water.h: must be >= 1e-12, got 9.99988867e-321"},
    {"{\"water\":{\"source\":\"file\",\"path\":\"p\",\"h\":1e-40}}", VFX_ERR_INVALID_ARGUMENT,
     "water.h: must be >= 1e-12, got 1e-40"},
    {"{\"water\":{\"source\":\"file\",\"path\":\"p\",\"quality\":{\"step\":1e-320}}}", VFX_ERR_INVALID_ARGUMENT,
     "water.quality.step: 1e-320 is 0 as float32"},
    {"{\"water\":{\"source\":\"simulation\",\"simulation\":{\"tank\":{\"min\":[0,0,0],\"max\":[1,1,1]},"
     "\"fluid\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"particle_count\":10,\"dt\":1e-320}}}",
     VFX_ERR_INVALID_ARGUMENT, "water.simulation.dt: 1e-320 is 0 as float32"},
    {"{\"volume\":{\"path\":\"a.vtu\",\"ert_threshold\":1e-320}}", VFX_ERR_INVALID_ARGUMENT,
     "volume.ert_threshold: 1e-320 is 0 as float32"},
    {"{\"beam_settings\":{\"c\":1e-320}}", VFX_ERR_INVALID_ARGUMENT, "beam_settings.c: 1e-320 is 0 as float32"},
    {"{\"meshes\":[{\"path\":\"a\",\"scale\":1e-320}]}", VFX_ERR_INVALID_ARGUMENT, "meshes[0].scale: 1e-320 is 0 as float32"},
    {"{\"meshes\":[{\"path\":\"a\",\"scale\":[1,1e-320,1]}]}", VFX_ERR_INVALID_ARGUMENT, "meshes[0].scale[1]: 1e-320 is 0"},
    {"{\"beams\":[{\"head\":[0,0,0],\"dir\":[1,0,0],\"keyframes\":{\"radius\":[{\"t\":0,\"value\":1e-320}]}}]}",
     VFX_ERR_INVALID_ARGUMENT, "beams[0].keyframes.radius[0].value: 1e-320 is 0 as float32"},
    {"{\"camera\":{\"width\":16777217}}", VFX_ERR_INVALID_ARGUMENT, "camera.width: must be <= 16384, got 16777217"},
    /* the keys other issues added (volume.animate, beam look, bloom), attacked the same way */
    {"{\"volume\":{\"path\":\"a.vtu\",\"animate\":{\"ripple\":{\"amplitude\":0.1,\"wavelength\":1e-320}}}}",
     VFX_ERR_INVALID_ARGUMENT, "volume.animate.ripple.wavelength: 1e-320 is 0 as float32"},
    {"{\"volume\":{\"path\":\"a.vtu\",\"animate\":{\"ripple\":{\"amplitude\":0.1,\"period_s\":1e-40}}}}",
     VFX_ERR_INVALID_ARGUMENT, "volume.animate.ripple.period_s: 1e-40 is subnormal as float32"},
    /* below the plugin's row for vfx_beam.surge_wavelength (1e-40 made the beam's profile NaN) */
    {"{\"beams\":[{\"head\":[0,0,0],\"dir\":[1,0,0],\"surges\":{\"wavelength\":1e-7}}]}", VFX_ERR_INVALID_ARGUMENT,
     "beams[0].surges.wavelength: must be 0 (8 x radius) or >= 1e-06, got 1e-07"},
    /* the advice names 0 only where the range takes it (h > 0 does not; amplitude >= 0 does) */
    {"{\"water\":{\"source\":\"file\",\"path\":\"p\",\"h\":-1e-40}}", VFX_ERR_INVALID_ARGUMENT,
     "water.h: must be >= 1e-12, got -1e-40"},
    {"{\"water\":{\"source\":\"file\",\"path\":\"p\",\"threshold\":1e-40}}", VFX_ERR_INVALID_ARGUMENT,
     "below 1.17549435e-38): give a value of magnitude 1.17549435e-38 or more"},
    {"{\"water\":{\"source\":\"simulation\",\"simulation\":{\"tank\":{\"min\":[0,0,0],\"max\":[1,1,1]},"
     "\"fluid\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"particle_count\":10,\"paddle\":{\"amplitude\":1e-40}}}}",
     VFX_ERR_INVALID_ARGUMENT, "water.simulation.paddle.amplitude: 1e-40 is subnormal as float32 (magnitude below "
     "1.17549435e-38): give 0 or a value of magnitude 1.17549435e-38 or more"},
    {"{\"beams\":[{\"head\":[0,0,0],\"dir\":[1,0,0],\"flow\":{\"amount\":0.5,\"scale\":-1}}]}",
     VFX_ERR_INVALID_ARGUMENT, "beams[0].flow.scale: must be >= 0, got -1"},
    {"{\"beams\":[{\"head\":[0,0,0],\"dir\":[1,0,0],\"exposure\":1e39}]}", VFX_ERR_INVALID_ARGUMENT,
     "beams[0].exposure: must be <= 64, got 1e+39"},
    {"{\"beams\":[{\"head\":[0,0,0],\"dir\":[1,0,0],\"intensity\":1e-320}]}", VFX_ERR_INVALID_ARGUMENT,
     "beams[0].intensity: 1e-320 is 0 as float32"},
    {"{\"beam_settings\":{\"bloom_levels\":99}}", VFX_ERR_INVALID_ARGUMENT, "beam_settings.bloom_levels: must be <= 8, got 99"},
    {"{\"water\":{\"source\":\"file\",\"path\":\"p\",\"quality\":{\"kernel\":\"ellipsoid\"}}}", VFX_ERR_INVALID_ARGUMENT,
     "water.quality.kernel"},
    {"{\"water\":{\"source\":\"file\",\"path\":\"p\",\"quality\":{\"method\":\"paper\",\"kernel\":\"anisotropic\"}}}",
     VFX_ERR_INVALID_ARGUMENT, "water.quality.kernel: \"anisotropic\" is drawn by method \"tile\" only"},
    {"{\"beam_settings\":{\"bloom_strength\":1e-320}}", VFX_ERR_INVALID_ARGUMENT,
     "beam_settings.bloom_strength: 1e-320 is 0 as float32"},
    {"{\"volume\":{\"path\":\"a.vtu\",\"scalar\":\"0123456789012345678901234567890123456789012345678901234567890123456789\"}}",
     VFX_ERR_INVALID_ARGUMENT, "volume.scalar: string of 70 bytes is longer than 63"},
};

static void test_bad_inputs(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof bad_cases / sizeof bad_cases[0]; ++i) {
        test_log log = {0};
        rt_scene *s = (rt_scene *)&log; /* must be reset to NULL */
        char err[512] = "";
        vfx_result r = load(bad_cases[i].json, &log, &s, err, sizeof err);
        if (r != bad_cases[i].code || !strstr(err, bad_cases[i].needle))
            fail_msg("case %zu: %s\n got %d \"%s\"\n want %d containing \"%s\"", i, bad_cases[i].json, r, err,
                     bad_cases[i].code, bad_cases[i].needle);
        assert_null(s);
    }
}

/* "environment": the defaults, every key read, and bad values refused with their path. */
static void test_environment(void **state)
{
    (void)state;
    test_log log = {0};
    rt_scene *s = NULL;
    char err[512] = "";
    assert_int_equal(load("{\"environment\": {}}", &log, &s, err, sizeof err), VFX_OK);
    assert_true(s->environment.sky);
    assert_true(s->environment.sun_dir[1] > 0 && s->environment.fog == 0);
    rt_scene_free(s);
    assert_int_equal(load("{}", &log, &s, err, sizeof err), VFX_OK);
    assert_false(s->environment.sky); /* no environment: the clear colour, as before */
    rt_scene_free(s);
    assert_int_equal(load("{\"environment\": {\"sky\": \"none\", \"sun_dir\": [0, 1, 0], \"fog\": 0.5}}",
                          &log, &s, err, sizeof err), VFX_OK);
    assert_false(s->environment.sky);
    assert_true(s->environment.sun_dir[1] == 1 && s->environment.fog == 0.5f);
    rt_scene_free(s);
    /* out of range: VFX_ERR_INVALID_ARGUMENT; the wrong JSON type: VFX_ERR_FORMAT */
    static const struct { const char *json, *needle; vfx_result code; } bad[] = {
        {"{\"environment\": {\"sky\": \"noon\"}}", "environment.sky", VFX_ERR_INVALID_ARGUMENT},
        {"{\"environment\": {\"sun_dir\": [0, 0, 0]}}", "environment.sun_dir", VFX_ERR_INVALID_ARGUMENT},
        {"{\"environment\": {\"fog\": -1}}", "environment.fog", VFX_ERR_INVALID_ARGUMENT},
        {"{\"environment\": {\"fog\": 11}}", "environment.fog", VFX_ERR_INVALID_ARGUMENT},
        {"{\"environment\": 3}", "environment", VFX_ERR_FORMAT},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        s = NULL;
        err[0] = 0;
        assert_int_equal(load(bad[i].json, &log, &s, err, sizeof err), bad[i].code);
        if (!strstr(err, bad[i].needle))
            fail_msg("%s: error \"%s\" does not name %s", bad[i].json, err, bad[i].needle);
        assert_null(s);
    }
}

/* A NUL inside the text was skipped as whitespace by cJSON (it parses to the given length). */
static void test_nul_byte(void **state)
{
    (void)state;
    static const char json[] = "{\"version\":1,\0\"name\":\"x\"}";
    rt_scene *s = NULL;
    char err[256] = "";
    assert_int_equal(rt_scene_load_mem(json, sizeof json - 1, NULL, NULL, &s, err, sizeof err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "NUL byte at line 1, column 14 (byte 13)"));
    assert_null(s);
    /* a scene path that is a FIFO or a directory: refused, without blocking */
    char dir[] = "/tmp/vfx_scfifo_XXXXXX", p[64];
    assert_non_null(mkdtemp(dir));
    snprintf(p, sizeof p, "%s/s.json", dir);
    assert_int_equal(mkfifo(p, 0600), 0);
    alarm(30);
    assert_int_equal(rt_scene_load_file(p, NULL, &s, err, sizeof err), VFX_ERR_IO);
    assert_non_null(strstr(err, "is a FIFO"));
    alarm(0);
    assert_int_equal(rt_scene_load_file(dir, NULL, &s, err, sizeof err), VFX_ERR_IO);
    assert_non_null(strstr(err, "is a directory"));
    unlink(p);
    rmdir(dir);
}

static void test_too_many_beams(void **state)
{
    (void)state;
    size_t cap = RT_SCENE_MAX_BEAMS + 1, len = 32 + cap * 40;
    char *json = malloc(len), *p = json;
    p += sprintf(p, "{\"beams\":[");
    for (size_t i = 0; i < cap; ++i)
        p += sprintf(p, "%s{\"head\":[0,0,0],\"dir\":[1,0,0]}", i ? "," : "");
    sprintf(p, "]}");
    test_log log = {0};
    rt_scene *s = NULL;
    char err[256];
    assert_int_equal(load(json, &log, &s, err, sizeof err), VFX_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "beams: 257 beams, above the cap of 256"));
    /* exactly the cap loads */
    p = strrchr(json, '{');
    if (!p || p == json)
        fail_msg("no last beam object in the generated scene");
    sprintf(p - 1, "]}");
    assert_int_equal(load(json, &log, &s, err, sizeof err), VFX_OK);
    assert_int_equal(s->beam_count, RT_SCENE_MAX_BEAMS);
    rt_scene_free(s);
    free(json);
}

static void test_syntax_errors(void **state)
{
    (void)state;
    test_log log = {0};
    rt_scene *s = NULL;
    char err[256];
    /* the stray comma is on line 3, column 18 (1-based): cJSON stops at or just before it */
    const char *json = "{\n  \"camera\": {\n    \"eye\": [1, 2,, 3]\n  }\n}\n";
    assert_int_equal(load(json, &log, &s, err, sizeof err), VFX_ERR_FORMAT);
    assert_null(s);
    assert_non_null(strstr(err, "JSON syntax error at line 3, column"));
    /* truncated file */
    assert_int_equal(load("{\"camera\": {\"eye\": [1", &log, &s, err, sizeof err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "line 1"));
    /* empty input */
    assert_int_equal(load("", &log, &s, err, sizeof err), VFX_ERR_FORMAT);
    /* two objects: text after the scene */
    assert_int_equal(load("{}\n{}", &log, &s, err, sizeof err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "line 2, column 1 (byte 3): text after the scene object"));
    /* an embedded NUL inside the given length */
    rt_logger lg = {test_log_fn, &log};
    assert_int_equal(rt_scene_load_mem("{}\0{}", 5, NULL, &lg, &s, err, sizeof err), VFX_ERR_FORMAT);
    /* NULL arguments */
    assert_int_equal(rt_scene_load_mem(NULL, 3, NULL, &lg, &s, err, sizeof err), VFX_ERR_INVALID_ARGUMENT);
    assert_int_equal(rt_scene_load_mem("{}", 2, NULL, &lg, NULL, err, sizeof err), VFX_ERR_INVALID_ARGUMENT);
    /* deep nesting beyond cJSON's limit (1000) is a syntax error, not a stack overflow */
    enum { depth = 5000 };
    static char deep[2 * depth + 16];
    strcpy(deep, "{\"a\":");
    memset(deep + 5, '[', depth);
    memset(deep + 5 + depth, ']', depth);
    strcpy(deep + 5 + 2 * depth, "}");
    assert_int_equal(load(deep, &log, &s, err, sizeof err), VFX_ERR_FORMAT);
    /* named as the nesting, not as a syntax error at a column (byte 1005: the 1001st bracket) */
    assert_non_null(strstr(err, "JSON nested deeper than 1000 arrays and objects (the parser's limit) at line 1"));
    /* 999 arrays deep (1000 with the root) parses: the unknown key is only warned about */
    memset(deep + 5, '[', 999);
    memset(deep + 5 + 999, ']', 999);
    strcpy(deep + 5 + 2 * 999, "}");
    assert_int_equal(load(deep, &log, &s, err, sizeof err), VFX_OK);
    rt_scene_free(s);
}

static void test_unknown_keys_warn(void **state)
{
    (void)state;
    test_log log = {0};
    rt_scene *s = NULL;
    char err[256];
    assert_int_equal(load("{\"camera\":{\"fov\":40},\"beams\":[{\"head\":[0,0,0],\"dir\":[1,0,0],\"raduis\":1}]}",
                          &log, &s, err, sizeof err),
                     VFX_OK);
    assert_int_equal(log.warnings, 2);
    assert_string_equal(log.last, "beams[0].raduis: unknown key ignored");
    rt_scene_free(s);
    log = (test_log){0};
    assert_int_equal(load("{\"name\":\"a\",\"name\":\"b\"}", &log, &s, err, sizeof err), VFX_OK);
    assert_int_equal(log.warnings, 1);
    assert_string_equal(log.last, "name: duplicate key, the first one is used");
    assert_string_equal(s->name, "a");
    rt_scene_free(s);
}

/* An origin far from the content: the pool of default.json's size (16,384 particles, spacing
 * 0.053 m) stored 1e6 m from an explicit origin sits where float32 positions are 0.0625 m apart
 * (the simulation was wrecked and the water drew 26 pixels, with nothing said): a warning names
 * the origin, the key and the float32 step; the camera 1e6 m out against its near plane too.
 * Without the key (camera-relative) or with the origin at the content: nothing. */
static void test_origin_far_from_content(void **state)
{
    (void)state;
    const char *pool = "\"water\":{\"source\":\"simulation\",\"simulation\":{\"tank\":{\"min\":[-1.65,0,-1.25],"
                       "\"max\":[1.65,1.4,1.25]},\"fluid\":{\"min\":[-1.6,0.02,-1.2],\"max\":[1.6,0.34,1.2]},"
                       "\"particle_count\":16384}}";
    const char *origins[3] = {"\"origin\":[1e6,0,0],", "", "\"origin\":[1,0,0],"};
    for (int k = 0; k < 3; ++k) {
        char json[1024];
        snprintf(json, sizeof json, "{%s\"camera\":{\"eye\":[0,2,6]},%s}", origins[k], pool);
        test_log log = {0};
        rt_scene *s = NULL;
        char err[256];
        assert_int_equal(load(json, &log, &s, err, sizeof err), VFX_OK);
        print_message("origin case %d: %d warnings; %s\n", k, log.warnings, log.last);
        if (k == 0) {
            assert_int_equal(log.warnings, 2); /* the tank and the camera */
            assert_non_null(strstr(log.last, "origin [1000000, 0, 0]: camera.eye is 1e+06 m from it"));
        } else {
            assert_int_equal(log.warnings, 0);
        }
        rt_scene_free(s);
    }
    /* the tank alone (a camera near the origin): its own warning */
    char json[1024];
    snprintf(json, sizeof json, "{\"origin\":[0,0,0],\"camera\":{\"eye\":[0,2,6]},%s}", pool);
    char *at = strstr(json, "[-1.65,0,-1.25]");
    assert_non_null(at);
    memcpy(at, "[-5e5,0,-1.250]", 15); /* the tank reaching 5e5 m out */
    test_log log = {0};
    rt_scene *s = NULL;
    char err[256];
    assert_int_equal(load(json, &log, &s, err, sizeof err), VFX_OK);
    assert_int_equal(log.warnings, 1);
    assert_non_null(strstr(log.last, "water.simulation.tank reaches 500000 m from it, where float32 positions are "
                                     "0.03125 m apart, more than 1/64 of the particle spacing"));
    rt_scene_free(s);
}

/* Camera-relative by default: without "origin" the origin is camera.eye (in double), every
 * position is stored relative to it, and a position the scene leaves out keeps its world
 * default; stored + origin must give back the world values (the reference: the same scene with
 * the opt-out "origin": [0, 0, 0], stored as world values). */
static void test_origin_default(void **state)
{
    (void)state;
    const char *body =
        "\"camera\":{\"eye\":[10000.25,2,6.5]},"          /* target left out: world default */
        "\"meshes\":[{\"box\":{\"min\":[0,0,0],\"max\":[1,1,1]}},"  /* no translate: world 0 */
        "{\"box\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"translate\":[10001,0,0]}],"
        "\"beams\":[{\"head\":[10000,1,0],\"dir\":[1,0,0]}],"
        "\"water\":{\"source\":\"generator\",\"generator\":{\"kind\":\"layers\",\"count\":8}}}";
    char rel[1024], abs_[1024];
    snprintf(rel, sizeof rel, "{%s", body);
    snprintf(abs_, sizeof abs_, "{\"origin\":[0,0,0],%s", body);
    test_log log = {0};
    rt_scene *r = NULL, *w = NULL;
    char err[256];
    assert_int_equal(load(rel, &log, &r, err, sizeof err), VFX_OK);
    assert_int_equal(load(abs_, &log, &w, err, sizeof err), VFX_OK);
    assert_true(r->origin[0] == 10000.25 && r->origin[1] == 2 && r->origin[2] == 6.5);
    assert_true(w->origin[0] == 0 && w->origin[1] == 0 && w->origin[2] == 0);
    for (int k = 0; k < 3; ++k) {
        /* stored relative: eye 0; the world values agree within the world values' float32 ulp
         * (1e-3 at 1e4: the relative ones are the more exact) */
        assert_true(r->camera.eye[k] == 0);
        double tol = 1e-3;
        assert_true(fabs(r->camera.target[k] + r->origin[k] - w->camera.target[k]) <= tol);
        assert_true(fabs(r->meshes[0].model[12 + k] + r->origin[k] - w->meshes[0].model[12 + k]) <= tol);
        assert_true(fabs(r->meshes[1].model[12 + k] + r->origin[k] - w->meshes[1].model[12 + k]) <= tol);
        assert_true(fabs(r->beams[0].base.head[k] + r->origin[k] - w->beams[0].base.head[k]) <= tol);
        assert_true(fabs(r->water.origin[k] + r->origin[k] - w->water.origin[k]) <= tol);
    }
    assert_close(r->camera.target[0], -10000.25); /* the default target (0, 0.5, 0), relative */
    assert_close(r->beams[0].base.head[0], -0.25);
    rt_scene_free(r);
    rt_scene_free(w);
    /* no camera object at all: the default eye is the origin */
    assert_int_equal(load("{}", &log, &r, err, sizeof err), VFX_OK);
    assert_true(r->origin[0] == 0 && r->origin[1] == 2 && r->origin[2] == 6);
    assert_close(r->camera.eye[1], 0);
    assert_close(r->camera.target[1], -1.5);
    assert_close(r->camera.target[2], -6);
    rt_scene_free(r);
}

static void test_keyframes(void **state)
{
    (void)state;
    const char *json =
        "{\"origin\":[0,0,0],\"beams\":[{\"head\":[0,0,0],\"dir\":[1,0,0],\"keyframes\":{"
        "\"length\":[{\"t\":1,\"value\":2},{\"t\":3,\"value\":6},{\"t\":4,\"value\":4}],"
        "\"head\":[{\"t\":0,\"value\":[0,0,0]},{\"t\":2,\"value\":[2,-4,8]}],"
        "\"dir\":[{\"t\":0,\"value\":[1,0,0]},{\"t\":2,\"value\":[-1,0,0]}],"
        "\"color\":[{\"t\":0,\"value\":[0,0,0,1]},{\"t\":10,\"value\":[1,0.5,0,1]}]}},"
        "{\"head\":[5,5,5],\"dir\":[0,1,0],\"loop_s\":2,\"keyframes\":{\"radius\":[{\"t\":0,\"value\":1},"
        "{\"t\":2,\"value\":3}]}}]}";
    test_log log = {0};
    rt_scene *s = NULL;
    char err[256];
    assert_int_equal(load(json, &log, &s, err, sizeof err), VFX_OK);
    vfx_beam b[4];
    /* hand-computed: length keys (1,2) (3,6) (4,4) */
    struct { double t, length; } L[] = {{-5, 2}, {1, 2}, {2, 4}, {2.5, 5}, {3, 6}, {3.25, 5.5}, {4, 4}, {100, 4}};
    for (size_t i = 0; i < sizeof L / sizeof L[0]; ++i) {
        assert_int_equal(rt_scene_beams_at(s, L[i].t, b, 4, NULL, 0, NULL), 2);
        assert_close(b[0].length, L[i].length);
    }
    rt_scene_beams_at(s, 0.5, b, 4, NULL, 0, NULL);
    assert_close(b[0].head[0], 0.5);
    assert_close(b[0].head[1], -1);
    assert_close(b[0].head[2], 2);
    assert_close(b[0].color[0], 0.05);
    assert_close(b[0].color[1], 0.025);
    assert_close(b[0].color[3], 1);
    assert_close(b[0].dir[0], 0.5);
    assert_close(b[0].radius, 0.5); /* not animated: the default */
    /* opposite direction keys pass through zero at t=1: the earlier key's direction is held */
    rt_scene_beams_at(s, 1.0, b, 4, NULL, 0, NULL);
    assert_close(b[0].dir[0], 1);
    /* beam 1 loops every 2 s: t=5 -> 1 -> radius 2; t=-0.5 -> 1.5 -> 2.5; static head */
    rt_scene_beams_at(s, 5.0, b, 4, NULL, 0, NULL);
    assert_close(b[1].radius, 2);
    assert_close(b[1].head[0], 5);
    rt_scene_beams_at(s, -0.5, b, 4, NULL, 0, NULL);
    assert_close(b[1].radius, 2.5);
    /* non-finite time is treated as 0; n smaller than the count writes n */
    assert_int_equal(rt_scene_beams_at(s, NAN, b, 1, NULL, 0, NULL), 1);
    assert_close(b[0].length, 2);
    assert_int_equal(rt_scene_beams_at(s, 0, NULL, 4, NULL, 0, NULL), 0);
    rt_scene_free(s);
    /* an animated head with no static head takes the first key as the base */
    assert_int_equal(load("{\"beams\":[{\"dir\":[1,0,0],\"keyframes\":{\"head\":[{\"t\":0,\"value\":[7,8,9]}]}}]}",
                          &log, &s, err, sizeof err),
                     VFX_OK);
    assert_close(s->beams[0].base.head[1] + s->origin[1], 8); /* stored relative to the default origin */
    rt_scene_free(s);
}

static void test_sample_scenes(void **state)
{
    (void)state;
    const char *root = getenv("VFX_SOURCE_ROOT");
    if (!root)
        root = ".";
    static const char *names[] = {"default", "beams-only", "water-only", "empty", "long-run"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; ++i) {
        char path[1024], err[512];
        snprintf(path, sizeof path, "%s/sample_game/scenes/%s.json", root, names[i]);
        test_log log = {0};
        rt_logger lg = {test_log_fn, &log};
        rt_scene *s = NULL;
        vfx_result r = rt_scene_load_file(path, &lg, &s, err, sizeof err);
        if (r)
            fail_msg("%s: %s", path, err);
        assert_int_equal(log.warnings, 0);
        assert_string_equal(s->name, names[i]);
        if (s->has_water) {
            float *xyz = NULL;
            uint32_t n = 0;
            assert_int_equal(rt_scene_water_particles(&s->water, &xyz, &n, err, sizeof err), VFX_OK);
            assert_int_equal(n, s->water.count);
            /* llvmpipe budget of the sample scenes: the default and the water showcase carry the
             * 16,384-particle pool, the others stay small */
            assert_true(n <= 16384);
            free(xyz);
        }
        if (i == 0) {
            assert_true(s->beam_count >= 3 && s->beam_count <= 5); /* the fifth strikes the pool */
            assert_true(s->beams[0].joint_count >= 2 && s->beams[0].joint_track.count >= 2); /* it bends, animated */
            assert_true(s->has_water && s->water.source == RT_SCENE_WATER_SIMULATION && s->water.paddle);
            /* ramp_s absent: the paddle's amplitude ramps in over one period */
            assert_true(s->water.paddle_ramp_s == s->water.paddle_period_s && s->water.paddle_period_s > 0.f);
            assert_int_equal(s->water.settle_steps, 120); /* absent: the block settles before frame 0 */
            assert_true(s->has_volume);
            assert_true(s->mesh_count >= 1);
        }
        rt_scene_free(s);
    }
    /* the embedded copy is the same text and loads the same way */
    char path[1024];
    snprintf(path, sizeof path, "%s/sample_game/scenes/default.json", root);
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    static char text[1 << 16];
    size_t n = fread(text, 1, sizeof text, f);
    fclose(f);
    assert_int_equal(n, game_default_scene_json_len);
    assert_memory_equal(text, game_default_scene_json, n);
    rt_scene *s = NULL;
    char err[256];
    test_log log = {0};
    rt_logger lg = {test_log_fn, &log};
    assert_int_equal(rt_scene_load_mem(game_default_scene_json, game_default_scene_json_len, NULL, &lg, &s, err, sizeof err),
                     VFX_OK);
    rt_scene_free(s);
}

static void test_relative_paths_and_io(void **state)
{
    (void)state;
    char dir[] = "/tmp/vfx_scene_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char scene_path[256], part_path[256], err[512];
    snprintf(scene_path, sizeof scene_path, "%s/s.json", dir);
    snprintf(part_path, sizeof part_path, "%s/p.bin", dir);
    FILE *f = fopen(scene_path, "w");
    fputs("{\"origin\":[0,0,0],\"water\":{\"source\":\"file\",\"path\":\"p.bin\"}}", f);
    fclose(f);
    const float xyz[6] = {1, 2, 3, 4, 5, 6};
    assert_int_equal(rt_particle_file_save(part_path, xyz, 2, err, sizeof err), VFX_OK);
    rt_scene *s = NULL;
    assert_int_equal(rt_scene_load_file(scene_path, NULL, &s, err, sizeof err), VFX_OK);
    assert_string_equal(s->water.path, part_path);
    float *got = NULL;
    uint32_t n = 0;
    assert_int_equal(rt_scene_water_particles(&s->water, &got, &n, err, sizeof err), VFX_OK);
    assert_int_equal(n, 2);
    assert_memory_equal(got, xyz, sizeof xyz);
    free(got);
    rt_scene_free(s);
    /* a syntax error in a file names the file and the line */
    f = fopen(scene_path, "w");
    fputs("{\n\"camera\": }", f);
    fclose(f);
    assert_int_equal(rt_scene_load_file(scene_path, NULL, &s, err, sizeof err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, scene_path));
    assert_non_null(strstr(err, "line 2"));
    unlink(scene_path);
    unlink(part_path);
    rmdir(dir);
    assert_int_equal(rt_scene_load_file(scene_path, NULL, &s, err, sizeof err), VFX_ERR_IO);
    assert_non_null(strstr(err, "cannot open"));
    assert_int_equal(rt_scene_load_file("/tmp", NULL, &s, err, sizeof err) != VFX_OK, 1);
}

static void test_generators(void **state)
{
    (void)state;
    rt_scene_water w = {.source = RT_SCENE_WATER_GENERATOR, .generator = RT_SCENE_GEN_LAYERS, .count = 600,
                         .origin = {1, 2, 3}, .spacing = 0.5f, .layer_side = 24};
    float *p = NULL;
    uint32_t n = 0;
    char err[256];
    assert_int_equal(rt_scene_water_particles(&w, &p, &n, err, sizeof err), VFX_OK);
    assert_int_equal(n, 600);
    /* particle 577 = layer 1 (576 per layer), index 1 in that layer: x = 1 + 0.5, y = 2 + 0.5, z = 3 */
    assert_close(p[3 * 577], 1.5);
    assert_close(p[3 * 577 + 1], 2.5);
    assert_close(p[3 * 577 + 2], 3);
    assert_close(p[3 * 575 + 2], 3 + 23 * 0.5);
    free(p);
    /* box: exact count, every particle inside, no two identical */
    w = (rt_scene_water){.source = RT_SCENE_WATER_GENERATOR, .generator = RT_SCENE_GEN_BOX, .count = 1000,
                          .box_min = {-1, 0, 0}, .box_max = {1, 0.5f, 3}};
    assert_int_equal(rt_scene_water_particles(&w, &p, &n, err, sizeof err), VFX_OK);
    assert_int_equal(n, 1000);
    for (uint32_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k)
            assert_true(p[3 * i + k] >= w.box_min[k] - 1e-5f && p[3 * i + k] <= w.box_max[k] + 1e-5f);
    for (uint32_t i = 1; i < n; ++i)
        assert_memory_not_equal(&p[3 * i], &p[3 * (i - 1)], 12);
    free(p);
    /* sphere */
    w = (rt_scene_water){.source = RT_SCENE_WATER_GENERATOR, .generator = RT_SCENE_GEN_SPHERE, .count = 2000,
                          .center = {0, 1, 0}, .radius = 0.5f};
    assert_int_equal(rt_scene_water_particles(&w, &p, &n, err, sizeof err), VFX_OK);
    assert_int_equal(n, 2000);
    for (uint32_t i = 0; i < n; ++i) {
        double d = hypot(hypot(p[3 * i], p[3 * i + 1] - 1.0), p[3 * i + 2]);
        assert_true(d <= 0.5 + 1e-5);
    }
    free(p);
    /* zero particles: defined, empty */
    w.count = 0;
    assert_int_equal(rt_scene_water_particles(&w, &p, &n, err, sizeof err), VFX_OK);
    assert_int_equal(n, 0);
    assert_null(p);
    /* simulation: the initial block */
    w = (rt_scene_water){.source = RT_SCENE_WATER_SIMULATION, .count = 500, .box_min = {0, 0, 0}, .box_max = {1, 1, 1}};
    assert_int_equal(rt_scene_water_particles(&w, &p, &n, err, sizeof err), VFX_OK);
    assert_int_equal(n, 500);
    free(p);
}

static void test_volume_generate_and_transfer(void **state)
{
    (void)state;
    rt_scene_volume v = {.generated = true, .gen_cells = 3, .gen_min = {0, 0, 0}, .gen_max = {2, 1, 3}};
    float *pts = NULL, *sc = NULL;
    uint32_t *tets = NULL, np = 0, nt = 0;
    char err[256];
    assert_int_equal(rt_scene_volume_generate(&v, &pts, &np, &tets, &nt, &sc, err, sizeof err), VFX_OK);
    assert_int_equal(np, 64);
    assert_int_equal(nt, 6 * 27);
    /* independent check in double: every tet positive, their volumes sum to the box's (6) */
    double total = 0;
    for (uint32_t t = 0; t < nt; ++t) {
        const float *a = &pts[3 * tets[4 * t]], *b = &pts[3 * tets[4 * t + 1]], *c = &pts[3 * tets[4 * t + 2]],
                    *d = &pts[3 * tets[4 * t + 3]];
        double u[3], w[3], e[3];
        for (int k = 0; k < 3; ++k)
            u[k] = b[k] - a[k], w[k] = c[k] - a[k], e[k] = d[k] - a[k];
        double vol = (u[0] * (w[1] * e[2] - w[2] * e[1]) - u[1] * (w[0] * e[2] - w[2] * e[0]) +
                      u[2] * (w[0] * e[1] - w[1] * e[0])) / 6.0;
        assert_true(vol > 0);
        total += vol;
        for (int k = 0; k < 4; ++k)
            assert_true(tets[4 * t + k] < np);
    }
    assert_true(fabs(total - 6.0) < 1e-9);
    /* scalar: 1 at nothing but 0 at the corners (distance = half-diagonal) */
    assert_close(sc[0], 0);
    free(pts), free(tets), free(sc);
    v.gen_cells = 0;
    assert_int_equal(rt_scene_volume_generate(&v, &pts, &np, &tets, &nt, &sc, err, sizeof err), VFX_ERR_INVALID_ARGUMENT);

    /* transfer: points (0: 0,0,0,0) (1: 1,0,0,1) (3: 1,1,1,3) sampled at 7 entries over [0, 3] */
    rt_scene_volume tv = {.transfer_count = 3,
                           .transfer = {{0, {0, 0, 0, 0}}, {1, {1, 0, 0, 1}}, {3, {1, 1, 1, 3}}}};
    float rgba[28], lo, hi;
    rt_scene_transfer_sample(&tv, 7, rgba, &lo, &hi);
    assert_close(lo, 0);
    assert_close(hi, 3);
    assert_close(rgba[4 * 1 + 0], 0.5); /* s = 0.5 */
    assert_close(rgba[4 * 1 + 3], 0.5);
    assert_close(rgba[4 * 2 + 0], 1);   /* s = 1 */
    assert_close(rgba[4 * 3 + 1], 0.25); /* s = 1.5 */
    assert_close(rgba[4 * 3 + 3], 1.5);
    assert_close(rgba[4 * 6 + 2], 1);   /* s = 3 */
    assert_close(rgba[4 * 6 + 3], 3);
    tv.transfer_normalized = true;
    rt_scene_transfer_sample(&tv, 7, rgba, &lo, &hi);
    assert_close(lo, 0);
    assert_close(hi, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_field),
        cmocka_unit_test(test_defaults),
        cmocka_unit_test(test_bad_inputs),
        cmocka_unit_test(test_too_many_beams),
        cmocka_unit_test(test_nul_byte),
        cmocka_unit_test(test_environment),
        cmocka_unit_test(test_syntax_errors),
        cmocka_unit_test(test_unknown_keys_warn),
        cmocka_unit_test(test_origin_default), cmocka_unit_test(test_origin_far_from_content),
        cmocka_unit_test(test_keyframes),
        cmocka_unit_test(test_sample_scenes),
        cmocka_unit_test(test_relative_paths_and_io),
        cmocka_unit_test(test_generators),
        cmocka_unit_test(test_volume_generate_and_transfer),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
