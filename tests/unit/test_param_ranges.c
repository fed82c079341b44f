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
#include "lab/lab_beams.h"
#include "lab/lab_ranges.h"
#include "lab/volfx_lab.h"
#include "water/water_params.h"
#include <float.h>

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
    static char doc[1 << 18], want[1 << 16];
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

/* Row i of the two tables: the ABI's (volfx_ranges.h), then the lab's (plugin/lab/lab_ranges.h,
 * whose rows the lab checks its structs against). */
#define ROW_COUNT (VFX_RANGE_COUNT + VOLFX_LAB_RANGE_COUNT)
static const volfx_range *row_at(int i)
{
    return i < VFX_RANGE_COUNT ? volfx_range_row((vfx_range_id)i)
                               : volfx_lab_range_row((volfx_lab_range_id)(i - VFX_RANGE_COUNT));
}

static vfx_result check_at(vfx_context *c, int i, double v)
{
    return i < VFX_RANGE_COUNT ? volfx_range_check(c, "t", (vfx_range_id)i, v)
                               : volfx_lab_range_check(c, "t", (volfx_lab_range_id)(i - VFX_RANGE_COUNT), v);
}

static void test_every_row(void **state)
{
    (void)state;
    vfx_context *c = fake_ctx();
    for (int i = 0; i < ROW_COUNT; ++i) {
        const volfx_range *r = row_at(i);
        const char *fld = strchr(r->field, '.') + 1;
        if (r->flags & (VFX_RANGE_ANY | VFX_RANGE_MASK))
            continue; /* test_struct_walk: every value fits / bits */
        double lo_in = r->flags & VFX_RANGE_LO_OPEN ? (r->lo == 0 ? 1e-6 : r->lo * 1.0001) : r->lo;
        expect(c, check_at(c, i, lo_in), VFX_OK, NULL);
        expect(c, check_at(c, i, r->hi), VFX_OK, NULL);
        double over = r->flags & VFX_RANGE_INT ? r->hi + 1 : r->hi * 1.001 + 1e-6;
        expect(c, check_at(c, i, over), VFX_ERR_INVALID_ARGUMENT, fld);
        if (r->lo != 0 || (r->flags & VFX_RANGE_LO_OPEN) || !(r->flags & VFX_RANGE_INT)) {
            double under = r->flags & VFX_RANGE_LO_OPEN ? r->lo : r->lo - (r->flags & VFX_RANGE_INT ? 1 : fmax(1e-3, fabs(r->lo) * 1e-3));
            if (!(under == 0 && (r->flags & VFX_RANGE_ZERO)) && !(r->flags & VFX_RANGE_INT && under < 0))
                expect(c, check_at(c, i, under), VFX_ERR_INVALID_ARGUMENT, fld);
        }
        expect(c, check_at(c, i, NAN), VFX_ERR_INVALID_ARGUMENT, fld);
        expect(c, check_at(c, i, INFINITY), VFX_ERR_INVALID_ARGUMENT, fld);
        expect(c, check_at(c, i, -INFINITY), VFX_ERR_INVALID_ARGUMENT, fld);
        int zero_in = (r->flags & VFX_RANGE_LO_OPEN ? 0 > r->lo : 0 >= r->lo) && 0 <= r->hi;
        expect(c, check_at(c, i, 0),
               (r->flags & VFX_RANGE_ZERO) || zero_in ? VFX_OK : VFX_ERR_INVALID_ARGUMENT, NULL);
    }
    free(c);
}

/* Where each row's field lies: the row's field text must be the struct and member named here
 * (so a row cannot name a field that does not exist), and test_struct_walk sets the member in a
 * valid struct and calls the check the effect calls. Every row must be here. */
enum { K_NONE, K_WATER, K_BEAM, K_BEAMS_VIEW, K_LAB_BEAMS, K_VOLUME, K_FRAME, K_FRAME_DEPTH, K_WATER_FOAM, K_OTHER };
enum { T_F32 = 1, T_U32, T_F64, T_U64 };
typedef struct fmap {
    int kind;
    const char *name;
    size_t off;
    int type, n;
} fmap;
#define TYPE_OF_(x) _Generic((x), float: T_F32, uint32_t: T_U32, double: T_F64, uint64_t: T_U64)
#define M_(id, k, s, m) [VFX_RANGE_##id] = {k, #s "." #m, offsetof(s, m), TYPE_OF_(((s *)0)->m), \
                                            (int)(sizeof(((s *)0)->m) / 4 / (TYPE_OF_(((s *)0)->m) >= T_F64 ? 2 : 1))},
#define MA_(id, k, s, m) [VFX_RANGE_##id] = {k, #s "." #m, offsetof(s, m), TYPE_OF_(((s *)0)->m[0]), \
                                            (int)(sizeof(((s *)0)->m) / sizeof(((s *)0)->m[0]))},
#define LM_(id, k, s, m) [VFX_RANGE_COUNT + VOLFX_LAB_RANGE_##id] = {k, #s "." #m, offsetof(s, m), TYPE_OF_(((s *)0)->m), 1},
static const fmap MAP[ROW_COUNT] = {
    M_(WATER_H, K_WATER, vfx_water_params, h) M_(WATER_THRESHOLD, K_WATER, vfx_water_params, threshold)
    M_(WATER_MAX_SAMPLES, K_WATER, vfx_water_params, max_samples) M_(WATER_STEP, K_WATER, vfx_water_params, step)
    M_(WATER_REFINE_ITERS, K_WATER, vfx_water_params, refine_iters)
    M_(WATER_PYRAMID_LEVEL, K_WATER, vfx_water_params, pyramid_level) MA_(WATER_COLOR, K_WATER, vfx_water_params, color)
    M_(WATER_ABSORPTION, K_WATER, vfx_water_params, absorption) M_(WATER_IOR, K_WATER, vfx_water_params, ior)
    M_(WATER_ANISO_RADIUS, K_WATER, vfx_water_params, aniso_radius)
    M_(WATER_ANISO_MAX_STRETCH, K_WATER, vfx_water_params, aniso_max_stretch)
    M_(WATER_ANISO_MIN_NEIGHBOURS, K_WATER, vfx_water_params, aniso_min_neighbours)
    M_(WATER_ANISO_SCALE, K_WATER, vfx_water_params, aniso_scale)
    M_(WATER_ANISO_SMOOTHING, K_WATER, vfx_water_params, aniso_smoothing)
    M_(WATER_METHOD, K_WATER, vfx_water_params, method) M_(WATER_PRESET, K_WATER, vfx_water_params, preset)
    M_(WATER_KERNEL, K_WATER, vfx_water_params, kernel) M_(WATER_FEATURES_OFF, K_WATER, vfx_water_params, features_off)
    M_(WATER_DIFFUSE_MAX, K_WATER, vfx_water_params, diffuse_max) MA_(WATER_GRAVITY, K_WATER, vfx_water_params, gravity)
    MA_(WATER_TRAPPED_AIR, K_WATER, vfx_water_params, trapped_air)
    MA_(WATER_WAVE_CREST, K_WATER, vfx_water_params, wave_crest) MA_(WATER_ENERGY, K_WATER, vfx_water_params, energy)
    M_(WATER_RATE_TRAPPED_AIR, K_WATER, vfx_water_params, rate_trapped_air)
    M_(WATER_RATE_WAVE_CREST, K_WATER, vfx_water_params, rate_wave_crest)
    M_(WATER_LIFETIME, K_WATER, vfx_water_params, lifetime) M_(WATER_BUOYANCY, K_WATER, vfx_water_params, buoyancy)
    M_(WATER_DRAG, K_WATER, vfx_water_params, drag) M_(WATER_SPRAY_BELOW, K_WATER, vfx_water_params, spray_below)
    M_(WATER_BUBBLE_ABOVE, K_WATER, vfx_water_params, bubble_above)
    M_(PARTICLE_COUNT, K_OTHER, vfx_particle_view, count) M_(PARTICLE_REVISION, K_OTHER, vfx_particle_view, revision)
    M_(GPU_COLUMN_BUFFER, K_OTHER, vfx_gpu_column, buffer) M_(GPU_COLUMN_STRIDE, K_OTHER, vfx_gpu_column, stride)
    M_(GPU_COLUMN_OFFSET, K_OTHER, vfx_gpu_column, offset)
    MA_(BEAM_HEAD, K_BEAM, vfx_beam, head) MA_(BEAM_DIR, K_BEAM, vfx_beam, dir)
    M_(BEAM_LENGTH, K_BEAM, vfx_beam, length) M_(BEAM_RADIUS, K_BEAM, vfx_beam, radius) M_(BEAM_A, K_BEAM, vfx_beam, a)
    M_(BEAM_B, K_BEAM, vfx_beam, b) M_(BEAM_EPS, K_BEAM, vfx_beam, eps) MA_(BEAM_COLOR, K_BEAM, vfx_beam, color)
    M_(BEAM_INTENSITY, K_BEAM, vfx_beam, intensity) M_(BEAM_EXPOSURE, K_BEAM, vfx_beam, exposure)
    M_(BEAM_FLOW_AMOUNT, K_BEAM, vfx_beam, flow_amount) M_(BEAM_FLOW_SPEED, K_BEAM, vfx_beam, flow_speed)
    M_(BEAM_FLOW_SCALE, K_BEAM, vfx_beam, flow_scale) M_(BEAM_FLOW_TWIST, K_BEAM, vfx_beam, flow_twist)
    M_(BEAM_HEAD_RADIUS, K_BEAM, vfx_beam, head_radius) M_(BEAM_ORB_RADIUS, K_BEAM, vfx_beam, orb_radius)
    M_(BEAM_ORB_STRENGTH, K_BEAM, vfx_beam, orb_strength) M_(BEAM_ORB_PULSE, K_BEAM, vfx_beam, orb_pulse)
    M_(BEAM_ORB_PULSE_HZ, K_BEAM, vfx_beam, orb_pulse_hz) M_(BEAM_TAPER, K_BEAM, vfx_beam, taper)
    M_(BEAM_SURGE_AMOUNT, K_BEAM, vfx_beam, surge_amount) M_(BEAM_SURGE_WAVELENGTH, K_BEAM, vfx_beam, surge_wavelength)
    M_(BEAM_SURGE_SPEED, K_BEAM, vfx_beam, surge_speed) M_(BEAM_CORE, K_BEAM, vfx_beam, core)
    M_(BEAM_FALLOFF, K_BEAM, vfx_beam, falloff) M_(BEAM_RAMP, K_BEAM, vfx_beam, ramp)
    M_(BEAM_FLOW_KIND, K_BEAM, vfx_beam, flow_kind) M_(BEAM_JOINT_FIRST, K_BEAM, vfx_beam, joint_first)
    M_(BEAM_JOINT_COUNT, K_BEAM, vfx_beam, joint_count)
    M_(BEAMS_COUNT, K_BEAMS_VIEW, vfx_beams_view, count) M_(BEAMS_SATURATION, K_BEAMS_VIEW, vfx_beams_view, saturation)
    M_(BEAMS_BLOOM, K_BEAMS_VIEW, vfx_beams_view, bloom) M_(BEAMS_JOINT_COUNT, K_BEAMS_VIEW, vfx_beams_view, joint_count)
    M_(BEAMS_C, K_BEAMS_VIEW, vfx_beams_view, saturate_c) M_(BEAMS_FAR, K_BEAMS_VIEW, vfx_beams_view, far_distance)
    M_(BEAMS_BLOOM_STRENGTH, K_BEAMS_VIEW, vfx_beams_view, bloom_strength)
    M_(BEAMS_BLOOM_LEVELS, K_BEAMS_VIEW, vfx_beams_view, bloom_levels)
    M_(VOLUME_POINT_COUNT, K_VOLUME, vfx_volume_view, point_count) M_(VOLUME_TET_COUNT, K_VOLUME, vfx_volume_view, tet_count)
    M_(VOLUME_SCALAR_MIN, K_VOLUME, vfx_volume_view, scalar_min) M_(VOLUME_SCALAR_MAX, K_VOLUME, vfx_volume_view, scalar_max)
    M_(VOLUME_TRANSFER_COUNT, K_VOLUME, vfx_volume_view, transfer_count)
    M_(VOLUME_TRANSFER_METHOD, K_VOLUME, vfx_volume_view, transfer_method)
    MA_(VOLUME_MODEL, K_VOLUME, vfx_volume_view, model) M_(VOLUME_REVISION, K_VOLUME, vfx_volume_view, revision)
    M_(VOLUME_ERT_THRESHOLD, K_VOLUME, vfx_volume_view, ert_threshold) M_(VOLUME_TILES, K_VOLUME, vfx_volume_view, tiles)
    M_(VOLUME_UPDATE_C, K_VOLUME, vfx_volume_view, update_c) M_(VOLUME_WORKERS, K_VOLUME, vfx_volume_view, workers)
    M_(FRAME_FRAMEBUFFER, K_FRAME, vfx_frame_view, framebuffer) M_(FRAME_COLOR_TEXTURE, K_FRAME, vfx_frame_view, color_texture)
    M_(FRAME_DEPTH_TEXTURE, K_FRAME, vfx_frame_view, depth_texture) M_(FRAME_WIDTH, K_FRAME, vfx_frame_view, width)
    M_(FRAME_HEIGHT, K_FRAME, vfx_frame_view, height) MA_(FRAME_VIEW_MATRIX, K_FRAME, vfx_frame_view, view)
    MA_(FRAME_PROJ, K_FRAME, vfx_frame_view, proj) MA_(FRAME_EYE, K_FRAME, vfx_frame_view, eye)
    M_(FRAME_NEAR, K_FRAME, vfx_frame_view, near_plane) M_(FRAME_FAR, K_FRAME, vfx_frame_view, far_plane)
    M_(FRAME_FOV_Y, K_FRAME, vfx_frame_view, fov_y) M_(FRAME_EFFECTS, K_FRAME, vfx_frame_view, effects)
    MA_(FRAME_ORIGIN, K_FRAME, vfx_frame_view, origin) M_(FRAME_COLOR_HDR, K_FRAME, vfx_frame_view, color_hdr)
    M_(FRAME_ENVIRONMENT_CUBEMAP, K_FRAME, vfx_frame_view, environment_cubemap)
    M_(FRAME_VIEW_ID, K_FRAME, vfx_frame_view, view_id) M_(FRAME_LAYER_TEXTURE, K_FRAME, vfx_frame_view, layer_texture)
    M_(FRAME_DEPTH_RENDERBUFFER, K_FRAME_DEPTH, vfx_frame_depth, depth_renderbuffer)
    M_(FRAME_DEPTH_FRAMEBUFFER, K_FRAME_DEPTH, vfx_frame_depth, depth_framebuffer)
    M_(FRAME_DEPTH_FLIP_Y, K_FRAME_DEPTH, vfx_frame_depth, flip_y)
    M_(FRAME_DEPTH_CONVENTION, K_FRAME_DEPTH, vfx_frame_depth, depth_convention)
    M_(GL_STATE_SKIP_RESTORE, K_OTHER, vfx_gl_state_desc, skip_restore)
    M_(LIGHTS_CAPACITY, K_OTHER, vfx_lights, capacity)
    M_(IMPACT_EVENTS_CAPACITY, K_OTHER, vfx_impact_events, capacity)
    M_(WATER_FOAM_LAYER, K_WATER_FOAM, vfx_water_foam, layer) M_(WATER_FOAM_IMPACTS, K_WATER_FOAM, vfx_water_foam, impacts)
    M_(WATER_FOAM_LIFETIME, K_WATER_FOAM, vfx_water_foam, lifetime) M_(WATER_FOAM_CELL, K_WATER_FOAM, vfx_water_foam, cell)
    M_(WATER_FOAM_DIFFUSION, K_WATER_FOAM, vfx_water_foam, diffusion)
    M_(WATER_FOAM_DEPOSIT, K_WATER_FOAM, vfx_water_foam, deposit)
    M_(WATER_FOAM_IMPACT_RATE, K_WATER_FOAM, vfx_water_foam, impact_rate)
    M_(WATER_FOAM_IMPACT_SPEED, K_WATER_FOAM, vfx_water_foam, impact_speed)
    LM_(BEAMS_MARCH_SAMPLES, K_LAB_BEAMS, vfx_lab_beams, march_samples)
};

/* One valid struct of each kind, a member set, and the check the plugin runs on it. */
typedef union any_struct {
    vfx_water_params w;
    vfx_beam b;
    vfx_beams_view bv;
    vfx_lab_beams lb;
    vfx_volume_view vv;
    vfx_frame_view fv;
    vfx_frame_depth fd;
    vfx_water_foam wf;
} any_struct;

static void baseline(int kind, any_struct *u)
{
    memset(u, 0, sizeof *u);
    switch (kind) {
    case K_WATER:
        u->w = (vfx_water_params){.type = VFX_TYPE_WATER_PARAMS, .color = {0.5f, 0.5f, 0.5f},
                                  .gravity = {0, -9.81f, 0}, .spray_below = 1, .bubble_above = 10000};
        break;
    case K_BEAM:
        u->b = (vfx_beam){.type = VFX_TYPE_BEAM, .head = {1, 1, 1}, .dir = {1, 0, 0}, .length = 1, .radius = 0.5f,
                          .a = 0.05f, .b = 0.03f, .eps = 0.02f, .color = {1, 1, 1, 1}};
        break;
    case K_FRAME:
        u->fv = (vfx_frame_view){.type = VFX_TYPE_FRAME_VIEW, .width = 64, .height = 64, .fov_y = 1,
                                 .view = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1},
                                 .proj = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, -1, 0, 0, -0.2f, 0}};
        break;
    case K_WATER_FOAM:
        u->wf.type = VFX_TYPE_WATER_FOAM;
        break;
    case K_LAB_BEAMS:
        u->lb = (vfx_lab_beams){.type = VFX_TYPE_LAB_BEAMS, .method = VFX_BEAMS_METHOD_MARCH};
        break;
    case K_VOLUME:
        for (int k = 0; k < 16; ++k)
            u->vv.model[k] = k % 5 == 0 ? 1.f : 0.f;
        u->vv.type = VFX_TYPE_VOLUME_VIEW;
        break;
    default:
        u->bv.type = VFX_TYPE_BEAMS_VIEW;
        break;
    }
}

static vfx_result run_check(vfx_context *c, int kind, any_struct *u)
{
    volfx_water_resolved out;
    switch (kind) {
    case K_WATER: return volfx_water_params_resolve(c, &u->w, &out);
    case K_BEAM: return volfx_beam_check_ranges(c, 0, &u->b);
    case K_BEAMS_VIEW: return volfx_beams_view_check_ranges(c, &u->bv);
    case K_LAB_BEAMS: {
        uint32_t method; /* what the beams hand a chained vfx_lab_beams to */
        return volfx_lab_beams_struct(c, &u->lb, &method);
    }
    case K_VOLUME: return volfx_volume_view_check_ranges(c, &u->vv);
    case K_FRAME: return volfx_frame_view_check_ranges(c, &u->fv);
    case K_FRAME_DEPTH: return volfx_frame_depth_check_ranges(c, &u->fd);
    case K_WATER_FOAM: return volfx_water_foam_check_ranges(c, &u->wf);
    }
    return VFX_OK;
}

static void set_member(any_struct *u, const fmap *m, int comp, double v)
{
    char *at = (char *)u + m->off;
    switch (m->type) {
    case T_F32: ((float *)at)[comp] = (float)v; break;
    case T_U32: ((uint32_t *)at)[comp] = (uint32_t)v; break;
    case T_F64: ((double *)at)[comp] = v; break;
    default: ((uint64_t *)at)[comp] = (uint64_t)v; break;
    }
}

/* The next value of the member's type past x towards `to` (the member holds it exactly). */
static double next_of(const fmap *m, double x, double to)
{
    if (m->type == T_F32)
        return nextafterf((float)x, (float)to);
    if (m->type == T_F64)
        return nextafter(x, to);
    return to > x ? x + 1 : x - 1;
}

/* Every row, through the struct: each end set in a valid struct is accepted by the check the
 * effect calls, and the member's next value outside each end refused naming the field (the
 * lower end on the first component, the upper on the last: a clamp pair's min and max). A row
 * whose field the plugin never checks, or checks against another row, fails here. */
static void test_struct_walk(void **state)
{
    (void)state;
    vfx_context *c = fake_ctx();
    int walked = 0;
    for (int i = 0; i < ROW_COUNT; ++i) {
        const volfx_range *r = row_at(i);
        const fmap *m = &MAP[i];
        if (m->kind == K_NONE)
            fail_msg("row %s has no entry in this test's MAP", r->field);
        if (strcmp(m->name, r->field) != 0)
            fail_msg("row %d names %s, but its member is %s", i, r->field, m->name);
        if ((r->flags & VFX_RANGE_ANY) || m->kind == K_OTHER)
            continue;
        assert_true(m->kind != K_OTHER); /* a checked row must name a checked struct */
        any_struct u;
        double ins[2], outs[2];
        int nin = 0, nout = 0;
        if (r->flags & VFX_RANGE_MASK) {
            ins[nin++] = r->hi;
            uint32_t bit = 1;
            while (bit & (uint32_t)r->hi)
                bit <<= 1;
            outs[nout++] = bit;
        } else {
            ins[nin++] = r->flags & VFX_RANGE_LO_OPEN ? next_of(m, r->lo, INFINITY) : r->lo;
            ins[nin++] = r->hi;
            double under = r->flags & VFX_RANGE_LO_OPEN ? r->lo : next_of(m, r->lo, -INFINITY);
            if (!(under == 0 && (r->flags & VFX_RANGE_ZERO)) && !(m->type == T_U32 && under < 0))
                outs[nout++] = under;
            if (!(m->type == T_U32 && r->hi >= 4294967295.0))
                outs[nout++] = next_of(m, r->hi, INFINITY);
        }
        for (int k = 0; k < nin; ++k) {
            baseline(m->kind, &u);
            set_member(&u, m, k == 0 ? 0 : m->n - 1, ins[k]);
            vfx_result res = run_check(c, m->kind, &u);
            if (res != VFX_OK)
                fail_msg("%s = %.9g (an end of its row) refused: %s", r->field, ins[k], c->last_error);
        }
        for (int k = 0; k < nout; ++k) {
            baseline(m->kind, &u);
            int comp = (r->flags & VFX_RANGE_MASK) || outs[k] < r->lo ? 0 : m->n - 1;
            set_member(&u, m, comp, outs[k]);
            vfx_result res = run_check(c, m->kind, &u);
            if (res != VFX_ERR_INVALID_ARGUMENT || !strstr(c->last_error, r->field))
                fail_msg("%s = %.9g (just outside its row) gave %d \"%s\"", r->field, outs[k], res,
                         res ? c->last_error : "");
            assert_int_equal(c->last_error_id, VFX_LOG_ID_PARAM_RANGE);
        }
        ++walked;
    }
    assert_true(walked >= 80); /* the walk cannot silently shrink */
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
    expect(c, volfx_beams_view_check_ranges(c, &v), VFX_ERR_INVALID_ARGUMENT, "vfx_beams_view.saturate_c -1");
    vfx_lab_beams lb = {.type = VFX_TYPE_LAB_BEAMS, .method = VFX_BEAMS_METHOD_MARCH, .march_samples = 5000};
    uint32_t method = 0;
    expect(c, volfx_lab_beams_struct(c, &lb, &method), VFX_ERR_INVALID_ARGUMENT, "vfx_lab_beams.march_samples 5000");
    lb.march_samples = 0;
    expect(c, volfx_lab_beams_struct(c, &lb, &method), VFX_OK, NULL);
    assert_int_equal(method, 32); /* the baseline's default samples */
    lb.method = 2;
    expect(c, volfx_lab_beams_struct(c, &lb, &method), VFX_ERR_INVALID_ARGUMENT, "vfx_lab_beams.method 2 unknown");
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
        static char t[1 << 16];
        table_text(t, sizeof t);
        fputs(t, stdout);
        return 0;
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_docs_table),
        cmocka_unit_test(test_every_row),
        cmocka_unit_test(test_struct_walk),
        cmocka_unit_test(test_water_abi_values),
        cmocka_unit_test(test_beam_abi_values),
        cmocka_unit_test(test_resolve_defaults),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
