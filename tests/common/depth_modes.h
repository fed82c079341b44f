/* depth_modes.h — the engine's own depth, made from a host's standard one, for tests that
 * compare effects against their float64 references under every depth the plugin accepts
 * (docs/integration.md, "The engine's own depth"): the frame view the plugin receives has the
 * host's depth
 *   DEPTH_RENDERBUFFER  copied into a depth renderbuffer (depth_texture 0),
 *   DEPTH_REVERSED      rewritten as reversed-Z with an infinite far plane under GL_ZERO_TO_ONE
 *                       (window depth near / view depth, in double, rounded once to float32), the
 *                       projection the matching reversed infinite one,
 *   DEPTH_FLIPPED       stored top row first (flip_y),
 *   DEPTH_INFINITE      the standard convention with an infinite far plane (window depth
 *                       1 - near / view depth), the projection the matching infinite one,
 *   DEPTH_ENGINE        renderbuffer, reversed and flipped at once (OGRE's render textures with
 *                       reversed-Z),
 * through the vfx_frame_depth chained into the frame view. depth_mode_render_with() does it for
 * any render call; depth_mode_set() wraps a game app's. Header-only; needs epoxy. */
#ifndef TEST_DEPTH_MODES_H
#define TEST_DEPTH_MODES_H

#include <epoxy/gl.h>
#include <stdlib.h>
#include <string.h>

#include <volfx/volfx.h>


enum { DEPTH_STANDARD = 0, DEPTH_RENDERBUFFER = 1, DEPTH_REVERSED = 2, DEPTH_FLIPPED = 4, DEPTH_INFINITE = 8,
       DEPTH_ENGINE = DEPTH_RENDERBUFFER | DEPTH_REVERSED | DEPTH_FLIPPED };

/* Every mode a test runs, with its name for messages. */
static const struct { int mode; const char *name; } depth_modes_all[] = {
    {DEPTH_RENDERBUFFER, "renderbuffer"}, {DEPTH_REVERSED, "reversed-Z, infinite, GL_ZERO_TO_ONE"},
    {DEPTH_FLIPPED, "flipped rows"}, {DEPTH_INFINITE, "infinite far"}, {DEPTH_ENGINE, "all at once"}};
#define DEPTH_MODES_COUNT (sizeof depth_modes_all / sizeof depth_modes_all[0])

typedef struct depth_mode_state {
    int mode;
    const vfx_plugin_api *real;
    vfx_plugin_api wrapped;
    GLuint tex, rb, fbo, src_fbo;
    uint32_t w, h;
} depth_mode_state;

static depth_mode_state depth_mode_g;

/* The host's depth texture read back (rows bottom first). */
static inline float *depth_mode_read(GLuint tex, uint32_t w, uint32_t h)
{
    float *d = malloc(sizeof(float) * w * h);
    glGetTextureImage(tex, 0, GL_DEPTH_COMPONENT, GL_FLOAT, (GLsizei)(sizeof(float) * w * h), d);
    return d;
}

/* Renders `in` through `render` with its depth (a standard depth_texture, or none: far) given
 * in s->mode. */
static inline vfx_result depth_mode_render_with(depth_mode_state *s,
                                                vfx_result (*render)(vfx_context *, const vfx_frame_view *),
                                                vfx_context *ctx, const vfx_frame_view *in)
{
    vfx_frame_view fv = *in;
    vfx_frame_view *v = &fv;
    uint32_t w = v->width, h = v->height;
    float *d = v->depth_texture ? depth_mode_read(v->depth_texture, w, h) : NULL;
    if (!d) { /* no depth: the far plane everywhere */
        d = malloc(sizeof(float) * w * h);
        for (size_t k = 0; k < (size_t)w * h; ++k)
            d[k] = 1.f;
    }
    const double p10 = v->proj[10], p14 = v->proj[14];
    const double n = v->near_plane > 0 ? v->near_plane : p14 / (p10 - 1.0); /* view depth at NDC -1 */
    for (uint32_t j = 0; j < h; ++j)
        for (uint32_t i = 0; i < w; ++i) {
            float *x = &d[(size_t)j * w + i];
            if (s->mode & DEPTH_REVERSED) { /* standard window depth -> view depth -> reversed */
                double D = p14 / ((2.0 * *x - 1.0) + p10);
                *x = *x >= 1.f ? 0.f : (float)(n / D);
            } else if (s->mode & DEPTH_INFINITE) { /* -> the window depth of the infinite one */
                double D = p14 / ((2.0 * *x - 1.0) + p10);
                *x = *x >= 1.f ? 1.f : (float)(1.0 - n / D);
            }
        }
    if (s->mode & DEPTH_FLIPPED)
        for (uint32_t j = 0; j < h / 2; ++j)
            for (uint32_t i = 0; i < w; ++i) {
                float t = d[(size_t)j * w + i];
                d[(size_t)j * w + i] = d[(size_t)(h - 1 - j) * w + i];
                d[(size_t)(h - 1 - j) * w + i] = t;
            }
    if (!s->tex || s->w != w || s->h != h) {
        glDeleteTextures(1, &s->tex);
        glDeleteRenderbuffers(1, &s->rb);
        glDeleteFramebuffers(1, &s->fbo);
        glDeleteFramebuffers(1, &s->src_fbo);
        glCreateTextures(GL_TEXTURE_2D, 1, &s->tex);
        glTextureStorage2D(s->tex, 1, GL_DEPTH_COMPONENT32F, (GLsizei)w, (GLsizei)h);
        glCreateRenderbuffers(1, &s->rb);
        glNamedRenderbufferStorage(s->rb, GL_DEPTH_COMPONENT32F, (GLsizei)w, (GLsizei)h);
        glCreateFramebuffers(1, &s->fbo);
        glNamedFramebufferRenderbuffer(s->fbo, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, s->rb);
        glCreateFramebuffers(1, &s->src_fbo);
        glNamedFramebufferTexture(s->src_fbo, GL_DEPTH_ATTACHMENT, s->tex, 0);
        s->w = w, s->h = h;
    }
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTextureSubImage2D(s->tex, 0, 0, 0, (GLsizei)w, (GLsizei)h, GL_DEPTH_COMPONENT, GL_FLOAT, d);
    free(d);
    v->depth_texture = s->tex;
    vfx_frame_depth fd = {.type = VFX_TYPE_FRAME_DEPTH, .next = v->next, .flip_y = (s->mode & DEPTH_FLIPPED) != 0,
                          .depth_convention = (s->mode & DEPTH_REVERSED) ? VFX_DEPTH_ZERO_TO_ONE : VFX_DEPTH_STANDARD};
    if (s->mode & DEPTH_RENDERBUFFER) {
        glBlitNamedFramebuffer(s->src_fbo, s->fbo, 0, 0, (GLint)w, (GLint)h, 0, 0, (GLint)w, (GLint)h,
                               GL_DEPTH_BUFFER_BIT, GL_NEAREST);
        fd.depth_renderbuffer = s->rb;
        v->depth_texture = 0;
    }
    if (s->mode & DEPTH_REVERSED) { /* reversed, infinite: NDC z = near / view depth */
        v->proj[10] = 0.f;
        v->proj[14] = (float)n;
        v->near_plane = v->far_plane = 0.f;
    } else if (s->mode & DEPTH_INFINITE) { /* infinite: NDC z = -1 + 2 near / view depth */
        v->proj[10] = -1.f;
        v->proj[14] = (float)(-2.0 * n);
        v->near_plane = v->far_plane = 0.f;
    }
    v->next = &fd;
    return render(ctx, v);
}

/* Deletes the GL objects of s (the state stays usable: they are remade). */
static inline void depth_mode_free(depth_mode_state *s)
{
    glDeleteTextures(1, &s->tex);
    glDeleteRenderbuffers(1, &s->rb);
    glDeleteFramebuffers(1, &s->fbo);
    glDeleteFramebuffers(1, &s->src_fbo);
    s->tex = s->rb = s->fbo = s->src_fbo = 0;
}

static inline vfx_result depth_mode_render(vfx_context *ctx, const vfx_frame_view *in)
{
    return depth_mode_render_with(&depth_mode_g, depth_mode_g.real->render, ctx, in);
}

/* From now on the app's plugin receives its depth in `mode` (DEPTH_STANDARD: as the host has it).
 * Defined where the game app's header is included. */
#ifdef GAME_APP_H
static inline void depth_mode_set(game_app *app, int mode)
{
    depth_mode_state *s = &depth_mode_g;
    if (!s->real) {
        s->real = app->api;
        s->wrapped = *app->api;
        s->wrapped.render = depth_mode_render;
    }
    s->mode = mode;
    app->api = mode ? &s->wrapped : s->real;
}
#endif

#endif
