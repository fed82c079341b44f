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

static rt_scene *load(const char *json, char *err, size_t errlen)
{
    rt_scene *s = NULL;
    rt_scene_load_mem(json, strlen(json), NULL, NULL, &s, err, errlen);
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
    vfx_beam2 b[2];
    assert_int_equal(rt_scene_beams2_at(s, 1.0, b, 2), 2);
    /* defaults: the smooth support, the hot ramp, intensity 1, no exposure, no flow */
    assert_int_equal(b[0].falloff, VFX_BEAM_FALLOFF_SMOOTH);
    assert_int_equal(b[0].ramp, VFX_BEAM_RAMP_HOT);
    assert_true(b[0].intensity == 1.f && b[0].exposure == 0.f && b[0].flow_amount == 0.f);
    assert_int_equal(b[1].falloff, VFX_BEAM_FALLOFF_HARD);
    assert_int_equal(b[1].ramp, VFX_BEAM_RAMP_THESIS);
    assert_true(fabsf(b[1].intensity - 2.f) < 1e-6f); /* keyframed: halfway from 1 to 3 */
    assert_true(fabsf(b[1].exposure - 1.f) < 1e-6f);
    assert_true(b[1].flow_amount == 0.3f && b[1].flow_speed == 4.f && b[1].flow_scale == 0.7f);
    assert_true(b[1].v1.head[1] == 1.f);
    assert_int_equal(s->beams_view2.bloom, VFX_BEAMS_BLOOM_OFF);
    assert_true(s->beams_view2.bloom_strength == 0.3f);
    assert_int_equal(s->beams_view2.bloom_levels, 3);
    /* rt_scene_beams_at gives the version 1 part of the same beams */
    vfx_beam v1[2];
    assert_int_equal(rt_scene_beams_at(s, 1.0, v1, 2), 2);
    assert_memory_equal(&v1[1], &b[1].v1, sizeof v1[1]);
    rt_scene_free(s);
}

static void test_bad_values(void **state)
{
    (void)state;
    static const struct {
        const char *beam, *msg;
    } cases[] = {
        {"\"falloff\": \"soft\"", "beams[0].falloff: unknown value \"soft\""},
        {"\"ramp\": 3", "beams[0].ramp"},
        {"\"intensity\": 0", "beams[0].intensity"},
        {"\"exposure\": 100", "beams[0].exposure"},
        {"\"flow\": {\"amount\": 2}", "beams[0].flow.amount"},
        {"\"flow\": 1", "beams[0].flow"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        char json[512], err[256] = "";
        snprintf(json, sizeof json, "{\"version\": 1, \"beams\": [{\"head\": [0, 0, 0], \"dir\": [1, 0, 0], %s}]}",
                 cases[i].beam);
        rt_scene *s = load(json, err, sizeof err);
        if (s || !strstr(err, cases[i].msg))
            printf("case %s: got \"%s\"\n", cases[i].beam, err);
        assert_null(s);
        assert_non_null(strstr(err, cases[i].msg));
    }
    char err[256] = "";
    assert_null(load("{\"version\": 1, \"beam_settings\": {\"bloom_levels\": 9}}", err, sizeof err));
    assert_non_null(strstr(err, "beam_settings.bloom_levels"));
    assert_null(load("{\"version\": 1, \"beam_settings\": {\"bloom\": \"yes\"}}", err, sizeof err));
    assert_non_null(strstr(err, "beam_settings.bloom"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults_and_values),
        cmocka_unit_test(test_bad_values),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
