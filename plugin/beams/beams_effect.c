/* beams_effect.c — seed 003 on the GPU: beams binned to screen tiles on the CPU, one
 * fullscreen pass integrating the closed form per pixel up to the host's depth (and the
 * water's) and turning it into linear radiance (RGBA16F), an optional bloom chain over that
 * light, one pass adding it into the host frame. Host views of version 1 and 2 are read. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "beams/beam_field.h"
#include "beams/beams_bin.h"
#include "beams/beams_impact.h"
#include "gpu/gpu.h"
#include "gpu/pass.h"
#include "effect.h"
#include "param_ranges.h"
#include "lab_hooks.h"

#define MAX_BEAMS (1u << 20)
#define MAX_BLOOM_LEVELS 8
_Static_assert(VOLFX_BEAMS_BIN_MAX_POINTS >= VOLFX_BEAM_MAX_JOINTS, "a polyline fits a capsule");

/* std430, mirrors struct Beam in shaders/beams/integrate.frag */
typedef struct beam_gpu {
    float m_l[4], d_r[4], ab_eps[4], color[4], look[4];
    uint32_t mode[4];
    float an0[4], an1[4], look2[4]; /* the anatomy (beam_field.glsl), core / flow kind / twist */
} beam_gpu;

/* std140, mirrors BeamsFrame in shaders/beams/frame.glsl */
typedef struct beams_block {
    float far, c;
    int32_t tile_px, tiles_x, has_water, smooth_saturation, bloom;
    float bloom_gain, _pad[2];
} beams_block;

/* The look of one beam, resolved from a version 2 beam or version 1 defaults. */
typedef struct beam_look {
    float intensity, exposure, flow_amount, flow_speed, flow_scale;
    float color[4];  /* the beam's colour; all 0 -> white */
    bool thesis;
    float core, twist;    /* hue-keeping ramp's core (0: the hot or thesis ramp), spiral */
    uint32_t flow_kind;
    bool anatomy;         /* needs the ANATOMY program (head radius, orb, profile, core, spiral) */
} beam_look;

typedef struct beams_state {
    GLuint prog_integrate[64]; /* [smooth | polyline << 1 | anatomy << 2 | water << 3 | dry << 4 | mark << 5]:
                                * code only where needed */
    GLuint prog_composite, prog_down, prog_up;
    GLuint beam_buf, range_buf, list_buf, joint_buf;
    size_t beam_cap, range_cap, list_cap, joint_cap; /* bytes */
    float (*joint_xyz)[4];      /* polyline joints this frame, eye-relative (capacity: beams x max) */
    uint32_t joint_used;
    GLuint acc_tex, light_tex, acc_fbo;   /* H (RG32F: in front of the water, behind it) and light (RGBA16F) */
    GLuint behind_tex, split_fbo;         /* light behind the water (RGBA16F), and the 3-target framebuffer:
                                           * made the first frame with water */
    GLuint split_stencil;                 /* its stencil: 1 where the pixel has water in front */
    bool prepared;                        /* the integrate pass ran this render (beams_prepare) */
    bool bloom;                           /* this render's bloom, and its levels */
    uint32_t levels;
    GLuint bloom_tex[MAX_BLOOM_LEVELS + 1], bloom_fbo[MAX_BLOOM_LEVELS + 1]; /* [1..levels] */
    uint32_t bloom_w[MAX_BLOOM_LEVELS + 1], bloom_h[MAX_BLOOM_LEVELS + 1];
    uint32_t bloom_levels;                /* allocated levels */
    volfx_ubo ubo;
    volfx_beams_grid grid;                /* the target in pixels and tiles */
    vfx_beams_view view;                  /* the host's answer (next cleared) */
    uint32_t lab_method;                  /* a lab method (lab_hooks.h beams_struct); 0: the closed form */
    double time;
    float dt;
    volfx_beams_impact *impact;           /* flares, sparks, glow, lights (beams_impact.h) */
    volfx_beam_d *beams;        /* validated, normalised */
    beam_look *looks;
    beam_gpu *gpu;
    uint32_t (*rects)[4];     /* per beam: its tile rectangle this frame */
    volfx_beams_capsule *caps; /* per beam: its support for the per-tile test */
    float (*cones)[4];        /* per tile: its cone of pixel rays this frame */
    bool *visible;            /* per beam: on screen this frame */
    uint32_t count, capacity;
    uint32_t *ranges, *list;  /* 2 per tile; tile lists */
    uint32_t list_capacity, pairs;  /* list entries allocated, used this frame */
} beams_state;

/* Asks the host for its view (a zeroed one with its type set); the host keeps the type. */
static vfx_result query_view(vfx_context *ctx, vfx_beams_view *v)
{
    memset(v, 0, sizeof *v);
    v->type = VFX_TYPE_BEAMS_VIEW;
    return ctx->host.beams(ctx->host.user, v);
}

static bool beams_present(vfx_context *ctx)
{
    vfx_beams_view v;
    return ctx->host.beams && query_view(ctx, &v) == VFX_OK && v.count > 0;
}

static void free_bloom(beams_state *s)
{
    for (uint32_t i = 1; i <= s->bloom_levels; ++i) {
        glDeleteTextures(1, &s->bloom_tex[i]);
        glDeleteFramebuffers(1, &s->bloom_fbo[i]);
        s->bloom_tex[i] = s->bloom_fbo[i] = 0;
    }
    s->bloom_levels = 0;
}

/* The arrays sized by the beam count (remade when the count outgrows them). */
static void free_per_beam(vfx_context *ctx, beams_state *s)
{
    volfx_free(ctx, s->beams);
    volfx_free(ctx, s->looks);
    volfx_free(ctx, s->joint_xyz);
    volfx_free(ctx, s->gpu);
    volfx_free(ctx, s->rects);
    volfx_free(ctx, s->caps);
    volfx_free(ctx, s->visible);
}

static void beams_destroy(vfx_context *ctx, void *state)
{
    beams_state *s = state;
    if (!s)
        return;
    GLuint bufs[4] = {s->beam_buf, s->range_buf, s->list_buf, s->joint_buf};
    glDeleteBuffers(4, bufs);
    glDeleteTextures(1, &s->acc_tex);
    glDeleteTextures(1, &s->light_tex);
    glDeleteFramebuffers(1, &s->acc_fbo);
    glDeleteTextures(1, &s->behind_tex);
    glDeleteFramebuffers(1, &s->split_fbo);
    glDeleteRenderbuffers(1, &s->split_stencil);
    free_bloom(s);
    volfx_ubo_destroy(&s->ubo);
    volfx_beams_impact_destroy(ctx, s->impact);
    free_per_beam(ctx, s);
    volfx_free(ctx, s->ranges);
    volfx_free(ctx, s->cones);
    volfx_free(ctx, s->list);
    volfx_free(ctx, s); /* programs belong to the shared cache */
}

static vfx_result beams_create(vfx_context *ctx, void **out)
{
    beams_state *s = volfx_alloc(ctx, sizeof *s);
    if (!s)
        return VFX_ERR_OUT_OF_MEMORY;
    s->prog_composite = volfx_gpu_program(ctx, "common/fullscreen.vert", "beams/composite.frag", NULL);
    s->prog_down = volfx_gpu_program(ctx, "common/fullscreen.vert", "beams/bloom_down.frag", NULL);
    s->prog_up = volfx_gpu_program(ctx, "common/fullscreen.vert", "beams/bloom_up.frag", NULL);
    if (!s->prog_composite || !s->prog_down || !s->prog_up
        || !volfx_ubo_create(ctx, &s->ubo, sizeof(beams_block), "beams.frame")) {
        beams_destroy(ctx, s);
        return VFX_ERR_GL;
    }
    vfx_result ir = volfx_beams_impact_create(ctx, &s->impact);
    if (ir) {
        beams_destroy(ctx, s);
        return ir;
    }
    GLuint bufs[4];
    glCreateBuffers(4, bufs);
    s->beam_buf = bufs[0], s->range_buf = bufs[1], s->list_buf = bufs[2], s->joint_buf = bufs[3];
    volfx_gpu_label(GL_BUFFER, s->joint_buf, "beams.joints");
    volfx_gpu_label(GL_BUFFER, s->beam_buf, "beams.beams");
    volfx_gpu_label(GL_BUFFER, s->range_buf, "beams.tile_ranges");
    volfx_gpu_label(GL_BUFFER, s->list_buf, "beams.tile_lists");
    *out = s;
    return VFX_OK;
}

static GLuint make_target(GLenum fmt, uint32_t w, uint32_t h, bool linear, const char *label)
{
    GLuint t;
    glCreateTextures(GL_TEXTURE_2D, 1, &t);
    glTextureStorage2D(t, 1, fmt, (GLsizei)w, (GLsizei)h);
    glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, linear ? GL_LINEAR : GL_NEAREST);
    glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, linear ? GL_LINEAR : GL_NEAREST);
    glTextureParameteri(t, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(t, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    volfx_gpu_label(GL_TEXTURE, t, label);
    return t;
}

/* (Re)makes the bloom chain: level i is the light at 1/2^i of the size, RGBA16F, bilinear. */
static vfx_result make_bloom(vfx_context *ctx, beams_state *s, uint32_t levels)
{
    free_bloom(s);
    for (uint32_t i = 1; i <= levels; ++i) {
        uint32_t w = s->grid.width >> i, h = s->grid.height >> i;
        s->bloom_w[i] = w ? w : 1, s->bloom_h[i] = h ? h : 1;
        s->bloom_tex[i] = make_target(GL_RGBA16F, s->bloom_w[i], s->bloom_h[i], true, "beams.bloom");
        glCreateFramebuffers(1, &s->bloom_fbo[i]);
        glNamedFramebufferTexture(s->bloom_fbo[i], GL_COLOR_ATTACHMENT0, s->bloom_tex[i], 0);
        s->bloom_levels = i;
        vfx_result r = volfx_gpu_check_target(ctx, s->bloom_fbo[i], "beams: bloom level", s->bloom_w[i], s->bloom_h[i]);
        if (r)
            return r;
    }
    return VFX_OK;
}

static vfx_result beams_resize(vfx_context *ctx, void *state, uint32_t w, uint32_t h)
{
    beams_state *s = state;
    glDeleteTextures(1, &s->acc_tex);
    glDeleteTextures(1, &s->light_tex);
    glDeleteFramebuffers(1, &s->acc_fbo);
    glDeleteTextures(1, &s->behind_tex);
    glDeleteFramebuffers(1, &s->split_fbo);
    glDeleteRenderbuffers(1, &s->split_stencil);
    s->behind_tex = s->split_fbo = s->split_stencil = 0;
    free_bloom(s);
    s->acc_tex = make_target(GL_RG32F, w, h, false, "beams.H");
    s->light_tex = make_target(GL_RGBA16F, w, h, true, "beams.light");
    glCreateFramebuffers(1, &s->acc_fbo);
    glNamedFramebufferTexture(s->acc_fbo, GL_COLOR_ATTACHMENT0, s->acc_tex, 0);
    glNamedFramebufferTexture(s->acc_fbo, GL_COLOR_ATTACHMENT1, s->light_tex, 0);
    static const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glNamedFramebufferDrawBuffers(s->acc_fbo, 2, bufs);
    vfx_result r = volfx_gpu_check_target(ctx, s->acc_fbo, "beams: H and light targets", w, h);
    if (r)
        return r;
    s->grid = volfx_beams_grid_of(w, h);
    volfx_free(ctx, s->ranges);
    s->ranges = volfx_alloc(ctx, (size_t)s->grid.tiles_x * s->grid.tiles_y * 2 * sizeof(uint32_t));
    volfx_free(ctx, s->cones);
    s->cones = volfx_alloc(ctx, (size_t)s->grid.tiles_x * s->grid.tiles_y * sizeof *s->cones);
    return s->ranges && s->cones ? VFX_OK : VFX_ERR_OUT_OF_MEMORY;
}

/* The look of a beam, checked. */
static vfx_result beam_look_of(vfx_context *ctx, uint32_t i, const vfx_beam *b2, beam_look *out)
{
    *out = (beam_look){.intensity = 1.f, .thesis = true};
    if (b2->falloff > VFX_BEAM_FALLOFF_HARD || b2->ramp > VFX_BEAM_RAMP_THESIS)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_BEAM_FIELD,
                          "beams[%u]: falloff %u / ramp %u unknown", i,
                          b2->falloff, b2->ramp);
    if (!(b2->intensity >= 0) || !isfinite(b2->intensity) || !isfinite(b2->exposure)
        || fabsf(b2->exposure) > 64.f || !(b2->flow_amount >= 0 && b2->flow_amount <= 1)
        || !isfinite(b2->flow_speed) || !(b2->flow_scale >= 0) || !isfinite(b2->flow_scale))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_PARAM_RANGE,
                          "beams[%u]: needs intensity >= 0, |exposure| <= 64, flow_amount in [0, 1], finite "
                          "flow_speed, flow_scale >= 0 (got %g, %g, %g, %g, %g)", i, (double)b2->intensity,
                          (double)b2->exposure, (double)b2->flow_amount, (double)b2->flow_speed,
                          (double)b2->flow_scale);
    out->intensity = b2->intensity > 0 ? b2->intensity : 1.f;
    out->exposure = b2->exposure;
    out->flow_amount = b2->flow_amount;
    out->flow_speed = b2->flow_speed;
    out->flow_scale = b2->flow_scale;
    out->thesis = b2->ramp == VFX_BEAM_RAMP_THESIS;
    return VFX_OK;
}

/* A beam's anatomy, checked, into the field (bd) and the look; `time` drives the orb's pulse
 * and the surges. */
static vfx_result beam_anatomy_of(vfx_context *ctx, uint32_t i, const vfx_beam *b3, double time, volfx_beam_d *bd,
                                  beam_look *lk)
{
    const float f[] = {b3->head_radius, b3->orb_radius, b3->orb_strength, b3->orb_pulse, b3->orb_pulse_hz, b3->taper,
                       b3->surge_amount, b3->surge_wavelength, b3->surge_speed, b3->flow_twist, b3->core};
    bool finite = true;
    for (size_t k = 0; k < sizeof f / sizeof f[0]; ++k)
        finite &= isfinite(f[k]) != 0;
    if (!finite || !(b3->head_radius >= 0 && b3->orb_radius >= 0 && b3->orb_strength >= 0) || !(b3->orb_pulse <= 1)
        || !(b3->orb_pulse >= 0 && b3->orb_pulse_hz >= 0) || !(b3->taper >= 0 && b3->taper <= 0.95f)
        || !(b3->surge_amount >= 0 && b3->surge_amount <= 4) || !(b3->surge_wavelength >= 0)
        || !(b3->core >= 0 && b3->core <= 1) || b3->flow_kind > VFX_BEAM_FLOW_SPIRAL
        || !(fabsf(b3->flow_twist) <= 64))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_PARAM_RANGE,
                          "beams[%u]: vfx_beam needs finite head_radius, orb_radius, orb_strength >= 0, orb_pulse "
                          "in [0, 1], orb_pulse_hz >= 0, taper in [0, 0.95], surge_amount in [0, 4], "
                          "surge_wavelength >= 0, core in [0, 1], flow_kind 0..1, |flow_twist| <= 64 (got %g, %g, "
                          "%g, %g, %g, %g, %g, %g, %g, %u, %g)", i, (double)b3->head_radius, (double)b3->orb_radius,
                          (double)b3->orb_strength, (double)b3->orb_pulse, (double)b3->orb_pulse_hz,
                          (double)b3->taper, (double)b3->surge_amount, (double)b3->surge_wavelength,
                          (double)b3->core, b3->flow_kind, (double)b3->flow_twist);
    bd->head_radius = b3->head_radius;
    if (b3->orb_radius > 0) {
        double pulse = 1.0 + b3->orb_pulse * sin(6.283185307179586 * fmod(time * b3->orb_pulse_hz, 1.0));
        bd->orb_radius = b3->orb_radius * pulse;
        bd->orb_a = b3->orb_strength > 0 ? b3->orb_strength : bd->a;
    }
    if (!bd->joint_count) {
        bd->taper = b3->taper;
        bd->surge = b3->surge_amount;
        double wl = b3->surge_wavelength > 0 ? b3->surge_wavelength : 8.0 * bd->radius;
        bd->surge_inv_wl = bd->surge > 0 ? 1.0 / wl : 0.0;
        bd->surge_phase = bd->surge > 0 ? fmod(fmod(time * b3->surge_speed / wl, 1.0) + 1.0, 1.0) : 0.0;
    }
    lk->core = b3->core;
    lk->flow_kind = b3->flow_kind;
    lk->twist = b3->flow_twist != 0 ? b3->flow_twist : 1.f;
    lk->anatomy = bd->head_radius > 0 || bd->orb_radius > 0 || bd->taper > 0 || bd->surge > 0 || lk->core > 0
                  || (lk->flow_kind == VFX_BEAM_FLOW_SPIRAL && lk->flow_amount > 0);
    return VFX_OK;
}

static vfx_result beams_update(vfx_context *ctx, void *state, double time, float dt)
{
    beams_state *s = state;
    vfx_beams_view v;
    vfx_result r = query_view(ctx, &v);
    if (r)
        return volfx_fail(ctx, r == VFX_ERR_NOT_FOUND ? VFX_ERR_ABI : r, VFX_LOG_ID_HOST_CALLBACK,
                          "beams: host beams failed (%d)", (int)r);
    if ((r = volfx_check_type(ctx, &v, VFX_TYPE_BEAMS_VIEW, "beams: host beams view (vfx_beams_view)")))
        return r;
    const void *lab = volfx_chain_find(v.next, VFX_TYPE_LAB_BEAMS);
    v.next = NULL;
    const vfx_beam *beams = v.beams;
    if (v.count > MAX_BEAMS || !beams)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_BEAMS_COUNT,
                          "beams: %u beams (at most %u, non-NULL array)",
                          v.count, MAX_BEAMS);
    /* the lab's struct (the ray-marching baseline): read by the lab library only */
    uint32_t lab_method = 0;
    if (lab && !ctx->lab)
        return volfx_fail(ctx, VFX_ERR_UNSUPPORTED, VFX_LOG_ID_BEAMS_VIEW_FIELD,
                          "beams: a vfx_lab_beams (type 0x%x) is chained into vfx_beams_view: lab structs are read "
                          "only with the lab library attached (volfx_lab_attach: tests and benches), not by libvolfx",
                          (unsigned)VFX_TYPE_LAB_BEAMS);
    if (lab && (r = ctx->lab->beams_struct(ctx, lab, &lab_method)))
        return r;
    if ((r = volfx_beams_view_check_ranges(ctx, &v)))
        return r;
    if (!(v.saturate_c >= 0) || !isfinite(v.saturate_c) || !(v.far_distance >= 0)
        || !isfinite(v.far_distance))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_PARAM_RANGE,
                          "beams: saturate_c and far_distance must be finite and >= 0");
    if (v.bloom > VFX_BEAMS_BLOOM_OFF || v.bloom_levels > MAX_BLOOM_LEVELS || !(v.bloom_strength >= 0)
        || !isfinite(v.bloom_strength))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_PARAM_RANGE,
                          "beams: bloom %u (0..2), bloom_levels %u (0..%u), bloom_strength %g (finite, >= 0)",
                          v.bloom, v.bloom_levels, MAX_BLOOM_LEVELS, (double)v.bloom_strength);
    uint32_t n = v.count;
    if (n > s->capacity) {
        free_per_beam(ctx, s);
        s->beams = volfx_alloc(ctx, n * sizeof *s->beams);
        s->looks = volfx_alloc(ctx, n * sizeof *s->looks);
        s->joint_xyz = volfx_alloc(ctx, (size_t)n * VOLFX_BEAM_MAX_JOINTS * sizeof *s->joint_xyz);
        s->gpu = volfx_alloc(ctx, n * sizeof *s->gpu);
        s->rects = volfx_alloc(ctx, n * sizeof *s->rects);
        s->caps = volfx_alloc(ctx, n * sizeof *s->caps);
        s->visible = volfx_alloc(ctx, n * sizeof *s->visible);
        s->capacity = (s->beams && s->looks && s->joint_xyz && s->gpu && s->rects && s->caps && s->visible) ? n : 0;
        if (!s->capacity)
            return VFX_ERR_OUT_OF_MEMORY;
    }
    if (!volfx_beams_impact_set_count(ctx, s->impact, n))
        return VFX_ERR_OUT_OF_MEMORY;
    char err[200];
    for (uint32_t i = 0; i < n; ++i) {
        const vfx_beam *b2i = &beams[i];
        char what[48];
        snprintf(what, sizeof what, "beams[%u] (vfx_beam)", i);
        if ((r = volfx_check_type(ctx, b2i, VFX_TYPE_BEAM, what)))
            return r;
        const vfx_beam *b = b2i;
        vfx_beam straight;
        if (b2i->joint_count) { /* a bending beam's head, dir and length are ignored */
            straight = *b;
            straight.dir[0] = 1.f, straight.dir[1] = straight.dir[2] = 0.f;
            straight.head[0] = straight.head[1] = straight.head[2] = straight.length = 0.f;
            b = &straight;
        }
        if ((r = volfx_beam_check_ranges(ctx, i, b)))
            return r;
        if (volfx_beam_validate(b, &s->beams[i], err, sizeof err))
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_BEAM_FIELD, "beams[%u]: %s", i, err);
        if ((r = beam_look_of(ctx, i, b2i, &s->looks[i])))
            return r;
        s->beams[i].smooth = b2i->falloff != VFX_BEAM_FALLOFF_HARD;
        uint32_t jc = b2i->joint_count, jf = b2i->joint_first;
        if (jc && (!v.joints || jf > v.joint_count || jc > v.joint_count - jf))
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_BEAM_JOINTS,
                              "beams[%u]: joints %u..%u outside the view's %u joints",
                              i, jf, jf + jc, v.joints ? v.joint_count : 0);
        if (jc && volfx_beam_set_joints(&s->beams[i], v.joints + 3 * (size_t)jf, jc, err, sizeof err))
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_BEAM_JOINTS, "beams[%u]: %s", i, err);
        if ((r = beam_anatomy_of(ctx, i, b2i, time, &s->beams[i], &s->looks[i])))
            return r;
        const float *c = b->color;
        bool none = c[0] == 0 && c[1] == 0 && c[2] == 0;
        for (int k = 0; k < 4; ++k)
            s->looks[i].color[k] = none ? 1.f : c[k];
        volfx_beams_impact_set_beam(s->impact, i, &s->beams[i], s->looks[i].color,
                                    s->looks[i].intensity * exp2f(s->looks[i].exposure));
    }
    s->count = n;
    s->view = v;
    s->lab_method = lab_method;
    s->time = time;
    s->dt = dt;
    return VFX_OK;
}

static vfx_result upload(vfx_context *ctx, GLuint buf, size_t *cap, const void *data, size_t bytes)
{
    if (bytes == 0)
        bytes = 16; /* an empty SSBO binding is invalid; keep a tiny one */
    if (bytes > *cap) {
        glNamedBufferData(buf, (GLsizeiptr)bytes, NULL, GL_DYNAMIC_DRAW);
        *cap = bytes;
    }
    if (data)
        glNamedBufferSubData(buf, 0, (GLsizeiptr)bytes, data);
    const char *e = volfx_gpu_error_string();
    return e ? volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR,
                          "beams: buffer upload of %zu bytes: %s", bytes, e) : VFX_OK;
}

/* Beam i as the integrate pass reads it (camera-relative: heads are M - eye in double, so a
 * beam a million units away keeps float32 digits), and the sphere bounding it (centre relative
 * to the eye, radius). A polyline's joints go into joint_xyz. */
static void pack_beam(beams_state *s, uint32_t i, const double eye[3], float c, double centre[3], double *bound)
{
    const volfx_beam_d *b = &s->beams[i];
    beam_gpu *g = &s->gpu[i];
    double rel[3], half = 0.5 * b->length;
    for (int k = 0; k < 3; ++k) {
        rel[k] = b->head[k] - eye[k];
        centre[k] = rel[k] + 0.5 * b->length * b->dir[k];
        g->m_l[k] = (float)rel[k];
        g->d_r[k] = (float)b->dir[k];
    }
    uint32_t jfirst = s->joint_used;
    if (b->joint_count >= 2) {
        /* joints camera-relative like the head; the bounding sphere of their box stands in
         * for (M, D, L) where only bounds are used (culling, the marching chord) */
        double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
        for (int j = 0; j < b->joint_count; ++j) {
            float *out = s->joint_xyz[s->joint_used++];
            for (int k = 0; k < 3; ++k) {
                double x = b->joints[j][k] - eye[k];
                out[k] = (float)x;
                lo[k] = fmin(lo[k], x), hi[k] = fmax(hi[k], x);
            }
            out[3] = 0.f;
        }
        half = 0;
        for (int k = 0; k < 3; ++k) {
            centre[k] = 0.5 * (lo[k] + hi[k]);
            half += 0.25 * (hi[k] - lo[k]) * (hi[k] - lo[k]);
        }
        half = sqrt(half);
        for (int k = 0; k < 3; ++k)
            g->m_l[k] = (float)(centre[k] - (k == 0 ? half : 0.0)), g->d_r[k] = k == 0 ? 1.f : 0.f;
    }
    g->m_l[3] = (float)(2.0 * half), g->d_r[3] = (float)b->radius;
    double rmax = volfx_beam_max_radius(b); /* head, orb and body at its widest */
    volfx_beams_capsule *cap = &s->caps[i]; /* the support: within rmax of the axis or polyline */
    cap->r = rmax;
    cap->n = b->joint_count >= 2 ? (uint32_t)b->joint_count : 2;
    for (uint32_t j = 0; j < cap->n; ++j)
        for (int k = 0; k < 3; ++k)
            cap->p[j][k] = b->joint_count >= 2 ? b->joints[j][k] - eye[k]
                                               : rel[k] + (j ? b->length * b->dir[k] : 0.0);
    const beam_look *lk = &s->looks[i];
    float gain = exp2f(lk->exposure), wavelength = lk->flow_scale > 0 ? lk->flow_scale : 2.f * (float)b->radius;
    g->ab_eps[0] = (float)b->a, g->ab_eps[1] = (float)b->b, g->ab_eps[2] = (float)b->eps;
    g->ab_eps[3] = 1.f / wavelength;
    g->look[0] = lk->intensity;
    g->look[1] = gain / c;
    g->look[2] = lk->flow_amount;
    /* the phase wraps at 2^12 wavelengths so float32 keeps its fraction after hours */
    g->look[3] = (float)fmod(s->time * lk->flow_speed / wavelength, 4096.0);
    g->mode[0] = (uint32_t)b->smooth, g->mode[1] = lk->thesis;
    g->mode[2] = jfirst, g->mode[3] = (uint32_t)b->joint_count;
    float an0[4] = {(float)b->head_radius, (float)b->orb_radius, (float)b->orb_a, 0.f};
    float an1[4] = {(float)b->taper, (float)b->surge, (float)b->surge_inv_wl, (float)b->surge_phase};
    float look2[4] = {lk->core, (float)lk->flow_kind, lk->twist, 0.f};
    memcpy(g->an0, an0, sizeof an0);
    memcpy(g->an1, an1, sizeof an1);
    memcpy(g->look2, look2, sizeof look2);
    /* the thesis ramp tints with colour x intensity x 2^exposure  */
    for (int k = 0; k < 4; ++k)
        g->color[k] = lk->color[k] * (lk->thesis && k < 3 ? lk->intensity * gain : 1.f);
    *bound = half + rmax;
}

/* The CPU half of a frame: every beam packed for the GPU and binned to the screen tiles it can
 * touch (beams_bin.h), with the frame gate's eye and camera-relative view-projection; stats. */
static vfx_result bin_beams(vfx_context *ctx, beams_state *s, const volfx_frame_targets *t, float c)
{
    s->joint_used = 0;
    for (uint32_t i = 0; i < s->count; ++i) {
        double centre[3], bound;
        pack_beam(s, i, t->view_eye, c, centre, &bound);
        s->visible[i] = volfx_beams_bin_rect(&s->grid, t->cam_view_proj, centre, bound, s->rects[i]);
    }
    uint64_t bound = volfx_beams_bin_pairs((const uint32_t(*)[4])s->rects, s->visible, s->count);
    if (bound > UINT32_MAX / 2)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_BEAMS_TILE_PAIRS,
                          "beams: %llu beam-tile pairs", (unsigned long long)bound);
    if (bound > s->list_capacity) {
        volfx_free(ctx, s->list);
        s->list = volfx_alloc(ctx, bound * sizeof(uint32_t));
        s->list_capacity = s->list ? (uint32_t)bound : 0;
    }
    if (bound && !s->list)
        return VFX_ERR_OUT_OF_MEMORY;
    uint32_t ntiles = s->grid.tiles_x * s->grid.tiles_y;
    volfx_beams_grid_cones(&s->grid, t->inv_cam_view_proj, s->cones);
    uint64_t pairs = 0;
    uint32_t empty = volfx_beams_bin_fill(&s->grid, (const uint32_t(*)[4])s->rects, s->visible, s->count, s->caps,
                                          (const float(*)[4])s->cones, s->ranges, s->list, &pairs);
    /* pixels x beams the integrate pass evaluates (edge tiles hold fewer pixels) */
    double pixel_pairs = 0;
    for (uint32_t k = 0; k < ntiles; ++k) {
        uint32_t tx = k % s->grid.tiles_x, ty = k / s->grid.tiles_x;
        uint32_t w = s->grid.width - tx * VOLFX_BEAMS_TILE_PX, h = s->grid.height - ty * VOLFX_BEAMS_TILE_PX;
        pixel_pairs += (double)s->ranges[2 * k + 1] * (w < VOLFX_BEAMS_TILE_PX ? w : VOLFX_BEAMS_TILE_PX)
                       * (h < VOLFX_BEAMS_TILE_PX ? h : VOLFX_BEAMS_TILE_PX);
    }
    volfx_stat_set(ctx, "beams.count", s->count);
    volfx_stat_set(ctx, "beams.tiles", ntiles);
    volfx_stat_set(ctx, "beams.tiles_empty", empty);
    volfx_stat_set(ctx, "beams.pairs", (double)pairs);
    volfx_stat_set(ctx, "beams.pairs_culled", (double)s->count * ntiles - (double)pairs);
    volfx_stat_set(ctx, "beams.pairs_rect", (double)bound);
    volfx_stat_set(ctx, "beams.pixel_pairs", pixel_pairs);
    s->pairs = (uint32_t)pairs;
    return VFX_OK;
}

/* The integrate program for this frame's beams: code only for what some beam needs; a lab
 * method's from the lab (lab_hooks.h beams_program), in the same variant, *pass its pass name.
 * With water, `draw` picks the split draws' program (integrate_draws): DRAW_WET the pixels with
 * water in front, DRAW_DRY the others, DRAW_MARK the stencil of the first. */
enum { DRAW_WET, DRAW_DRY, DRAW_MARK };
static GLuint integrate_program(vfx_context *ctx, beams_state *s, bool water, int draw, const char **pass)
{
    bool any_smooth = false, any_poly = false, any_anat = false;
    for (uint32_t i = 0; i < s->count; ++i)
        any_smooth |= s->beams[i].smooth != 0, any_poly |= s->beams[i].joint_count >= 2,
            any_anat |= s->looks[i].anatomy;
    unsigned variant = (unsigned)any_smooth | (unsigned)any_poly << 1 | (unsigned)any_anat << 2 | (unsigned)water << 3
                       | (unsigned)(water && draw == DRAW_DRY) << 4 | (unsigned)(water && draw == DRAW_MARK) << 5;
    if (s->prog_integrate[variant] && !s->lab_method)
        return s->prog_integrate[variant];
    static const char *const names[6] = {"#define VOLFX_BEAMS_SMOOTH 1\n", "#define VOLFX_BEAMS_POLYLINE 1\n",
                                         "#define VOLFX_BEAMS_ANATOMY 1\n", "#define VOLFX_BEAMS_WATER 1\n",
                                         "#define VOLFX_BEAMS_DRY 1\n", "#define VOLFX_BEAMS_MARK 1\n"};
    char defs[240] = "";
    for (unsigned k = 0; k < 6; ++k)
        if (variant >> k & 1u)
            strncat(defs, names[k], sizeof defs - strlen(defs) - 1);
    if (s->lab_method) /* set only with a lab attached (beams_update) */
        return ctx->lab->beams_program(ctx, s->lab_method, variant ? defs : NULL, pass);
    s->prog_integrate[variant] = volfx_gpu_program(ctx, "common/fullscreen.vert", "beams/integrate.frag",
                                                   variant ? defs : NULL);
    return s->prog_integrate[variant];
}

/* down: light -> 1/2 -> ... -> 1/2^levels; up: each level's tent added onto the next larger,
 * so level 1 ends holding the sum of all levels */
static void bloom_passes(vfx_context *ctx, beams_state *s, uint32_t levels)
{
    for (uint32_t i = 1; i <= levels; ++i) {
        volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "beams.bloom_down", .framebuffer = s->bloom_fbo[i],
                                                 .width = s->bloom_w[i], .height = s->bloom_h[i]});
        glUseProgram(s->prog_down);
        glBindTextureUnit(0, i == 1 ? s->light_tex : s->bloom_tex[i - 1]);
        volfx_gpu_fullscreen(ctx);
        volfx_pass_end(ctx);
    }
    for (uint32_t i = levels; i > 1; --i) {
        volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "beams.bloom_up", .framebuffer = s->bloom_fbo[i - 1],
                                                 .width = s->bloom_w[i - 1], .height = s->bloom_h[i - 1],
                                                 .blend = VOLFX_BLEND_ADD});
        glUseProgram(s->prog_up);
        glBindTextureUnit(0, s->bloom_tex[i]);
        volfx_gpu_fullscreen(ctx);
        volfx_pass_end(ctx);
    }
}

/* The 3-target framebuffer of a frame with water: H, the light in front of the water surface,
 * the light behind it, and a stencil (made the first frame with water, kept until a resize). */
static vfx_result split_targets(vfx_context *ctx, beams_state *s)
{
    if (s->split_fbo)
        return VFX_OK;
    s->behind_tex = make_target(GL_RGBA16F, s->grid.width, s->grid.height, false, "beams.behind_water");
    glCreateFramebuffers(1, &s->split_fbo);
    glNamedFramebufferTexture(s->split_fbo, GL_COLOR_ATTACHMENT0, s->acc_tex, 0);
    glNamedFramebufferTexture(s->split_fbo, GL_COLOR_ATTACHMENT1, s->light_tex, 0);
    glNamedFramebufferTexture(s->split_fbo, GL_COLOR_ATTACHMENT2, s->behind_tex, 0);
    glCreateRenderbuffers(1, &s->split_stencil);
    glNamedRenderbufferStorage(s->split_stencil, GL_STENCIL_INDEX8, (GLsizei)s->grid.width, (GLsizei)s->grid.height);
    glNamedFramebufferRenderbuffer(s->split_fbo, GL_STENCIL_ATTACHMENT, GL_RENDERBUFFER, s->split_stencil);
    static const GLenum bufs[3] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
    glNamedFramebufferDrawBuffers(s->split_fbo, 3, bufs);
    return volfx_gpu_check_target(ctx, s->split_fbo, "beams: H, light and behind-the-water targets", s->grid.width,
                                  s->grid.height);
}

/* The integrate pass's draws into the bound framebuffer. Without water one. With water three:
 * the stencil marks the pixels with water in front (the program's own test, so both draws agree
 * with it exactly), then those pixels get the split program (two integrals a beam) and the others
 * the dry one (one, nothing behind). In one program llvmpipe would run the second integral on
 * every pixel: it runs both sides of an if, and a discard does not skip the rest, but its early
 * stencil test skips a fragment group that fails it. Leaves the stencil test off (the baseline);
 * the host's stencil state comes back with gl_state. */
static void integrate_draws(vfx_context *ctx, beams_state *s, const GLuint prog[3], bool water)
{
    if (!water) {
        glUseProgram(prog[0]);
        volfx_gpu_fullscreen(ctx);
        return;
    }
    glStencilMask(0xffu);
    glClearNamedFramebufferiv(s->split_fbo, GL_STENCIL, 0, (const GLint[]){0});
    glEnable(GL_STENCIL_TEST);
    glStencilFunc(GL_ALWAYS, 1, 0xffu);
    glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glUseProgram(prog[DRAW_MARK]);
    volfx_gpu_fullscreen(ctx);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
    glStencilFunc(GL_EQUAL, 1, 0xffu);
    glUseProgram(prog[DRAW_WET]);
    volfx_gpu_fullscreen(ctx);
    glStencilFunc(GL_EQUAL, 0, 0xffu);
    glUseProgram(prog[DRAW_DRY]);
    volfx_gpu_fullscreen(ctx);
    glDisable(GL_STENCIL_TEST);
}

/* The first GL half of a frame, before the water's shading: uploads, the integrate (or the lab's)
 * pass into H and light (split at the water's surface when there is water: the light in front of
 * it and the light behind it), the impacts. The camera comes from the VolfxFrame block
 * (shaders/common/frame.glsl), bound by the frame gate. */
static vfx_result integrate_passes(vfx_context *ctx, beams_state *s, volfx_frame_targets *t, float c)
{
    uint32_t ntiles = s->grid.tiles_x * s->grid.tiles_y;
    vfx_result r;
    if ((r = upload(ctx, s->beam_buf, &s->beam_cap, s->gpu, s->count * sizeof(beam_gpu)))
        || (r = upload(ctx, s->range_buf, &s->range_cap, s->ranges, (size_t)ntiles * 2 * sizeof(uint32_t)))
        || (r = upload(ctx, s->list_buf, &s->list_cap, s->list, (size_t)s->pairs * sizeof(uint32_t)))
        || (r = upload(ctx, s->joint_buf, &s->joint_cap, s->joint_xyz, s->joint_used * sizeof s->joint_xyz[0])))
        return r;
    bool water = t->water_dist != 0;
    const char *pass = NULL;
    GLuint prog[3] = {integrate_program(ctx, s, water, DRAW_WET, &pass),
                      water ? integrate_program(ctx, s, water, DRAW_DRY, &pass) : 0,
                      water ? integrate_program(ctx, s, water, DRAW_MARK, &pass) : 0};
    if (!prog[0] || (water && (!prog[1] || !prog[2])))
        return VFX_ERR_GL;
    if (water && (r = split_targets(ctx, s)))
        return r;
    /* bloom: on unless the view says off */
    s->bloom = s->view.bloom != VFX_BEAMS_BLOOM_OFF;
    uint32_t levels = s->view.bloom_levels ? s->view.bloom_levels : 5;
    while (levels > 1 && ((s->grid.width >> levels) == 0 || (s->grid.height >> levels) == 0))
        levels--; /* a tiny target: no level below 1x1 */
    if (s->bloom && levels != s->bloom_levels && (r = make_bloom(ctx, s, levels)))
        return r;
    s->levels = levels;
    float strength = s->view.bloom_strength > 0 ? s->view.bloom_strength : 0.6f;
    float far = s->view.far_distance > 0 ? s->view.far_distance : t->far_plane;
    if (!(far > 0))
        far = 1e30f;
    beams_block blk = {.far = far, .c = c, .tile_px = VOLFX_BEAMS_TILE_PX, .tiles_x = (int32_t)s->grid.tiles_x,
                       .has_water = water,
                       .smooth_saturation = s->view.saturation == VFX_SATURATE_SMOOTH,
                       .bloom = s->bloom, .bloom_gain = strength / (float)levels};
    volfx_ubo_update(&s->ubo, &blk, sizeof blk);
    volfx_ubo_bind(&s->ubo, 3);

    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = s->lab_method ? pass : "beams.integrate",
                                             .framebuffer = water ? s->split_fbo : s->acc_fbo,
                                             .width = s->grid.width, .height = s->grid.height});
    glBindTextureUnit(0, t->scene_depth);
    glBindTextureUnit(1, t->water_dist);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, s->beam_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, s->range_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, s->list_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, s->joint_buf);
    integrate_draws(ctx, s, prog, water);
    volfx_pass_end(ctx);
    if ((r = volfx_beams_impact_render(ctx, s->impact, t, s->light_tex, s->time, s->dt)))
        return r;
    t->beams_light = s->light_tex;
    t->beams_behind = water ? s->behind_tex : 0;
    const char *e = volfx_gpu_error_string();
    return e ? volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR, "beams integrate: %s", e) : VFX_OK;
}

/* The prepare step (effect.h): CPU binning, then the integrate pass and the impacts, before the
 * water's shading reads the light. Reads only the frame gate (targets). */
static vfx_result beams_prepare(vfx_context *ctx, void *state, volfx_frame_targets *targets)
{
    beams_state *s = state;
    float c = s->view.saturate_c > 0 ? s->view.saturate_c : 1.f;
    vfx_result r = bin_beams(ctx, s, targets, c);
    s->prepared = r == VFX_OK && (r = integrate_passes(ctx, s, targets, c)) == VFX_OK;
    return r;
}

/* The second half, after the water and the volume: the bloom chain over the light in front of
 * the water, and the composite into the frame gate's framebuffer. */
static vfx_result beams_render(vfx_context *ctx, void *state, volfx_frame_targets *t)
{
    beams_state *s = state;
    if (!s->prepared)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_EFFECT_ORDER,
                          "beams render: the prepare step did not run this render");
    s->prepared = false;
    if (s->bloom)
        bloom_passes(ctx, s, s->levels);
    volfx_stat_set(ctx, "beams.bloom_levels", s->bloom ? s->levels : 0);
    glBindTextureUnit(0, s->light_tex);
    glBindTextureUnit(1, s->bloom ? s->bloom_tex[1] : s->light_tex);
    volfx_ubo_bind(&s->ubo, 3);
    volfx_composite_targets(ctx, t, "beams.composite", s->prog_composite, VOLFX_BLEND_ADD);
    const char *e = volfx_gpu_error_string();
    return e ? volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR, "beams render: %s", e) : VFX_OK;
}

static vfx_result beams_read_raw(vfx_context *ctx, void *state, float *out, size_t count)
{
    beams_state *s = state;
    size_t n = (size_t)s->grid.width * s->grid.height;
    if (count < n)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_READ_BUFFER_SIZE,
                          "beams read_raw: %zu floats < %zu", count, n);
    return volfx_gpu_read_top_first(ctx, s->acc_tex, GL_RED, 1, 0, s->grid.width, s->grid.height, out);
}

vfx_result volfx_beams_debug_split(vfx_context *ctx, float *out, size_t count)
{
    beams_state *s = ctx->effect_state[VFX_EFFECT_BEAMS];
    if (!s || !s->acc_tex)
        return volfx_fail(ctx, VFX_ERR_NOT_FOUND, VFX_LOG_ID_EFFECT_NOT_RENDERED,
                          "beams debug split: no beams effect or no render yet");
    size_t n = (size_t)s->grid.width * s->grid.height * 2;
    if (!out || count < n)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_READ_BUFFER_SIZE,
                          "beams debug split: %zu floats, need %zu", count, n);
    return volfx_gpu_read_top_first(ctx, s->acc_tex, GL_RG, 2, -1, s->grid.width, s->grid.height, out);
}

volfx_beams_impact *volfx_beams_impact_of(vfx_context *ctx)
{
    beams_state *s = ctx->effect_state[VFX_EFFECT_BEAMS];
    return s ? s->impact : NULL;
}

const volfx_effect_ops volfx_beams_ops = {
    .name = "beams",
    .kind = VFX_EFFECT_BEAMS,
    .present = beams_present,
    .create = beams_create,
    .destroy = beams_destroy,
    .resize = beams_resize,
    .update = beams_update,
    .prepare = beams_prepare,
    .render = beams_render,
    .read_raw = beams_read_raw,
};
