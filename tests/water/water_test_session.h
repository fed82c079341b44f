/* water_test_session.h — a plugin context over a test_particle_host drawing into a small RGBA8
 * target, counters read synchronously (water_diffuse, water_foam). */
#ifndef WATER_TEST_SESSION_H
#define WATER_TEST_SESSION_H

#include <epoxy/gl.h>
#include <string.h>

#include "context.h"
#include "test_particle_host.h"

typedef struct water_session {
    vfx_plugin_api api;
    vfx_context *ctx;
    GLuint fbo, col;
    vfx_frame_view fv;
} water_session;

/* A context over h, a w x hh target, the camera at `eye` looking down -z (the draws run too),
 * and this frame's counters in every stat (ctx->debug.sync_counters). */
static inline void water_session_open(water_session *ss, test_particle_host *h, uint32_t w, uint32_t hh,
                                      const float eye[3])
{
    memset(ss, 0, sizeof *ss);
    vfx_context_desc api = test_particle_host_desc(h);
    ss->api.type = VFX_TYPE_PLUGIN_API;
    assert_int_equal(vfx_plugin_entry(VFX_ABI_VERSION, NULL, &ss->api), VFX_OK);
    assert_int_equal(ss->api.create(&api, &ss->ctx), VFX_OK);
    ss->ctx->debug.sync_counters = true;
    glCreateTextures(GL_TEXTURE_2D, 1, &ss->col);
    glTextureStorage2D(ss->col, 1, GL_RGBA8, (GLsizei)w, (GLsizei)hh);
    glCreateFramebuffers(1, &ss->fbo);
    glNamedFramebufferTexture(ss->fbo, GL_COLOR_ATTACHMENT0, ss->col, 0);
    ss->fv = (vfx_frame_view){.type = VFX_TYPE_FRAME_VIEW, .framebuffer = ss->fbo, .width = w, .height = hh};
    test_frame_view_look(&ss->fv, eye, 0.0f);
}

/* One update of dt seconds and one render. */
static inline void water_session_frame(water_session *ss, float dt)
{
    assert_int_equal(ss->api.update(ss->ctx, 0.0, dt), VFX_OK);
    assert_int_equal(ss->api.render(ss->ctx, &ss->fv), VFX_OK);
}

/* The stat `name` of the last frame, or -1. */
static inline double water_session_stat(water_session *ss, const char *name)
{
    return test_stat(&ss->api, ss->ctx, name);
}

static inline void water_session_close(water_session *ss)
{
    ss->api.destroy(ss->ctx);
    glDeleteFramebuffers(1, &ss->fbo);
    glDeleteTextures(1, &ss->col);
}

#endif
