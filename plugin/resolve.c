/* resolve.c — see resolve.h. Each struct's zero fields are resolved by the code the effects run
 * (water_params.c, water_aniso.c, water_diffuse.c, frame_check.c; the volume's by the renderer's
 * tet_options_default) or, where an effect applies a constant inline, by the same constant named
 * here once (beams_effect.c). */
#include "resolve.h"

#include <float.h>
#include <math.h>
#include <string.h>
#include <unistd.h>

#include "frame_check.h"
#if VFX_WITH_WATER
#include "water/water_internal.h"
#include "water/water_params.h"
#endif
#if VFX_WITH_TETVOL
#include "tet_render.h"
#endif

#define SET0(field, value) do { if ((field) == 0) (field) = (value); } while (0)

#if VFX_WITH_WATER
/* h from the context's last update (the water's resolved h), 0 when there is none. */
static float last_h(const vfx_context *ctx)
{
    const water_state *s = ctx ? ctx->effect_state[VFX_EFFECT_WATER] : NULL;
    return s && s->params.h > 0 ? s->params.h : 0.0f;
}

static vfx_result resolve_water(vfx_context *ctx, vfx_water_params *p)
{
    volfx_water_resolved res;
    volfx_water_diffuse_params dp;
    vfx_result r = volfx_water_params_resolve(ctx, p, &res);
    if (r == VFX_OK && res.p.h == 0 && last_h(ctx) > 0)
        r = volfx_water_params_set_h(ctx, &res, last_h(ctx));
    if (r == VFX_OK)
        r = volfx_water_diffuse_params_check(ctx, p, &dp);
    if (r)
        return r;
    SET0(p->h, res.p.h);
    SET0(p->threshold, res.p.threshold);
    SET0(p->max_samples, res.p.max_samples);
    SET0(p->step, res.p.step);
    SET0(p->refine_iters, res.p.refine_iters);
    SET0(p->pyramid_level, res.p.pyramid_level);
    if (p->method == VFX_WATER_METHOD_DEFAULT)
        p->method = res.p.method <= VFX_WATER_METHOD_PAPER && res.p.method >= VFX_WATER_METHOD_TILE
                        ? res.p.method : VFX_WATER_METHOD_TILE;
    if (p->color[0] == 0 && p->color[1] == 0 && p->color[2] == 0)
        memcpy(p->color, res.p.color, sizeof p->color);
    SET0(p->absorption, res.p.absorption);
    SET0(p->ior, res.p.ior);
    SET0(p->preset, res.preset);
    SET0(p->kernel, res.kp.kernel);
    SET0(p->aniso_radius, res.kp.radius);
    SET0(p->aniso_max_stretch, res.kp.max_stretch);
    SET0(p->aniso_min_neighbours, res.kp.min_neighbours);
    SET0(p->aniso_scale, res.kp.scale);
    SET0(p->aniso_smoothing, res.kp.smoothing);
    SET0(p->diffuse_max, dp.max);
    if (p->gravity[0] == 0 && p->gravity[1] == 0 && p->gravity[2] == 0)
        memcpy(p->gravity, dp.gravity, sizeof p->gravity);
    for (int e = 0; e < 2; ++e) {
        SET0(p->trapped_air[e], dp.ta[e]);
        SET0(p->wave_crest[e], dp.wc[e]);
        SET0(p->energy[e], dp.ek[e]);
    }
    SET0(p->rate_trapped_air, dp.rate_ta);
    SET0(p->rate_wave_crest, dp.rate_wc);
    SET0(p->lifetime, dp.lifetime);
    SET0(p->buoyancy, dp.buoyancy);
    SET0(p->drag, dp.drag);
    SET0(p->spray_below, dp.spray_below);
    SET0(p->bubble_above, dp.bubble_above);
    return VFX_OK;
}
#endif

/* What beams_effect.c applies to a zero field (its radius-relative ones need the radius). */
static void resolve_beam(vfx_beam *b)
{
    SET0(b->falloff, VFX_BEAM_FALLOFF_SMOOTH);
    SET0(b->ramp, VFX_BEAM_RAMP_HOT);
    SET0(b->intensity, 1.0f);
    if (b->color[0] == 0 && b->color[1] == 0 && b->color[2] == 0)
        b->color[0] = b->color[1] = b->color[2] = b->color[3] = 1.0f;
    SET0(b->flow_twist, 1.0f);
    if (b->radius > 0) {
        SET0(b->flow_scale, 2.0f * b->radius);
        SET0(b->head_radius, b->radius);
        SET0(b->surge_wavelength, 8.0f * b->radius);
    }
    if (b->orb_radius > 0)
        SET0(b->orb_strength, b->a);
}

static void resolve_beams_view(vfx_beams_view *v)
{
    SET0(v->saturate_c, 1.0f);
    SET0(v->bloom, VFX_BEAMS_BLOOM_ON);
    SET0(v->bloom_levels, 5u);
    SET0(v->bloom_strength, 0.6f);
}

static void resolve_volume_view(vfx_volume_view *v)
{
#if VFX_WITH_TETVOL
    /* volume_effect.c leaves a zero field at the renderer's default: ask it */
    tet_options o;
    tet_options_default(&o);
    SET0(v->ert_threshold, o.ert_threshold);
    SET0(v->tiles, (uint32_t)o.tiles_d);
    SET0(v->update_c, (uint32_t)o.update_c);
#else
    SET0(v->ert_threshold, 0.9f); /* tet_options_default's, for a build without the renderer */
    SET0(v->tiles, 20u);
    SET0(v->update_c, 100u);
#endif
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    SET0(v->workers, (uint32_t)(cores > 0 ? (cores < 64 ? cores : 64) : 1));
    bool zero = true;
    for (int i = 0; i < 16; ++i)
        zero = zero && v->model[i] == 0;
    if (zero)
        for (int i = 0; i < 16; ++i)
            v->model[i] = i % 5 == 0 ? 1.0f : 0.0f;
}

/* The frame gate's defaults: eye from the view matrix, near/far from the projection. */
static void resolve_frame_view(vfx_frame_view *v)
{
    float inv[16];
    if (v->eye[0] == 0 && v->eye[1] == 0 && v->eye[2] == 0 && volfx_mat4_invert(v->view, inv))
        memcpy(v->eye, inv + 12, sizeof v->eye);
    double n = 0, f = 0, tol = 0;
    if (v->near_plane == 0 && v->far_plane == 0 && volfx_projection_planes(v->proj, &n, &f, &tol) && n > 0 && f > n) {
        v->near_plane = (float)n;
        v->far_plane = isinf(f) || f > FLT_MAX ? FLT_MAX : (float)f;
    }
}

vfx_result volfx_resolve_defaults(vfx_context *ctx, void *inout)
{
    if (!inout)
        return ctx ? volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_API_ARGUMENT,
                                "resolve_defaults: inout is NULL") : VFX_ERR_INVALID_ARGUMENT;
    vfx_struct_type type = ((const vfx_chain *)inout)->type;
    switch (type) {
    case VFX_TYPE_WATER_PARAMS:
#if VFX_WITH_WATER
        return resolve_water(ctx, inout);
#else
        return ctx ? volfx_fail(ctx, VFX_ERR_UNSUPPORTED, VFX_LOG_ID_EFFECT_NOT_BUILT,
                                "resolve_defaults: the water is not built in") : VFX_ERR_UNSUPPORTED;
#endif
    case VFX_TYPE_BEAM: resolve_beam(inout); return VFX_OK;
    case VFX_TYPE_BEAMS_VIEW: resolve_beams_view(inout); return VFX_OK;
    case VFX_TYPE_VOLUME_VIEW: resolve_volume_view(inout); return VFX_OK;
    case VFX_TYPE_FRAME_VIEW: resolve_frame_view(inout); return VFX_OK;
    case VFX_TYPE_CONTEXT_DESC: /* NULL alloc/free mean the C library's: nothing a value can say */
    case VFX_TYPE_PARTICLE_VIEW: /* no defaulted field */
    case VFX_TYPE_GL_STATE_DESC: /* skip_restore 0 is the save and restore */
    case VFX_TYPE_FRAME_DEPTH: /* zero is the standard depth */
        return VFX_OK;
    default:
        break;
    }
    if (ctx)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_STRUCT_TYPE,
                             "resolve_defaults: a struct of type %u has no defaults to resolve", (unsigned)type);
    return VFX_ERR_INVALID_ARGUMENT;
}
