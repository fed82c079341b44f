/* entry.c — the exported entry point and the context lifecycle. Effects are created the
 * first frame the host's world holds them and destroyed when it no longer does, so an absent
 * effect costs no shader, no buffer and no pass. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gpu/gpu.h"
#include "gpu/scan.h"
#include "effect.h"
#include "context.h"
#include "frame_check.h"
#include "resolve.h"
#if VFX_WITH_BEAMS
#include "beams/beams_impact.h"
#endif

/* --------------------------------------------------------------------- lifecycle */

/* Binds this context's GL table to the calling thread for the call (gpu/gl.h says why). */
static void gl_bind(vfx_context *ctx)
{
    volfx_gl_current = ctx->gl;
}

/* The GL state contract (gpu/gl_state.h, docs/integration.md): the outermost API call that
 * touches GL saves the host's state, sets the baseline every pass depends on, and gl_leave puts
 * the host's state back; calls made inside it (warm_up's render, render's resize) only count. A
 * host that resets its own state skips the save and the restore, never the baseline. */
static void gl_enter(vfx_context *ctx)
{
    gl_bind(ctx);
    if (ctx->gl_calls++ == 0) {
        if (!ctx->gl_skip_restore)
            volfx_gl_state_save(&ctx->gl_saved, ctx->gl_compat);
        volfx_gl_state_baseline(ctx->gl_compat);
    }
}

static vfx_result gl_leave(vfx_context *ctx, vfx_result r)
{
    if (--ctx->gl_calls == 0 && !ctx->gl_skip_restore)
        volfx_gl_state_restore(&ctx->gl_saved);
    return r;
}

/* Which profile the context has (a compatibility profile also has GL_ALPHA_TEST to turn off),
 * and a context that cannot serve refused with its version and profile: desktop GL 4.5, core
 * or compatibility, with every command resolved (gl_load). */
static vfx_result gl_profile(vfx_context *ctx)
{
    GLint mask = 0, major = 0, minor = 0;
    glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &mask);
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    const char *version = glGetString(GL_VERSION) ? (const char *)glGetString(GL_VERSION) : "(none)";
    const char *profile = (mask & GL_CONTEXT_CORE_PROFILE_BIT) ? "core profile"
                          : (mask & GL_CONTEXT_COMPATIBILITY_PROFILE_BIT) ? "compatibility profile"
                          : "no profile";
    if (major * 10 + minor < 45 || !strncmp(version, "OpenGL ES", 9))
        return volfx_fail(ctx, VFX_ERR_GL_UNSUPPORTED, VFX_LOG_ID_GL_VERSION,
                          "volfx needs desktop GL 4.5 (core or compatibility "
                          "profile), the current context is %s, %s", version, profile);
    ctx->gl_compat = (mask & GL_CONTEXT_COMPATIBILITY_PROFILE_BIT) != 0;
    volfx_log(ctx, VFX_LOG_DEBUG, VFX_LOG_ID_GL_INFO, "GL context %s, %s", version, profile);
    return VFX_OK;
}

/* Resolves every GL command the plugin uses through the host's loader; a missing one is refused
 * with its name. The version is checked first when it can be, since a 3.3 context missing 4.5
 * commands says more as "needs 4.5, got 3.3". */
static vfx_result gl_load(vfx_context *ctx)
{
    ctx->gl = volfx_alloc(ctx, sizeof *ctx->gl);
    if (!ctx->gl)
        return VFX_ERR_OUT_OF_MEMORY;
    const char *missing = NULL;
    unsigned lookups = volfx_gl_load(ctx->gl, ctx->host.gl_get_proc_address, ctx->host.user, &missing);
    gl_bind(ctx);
    if (missing && ctx->gl->GetString && ctx->gl->GetIntegerv) {
        GLint major = 0, minor = 0;
        glGetIntegerv(GL_MAJOR_VERSION, &major);
        glGetIntegerv(GL_MINOR_VERSION, &minor);
        if (major * 10 + minor < 45)
            return gl_profile(ctx); /* the refusal naming version and profile */
    }
    if (missing)
        return volfx_fail(ctx, VFX_ERR_GL_UNSUPPORTED, VFX_LOG_ID_GL_COMMAND_MISSING,
                             "host gl_get_proc_address found no '%s' (one of the %u GL 4.5 commands volfx uses)",
                          missing, lookups);
    volfx_log(ctx, VFX_LOG_DEBUG, VFX_LOG_ID_GL_INFO,
              "%u GL commands resolved through the host's gl_get_proc_address", lookups);
    return VFX_OK;
}

static void register_effects(vfx_context *ctx)
{
#if VFX_WITH_WATER
    ctx->effect_ops[VFX_EFFECT_WATER] = &volfx_water_ops;
#endif
#if VFX_WITH_BEAMS
    ctx->effect_ops[VFX_EFFECT_BEAMS] = &volfx_beams_ops;
#endif
#if VFX_WITH_TETVOL
    ctx->effect_ops[VFX_EFFECT_VOLUME] = &volfx_volume_ops;
#endif
    (void)ctx;
}

static void plugin_destroy(vfx_context *ctx)
{
    if (!ctx)
        return;
    /* the effects free GL objects: through this context's table (another context's destroy may
     * have cleared the thread's) */
    if (ctx->gl)
        gl_bind(ctx);
    for (int k = 0; k < VFX_EFFECT_COUNT; ++k)
        if (ctx->effect_state[k] && ctx->effect_ops[k]) {
            ctx->effect_ops[k]->destroy(ctx, ctx->effect_state[k]);
            ctx->effect_state[k] = NULL;
        }
    if (ctx->gl) {
        volfx_frame_check_destroy(ctx);
        volfx_gpu_scan_destroy(ctx);
        volfx_gpu_destroy(ctx, ctx->gpu);
        volfx_gl_current = NULL; /* nothing may call GL through a freed table */
        volfx_free(ctx, ctx->gl);
    }
    vfx_context_desc host = ctx->host;
    if (host.free)
        host.free(host.user, ctx);
    else
        free(ctx);
}

static vfx_result plugin_create(const vfx_context_desc *host, vfx_context **out)
{
    if (!out)
        return VFX_ERR_INVALID_ARGUMENT;
    *out = NULL;
    if (!host || host->type != VFX_TYPE_CONTEXT_DESC) {
        if (host && host->log)
            host->log(host->user, VFX_LOG_ERROR, VFX_LOG_ID_STRUCT_TYPE,
                      "volfx create: the context description is NULL or not of type VFX_TYPE_CONTEXT_DESC");
        return VFX_ERR_ABI;
    }
    char msg[160];
    if (volfx_check_host(host, msg, sizeof msg)) {
        if (host->log)
            host->log(host->user, VFX_LOG_ERROR, VFX_LOG_ID_CONTEXT_DESC, msg);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    vfx_context *ctx = host->alloc ? host->alloc(host->user, sizeof *ctx, 64) : malloc(sizeof *ctx);
    if (!ctx)
        return VFX_ERR_OUT_OF_MEMORY;
    memset(ctx, 0, sizeof *ctx);
    ctx->host = *host;
    const vfx_gl_state_desc *gs = volfx_chain_find(host->next, VFX_TYPE_GL_STATE_DESC);
    ctx->gl_skip_restore = gs && gs->skip_restore;
    ctx->host.next = NULL; /* the chain is the host's, valid only during this call */
    ctx->stats.type = ctx->last_stats.type = VFX_TYPE_STATS;
    register_effects(ctx);
    vfx_result r = host->gl_get_proc_address
                       ? gl_load(ctx)
                       : volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_CONTEXT_DESC,
                                    "volfx create: the context description has no "
                                    "gl_get_proc_address (the plugin resolves every GL command through it)");
    if (r == VFX_OK && (r = gl_profile(ctx)) == VFX_OK) {
        gl_enter(ctx);
        r = gl_leave(ctx, volfx_gpu_create(ctx, &ctx->gpu));
    }
    if (r != VFX_OK) {
        /* keep the message: the caller has no context to ask */
        plugin_destroy(ctx);
        return r;
    }
    *out = ctx;
    return VFX_OK;
}

/* Every effect's targets at width x height. When one cannot be made (out of memory), the
 * context goes back to its previous size and every effect is remade at it, so the next frame
 * draws as before; an effect that cannot be remade even then is dropped and made again by the
 * next update. The failed size is not kept. */
static vfx_result resize(vfx_context *ctx, uint32_t width, uint32_t height)
{
    if (width == 0 || height == 0 || width > 16384 || height > 16384)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_RESIZE_RANGE,
                        "resize: %ux%u outside 1..16384 in each direction", width, height);
    const uint32_t old_w = ctx->width, old_h = ctx->height;
    ctx->width = width;
    ctx->height = height;
    vfx_result r = VFX_OK;
    for (int k = 0; k < VFX_EFFECT_COUNT && !r; ++k)
        if (ctx->effect_state[k] && ctx->effect_ops[k]->resize)
            r = ctx->effect_ops[k]->resize(ctx, ctx->effect_state[k], width, height);
    if (!r)
        return VFX_OK;
    char why[512];
    snprintf(why, sizeof why, "%s", ctx->last_error);
    const vfx_log_id why_id = ctx->last_error_id; /* the cause's kind is the failure's */
    while (glGetError() != GL_NO_ERROR) { /* the failure's GL_OUT_OF_MEMORY is not the next call's */
    }
    ctx->width = old_w;
    ctx->height = old_h;
    for (int k = 0; k < VFX_EFFECT_COUNT; ++k) {
        const volfx_effect_ops *ops = ctx->effect_ops[k];
        if (!ctx->effect_state[k] || !ops->resize || (old_w && ops->resize(ctx, ctx->effect_state[k], old_w, old_h) == VFX_OK))
            continue;
        ops->destroy(ctx, ctx->effect_state[k]); /* remade whole by the next update */
        ctx->effect_state[k] = NULL;
        ctx->rendered &= ~VFX_EFFECT_BIT(k);
    }
    return volfx_fail(ctx, r, why_id,
                      "resize to %ux%u failed, the context stays at %ux%u: %s", width, height, old_w, old_h, why);
}

static vfx_result plugin_resize(vfx_context *ctx, uint32_t width, uint32_t height)
{
    if (!ctx)
        return VFX_ERR_INVALID_ARGUMENT;
    gl_enter(ctx);
    return gl_leave(ctx, resize(ctx, width, height));
}

static vfx_result update(vfx_context *ctx, double time, float dt)
{
    if (!isfinite(time) || !isfinite(dt))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_UPDATE_TIME,
                          "update: time %g or dt %g is not finite",
                        time, (double)dt);
    char msg[160];
    if (volfx_check_host(&ctx->host, msg, sizeof msg))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_CONTEXT_DESC, "update: %s", msg);
    for (int k = 0; k < VFX_EFFECT_COUNT; ++k) {
        const volfx_effect_ops *ops = ctx->effect_ops[k];
        if (!ops)
            continue;
        bool present = ops->present(ctx);
        if (present != (ctx->effect_state[k] != NULL))
            ctx->rendered &= ~VFX_EFFECT_BIT(k); /* created or destroyed: nothing to read yet */
        if (present && !ctx->effect_state[k]) {
            vfx_result r = ops->create(ctx, &ctx->effect_state[k]);
            if (r)
                return r;
            volfx_log(ctx, VFX_LOG_DEBUG, VFX_LOG_ID_EFFECT_CREATED, "effect %s created", ops->name);
            if (ctx->width && ops->resize
                && (r = ops->resize(ctx, ctx->effect_state[k], ctx->width, ctx->height)))
                return r;
        } else if (!present && ctx->effect_state[k]) {
            ops->destroy(ctx, ctx->effect_state[k]);
            ctx->effect_state[k] = NULL;
            volfx_log(ctx, VFX_LOG_DEBUG, VFX_LOG_ID_EFFECT_DESTROYED,
                      "effect %s destroyed (absent from the world)", ops->name);
        }
        if (ctx->effect_state[k]) {
            vfx_result r = ops->update(ctx, ctx->effect_state[k], time, dt);
            if (r)
                return r;
        }
    }
    return VFX_OK;
}

vfx_result volfx_effects_prepare(vfx_context *ctx, volfx_frame_targets *targets)
{
    for (int k = 0; k < VFX_EFFECT_COUNT; ++k) {
        const volfx_effect_ops *ops = ctx->effect_ops[k];
        if (!ops || !ops->prepare || !ctx->effect_state[k] || !(targets->effects & VFX_EFFECT_BIT(k))
            || (ctx->prepared & VFX_EFFECT_BIT(k)))
            continue;
        ctx->prepared |= VFX_EFFECT_BIT(k);
        vfx_result r = ops->prepare(ctx, ctx->effect_state[k], targets);
        if (r)
            return r;
    }
    return VFX_OK;
}

/* The frame gate (frame_check.c) checks the view and derives the camera once; the effects then
 * read it from targets (and the VolfxFrame block it binds). */
static vfx_result plugin_update(vfx_context *ctx, double time, float dt)
{
    if (!ctx)
        return VFX_ERR_INVALID_ARGUMENT;
    gl_enter(ctx);
    return gl_leave(ctx, update(ctx, time, dt));
}

static vfx_result render(vfx_context *ctx, const vfx_frame_view *frame)
{
    volfx_frame_targets targets;
    vfx_frame_view checked; /* the frame view validated, near/far filled: the gate's scratch */
    vfx_result cr = volfx_frame_gate(ctx, frame, &targets, &checked);
    if (cr)
        return cr;
    if (targets.width != ctx->width || targets.height != ctx->height) {
        vfx_result r = resize(ctx, targets.width, targets.height);
        if (r)
            return r;
    }
    uint32_t mask = targets.effects;
    bool drawing = false;
    for (int k = 0; k < VFX_EFFECT_COUNT; ++k)
        drawing |= ctx->effect_state[k] && (mask & VFX_EFFECT_BIT(k));
    if ((cr = volfx_frame_gate_gl(ctx, drawing, &targets)))
        return cr;
    /* the engine's own depth, as the gate made it, where the host gave depth in any form */
    targets.host_depth = checked.depth_texture || ctx->frame_depth.depth_renderbuffer
                                 || ctx->frame_depth.depth_framebuffer ? targets.scene_depth : 0;

    ctx->stats.count = 0;
    ctx->stats.dropped = 0;
    ctx->prepared = 0;
    targets.beams_light = targets.beams_behind = 0;
    static const vfx_effect_kind order[VFX_EFFECT_COUNT] = {VFX_EFFECT_WATER, VFX_EFFECT_VOLUME,
                                                            VFX_EFFECT_BEAMS};
    vfx_result result = VFX_OK;
    for (int i = 0; i < VFX_EFFECT_COUNT && result == VFX_OK; ++i) {
        vfx_effect_kind k = order[i];
        if (!ctx->effect_state[k] || !(mask & VFX_EFFECT_BIT(k)))
            continue;
        /* the water has run it before its shading; without water, the beams' prepare runs here */
        if (k != VFX_EFFECT_WATER && (result = volfx_effects_prepare(ctx, &targets)))
            break;
        result = ctx->effect_ops[k]->render(ctx, ctx->effect_state[k], &targets);
        if (result == VFX_OK)
            ctx->rendered |= VFX_EFFECT_BIT(k);
    }
    volfx_gpu_frame_end(ctx);
    ctx->last_stats = ctx->stats;
    return result;
}

static vfx_result plugin_render(vfx_context *ctx, const vfx_frame_view *frame)
{
    if (!ctx)
        return VFX_ERR_INVALID_ARGUMENT;
    gl_enter(ctx);
    return gl_leave(ctx, render(ctx, frame));
}

static vfx_result plugin_get_stats(vfx_context *ctx, vfx_stats *out)
{
    if (!ctx)
        return VFX_ERR_INVALID_ARGUMENT;
    if (!out)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_API_ARGUMENT, "get_stats: out is NULL");
    vfx_result r = volfx_check_type(ctx, out, VFX_TYPE_STATS, "get_stats: vfx_stats");
    if (r)
        return r;
    void *next = out->next;
    *out = ctx->last_stats;
    out->next = next;
    return VFX_OK;
}

static const char *plugin_last_error(vfx_context *ctx, vfx_log_id *id_out)
{
    if (id_out)
        *id_out = ctx ? ctx->last_error_id : VFX_LOG_ID_NONE;
    return ctx ? ctx->last_error : "no context";
}

static vfx_result read_raw(vfx_context *ctx, vfx_effect_kind effect, float *out, size_t count)
{
    if (!out)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_API_ARGUMENT,
                          "read_raw: out is NULL (count %zu)", count);
    if ((unsigned)effect >= VFX_EFFECT_COUNT)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_API_ARGUMENT,
                          "read_raw: effect %d out of range", (int)effect);
    if (!ctx->effect_ops[effect])
        return volfx_fail(ctx, VFX_ERR_UNSUPPORTED, VFX_LOG_ID_EFFECT_NOT_BUILT,
                          "read_raw: effect %d is not built in", (int)effect);
    if (!ctx->effect_state[effect])
        return volfx_fail(ctx, VFX_ERR_NOT_FOUND, VFX_LOG_ID_EFFECT_NOT_RENDERED,
                          "read_raw: effect %s is absent from the world",
                        ctx->effect_ops[effect]->name);
    if (!(ctx->rendered & VFX_EFFECT_BIT(effect)))
        return volfx_fail(ctx, VFX_ERR_NOT_FOUND, VFX_LOG_ID_EFFECT_NOT_RENDERED,
                          "read_raw: effect %s has not been rendered since it was "
                          "created (nothing to read)", ctx->effect_ops[effect]->name);
    if (count < (size_t)ctx->width * ctx->height)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_READ_BUFFER_SIZE,
                          "read_raw: buffer of %zu floats, need %ux%u",
                        count, ctx->width, ctx->height);
    vfx_result r = ctx->effect_ops[effect]->read_raw(ctx, ctx->effect_state[effect], out, count);
    if (r || !ctx->frame_depth.flip_y)
        return r;
    /* a flipped frame's rows are stored top first, so the effect's bottom-first read came out
     * upside down: turn it back to the image's top row first */
    for (uint32_t j = 0, w = ctx->width; j < ctx->height / 2; ++j)
        for (uint32_t i = 0; i < w; ++i) {
            float t = out[(size_t)j * w + i];
            out[(size_t)j * w + i] = out[(size_t)(ctx->height - 1 - j) * w + i];
            out[(size_t)(ctx->height - 1 - j) * w + i] = t;
        }
    return VFX_OK;
}

static vfx_result plugin_read_raw(vfx_context *ctx, vfx_effect_kind effect, float *out, size_t count)
{
    if (!ctx)
        return VFX_ERR_INVALID_ARGUMENT;
    gl_enter(ctx);
    return gl_leave(ctx, read_raw(ctx, effect, out, count));
}

/* Program binaries kept in a host folder (gpu/program_cache.c). */
static vfx_result plugin_set_program_cache(vfx_context *ctx, const char *dir)
{
    if (!ctx)
        return VFX_ERR_INVALID_ARGUMENT;
    gl_enter(ctx);
    return gl_leave(ctx, volfx_gpu_set_program_cache(ctx, dir));
}

/* Warm-up: one render of the frame (it compiles exactly the variants the frame uses, and
 * llvmpipe-like drivers JIT their draw-time variants only when drawing), then a wait, so the
 * first real frame finds everything built. */
static vfx_result plugin_warm_up(vfx_context *ctx, const vfx_frame_view *frame)
{
    if (!ctx)
        return VFX_ERR_INVALID_ARGUMENT;
    gl_enter(ctx);
    vfx_result r = render(ctx, frame);
    if (r == VFX_OK)
        glFinish();
    return gl_leave(ctx, r);
}

/* The lights of the effects as of the last update (only the beams cast any). */
static vfx_result plugin_get_lights(vfx_context *ctx, vfx_lights *out)
{
    if (!ctx)
        return VFX_ERR_INVALID_ARGUMENT;
    if (!out)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_API_ARGUMENT, "get_lights: out is NULL");
    vfx_result r = volfx_check_type(ctx, out, VFX_TYPE_LIGHTS, "get_lights: vfx_lights");
    if (r)
        return r;
    if (out->capacity && !out->lights)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_API_ARGUMENT,
                          "get_lights: capacity %u with a NULL lights array",
                          out->capacity);
    out->count = out->total = 0;
    /* a chained vfx_impact_events (ABI 1.1) is an output too: the host's, so not const */
    vfx_impact_events *ev = (vfx_impact_events *)volfx_chain_find(out->next, VFX_TYPE_IMPACT_EVENTS);
    if (ev && ev->capacity && !ev->events)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_API_ARGUMENT,
                          "get_lights: vfx_impact_events capacity %u with a NULL "
                          "events array", ev->capacity);
    if (ev)
        ev->count = ev->total = 0;
#if VFX_WITH_BEAMS
    volfx_beams_impact *im = volfx_beams_impact_of(ctx);
    if (im)
        volfx_beams_impact_lights(im, out);
    if (im && ev) {
        ev->total = volfx_beams_impact_water_events(im, (volfx_impact_event *)ev->events, ev->capacity);
        ev->count = ev->total < ev->capacity ? ev->total : ev->capacity;
    }
#endif
    return VFX_OK;
}

/* The head of ABI 1's vfx_host_api (size, version, user, gl_get_proc_address, log), enough to
 * tell an ABI 1 host why it is refused through its own logger. */
typedef struct abi1_host_head {
    uint32_t size, version;
    void *user;
    void *(*gl_get_proc_address)(void *user, const char *name);
    void (*log)(void *user, vfx_log_level level, const char *message);
} abi1_host_head;

/* Tells the host why the entry refused it, through whatever logger its ABI version has. */
static void entry_refuse(uint32_t abi_version, const void *host, vfx_log_id id, const char *msg)
{
    if (!host)
        return;
    if (abi_version == 1) {
        /* an ABI 1 host passes a vfx_host_api of version 1 whose size covers these fields */
        const abi1_host_head *h1 = host;
        if (h1->version == 1 && h1->size >= sizeof *h1 && h1->log)
            h1->log(h1->user, VFX_LOG_ERROR, msg);
        return;
    }
    /* ABI 2 and every later one keep vfx_context_desc's head (type, next, user,
     * gl_get_proc_address, log) in place (docs/abi.md), so a newer host hears why too */
    const vfx_context_desc *d = host;
    if (abi_version >= VFX_ABI_VERSION && d->type == VFX_TYPE_CONTEXT_DESC && d->log)
        d->log(d->user, VFX_LOG_ERROR, id, msg);
}

VFX_EXPORT vfx_result vfx_plugin_entry(uint32_t abi_version, const vfx_context_desc *desc, vfx_plugin_api *out)
{
    if (abi_version != VFX_ABI_VERSION) {
        char msg[192];
        snprintf(msg, sizeof msg, "volfx: host ABI version %u, plugin ABI version %u (ABI 1.0): refused; rebuild "
                 "the host against this volfx.h", abi_version, VFX_ABI_VERSION);
        entry_refuse(abi_version, desc, VFX_LOG_ID_ABI_VERSION, msg);
        return VFX_ERR_ABI;
    }
    if (!out || out->type != VFX_TYPE_PLUGIN_API) {
        char msg[160];
        snprintf(msg, sizeof msg, "volfx: the plugin api table is %s (need type VFX_TYPE_PLUGIN_API = %u)",
                 out ? "of another type" : "NULL", (unsigned)VFX_TYPE_PLUGIN_API);
        entry_refuse(abi_version, desc, VFX_LOG_ID_STRUCT_TYPE, msg);
        return VFX_ERR_ABI;
    }
    void *next = out->next;
    memset(out, 0, sizeof *out);
    out->type = VFX_TYPE_PLUGIN_API;
    out->next = next;
    out->name = "volfx";
    out->effects_built = (VFX_WITH_WATER ? VFX_EFFECT_BIT(VFX_EFFECT_WATER) : 0)
                         | (VFX_WITH_BEAMS ? VFX_EFFECT_BIT(VFX_EFFECT_BEAMS) : 0)
                         | (VFX_WITH_TETVOL ? VFX_EFFECT_BIT(VFX_EFFECT_VOLUME) : 0);
    out->create = plugin_create;
    out->destroy = plugin_destroy;
    out->resize = plugin_resize;
    out->update = plugin_update;
    out->render = plugin_render;
    out->warm_up = plugin_warm_up;
    out->set_program_cache = plugin_set_program_cache;
    out->get_stats = plugin_get_stats;
    out->get_lights = plugin_get_lights;
    out->last_error = plugin_last_error;
    out->read_raw = plugin_read_raw;
    out->resolve_defaults = volfx_resolve_defaults;
    /* what this plugin reads, for a host about to chain an extension a 1.0 plugin would skip */
    vfx_plugin_info *info = (vfx_plugin_info *)volfx_chain_find(next, VFX_TYPE_PLUGIN_INFO);
    if (info) {
        info->abi_minor = VFX_ABI_MINOR;
        info->type_count = 64;
        info->known_types = 0;
        for (uint32_t t = VFX_TYPE_CONTEXT_DESC; t <= VFX_TYPE_WATER_FOAM; ++t)
            info->known_types |= 1ull << t;
    }
    return VFX_OK;
}
