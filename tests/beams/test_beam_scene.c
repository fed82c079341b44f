/* test_beam_scene.c — the beams' scene keys of version 2 (falloff, ramp, intensity, exposure,
 * flow, bloom settings): defaults, values reaching rt_scene_beams2_at, keyframed intensity and
 * exposure, and bad values refused with their JSON path. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "scene/scene.h"
#include "test_util.h"

static vfx_result g_code; /* the last load's result */

static rt_scene *load(const char *json, char *err, size_t errlen)
{
    rt_scene *s = NULL;
    g_code = rt_scene_load_mem(json, strlen(json), NULL, NULL, &s, err, errlen);
    return s;
}

static void test_defaults_and_values(void **state)
{
    (void)state;
    char err[256] = "";
    rt_scene *s = load("{\"version\": 1, \"beams\": ["
                       "{\"head\": [0, 0, 0], \"dir\": [1, 0, 0]},"
                       "{\"head\": [0, 1, 0], \"dir\": [1, 0, 0], \"falloff\": \"hard\", \"ramp\": \"thesis\","
                       " \"intensity\": 2.5, \"exposure\": -1, \"flow\": {\"amount\": 0.3, \"speed\": 4, \"scale\": 0.7},"
                       " \"loop_s\": 2, \"keyframes\": {\"intensity\": [{\"t\": 0, \"value\": 1}, {\"t\": 2, \"value\": 3}],"
                       " \"exposure\": [{\"t\": 0, \"value\": 0}, {\"t\": 2, \"value\": 2}]}}],"
                       "\"beam_settings\": {\"bloom\": false, \"bloom_strength\": 0.3, \"bloom_levels\": 3}}",
                       err, sizeof err);
    assert_non_null(s);
    vfx_beam b[2];
    assert_int_equal(rt_scene_beams_at(s, 1.0, b, 2, NULL, 0, NULL), 2);
    /* defaults: the smooth support, the hot ramp, intensity 1, no exposure, no flow */
    assert_int_equal(b[0].falloff, VFX_BEAM_FALLOFF_SMOOTH);
    assert_int_equal(b[0].ramp, VFX_BEAM_RAMP_HOT);
    assert_true(b[0].intensity == 1.f && b[0].exposure == 0.f && b[0].flow_amount == 0.f);
    assert_int_equal(b[1].falloff, VFX_BEAM_FALLOFF_HARD);
    assert_int_equal(b[1].ramp, VFX_BEAM_RAMP_THESIS);
    assert_true(fabsf(b[1].intensity - 2.f) < 1e-6f); /* keyframed: halfway from 1 to 3 */
    assert_true(fabsf(b[1].exposure - 1.f) < 1e-6f);
    assert_true(b[1].flow_amount == 0.3f && b[1].flow_speed == 4.f && b[1].flow_scale == 0.7f);
    assert_true(b[1].head[1] + s->origin[1] == 1.0); /* stored relative to the default origin (the eye) */
    assert_int_equal(s->beams_view.bloom, VFX_BEAMS_BLOOM_OFF);
    assert_true(s->beams_view.bloom_strength == 0.3f);
    assert_int_equal(s->beams_view.bloom_levels, 3);
    assert_int_equal(b[0].type, VFX_TYPE_BEAM);
    assert_int_equal(b[1].type, VFX_TYPE_BEAM);
    rt_scene_free(s);
}

static void test_bad_values(void **state)
{
    (void)state;
    /* a value out of range or unknown is VFX_ERR_INVALID_ARGUMENT, a value of the wrong JSON
     * type VFX_ERR_FORMAT; the message names the key's path */
    static const struct {
        const char *beam, *msg;
        vfx_result code;
    } cases[] = {
        {"\"falloff\": \"soft\"", "beams[0].falloff: unknown value \"soft\"", VFX_ERR_INVALID_ARGUMENT},
        {"\"ramp\": 3", "beams[0].ramp", VFX_ERR_FORMAT},
        {"\"intensity\": 0", "beams[0].intensity", VFX_ERR_INVALID_ARGUMENT},
        {"\"exposure\": 100", "beams[0].exposure", VFX_ERR_INVALID_ARGUMENT},
        {"\"flow\": {\"amount\": 2}", "beams[0].flow.amount", VFX_ERR_INVALID_ARGUMENT},
        {"\"flow\": 1", "beams[0].flow", VFX_ERR_FORMAT},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        char json[512], err[256] = "";
        snprintf(json, sizeof json, "{\"version\": 1, \"beams\": [{\"head\": [0, 0, 0], \"dir\": [1, 0, 0], %s}]}",
                 cases[i].beam);
        rt_scene *s = load(json, err, sizeof err);
        if (s || !strstr(err, cases[i].msg))
            printf("case %s: got \"%s\"\n", cases[i].beam, err);
        assert_null(s);
        assert_int_equal(g_code, cases[i].code);
        assert_non_null(strstr(err, cases[i].msg));
    }
    char err[256] = "";
    assert_null(load("{\"version\": 1, \"beam_settings\": {\"bloom_levels\": 9}}", err, sizeof err));
    assert_int_equal(g_code, VFX_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "beam_settings.bloom_levels"));
    assert_null(load("{\"version\": 1, \"beam_settings\": {\"bloom\": \"yes\"}}", err, sizeof err));
    assert_int_equal(g_code, VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "beam_settings.bloom"));
}

/* Bending beams: static joints, keyframed joints (interpolated per joint), the joints array
 * filled with joint_first indices, a beam whose joints do not fit left straight, bad joints. */
static void test_joints(void **state)
{
    (void)state;
    char err[256] = "";
    rt_scene *s = load("{\"version\": 1, \"beams\": ["
                       "{\"joints\": [[0, 0, 0], [1, 0, 0], [1, 1, 0]]},"
                       "{\"loop_s\": 2, \"keyframes\": {\"joints\": [{\"t\": 0, \"value\": [[0, 0, 0], [2, 0, 0]]},"
                       " {\"t\": 2, \"value\": [[0, 2, 0], [2, 4, 0]]}]}}]}",
                       err, sizeof err);
    if (!s)
        printf("%s\n", err);
    assert_non_null(s);
    vfx_beam b[2];
    float j[8][3];
    uint32_t nj = 99;
    assert_int_equal(rt_scene_beams_at(s, 1.0, b, 2, &j[0][0], 8, &nj), 2);
    assert_int_equal(nj, 5);
    assert_int_equal(b[0].joint_first, 0);
    assert_int_equal(b[0].joint_count, 3);
    assert_int_equal(b[1].joint_first, 3);
    assert_int_equal(b[1].joint_count, 2);
    /* joints are positions: stored relative to the scene's origin (here the default eye) */
    const double *o = s->origin;
    assert_true(j[2][1] + o[1] == 1.0);
    assert_true(j[3][1] + o[1] == 1.0 && j[4][0] + o[0] == 2.0 && j[4][1] + o[1] == 2.0); /* halfway */
    /* room for 4 joints: the second beam does not fit and stays straight */
    assert_int_equal(rt_scene_beams_at(s, 1.0, b, 2, &j[0][0], 4, &nj), 2);
    assert_int_equal(nj, 3);
    assert_int_equal(b[1].joint_count, 0);
    rt_scene_free(s);
    static const struct {
        const char *beam, *msg;
        vfx_result code;
    } bad[] = {
        {"\"joints\": [[0, 0, 0]]", "beams[0].joints: expected an array of 2 to 6", VFX_ERR_INVALID_ARGUMENT},
        {"\"joints\": [[0, 0, 0], [1, 0]]", "beams[0].joints[1]", VFX_ERR_FORMAT},
        {"\"joints\": [[0,0,0],[1,0,0],[2,0,0],[3,0,0],[4,0,0],[5,0,0],[6,0,0]]", "beams[0].joints",
         VFX_ERR_INVALID_ARGUMENT},
        {"\"joints\": [[0, 0, 0], [1, 0, 0]], \"keyframes\": {\"joints\": [{\"t\": 0, \"value\": [[0, 0, 0], [1, 0, 0], [2, 0, 0]]}]}",
         "beams[0].keyframes.joints[0].value: 3 joints; every key", VFX_ERR_INVALID_ARGUMENT},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        char json[512];
        snprintf(json, sizeof json, "{\"version\": 1, \"beams\": [{%s}]}", bad[i].beam);
        err[0] = 0;
        rt_scene *t = load(json, err, sizeof err);
        if (t || !strstr(err, bad[i].msg))
            printf("case %s: got \"%s\"\n", bad[i].beam, err);
        assert_null(t);
        assert_int_equal(g_code, bad[i].code);
        assert_non_null(strstr(err, bad[i].msg));
    }
}

/* The anatomy's keys (vfx_beam): values, keyframes, defaults (core 0.2 in scenes, 0 with the
 * thesis ramp) and bad values refused with their path. */
static void test_anatomy_keys(void **state)
{
    (void)state;
    char err[256] = "";
    rt_scene *s = load("{\"version\": 1, \"beams\": ["
                       "{\"head\": [0, 0, 0], \"dir\": [1, 0, 0]},"
                       "{\"head\": [0, 1, 0], \"dir\": [1, 0, 0], \"head_radius\": 0.9, \"orb_radius\": 0.4,"
                       " \"orb\": {\"pulse\": 0.3, \"pulse_hz\": 2}, \"taper\": 0.5, \"surges\": {\"wavelength\": 1.5,"
                       " \"speed\": 3}, \"flow\": {\"amount\": 0.6, \"kind\": \"spiral\", \"twist\": 2}, \"core\": 0.3,"
                       " \"loop_s\": 2, \"keyframes\": {\"surge\": [{\"t\": 0, \"value\": 0}, {\"t\": 2, \"value\": 1}],"
                       " \"orb_strength\": [{\"t\": 0, \"value\": 1}, {\"t\": 2, \"value\": 3}]}},"
                       "{\"head\": [0, 0, 0], \"dir\": [1, 0, 0], \"ramp\": \"thesis\"}]}",
                       err, sizeof err);
    assert_non_null(s);
    vfx_beam b[3];
    assert_int_equal(rt_scene_beams_at(s, 1.0, b, 3, NULL, 0, NULL), 3);
    assert_true(b[0].core == 0.2f && b[0].head_radius == 0.f && b[0].orb_radius == 0.f && b[0].taper == 0.f);
    assert_true(b[2].core == 0.f);
    assert_true(b[1].head_radius == 0.9f && b[1].orb_radius == 0.4f && b[1].orb_pulse == 0.3f);
    assert_true(b[1].orb_pulse_hz == 2.f && b[1].taper == 0.5f && b[1].surge_wavelength == 1.5f);
    assert_true(b[1].surge_speed == 3.f && b[1].flow_kind == VFX_BEAM_FLOW_SPIRAL && b[1].flow_twist == 2.f);
    assert_true(b[1].core == 0.3f && b[1].flow_amount == 0.6f);
    assert_true(fabsf(b[1].surge_amount - 0.5f) < 1e-6f && fabsf(b[1].orb_strength - 2.f) < 1e-6f); /* halfway */
    rt_scene_free(s);
    static const char *const bad[][2] = {
        {"\"taper\": 0.99", "beams[0].taper"},
        {"\"surge\": -1", "beams[0].surge"},
        {"\"core\": 2", "beams[0].core"},
        {"\"orb\": {\"pulse\": 1.5}", "beams[0].orb.pulse"},
        {"\"flow\": {\"kind\": \"swirl\"}", "beams[0].flow.kind"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        char json[256];
        snprintf(json, sizeof json, "{\"version\": 1, \"beams\": [{\"head\": [0, 0, 0], \"dir\": [1, 0, 0], %s}]}",
                 bad[i][0]);
        err[0] = 0;
        assert_null(load(json, err, sizeof err));
        if (!strstr(err, bad[i][1]))
            fail_msg("%s: error '%s' does not name %s", bad[i][0], err, bad[i][1]);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults_and_values),
        cmocka_unit_test(test_bad_values),
        cmocka_unit_test(test_joints),
        cmocka_unit_test(test_anatomy_keys),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
