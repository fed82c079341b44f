/* beams_impact.c — impacts and lights of the beams (issue 25, docs/beams.md "Impacts and
 * lights"). The hit of a beam with the host's depth is found on the GPU (shaders/beams/
 * impact_hit.comp), which also emits sparks and a glow spot there; impact_step.comp moves the
 * sparks (bouncing off the depth buffer) and ages the glow; impact_draw.* adds glow, sparks and
 * flares into the beams' light target before the bloom. The hits and counters are copied into a
 * ring of read-back buffers behind fences and read when a fence has passed (never a stall): the
 * stats and the impact lights are one to three frames late. */
#include "beams/beams_impact.h"

#include <math.h>
#include <string.h>

#include "gpu/gpu.h"
#include "gpu/pass.h"

#define RING 3
#define COUNTERS 8 /* hits, sparks alive, glows alive, spark cursor, glow cursor, 3 unused */
#define SPARKS_PER_S 180.f
#define GLOW_TAU_S 0.7f
#define GRAVITY 9.81f

/* std430, mirrors ImpactBeam in shaders/beams/impact_depth.glsl */
typedef struct impact_beam_gpu {
    float p[VOLFX_BEAM_MAX_JOINTS][4];
    float color[4];
    uint32_t info[4];
} impact_beam_gpu;

/* std140, mirrors ImpactFrame in shaders/beams/impact_depth.glsl */
typedef struct impact_block {
    float eye_dt[4];
    float params[4];
    uint32_t counts[4];
} impact_block;

/* A beam as set at update: its axis in the host's coordinates (head first), look. */
typedef struct impact_beam {
    double p[VOLFX_BEAM_MAX_JOINTS][3];
    uint32_t n;
    float rgb[3], gain, radius, a, b;
} impact_beam;

/* One read-back slot: counters then 3 vec4 per beam, behind a fence. */
typedef struct readback {
    GLuint buf;
    GLsync fence;
    uint32_t beams;
} readback;

struct volfx_beams_impact {
    GLuint prog_hit, prog_step, prog_glow, prog_spark, prog_flare;
    GLuint beam_buf, hit_buf, counter_buf, spark_buf, glow_buf, fbo, vao;
    volfx_ubo ubo;
    readback ring[RING];
    uint32_t ring_next;
    impact_beam *beams;
    impact_beam_gpu *gpu;
    uint32_t count, capacity;
    /* the newest read-back: */
    uint32_t impacts, sparks_alive, glows_alive, known_beams;
    float (*known_hits)[12];
    uint32_t frame;
    float emit_carry; /* fractional sparks carried to the next frame */
};

void volfx_beams_impact_destroy(vfx_context *ctx, volfx_beams_impact *im)
{
    if (!im)
        return;
    GLuint bufs[5] = {im->beam_buf, im->hit_buf, im->counter_buf, im->spark_buf, im->glow_buf};
    glDeleteBuffers(5, bufs);
    for (int k = 0; k < RING; ++k) {
        glDeleteBuffers(1, &im->ring[k].buf);
        if (im->ring[k].fence)
            glDeleteSync(im->ring[k].fence);
    }
    glDeleteFramebuffers(1, &im->fbo);
    glDeleteVertexArrays(1, &im->vao);
    volfx_ubo_destroy(&im->ubo);
    volfx_free(ctx, im->beams);
    volfx_free(ctx, im->gpu);
    volfx_free(ctx, im->known_hits);
    volfx_free(ctx, im); /* programs belong to the shared cache */
}

vfx_result volfx_beams_impact_create(vfx_context *ctx, volfx_beams_impact **out)
{
    volfx_beams_impact *im = volfx_alloc(ctx, sizeof *im);
    if (!im)
        return VFX_ERR_OUT_OF_MEMORY;
    im->known_hits = volfx_alloc(ctx, VOLFX_IMPACT_MAX_BEAMS * sizeof *im->known_hits);
    im->prog_hit = volfx_gpu_compute(ctx, "beams/impact_hit.comp", NULL);
    im->prog_step = volfx_gpu_compute(ctx, "beams/impact_step.comp", NULL);
    im->prog_glow = volfx_gpu_program(ctx, "beams/impact_draw.vert", "beams/impact_draw.frag", "#define GLOW 1");
    im->prog_spark = volfx_gpu_program(ctx, "beams/impact_draw.vert", "beams/impact_draw.frag", "#define SPARK 1");
    im->prog_flare = volfx_gpu_program(ctx, "beams/impact_draw.vert", "beams/impact_draw.frag", "#define FLARE 1");
    if (!im->known_hits || !im->prog_hit || !im->prog_step || !im->prog_glow || !im->prog_spark || !im->prog_flare
        || !volfx_ubo_create(ctx, &im->ubo, sizeof(impact_block), "beams.impact_frame")) {
        volfx_beams_impact_destroy(ctx, im);
        return im->known_hits ? VFX_ERR_GL : VFX_ERR_OUT_OF_MEMORY;
    }
    /* pools zeroed: lifetime 0 is dead */
    im->hit_buf = volfx_gpu_storage(VOLFX_IMPACT_MAX_BEAMS * 3 * 16, "beams.impact_hits");
    im->beam_buf = volfx_gpu_storage(VOLFX_IMPACT_MAX_BEAMS * sizeof(impact_beam_gpu), "beams.impact_beams");
    im->counter_buf = volfx_gpu_storage(COUNTERS * 4, "beams.impact_counters");
    im->spark_buf = volfx_gpu_storage(VOLFX_IMPACT_MAX_SPARKS * 3 * 16, "beams.sparks");
    im->glow_buf = volfx_gpu_storage(VOLFX_IMPACT_MAX_GLOWS * 3 * 16, "beams.glows");
    GLuint zero = 0;
    GLuint bufs[5] = {im->hit_buf, im->beam_buf, im->counter_buf, im->spark_buf, im->glow_buf};
    for (int k = 0; k < 5; ++k)
        glClearNamedBufferData(bufs[k], GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    for (int k = 0; k < RING; ++k) {
        glCreateBuffers(1, &im->ring[k].buf);
        glNamedBufferStorage(im->ring[k].buf, COUNTERS * 4 + VOLFX_IMPACT_MAX_BEAMS * 3 * 16, NULL,
                             GL_CLIENT_STORAGE_BIT);
        volfx_gpu_label(GL_BUFFER, im->ring[k].buf, "beams.impact_readback");
    }
    glCreateFramebuffers(1, &im->fbo);
    glCreateVertexArrays(1, &im->vao);
    const char *e = volfx_gpu_error_string();
    if (e) {
        volfx_beams_impact_destroy(ctx, im);
        return volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR, "beams impact: buffers: %s", e);
    }
    *out = im;
    return VFX_OK;
}

bool volfx_beams_impact_set_count(vfx_context *ctx, volfx_beams_impact *im, uint32_t n)
{
    if (n > VOLFX_IMPACT_MAX_BEAMS)
        n = VOLFX_IMPACT_MAX_BEAMS;
    if (n > im->capacity) {
        volfx_free(ctx, im->beams);
        volfx_free(ctx, im->gpu);
        im->beams = volfx_alloc(ctx, n * sizeof *im->beams);
        im->gpu = volfx_alloc(ctx, n * sizeof *im->gpu);
        im->capacity = im->beams && im->gpu ? n : 0;
        if (!im->capacity) {
            im->count = 0;
            return false;
        }
    }
    im->count = n;
    return true;
}

void volfx_beams_impact_set_beam(volfx_beams_impact *im, uint32_t i, const volfx_beam_d *b, const float rgb[3],
                                 float gain)
{
    if (i >= im->count)
        return;
    impact_beam *o = &im->beams[i];
    if (b->joint_count >= 2) {
        o->n = (uint32_t)b->joint_count;
        memcpy(o->p, b->joints, o->n * sizeof o->p[0]);
    } else {
        o->n = b->length > 0 ? 2 : 1; /* an orb (length 0) has no axis: no impact */
        for (int k = 0; k < 3; ++k)
            o->p[0][k] = b->head[k], o->p[1][k] = b->head[k] + b->length * b->dir[k];
    }
    memcpy(o->rgb, rgb, sizeof o->rgb);
    o->gain = gain, o->radius = (float)b->radius, o->a = (float)b->a, o->b = (float)b->b;
}

/* Takes the newest read-back whose fence has passed (waiting for none). */
static void poll_readbacks(vfx_context *ctx, volfx_beams_impact *im)
{
    (void)ctx;
    for (uint32_t k = 0; k < RING; ++k) {
        readback *rb = &im->ring[(im->ring_next + k) % RING]; /* oldest first */
        if (!rb->fence)
            continue;
        GLenum st = glClientWaitSync(rb->fence, 0, 0);
        if (st != GL_ALREADY_SIGNALED && st != GL_CONDITION_SATISFIED)
            continue;
        glDeleteSync(rb->fence);
        rb->fence = 0;
        uint32_t c[COUNTERS];
        glGetNamedBufferSubData(rb->buf, 0, sizeof c, c);
        im->impacts = c[0], im->sparks_alive = c[1], im->glows_alive = c[2];
        im->known_beams = rb->beams;
        if (rb->beams)
            glGetNamedBufferSubData(rb->buf, sizeof c, (GLsizeiptr)rb->beams * 48, im->known_hits);
    }
}

/* Copies counters and hits into the next ring slot behind a fence (a slot still in flight is
 * dropped: its frame's figures are skipped, never waited for). */
static void issue_readback(volfx_beams_impact *im, uint32_t beams)
{
    readback *rb = &im->ring[im->ring_next];
    im->ring_next = (im->ring_next + 1) % RING;
    if (rb->fence)
        glDeleteSync(rb->fence);
    glCopyNamedBufferSubData(im->counter_buf, rb->buf, 0, 0, COUNTERS * 4);
    if (beams)
        glCopyNamedBufferSubData(im->hit_buf, rb->buf, 0, COUNTERS * 4, (GLsizeiptr)beams * 48);
    rb->beams = beams;
    rb->fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
}

/* The beams camera-relative for the hit pass; how many have an axis on screen. */
static uint32_t pack(volfx_beams_impact *im, const volfx_frame_targets *t)
{
    uint32_t live = 0;
    for (uint32_t i = 0; i < im->count; ++i) {
        const impact_beam *b = &im->beams[i];
        impact_beam_gpu *g = &im->gpu[i];
        memset(g, 0, sizeof *g);
        double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
        for (uint32_t j = 0; j < b->n; ++j)
            for (int k = 0; k < 3; ++k) {
                double x = b->p[j][k] - t->view_eye[k];
                g->p[j][k] = (float)x;
                lo[k] = fmin(lo[k], x), hi[k] = fmax(hi[k], x);
            }
        for (int k = 0; k < 3; ++k)
            g->color[k] = b->rgb[k] * b->gain;
        g->color[3] = b->radius;
        g->info[0] = b->n >= 2 ? b->n : 0;
        if (!g->info[0])
            continue;
        /* on screen: the bounding box of the axis (plus R) against the clip volume, conservative */
        bool out_l = true, out_r = true, out_b = true, out_t = true, out_near = true;
        for (int c = 0; c < 8; ++c) {
            double q[3] = {(c & 1) ? hi[0] + b->radius : lo[0] - b->radius,
                           (c & 2) ? hi[1] + b->radius : lo[1] - b->radius,
                           (c & 4) ? hi[2] + b->radius : lo[2] - b->radius};
            const float *m = t->cam_view_proj;
            double x = m[0] * q[0] + m[4] * q[1] + m[8] * q[2] + m[12];
            double y = m[1] * q[0] + m[5] * q[1] + m[9] * q[2] + m[13];
            double w = m[3] * q[0] + m[7] * q[1] + m[11] * q[2] + m[15];
            out_l &= x < -w, out_r &= x > w, out_b &= y < -w, out_t &= y > w, out_near &= w <= 0;
        }
        live += !(out_l || out_r || out_b || out_t || out_near);
    }
    return live;
}

vfx_result volfx_beams_impact_render(vfx_context *ctx, volfx_beams_impact *im, const volfx_frame_targets *t,
                                     unsigned light, double time, float dt)
{
    poll_readbacks(ctx, im);
    uint32_t live = pack(im, t);
    bool alive = im->impacts || im->sparks_alive || im->glows_alive;
    volfx_stat_set(ctx, "beams.impacts", im->impacts);
    volfx_stat_set(ctx, "beams.sparks", im->sparks_alive);
    vfx_lights none = {.type = VFX_TYPE_LIGHTS};
    volfx_beams_impact_lights(im, &none);
    volfx_stat_set(ctx, "beams.lights", none.total);
    if (!live && !alive)
        return VFX_OK; /* an absent impact costs nothing */
    float want = SPARKS_PER_S * dt + im->emit_carry;
    uint32_t emit = want > 32.f ? 32u : (uint32_t)want;
    im->emit_carry = want > 32.f ? 0.f : want - (float)emit;
    impact_block blk = {.eye_dt = {(float)t->view_eye[0], (float)t->view_eye[1], (float)t->view_eye[2], dt},
                        .params = {(float)fmod(time, 4096.0), GRAVITY, 0.025f, GLOW_TAU_S},
                        .counts = {live ? im->count : 0, emit, im->frame++, t->water_dist != 0}};
    volfx_ubo_update(&im->ubo, &blk, sizeof blk);
    volfx_ubo_bind(&im->ubo, 5);
    glNamedBufferSubData(im->beam_buf, 0, (GLsizeiptr)(im->count ? im->count : 1) * sizeof(impact_beam_gpu), im->gpu);
    GLuint zero = 0;
    glClearNamedBufferSubData(im->counter_buf, GL_R32UI, 0, 3 * 4, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    glBindTextureUnit(0, t->scene_depth);
    if (t->water_dist)
        glBindTextureUnit(1, t->water_dist);
    GLuint bufs[5] = {im->beam_buf, im->hit_buf, im->counter_buf, im->spark_buf, im->glow_buf};
    for (GLuint k = 0; k < 5; ++k)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, k, bufs[k]);
    if (alive) {
        volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "beams.impact_step", .compute = true});
        glUseProgram(im->prog_step);
        glDispatchCompute(VOLFX_IMPACT_MAX_SPARKS / 64, 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        volfx_pass_end(ctx);
    }
    if (live) {
        volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "beams.impact_hit", .compute = true});
        glUseProgram(im->prog_hit);
        glDispatchCompute((im->count + 63) / 64, 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
        volfx_pass_end(ctx);
    } else {
        glClearNamedBufferData(im->hit_buf, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    }
    if (alive) { /* what the last read-back saw alive, or hit: draw (a new hit shows from its read-back on) */
        glNamedFramebufferTexture(im->fbo, GL_COLOR_ATTACHMENT0, light, 0);
        volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "beams.impact_draw", .framebuffer = im->fbo,
                                                 .width = t->width, .height = t->height,
                                                 .blend = VOLFX_BLEND_ADD});
        glBindVertexArray(im->vao);
        glUseProgram(im->prog_glow);
        glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, VOLFX_IMPACT_MAX_GLOWS);
        glUseProgram(im->prog_spark);
        glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, VOLFX_IMPACT_MAX_SPARKS);
        if (live) {
            glUseProgram(im->prog_flare);
            glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, (GLsizei)im->count);
        }
        glBindVertexArray(0);
        volfx_pass_end(ctx);
    }
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    issue_readback(im, live ? im->count : 0);
    const char *e = volfx_gpu_error_string();
    return e ? volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR, "beams impact: %s", e) : VFX_OK;
}

/* The distance past which a light's irradiance at normal incidence is below 1/256 of its value
 * at 1 unit: a point's I/d^2 at d = 16; a line's, facing the segment's middle (its strongest
 * bearing), E(d) = I L / (d sqrt(d^2 + L^2/4)), so E(d) = E(1) / 256 where
 * d^2 (d^2 + q) = K^2, q = L^2/4, K = 256 sqrt(1 + q): d^2 = (sqrt(q^2 + 4 K^2) - q) / 2. (The
 * former max(16, 16 sqrt(L / 2)), the two asymptotes, fell short between them: 13% at L = 2.3;
 * test beams_impact test_light_formulas.) */
static float light_radius(vfx_light_kind kind, float len)
{
    if (kind == VFX_LIGHT_POINT)
        return 16.f;
    double q = 0.25 * (double)len * len, k2 = 65536.0 * (1.0 + q);
    /* q^2 + 4 K^2 - q^2 over the sum: no cancellation when q is large */
    double d2 = 2.0 * k2 / (sqrt(q * q + 4.0 * k2) + q);
    return (float)sqrt(d2) * (1.f + 1e-6f); /* rounded outwards: "below" at the radius */
}

static void put_light(vfx_lights *out, vfx_light_kind kind, vfx_light_source src, uint32_t index, const double p0[3],
                      const double p1[3], const float rgb[3], float intensity)
{
    uint32_t k = out->total++;
    if (k >= out->capacity)
        return;
    vfx_light *l = &out->lights[k];
    memset(l, 0, sizeof *l);
    l->kind = kind, l->source = src, l->index = index;
    double len2 = 0;
    for (int c = 0; c < 3; ++c) {
        l->p0[c] = (float)p0[c], l->p1[c] = (float)p1[c];
        len2 += (p1[c] - p0[c]) * (p1[c] - p0[c]);
    }
    /* colour normalised to a largest component of 1, its scale moved into the intensity */
    float m = fmaxf(rgb[0], fmaxf(rgb[1], rgb[2]));
    for (int c = 0; c < 3; ++c)
        l->color[c] = m > 0 ? rgb[c] / m : 0.f;
    l->intensity = m > 0 ? intensity * m : 0.f;
    l->radius = light_radius(kind, (float)sqrt(len2));
    out->count = out->total < out->capacity ? out->total : out->capacity;
}

/* Light levels of the beams' parts, chosen so a beam 1 m above a floor lights it to about the
 * level of the dusk scene's sun (docs/beams.md "Lights"). */
#define BODY_INTENSITY 3.0f  /* per unit length, x the trail strength b / 0.5 */
#define HEAD_INTENSITY 4.0f  /* x the head strength a */
#define IMPACT_INTENSITY 8.0f

void volfx_beams_impact_lights(const volfx_beams_impact *im, vfx_lights *out)
{
    out->count = out->total = 0;
    for (uint32_t i = 0; i < im->count; ++i) {
        const impact_beam *b = &im->beams[i];
        for (uint32_t j = 0; j + 1 < b->n && b->b > 0; ++j)
            put_light(out, VFX_LIGHT_LINE, VFX_LIGHT_BEAM_BODY, i, b->p[j], b->p[j + 1], b->rgb,
                      BODY_INTENSITY * b->gain * b->b / 0.5f);
        if (b->a > 0)
            put_light(out, VFX_LIGHT_POINT, VFX_LIGHT_BEAM_HEAD, i, b->p[0], b->p[0], b->rgb,
                      HEAD_INTENSITY * b->gain * b->a);
    }
    for (uint32_t i = 0; i < im->known_beams && i < im->count; ++i) {
        const float *h = im->known_hits[i];
        if (h[3] == 0.f)
            continue;
        /* a little off the surface, so the surface under it is lit at a finite level */
        double p[3];
        for (int k = 0; k < 3; ++k)
            p[k] = (double)h[k] + 0.5 * im->beams[i].radius * h[4 + k];
        put_light(out, VFX_LIGHT_POINT, VFX_LIGHT_BEAM_IMPACT, i, p, p, im->beams[i].rgb,
                  IMPACT_INTENSITY * im->beams[i].gain);
    }
}

uint32_t volfx_beams_impact_water_events(const volfx_beams_impact *im, volfx_impact_event *out, uint32_t cap)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < im->known_beams && i < im->count; ++i) {
        const float *h = im->known_hits[i];
        const impact_beam *b = &im->beams[i];
        if (h[3] == 0.f || h[7] == 0.f || b->n < 2)
            continue;
        if (n < cap) {
            volfx_impact_event *e = &out[n];
            /* the direction of travel: from the segment behind the head toward the head */
            double d[3], len = 0;
            for (int k = 0; k < 3; ++k)
                d[k] = b->p[0][k] - b->p[1][k], len += d[k] * d[k];
            len = sqrt(len);
            for (int k = 0; k < 3; ++k) {
                e->position[k] = h[k];
                e->normal[k] = h[4 + k];
                e->direction[k] = len > 0 ? (float)(d[k] / len) : -h[4 + k];
            }
            float m = fmaxf(b->rgb[0], fmaxf(b->rgb[1], b->rgb[2]));
            e->energy = IMPACT_INTENSITY * b->gain * m;
            e->beam = i;
        }
        n++;
    }
    return n;
}

uint32_t volfx_beams_impact_debug_hits(volfx_beams_impact *im, float (*out)[8], uint32_t n)
{
    n = n < im->count ? n : im->count;
    for (uint32_t i = 0; i < n; ++i)
        glGetNamedBufferSubData(im->hit_buf, (GLintptr)i * 48, 32, out[i]);
    return n;
}

uint32_t volfx_beams_impact_debug_sparks(volfx_beams_impact *im, float (*out)[12], uint32_t n)
{
    n = n < VOLFX_IMPACT_MAX_SPARKS ? n : VOLFX_IMPACT_MAX_SPARKS;
    glGetNamedBufferSubData(im->spark_buf, 0, (GLsizeiptr)n * 48, out);
    return VOLFX_IMPACT_MAX_SPARKS;
}
