/* param_ranges.c — see param_ranges.h. */
#include "param_ranges.h"

#include <math.h>
#include <stdio.h>

static const volfx_range ROWS[VFX_RANGE_COUNT] = {
#define ROW_(id, field, key, lo, hi, flags, note) [VFX_RANGE_##id] = {field, key, lo, hi, flags, note},
    VFX_RANGE_TABLE(ROW_)
#undef ROW_
};

const volfx_range *volfx_range_row(vfx_range_id id)
{
    return &ROWS[id];
}

char *volfx_range_text(const volfx_range *r, char *out, size_t n)
{
    if (r->flags & VFX_RANGE_ANY)
        snprintf(out, n, "any");
    else if (r->flags & VFX_RANGE_MASK)
        snprintf(out, n, "bits of 0x%llx", (unsigned long long)r->hi);
    else if (r->flags & VFX_RANGE_INT)
        snprintf(out, n, "%.9g..%.9g%s", r->lo, r->hi, r->flags & VFX_RANGE_ZERO ? " or 0" : "");
    else
        snprintf(out, n, "%c%.9g, %.9g]%s", r->flags & VFX_RANGE_LO_OPEN ? '(' : '[', r->lo, r->hi,
                 r->flags & VFX_RANGE_ZERO ? " or 0" : "");
    return out;
}

static int fits(const volfx_range *r, double v)
{
    if (r->flags & VFX_RANGE_ANY)
        return 1;
    if (r->flags & VFX_RANGE_MASK)
        return v >= 0 && v <= 4294967295.0 && ((uint32_t)v & ~(uint32_t)r->hi) == 0;
    if (v == 0 && (r->flags & VFX_RANGE_ZERO))
        return 1;
    if ((r->flags & VFX_RANGE_LO_OPEN ? v > r->lo : v >= r->lo) && v <= r->hi) /* NaN fails */
        return 1;
    /* a float field at an end that is no float32 (1e-6, 0.95) holds the float nearest it, which
     * may lie just outside the double: the ends as float32 decide then */
    volatile float lo = (float)r->lo, hi = (float)r->hi;
    return !(r->flags & VFX_RANGE_INT) && isfinite(v) && (r->flags & VFX_RANGE_LO_OPEN ? v > lo : v >= lo) && v <= hi;
}

static vfx_result refuse(vfx_context *ctx, const char *what, const volfx_range *r, const char *index, double v)
{
    char t[96], val[40];
    if (r->flags & VFX_RANGE_MASK)
        snprintf(val, sizeof val, "0x%x", (unsigned)v);
    else
        snprintf(val, sizeof val, r->flags & VFX_RANGE_INT ? "%.0f" : "%g", v); /* integers in full */
    return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_PARAM_RANGE, "%s: %s%s %s outside %s%s%s%s", what, r->field, index, val,
                      volfx_range_text(r, t, sizeof t), r->note[0] ? " (" : "", r->note, r->note[0] ? ")" : "");
}

vfx_result volfx_range_check(vfx_context *ctx, const char *what, vfx_range_id id, double v)
{
    return volfx_range_check_row(ctx, what, &ROWS[id], v);
}

vfx_result volfx_range_check_row(vfx_context *ctx, const char *what, const volfx_range *r, double v)
{
    return fits(r, v) ? VFX_OK : refuse(ctx, what, r, "", v);
}

vfx_result volfx_range_check_vec(vfx_context *ctx, const char *what, vfx_range_id id, const float *v, int n)
{
    const volfx_range *r = &ROWS[id];
    int zero = 1;
    for (int k = 0; k < n; ++k)
        zero = zero && v[k] == 0;
    if (zero && (r->flags & VFX_RANGE_ZERO))
        return VFX_OK;
    /* a single 0 component is a colour, not the default: checked against the bounds alone */
    volfx_range strict = *r;
    strict.flags &= ~VFX_RANGE_ZERO;
    for (int k = 0; k < n; ++k)
        if (!fits(&strict, v[k])) {
            char idx[16];
            snprintf(idx, sizeof idx, "[%d]", k);
            return refuse(ctx, what, r, idx, v[k]);
        }
    return VFX_OK;
}

vfx_result volfx_water_params_check_ranges(vfx_context *ctx, const vfx_water_params *p)
{
    const char *w = "water";
    vfx_result r;
    if ((r = volfx_range_check(ctx, w, VFX_RANGE_WATER_H, p->h))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_THRESHOLD, p->threshold))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_MAX_SAMPLES, p->max_samples))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_STEP, p->step))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_REFINE_ITERS, p->refine_iters))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_PYRAMID_LEVEL, p->pyramid_level))
        || (r = volfx_range_check_vec(ctx, w, VFX_RANGE_WATER_COLOR, p->color, 3))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_ABSORPTION, p->absorption))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_IOR, p->ior)))
        return r;
    const vfx_water_params *k = p;
    if ((r = volfx_range_check(ctx, w, VFX_RANGE_WATER_ANISO_RADIUS, k->aniso_radius))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_ANISO_MAX_STRETCH, k->aniso_max_stretch))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_ANISO_MIN_NEIGHBOURS, k->aniso_min_neighbours))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_ANISO_SCALE, k->aniso_scale))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_ANISO_SMOOTHING, k->aniso_smoothing)))
        return r;
    if ((r = volfx_range_check(ctx, w, VFX_RANGE_WATER_METHOD, p->method))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_PRESET, p->preset))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_KERNEL, p->kernel))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_FEATURES_OFF, p->features_off)))
        return r;
    return volfx_water_diffuse_check_ranges(ctx, p);
}

/* Component k of a vector field against row id (0 fits where the row allows it). */
static vfx_result check_at(vfx_context *ctx, const char *what, vfx_range_id id, double v, int k)
{
    if (fits(&ROWS[id], v))
        return VFX_OK;
    char idx[16];
    snprintf(idx, sizeof idx, "[%d]", k);
    return refuse(ctx, what, &ROWS[id], idx, v);
}

/* Each end of a potential's clamp range alone: 0 is that end's default. */
static vfx_result check_pair(vfx_context *ctx, vfx_range_id id, const float v[2])
{
    vfx_result r;
    for (int e = 0; e < 2; ++e)
        if ((r = check_at(ctx, "water", id, v[e], e)))
            return r;
    return VFX_OK;
}

vfx_result volfx_water_diffuse_check_ranges(vfx_context *ctx, const vfx_water_params *p)
{
    const char *w = "water";
    vfx_result r;
    if ((r = volfx_range_check(ctx, w, VFX_RANGE_WATER_DIFFUSE_MAX, p->diffuse_max))
        || (r = volfx_range_check_vec(ctx, w, VFX_RANGE_WATER_GRAVITY, p->gravity, 3))
        || (r = check_pair(ctx, VFX_RANGE_WATER_TRAPPED_AIR, p->trapped_air))
        || (r = check_pair(ctx, VFX_RANGE_WATER_WAVE_CREST, p->wave_crest))
        || (r = check_pair(ctx, VFX_RANGE_WATER_ENERGY, p->energy)))
        return r;
    if ((r = volfx_range_check(ctx, w, VFX_RANGE_WATER_RATE_TRAPPED_AIR, p->rate_trapped_air))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_RATE_WAVE_CREST, p->rate_wave_crest))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_LIFETIME, p->lifetime))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_BUOYANCY, p->buoyancy))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_DRAG, p->drag))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_SPRAY_BELOW, p->spray_below))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_BUBBLE_ABOVE, p->bubble_above)))
        return r;
    return VFX_OK;
}

vfx_result volfx_water_foam_check_ranges(vfx_context *ctx, const vfx_water_foam *f)
{
    const char *w = "water";
    vfx_result r;
    if ((r = volfx_range_check(ctx, w, VFX_RANGE_WATER_FOAM_LAYER, f->layer))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_FOAM_IMPACTS, f->impacts))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_FOAM_LIFETIME, f->lifetime))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_FOAM_CELL, f->cell))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_FOAM_DIFFUSION, f->diffusion))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_FOAM_DEPOSIT, f->deposit))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_FOAM_IMPACT_RATE, f->impact_rate))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_WATER_FOAM_IMPACT_SPEED, f->impact_speed)))
        return r;
    return VFX_OK;
}

vfx_result volfx_beam_check_ranges(vfx_context *ctx, uint32_t i, const vfx_beam *b)
{
    char w[32];
    snprintf(w, sizeof w, "beams[%u]", i);
    vfx_result r;
    if ((r = volfx_range_check_vec(ctx, w, VFX_RANGE_BEAM_HEAD, b->head, 3))
        || (r = volfx_range_check_vec(ctx, w, VFX_RANGE_BEAM_DIR, b->dir, 3))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_FALLOFF, b->falloff))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_RAMP, b->ramp))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_FLOW_KIND, b->flow_kind))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_JOINT_COUNT, b->joint_count)))
        return r;
    if ((r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_LENGTH, b->length))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_RADIUS, b->radius))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_A, b->a))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_B, b->b))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_EPS, b->eps))
        || (r = volfx_range_check_vec(ctx, w, VFX_RANGE_BEAM_COLOR, b->color, 4)))
        return r;
    const vfx_beam *b2 = b;
    if ((r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_INTENSITY, b2->intensity))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_EXPOSURE, b2->exposure))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_FLOW_AMOUNT, b2->flow_amount))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_FLOW_SPEED, b2->flow_speed))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_FLOW_SCALE, b2->flow_scale)))
        return r;
    /* the anatomy's fields: a surge_wavelength of 1e-40 made the body's profile NaN and an
     * orb_strength of 3e38 Inf, and the beam vanished (they were checked for being finite only) */
    if ((r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_FLOW_TWIST, b->flow_twist))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_HEAD_RADIUS, b->head_radius))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_ORB_RADIUS, b->orb_radius))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_ORB_STRENGTH, b->orb_strength))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_ORB_PULSE, b->orb_pulse))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_ORB_PULSE_HZ, b->orb_pulse_hz))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_TAPER, b->taper))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_SURGE_AMOUNT, b->surge_amount))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_SURGE_WAVELENGTH, b->surge_wavelength))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_SURGE_SPEED, b->surge_speed))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_BEAM_CORE, b->core)))
        return r;
    return VFX_OK;
}

vfx_result volfx_beams_view_check_ranges(vfx_context *ctx, const vfx_beams_view *v)
{
    vfx_result r;
    if ((r = volfx_range_check(ctx, "beams", VFX_RANGE_BEAMS_COUNT, v->count))
        || (r = volfx_range_check(ctx, "beams", VFX_RANGE_BEAMS_SATURATION, v->saturation))
        || (r = volfx_range_check(ctx, "beams", VFX_RANGE_BEAMS_BLOOM, v->bloom)))
        return r;
    if ((r = volfx_range_check(ctx, "beams", VFX_RANGE_BEAMS_C, v->saturate_c))
        || (r = volfx_range_check(ctx, "beams", VFX_RANGE_BEAMS_FAR, v->far_distance)))
        return r;
    if ((r = volfx_range_check(ctx, "beams", VFX_RANGE_BEAMS_BLOOM_STRENGTH, v->bloom_strength))
        || (r = volfx_range_check(ctx, "beams", VFX_RANGE_BEAMS_BLOOM_LEVELS, v->bloom_levels)))
        return r;
    return VFX_OK;
}

vfx_result volfx_volume_view_check_ranges(vfx_context *ctx, const vfx_volume_view *v)
{
    const char *w = "volume[0]";
    vfx_result r;
    if ((r = volfx_range_check(ctx, w, VFX_RANGE_VOLUME_ERT_THRESHOLD, v->ert_threshold))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_VOLUME_TILES, v->tiles))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_VOLUME_UPDATE_C, v->update_c))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_VOLUME_WORKERS, v->workers)))
        return r;
    if ((r = volfx_range_check(ctx, w, VFX_RANGE_VOLUME_SCALAR_MIN, v->scalar_min))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_VOLUME_SCALAR_MAX, v->scalar_max))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_VOLUME_TRANSFER_COUNT, v->transfer_count))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_VOLUME_TRANSFER_METHOD, v->transfer_method))
        || (r = volfx_range_check_vec(ctx, w, VFX_RANGE_VOLUME_MODEL, v->model, 16)))
        return r;
    return VFX_OK;
}

vfx_result volfx_frame_view_check_ranges(vfx_context *ctx, const vfx_frame_view *v)
{
    const char *w = "render";
    vfx_result r;
    if ((r = volfx_range_check(ctx, w, VFX_RANGE_FRAME_WIDTH, v->width))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_FRAME_HEIGHT, v->height))
        || (r = volfx_range_check_vec(ctx, w, VFX_RANGE_FRAME_VIEW_MATRIX, v->view, 16))
        || (r = volfx_range_check_vec(ctx, w, VFX_RANGE_FRAME_PROJ, v->proj, 16))
        || (r = volfx_range_check_vec(ctx, w, VFX_RANGE_FRAME_EYE, v->eye, 3)))
        return r;
    if ((r = volfx_range_check(ctx, w, VFX_RANGE_FRAME_NEAR, v->near_plane))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_FRAME_FAR, v->far_plane))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_FRAME_FOV_Y, v->fov_y))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_FRAME_EFFECTS, v->effects))
        || (r = volfx_range_check(ctx, w, VFX_RANGE_FRAME_COLOR_HDR, v->color_hdr)))
        return r;
    for (int k = 0; k < 3; ++k) /* double: checked as it is, not through a float */
        if ((r = check_at(ctx, w, VFX_RANGE_FRAME_ORIGIN, v->origin[k], k)))
            return r;
    return VFX_OK;
}

vfx_result volfx_frame_depth_check_ranges(vfx_context *ctx, const vfx_frame_depth *d)
{
    return volfx_range_check(ctx, "render", VFX_RANGE_FRAME_DEPTH_CONVENTION, (double)d->depth_convention);
}
