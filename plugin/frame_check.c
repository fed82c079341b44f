/* frame_check.c — see frame_check.h. The checks are GL state queries (no pipeline stall), made
 * only when an effect will draw. */
#include "frame_check.h"

#include "gpu/gpu.h"
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

vfx_result volfx_check_host(const vfx_host_api *host, char *msg, size_t msglen)
{
    struct { const char *a, *b; bool ha, hb; } pairs[] = {
        {"particle_chunk_count", "particle_chunk", host->particle_chunk_count != NULL, host->particle_chunk != NULL},
        {"volume_count", "volume", host->volume_count != NULL, host->volume != NULL},
        {"alloc", "free", host->alloc != NULL, host->free != NULL},
    };
    for (size_t i = 0; i < sizeof pairs / sizeof pairs[0]; ++i)
        if (pairs[i].ha != pairs[i].hb) {
            snprintf(msg, msglen, "host api: %s is set but %s is NULL (set both or neither)",
                     pairs[i].ha ? pairs[i].a : pairs[i].b, pairs[i].ha ? pairs[i].b : pairs[i].a);
            return VFX_ERR_INVALID_ARGUMENT;
        }
    return VFX_OK;
}

static const char *target_name(GLint t)
{
    switch (t) {
    case GL_TEXTURE_2D: return "GL_TEXTURE_2D";
    case GL_TEXTURE_CUBE_MAP: return "GL_TEXTURE_CUBE_MAP";
    case GL_TEXTURE_2D_MULTISAMPLE: return "GL_TEXTURE_2D_MULTISAMPLE";
    case GL_TEXTURE_2D_ARRAY: return "GL_TEXTURE_2D_ARRAY";
    case GL_TEXTURE_3D: return "GL_TEXTURE_3D";
    case GL_TEXTURE_1D: return "GL_TEXTURE_1D";
    case GL_TEXTURE_RECTANGLE: return "GL_TEXTURE_RECTANGLE";
    default: return "another kind of";
    }
}

enum { WANT_COLOR, WANT_DEPTH, WANT_CUBE };

static vfx_result check_texture(vfx_context *ctx, const char *field, GLuint name, int want, uint32_t w,
                                uint32_t h)
{
    if (!glIsTexture(name))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "render: frame view %s %u is not a texture name "
                          "of this GL context", field, name);
    GLint target = 0;
    glGetTextureParameteriv(name, GL_TEXTURE_TARGET, &target);
    GLint need = want == WANT_CUBE ? GL_TEXTURE_CUBE_MAP : GL_TEXTURE_2D;
    if (target != need)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "render: frame view %s %u is a %s texture, need %s",
                          field, name, target_name(target), target_name(need));
    if (want == WANT_CUBE)
        return VFX_OK;
    GLint tw = 0, th = 0, fmt = 0, dbits = 0, rbits = 0;
    glGetTextureLevelParameteriv(name, 0, GL_TEXTURE_WIDTH, &tw);
    glGetTextureLevelParameteriv(name, 0, GL_TEXTURE_HEIGHT, &th);
    glGetTextureLevelParameteriv(name, 0, GL_TEXTURE_INTERNAL_FORMAT, &fmt);
    glGetTextureLevelParameteriv(name, 0, GL_TEXTURE_DEPTH_SIZE, &dbits);
    glGetTextureLevelParameteriv(name, 0, GL_TEXTURE_RED_SIZE, &rbits);
    if (want == WANT_DEPTH && dbits == 0)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "render: frame view depth_texture %u has internal "
                          "format 0x%04x, not a depth format", name, (unsigned)fmt);
    if (want == WANT_COLOR && (dbits > 0 || rbits == 0))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "render: frame view color_texture %u has internal "
                          "format 0x%04x, not a colour format", name, (unsigned)fmt);
    if (tw != (GLint)w || th != (GLint)h)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "render: frame view %s %u is %dx%d, the frame view "
                          "%ux%u (they must match)", field, name, tw, th, w, h);
    return VFX_OK;
}

static vfx_result check_framebuffer(vfx_context *ctx, GLuint fb, uint32_t w, uint32_t h)
{
    if (!glIsFramebuffer(fb))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "render: frame view framebuffer %u is not a "
                          "framebuffer name of this GL context", fb);
    GLenum st = glCheckNamedFramebufferStatus(fb, GL_DRAW_FRAMEBUFFER);
    if (st != GL_FRAMEBUFFER_COMPLETE)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "render: frame view framebuffer %u is not complete "
                          "(status 0x%04x)", fb, (unsigned)st);
    GLint type = GL_NONE, obj = 0, aw = -1, ah = -1;
    glGetNamedFramebufferAttachmentParameteriv(fb, GL_COLOR_ATTACHMENT0, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &type);
    if (type == GL_NONE)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "render: frame view framebuffer %u has no colour "
                          "attachment 0", fb);
    glGetNamedFramebufferAttachmentParameteriv(fb, GL_COLOR_ATTACHMENT0, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME, &obj);
    if (type == GL_TEXTURE) {
        GLint level = 0;
        glGetNamedFramebufferAttachmentParameteriv(fb, GL_COLOR_ATTACHMENT0, GL_FRAMEBUFFER_ATTACHMENT_TEXTURE_LEVEL, &level);
        glGetTextureLevelParameteriv((GLuint)obj, level, GL_TEXTURE_WIDTH, &aw);
        glGetTextureLevelParameteriv((GLuint)obj, level, GL_TEXTURE_HEIGHT, &ah);
    } else if (type == GL_RENDERBUFFER) {
        glGetNamedRenderbufferParameteriv((GLuint)obj, GL_RENDERBUFFER_WIDTH, &aw);
        glGetNamedRenderbufferParameteriv((GLuint)obj, GL_RENDERBUFFER_HEIGHT, &ah);
    }
    if (aw >= 0 && (aw < (GLint)w || ah < (GLint)h))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "render: frame view framebuffer %u colour attachment "
                          "is %dx%d, smaller than the frame view %ux%u", fb, aw, ah, w, h);
    return VFX_OK;
}

/* near/far the projection maps to clip z = -w and +w (GL convention), when it is the usual
 * perspective or orthographic form; false otherwise. far may be +Inf (infinite projection). */
static bool projection_planes(const float *P, double *n, double *f, double *far_tol)
{
    double p10 = P[10], p14 = P[14];
    if (P[3] != 0 || P[7] != 0)
        return false;
    if (P[11] == -1 && P[15] == 0) {
        *n = p14 / (p10 - 1);
        *f = p10 + 1 == 0 ? INFINITY : p14 / (p10 + 1);
        /* p10 + 1 cancels: float rounding of p10 is amplified by |p10| / |p10 + 1| */
        *far_tol = 1e-3 + 8 * FLT_EPSILON * fabs(p10) / fmax(fabs(p10 + 1), 1e-30);
        return true;
    }
    if (P[11] == 0 && P[15] == 1 && p10 != 0) {
        *n = (p14 + 1) / p10;
        *f = (p14 - 1) / p10;
        *far_tol = 1e-3 + 8 * FLT_EPSILON * (fabs(p14) + 1) / fmax(fabs(p14 - 1), 1e-30);
        return true;
    }
    return false;
}

static vfx_result check_planes(vfx_context *ctx, vfx_frame_view *v)
{
    double n = 0, f = 0, ftol = 0;
    bool known = projection_planes(v->proj, &n, &f, &ftol);
    if (known && !(n > 0 && f > n))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "render: frame view proj maps near %g and far %g "
                          "(from proj[10], proj[14]); need 0 < near < far", n, f);
    if (v->near_plane == 0 && v->far_plane == 0) {
        if (!known)
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "render: frame view near_plane and far_plane are "
                              "0 and proj is neither perspective nor orthographic: give both");
        v->near_plane = (float)n;
        v->far_plane = isinf(f) || f > FLT_MAX ? FLT_MAX : (float)f;
        return VFX_OK;
    }
    if (!isfinite(v->near_plane) || !(v->near_plane > 0))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "render: frame view near_plane %g must be > 0",
                          (double)v->near_plane);
    if (!isfinite(v->far_plane) || !(v->far_plane > v->near_plane))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "render: frame view far_plane %g must be finite and "
                          "> near_plane %g", (double)v->far_plane, (double)v->near_plane);
    if (known && fabs(v->near_plane - n) > 1e-3 * n)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "render: frame view near_plane %g, but proj has near "
                          "%g", (double)v->near_plane, n);
    if (known && !isinf(f) && fabs(v->far_plane - f) > ftol * f)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "render: frame view far_plane %g, but proj has far %g",
                          (double)v->far_plane, f);
    return VFX_OK;
}

static vfx_result far_depth(vfx_context *ctx, uint32_t w, uint32_t h, unsigned *out)
{
    if (!ctx->no_depth_tex || ctx->no_depth_w != w || ctx->no_depth_h != h) {
        volfx_frame_check_destroy(ctx);
        GLuint t = 0;
        glCreateTextures(GL_TEXTURE_2D, 1, &t);
        glTextureStorage2D(t, 1, GL_DEPTH_COMPONENT32F, (GLsizei)w, (GLsizei)h);
        const float one = 1.0f;
        glClearTexImage(t, 0, GL_DEPTH_COMPONENT, GL_FLOAT, &one);
        volfx_gpu_label(GL_TEXTURE, t, "volfx.no_scene_depth");
        if (!t)
            return volfx_fail(ctx, VFX_ERR_GL, "render: could not make the far-depth texture for depth_texture 0");
        ctx->no_depth_tex = t;
        ctx->no_depth_w = w;
        ctx->no_depth_h = h;
    }
    *out = ctx->no_depth_tex;
    return VFX_OK;
}

vfx_result volfx_check_frame(vfx_context *ctx, const vfx_frame_view *frame, bool drawing,
                             vfx_frame_view2 *out, volfx_frame_targets *targets)
{
    memset(out, 0, sizeof *out);
    memcpy(out, frame, frame->version == VFX_FRAME_VIEW2_VERSION ? sizeof(vfx_frame_view2) : sizeof(vfx_frame_view));
    vfx_frame_view *v = &out->v1;
    v->size = frame->version == VFX_FRAME_VIEW2_VERSION ? sizeof(vfx_frame_view2) : sizeof(vfx_frame_view);
    for (int k = 0; k < 3; ++k)
        if (!isfinite(v->eye[k]))
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "render: frame view eye[%d] is not finite", k);
    if (!isfinite(v->fov_y) || v->fov_y < 0 || v->fov_y >= 3.14159265f)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "render: frame view fov_y %g outside [0, pi) radians",
                          (double)v->fov_y);
    if (v->effects & ~((1u << VFX_EFFECT_COUNT) - 1))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, "render: frame view effects 0x%x has bits of no effect "
                          "(known: 0x%x)", v->effects, (1u << VFX_EFFECT_COUNT) - 1);
    vfx_result r = check_planes(ctx, v);
    if (r || !drawing)
        return r;
    if (v->framebuffer && (r = check_framebuffer(ctx, v->framebuffer, v->width, v->height)))
        return r;
    if (v->color_texture && (r = check_texture(ctx, "color_texture", v->color_texture, WANT_COLOR, v->width, v->height)))
        return r;
    if (v->depth_texture && (r = check_texture(ctx, "depth_texture", v->depth_texture, WANT_DEPTH, v->width, v->height)))
        return r;
    if (frame->version == VFX_FRAME_VIEW2_VERSION && out->environment_cubemap &&
        (r = check_texture(ctx, "environment_cubemap", out->environment_cubemap, WANT_CUBE, 0, 0)))
        return r;
    if (!v->depth_texture)
        return far_depth(ctx, v->width, v->height, &targets->scene_depth);
    return VFX_OK;
}

void volfx_frame_check_destroy(vfx_context *ctx)
{
    if (ctx->no_depth_tex) {
        GLuint t = ctx->no_depth_tex;
        glDeleteTextures(1, &t);
    }
    ctx->no_depth_tex = 0;
    ctx->no_depth_w = ctx->no_depth_h = 0;
}
