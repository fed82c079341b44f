/* The one table of documented ranges (plugin/include/volfx/volfx_ranges.h, issue 28): the
 * "Ranges" table of docs/scene-format.md is exactly what the table generates; every row's
 * boundaries are accepted and just outside, NaN and Inf refused naming the field; and the ABI
 * values the attack found accepted (water colour NaN / 1e30, ior Inf, negative or NaN h,
 * threshold, step, absorption, ior silently defaulted; beam radius and intensity 3e38, a NaN
 * colour) are refused by the functions the effects call.
 * usage: test_param_ranges DOCS/scene-format.md [--print] */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "context.h"
#include "param_ranges.h"
#include "water/water_params.h"

static const char *g_doc;

#define BEGIN "<!-- ranges: generated from plugin/include/volfx/volfx_ranges.h; test unit/param_ranges -->\n"
#define END "<!-- ranges: end -->\n"

/* The docs block the table gives. */
static void table_text(char *out, size_t n)
{
    size_t k = (size_t)snprintf(out, n, "%s| ABI field | scene key | range | note |\n|---|---|---|---|\n", BEGIN);
    for (int i = 0; i < VFX_RANGE_COUNT && k < n; ++i) {
        const volfx_range *r = volfx_range_row((vfx_range_id)i);
        char t[96];
        k += (size_t)snprintf(out + k, n - k, "| `%s` | %s | %s | %s |\n", r->field,
                              strcmp(r->scene_key, "-") ? r->scene_key : "-", volfx_range_text(r, t, sizeof t),
                              r->note);
    }
    if (k < n)
        snprintf(out + k, n - k, "%s", END);
}

static void test_docs_table(void **state)
{
    (void)state;
    FILE *f = fopen(g_doc, "rb");
    assert_non_null(f);
    static char doc[1 << 18], want[1 << 14];
    size_t n = fread(doc, 1, sizeof doc - 1, f);
    fclose(f);
    doc[n] = 0;
    table_text(want, sizeof want);
    const char *at = strstr(doc, BEGIN);
    if (!at || strncmp(at, want, strlen(want)) != 0)
        fail_msg("%s: its ranges table differs from volfx_ranges.h; the table it should hold "
                 "(test_param_ranges DOC --print):\n%s", g_doc, want);
}

static vfx_context *fake_ctx(void)
{
    vfx_context *c = calloc(1, sizeof *c); /* volfx_fail writes last_error only */
    assert_non_null(c);
    return c;
}

static void expect(vfx_context *c, vfx_result r, vfx_result want, const char *needle)
{
    if (r != want || (needle && !strstr(c->last_error, needle)))
        fail_msg("result %d (want %d), \"%s\" (want \"%s\")", r, want, c->last_error, needle ? needle : "");
}

static void test_every_row(void **state)
{
    (void)state;
    vfx_context *c = fake_ctx();
    for (int i = 0; i < VFX_RANGE_COUNT; ++i) {
        const volfx_range *r = volfx_range_row((vfx_range_id)i);
        const char *fld = strchr(r->field, '.') + 1;
        double lo_in = r->flags & VFX_RANGE_LO_OPEN ? (r->lo == 0 ? 1e-6 : r->lo * 1.0001) : r->lo;
        expect(c, volfx_range_check(c, "t", (vfx_range_id)i, lo_in), VFX_OK, NULL);
        expect(c, volfx_range_check(c, "t", (vfx_range_id)i, r->hi), VFX_OK, NULL);
        double over = r->flags & VFX_RANGE_INT ? r->hi + 1 : r->hi * 1.001 + 1e-6;
        expect(c, volfx_range_check(c, "t", (vfx_range_id)i, over), VFX_ERR_INVALID_ARGUMENT, fld);
        if (r->lo != 0 || (r->flags & VFX_RANGE_LO_OPEN) || !(r->flags & VFX_RANGE_INT)) {
            double under = r->flags & VFX_RANGE_LO_OPEN ? r->lo : r->lo - (r->flags & VFX_RANGE_INT ? 1 : 1e-3);
            if (!(under == 0 && (r->flags & VFX_RANGE_ZERO)) && !(r->flags & VFX_RANGE_INT && under < 0))
                expect(c, volfx_range_check(c, "t", (vfx_range_id)i, under), VFX_ERR_INVALID_ARGUMENT, fld);
        }
        expect(c, volfx_range_check(c, "t", (vfx_range_id)i, NAN), VFX_ERR_INVALID_ARGUMENT, fld);
        expect(c, volfx_range_check(c, "t", (vfx_range_id)i, INFINITY), VFX_ERR_INVALID_ARGUMENT, fld);
        expect(c, volfx_range_check(c, "t", (vfx_range_id)i, -INFINITY), VFX_ERR_INVALID_ARGUMENT, fld);
        int zero_in = (r->flags & VFX_RANGE_LO_OPEN ? 0 > r->lo : 0 >= r->lo) && 0 <= r->hi;
        expect(c, volfx_range_check(c, "t", (vfx_range_id)i, 0),
               (r->flags & VFX_RANGE_ZERO) || zero_in ? VFX_OK : VFX_ERR_INVALID_ARGUMENT, NULL);
    }
    free(c);
}

/* The attack's ABI values, through volfx_water_params_resolve (what the water effect calls). */
static void test_water_abi_values(void **state)
{
    (void)state;
    vfx_context *c = fake_ctx();
    static const struct { int field; float v; const char *needle; } bad[] = {
        {0, NAN, "vfx_water_params.color[0] nan"},    {0, 1e30f, "vfx_water_params.color[0] 1e+30"},
        {1, INFINITY, "vfx_water_params.ior inf"},     {1, -1, "vfx_water_params.ior -1"},
        {1, NAN, "vfx_water_params.ior nan"},          {1, 0.5f, "vfx_water_params.ior 0.5"},
        {2, -0.1f, "vfx_water_params.h -0.1"},         {2, NAN, "vfx_water_params.h nan"},
        {3, -1, "vfx_water_params.threshold -1"},      {3, NAN, "vfx_water_params.threshold nan"},
        {4, -0.01f, "vfx_water_params.step -0.01"},    {4, NAN, "vfx_water_params.step nan"},
        {5, -2, "vfx_water_params.absorption -2"},     {5, NAN, "vfx_water_params.absorption nan"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
        vfx_water_params p = {.type = VFX_TYPE_WATER_PARAMS};
        vfx_water_params *v = &p;
        switch (bad[k].field) {
        case 0: v->color[0] = bad[k].v, v->color[1] = v->color[2] = 0.5f; break;
        case 1: v->ior = bad[k].v; break;
        case 2: v->h = bad[k].v; break;
        case 3: v->threshold = bad[k].v; break;
        case 4: v->step = bad[k].v; break;
        default: v->absorption = bad[k].v; break;
        }
        volfx_water_resolved out;
        expect(c, volfx_water_params_resolve(c, &p, &out), VFX_ERR_INVALID_ARGUMENT,
               bad[k].needle);
        assert_int_equal(c->last_error_id, VFX_LOG_ID_PARAM_RANGE); /* the id is the contract */
    }
    /* a value at the edge of its range is used as given, not swapped for the default */
    vfx_water_params p = {.type = VFX_TYPE_WATER_PARAMS};
    p.ior = 1.0f;
    p.h = 0.2f;
    volfx_water_resolved out;
    expect(c, volfx_water_params_resolve(c, &p, &out), VFX_OK, NULL);
    assert_true(out.p.ior == 1.0f); /* was 1.333: "!(ior > 1)" took 1 for unset */
    /* max_samples and refine_iters: loop bounds, 4e9 hung a paper-method frame */
    p = (vfx_water_params){.type = VFX_TYPE_WATER_PARAMS};
    p.max_samples = 4000000000u;
    expect(c, volfx_water_params_resolve(c, &p, &out), VFX_ERR_INVALID_ARGUMENT, "max_samples 4000000000 outside 1..4096");
    p = (vfx_water_params){.type = VFX_TYPE_WATER_PARAMS};
    p.refine_iters = 4000000000u;
    expect(c, volfx_water_params_resolve(c, &p, &out), VFX_ERR_INVALID_ARGUMENT, "refine_iters 4000000000 outside 1..64");
    free(c);
}

static void test_beam_abi_values(void **state)
{
    (void)state;
    vfx_context *c = fake_ctx();
    vfx_beam good = {.type = VFX_TYPE_BEAM, .dir = {1, 0, 0}, .length = 1, .radius = 0.5f, .a = 0.05f, .b = 0.03f,
                     .eps = 0.02f, .intensity = 1};
    expect(c, volfx_beam_check_ranges(c, 3, &good), VFX_OK, NULL);
    vfx_beam b = good;
    b.radius = 3e38f; /* gave NaN for H */
    expect(c, volfx_beam_check_ranges(c, 3, &b), VFX_ERR_INVALID_ARGUMENT, "beams[3]: vfx_beam.radius 3e+38");
    b = good;
    b.color[1] = NAN; /* an invisible beam */
    expect(c, volfx_beam_check_ranges(c, 3, &b), VFX_ERR_INVALID_ARGUMENT, "beams[3]: vfx_beam.color[1] nan");
    vfx_beam l = good;
    l.intensity = 3e38f; /* an invisible beam */
    expect(c, volfx_beam_check_ranges(c, 3, &l), VFX_ERR_INVALID_ARGUMENT, "vfx_beam.intensity 3e+38");
    l = good;
    l.exposure = NAN;
    expect(c, volfx_beam_check_ranges(c, 3, &l), VFX_ERR_INVALID_ARGUMENT, "vfx_beam.exposure nan");
    /* the anatomy's fields (the beam vanished: NaN and Inf values) */
    l = good;
    l.surge_amount = 1, l.surge_wavelength = 1e-40f;
    expect(c, volfx_beam_check_ranges(c, 3, &l), VFX_ERR_INVALID_ARGUMENT, "beams[3]: vfx_beam.surge_wavelength 9.99995e-41 outside [1e-06, 1000000] or 0");
    l = good;
    l.orb_radius = 0.2f, l.orb_strength = 3e38f;
    expect(c, volfx_beam_check_ranges(c, 3, &l), VFX_ERR_INVALID_ARGUMENT, "beams[3]: vfx_beam.orb_strength 3e+38");
    l = good;
    l.surge_amount = 4, l.surge_wavelength = 1e-6f, l.orb_radius = 0.2f, l.orb_strength = 1e6f, l.taper = 0.95f, l.core = 1;
    expect(c, volfx_beam_check_ranges(c, 3, &l), VFX_OK, NULL);
    vfx_beams_view v = {.type = VFX_TYPE_BEAMS_VIEW, .saturate_c = -1};
    expect(c, volfx_beams_view_check_ranges(c, &v, 0), VFX_ERR_INVALID_ARGUMENT, "vfx_beams_view.saturate_c -1");
    v.saturate_c = 0;
    expect(c, volfx_beams_view_check_ranges(c, &v, 5000), VFX_ERR_INVALID_ARGUMENT, "vfx_lab_beams.march_samples 5000");
    free(c);
}

/* resolve_defaults without a context: what a zero beam, beams view, volume view and frame view
 * resolve to (the constants beams_effect.c, volume_effect.c and the frame gate apply), fields the
 * host set left alone, and a struct of no defaults refused. */
static void test_resolve_defaults(void **state)
{
    (void)state;
    vfx_plugin_api api = {.type = VFX_TYPE_PLUGIN_API};
    assert_int_equal(vfx_plugin_entry(VFX_ABI_VERSION, NULL, &api), VFX_OK);
    vfx_beam b = {.type = VFX_TYPE_BEAM, .radius = 0.5f, .a = 0.3f, .orb_radius = 0.2f, .intensity = 2};
    assert_int_equal(api.resolve_defaults(NULL, &b), VFX_OK);
    assert_int_equal(b.falloff, VFX_BEAM_FALLOFF_SMOOTH);
    assert_int_equal(b.ramp, VFX_BEAM_RAMP_HOT);
    assert_true(b.intensity == 2 && b.color[0] == 1 && b.color[3] == 1 && b.flow_scale == 1.0f);
    assert_true(b.head_radius == 0.5f && b.surge_wavelength == 4.0f && b.orb_strength == 0.3f && b.flow_twist == 1);
    vfx_beams_view bv = {.type = VFX_TYPE_BEAMS_VIEW, .bloom_levels = 3};
    assert_int_equal(api.resolve_defaults(NULL, &bv), VFX_OK);
    assert_true(bv.saturate_c == 1 && bv.bloom == VFX_BEAMS_BLOOM_ON && bv.bloom_levels == 3 && bv.bloom_strength == 0.6f);
    assert_true(bv.far_distance == 0); /* the camera's far plane: known only per frame */
    vfx_volume_view vv = {.type = VFX_TYPE_VOLUME_VIEW};
    assert_int_equal(api.resolve_defaults(NULL, &vv), VFX_OK);
    assert_true(vv.ert_threshold == 0.9f && vv.tiles == 20 && vv.update_c == 100 && vv.workers >= 1);
    assert_true(vv.model[0] == 1 && vv.model[5] == 1 && vv.model[15] == 1 && vv.model[1] == 0);
    /* a frame view: the eye from the view matrix, near/far from a perspective projection
     * (n 0.1, f 50: proj[10] = -(f+n)/(f-n), proj[14] = -2fn/(f-n)) */
    const float n = 0.1f, f = 50.f;
    vfx_frame_view fv = {.type = VFX_TYPE_FRAME_VIEW,
                         .view = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -1, -2, -4, 1},
                         .proj = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -(f + n) / (f - n), -1, 0, 0, -2 * f * n / (f - n), 0}};
    assert_int_equal(api.resolve_defaults(NULL, &fv), VFX_OK);
    assert_true(fabsf(fv.eye[0] - 1) < 1e-6f && fabsf(fv.eye[1] - 2) < 1e-6f && fabsf(fv.eye[2] - 4) < 1e-6f);
    assert_true(fabsf(fv.near_plane - n) < 1e-5f && fabsf(fv.far_plane - f) < 1e-2f);
    vfx_stats st = {.type = VFX_TYPE_STATS};
    assert_int_equal(api.resolve_defaults(NULL, &st), VFX_ERR_INVALID_ARGUMENT);
    assert_int_equal(api.resolve_defaults(NULL, NULL), VFX_ERR_INVALID_ARGUMENT);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s DOCS/scene-format.md [--print]\n", argv[0]);
        return 2;
    }
    g_doc = argv[1];
    if (argc > 2 && strcmp(argv[2], "--print") == 0) {
        static char t[1 << 14];
        table_text(t, sizeof t);
        fputs(t, stdout);
        return 0;
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_docs_table),
        cmocka_unit_test(test_every_row),
        cmocka_unit_test(test_water_abi_values),
        cmocka_unit_test(test_beam_abi_values),
        cmocka_unit_test(test_resolve_defaults),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
