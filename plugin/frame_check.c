/* frame_check.c — see frame_check.h. The checks are GL state queries (no pipeline stall), made
 * only when an effect will draw. */
#include "frame_check.h"

#include "gpu/gpu.h"
#include "gpu/pass.h"
#include "param_ranges.h"
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

vfx_result volfx_check_host(const vfx_context_desc *host, char *msg, size_t msglen)
{
    struct { const char *a, *b; bool ha, hb; } pairs[] = {
        {"particle_chunk_count", "particle_chunk", host->particle_chunk_count != NULL, host->particle_chunk != NULL},
        {"volume_count", "volume", host->volume_count != NULL, host->volume != NULL},
        {"alloc", "free", host->alloc != NULL, host->free != NULL},
    };
    for (size_t i = 0; i < sizeof pairs / sizeof pairs[0]; ++i)
        if (pairs[i].ha != pairs[i].hb) {
            snprintf(msg, msglen, "context desc: %s is set but %s is NULL (set both or neither)",
                     pairs[i].ha ? pairs[i].a : pairs[i].b, pairs[i].ha ? pairs[i].b : pairs[i].a);
            return VFX_ERR_INVALID_ARGUMENT;
        }
    return VFX_OK;
}

static const char *target_name(GLint t)
{
    switch (t) {
    case GL_TEXTURE_2D: return "a GL_TEXTURE_2D";
    case GL_TEXTURE_CUBE_MAP: return "a GL_TEXTURE_CUBE_MAP";
    case GL_TEXTURE_2D_MULTISAMPLE: return "a GL_TEXTURE_2D_MULTISAMPLE";
    case GL_TEXTURE_2D_ARRAY: return "a GL_TEXTURE_2D_ARRAY";
    case GL_TEXTURE_3D: return "a GL_TEXTURE_3D";
    case GL_TEXTURE_1D: return "a GL_TEXTURE_1D";
    case GL_TEXTURE_RECTANGLE: return "a GL_TEXTURE_RECTANGLE";
    default: return "an unknown kind of";
    }
}

static GLenum binding_of(GLenum target)
{
    switch (target) {
    case GL_TEXTURE_2D: return GL_TEXTURE_BINDING_2D;
    case GL_TEXTURE_CUBE_MAP: return GL_TEXTURE_BINDING_CUBE_MAP;
    case GL_TEXTURE_2D_MULTISAMPLE: return GL_TEXTURE_BINDING_2D_MULTISAMPLE;
    case GL_TEXTURE_2D_ARRAY: return GL_TEXTURE_BINDING_2D_ARRAY;
    case GL_TEXTURE_3D: return GL_TEXTURE_BINDING_3D;
    case GL_TEXTURE_1D: return GL_TEXTURE_BINDING_1D;
    default: return GL_TEXTURE_BINDING_RECTANGLE;
    }
}

/* The target a texture was made for. GL_TEXTURE_TARGET answers in a core context; Mesa's
 * compatibility profile refuses that query (GL_INVALID_ENUM, nothing written), so there each
 * candidate target is tried by binding the texture to it on unit 0 (binding to another target
 * than its own is GL_INVALID_OPERATION) and the unit's binding put back at once. That path reads
 * the GL error flag, so it clears errors the host left pending: only compatibility contexts. */
static GLint texture_target(GLuint name)
{
    GLint target = 0;
    glGetTextureParameteriv(name, GL_TEXTURE_TARGET, &target);
    if (target)
        return target;
    for (int i = 0; i < 8 && glGetError() != GL_NO_ERROR; ++i)
        ;
    static const GLenum candidates[] = {GL_TEXTURE_2D, GL_TEXTURE_CUBE_MAP, GL_TEXTURE_2D_MULTISAMPLE,
                                        GL_TEXTURE_2D_ARRAY, GL_TEXTURE_3D, GL_TEXTURE_1D, GL_TEXTURE_RECTANGLE};
    GLint active = GL_TEXTURE0;
    glGetIntegerv(GL_ACTIVE_TEXTURE, &active);
    glActiveTexture(GL_TEXTURE0);
    for (size_t i = 0; i < sizeof candidates / sizeof candidates[0] && !target; ++i) {
        GLint prev = 0;
        glGetIntegerv(binding_of(candidates[i]), &prev);
        glBindTexture(candidates[i], name);
        if (glGetError() == GL_NO_ERROR)
            target = (GLint)candidates[i];
        glBindTexture(candidates[i], (GLuint)prev);
    }
    glActiveTexture((GLenum)active);
    return target;
}

enum { WANT_COLOR, WANT_DEPTH, WANT_CUBE };

static vfx_result check_texture(vfx_context *ctx, const char *field, GLuint name, int want, uint32_t w,
                                uint32_t h)
{
    if (!glIsTexture(name))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: frame view %s %u is not a texture name "
                          "of this GL context", field, name);
    GLint target = texture_target(name);
    GLint need = want == WANT_CUBE ? GL_TEXTURE_CUBE_MAP : GL_TEXTURE_2D;
    if (target != need)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: frame view %s %u is %s texture, need %s texture",
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
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: frame view depth_texture %u has internal "
                          "format 0x%04x, not a depth format", name, (unsigned)fmt);
    if (want == WANT_COLOR && (dbits > 0 || rbits == 0))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: frame view color_texture %u has internal "
                          "format 0x%04x, not a colour format", name, (unsigned)fmt);
    if (tw != (GLint)w || th != (GLint)h)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: frame view %s %u is %dx%d, the frame view "
                          "%ux%u (they must match)", field, name, tw, th, w, h);
    return VFX_OK;
}

static vfx_result check_framebuffer(vfx_context *ctx, GLuint fb, uint32_t w, uint32_t h, bool *srgb)
{
    if (!glIsFramebuffer(fb))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: frame view framebuffer %u is not a "
                          "framebuffer name of this GL context", fb);
    GLenum st = glCheckNamedFramebufferStatus(fb, GL_DRAW_FRAMEBUFFER);
    if (st != GL_FRAMEBUFFER_COMPLETE)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: frame view framebuffer %u is not complete "
                          "(status 0x%04x)", fb, (unsigned)st);
    GLint type = GL_NONE, obj = 0, aw = -1, ah = -1;
    glGetNamedFramebufferAttachmentParameteriv(fb, GL_COLOR_ATTACHMENT0, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &type);
    if (type == GL_NONE)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: frame view framebuffer %u has no colour "
                          "attachment 0", fb);
    glGetNamedFramebufferAttachmentParameteriv(fb, GL_COLOR_ATTACHMENT0, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME, &obj);
    GLint encoding = GL_LINEAR;
    glGetNamedFramebufferAttachmentParameteriv(fb, GL_COLOR_ATTACHMENT0, GL_FRAMEBUFFER_ATTACHMENT_COLOR_ENCODING,
                                               &encoding);
    *srgb = encoding == GL_SRGB;
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
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: frame view framebuffer %u colour attachment "
                          "is %dx%d, smaller than the frame view %ux%u", fb, aw, ah, w, h);
    return VFX_OK;
}

/* near/far the projection maps to clip z = -w and +w (GL convention), when it is the usual
 * perspective or orthographic form; false otherwise. far may be +Inf (infinite projection). */
bool volfx_projection_planes(const float *P, double *n, double *f, double *far_tol)
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
    bool known = volfx_projection_planes(v->proj, &n, &f, &ftol);
    if (known && !(n > 0 && f > n))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW, "render: frame view proj maps near %g and far %g "
                          "(from proj[10], proj[14]); need 0 < near < far (a reversed-Z proj needs a chained "
                          "vfx_frame_depth)", n, f);
    if (v->near_plane == 0 && v->far_plane == 0) {
        if (!known)
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                              "render: frame view near_plane and far_plane are "
                              "0 and proj is neither perspective nor orthographic: give both");
        v->near_plane = (float)n;
        v->far_plane = isinf(f) || f > FLT_MAX ? FLT_MAX : (float)f;
        return VFX_OK;
    }
    if (!isfinite(v->near_plane) || !(v->near_plane > 0))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: frame view near_plane %g must be > 0",
                          (double)v->near_plane);
    if (!isfinite(v->far_plane) || !(v->far_plane > v->near_plane))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: frame view far_plane %g must be finite and "
                          "> near_plane %g", (double)v->far_plane, (double)v->near_plane);
    if (known && fabs(v->near_plane - n) > 1e-3 * n)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: frame view near_plane %g, but proj has near "
                          "%g", (double)v->near_plane, n);
    if (known && !isinf(f) && fabs(v->far_plane - f) > ftol * f)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: frame view far_plane %g, but proj has far %g",
                          (double)v->far_plane, f);
    return VFX_OK;
}

static void drop_far_depth(vfx_context *ctx)
{
    if (ctx->no_depth_tex) {
        GLuint t = ctx->no_depth_tex;
        glDeleteTextures(1, &t);
    }
    ctx->no_depth_tex = 0;
    ctx->no_depth_w = ctx->no_depth_h = 0;
}

static vfx_result far_depth(vfx_context *ctx, uint32_t w, uint32_t h, unsigned *out)
{
    if (!ctx->no_depth_tex || ctx->no_depth_w != w || ctx->no_depth_h != h) {
        drop_far_depth(ctx);
        GLuint t = 0;
        glCreateTextures(GL_TEXTURE_2D, 1, &t);
        glTextureStorage2D(t, 1, GL_DEPTH_COMPONENT32F, (GLsizei)w, (GLsizei)h);
        const float one = 1.0f;
        glClearTexImage(t, 0, GL_DEPTH_COMPONENT, GL_FLOAT, &one);
        volfx_gpu_label(GL_TEXTURE, t, "volfx.no_scene_depth");
        if (!t)
            return volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR,
                              "render: could not make the far-depth texture for depth_texture 0");
        ctx->no_depth_tex = t;
        ctx->no_depth_w = w;
        ctx->no_depth_h = h;
    }
    *out = ctx->no_depth_tex;
    return VFX_OK;
}

/* The view's type, the frame size and the matrices' finiteness; *checked gets a copy. */
static vfx_result read_view(vfx_context *ctx, const vfx_frame_view *frame, uint32_t *view_id,
                            vfx_frame_view *checked)
{
    vfx_result r = volfx_check_type(ctx, frame, VFX_TYPE_FRAME_VIEW, "render: frame view (vfx_frame_view)");
    if (r)
        return r;
    *view_id = frame->view_id;
    if (frame->width == 0 || frame->height == 0)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: frame is %ux%u", frame->width,
                          frame->height);
    for (int i = 0; i < 16; ++i)
        if (!isfinite(frame->view[i]) || !isfinite(frame->proj[i]))
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                              "render: camera matrix element %d is not finite", i);
    *checked = *frame;
    checked->next = NULL;
    return VFX_OK;
}

/* The engine's own depth, step 1 (no GL): a projection written for another clip control or
 * reversed (near at depth 1), or stored row-flipped, becomes the standard projection of the same
 * camera that every effect reads (GL_NEGATIVE_ONE_TO_ONE, near at -1, far +1, +Inf allowed); the
 * host's depth is then rewritten for it (depth_convert, step 2). Flipped rows are a projection
 * whose y is negated: what the effects draw and read lands on the stored rows, no copy. */
static vfx_result standardize(vfx_context *ctx, vfx_frame_view *v, volfx_frame_targets *t)
{
    const volfx_frame_depth *fd = &ctx->frame_depth;
    float *P = v->proj;
    bool persp = P[3] == 0 && P[7] == 0 && P[11] == -1 && P[15] == 0;
    bool ortho = P[3] == 0 && P[7] == 0 && P[11] == 0 && P[15] == 1 && P[10] != 0;
    double p10 = P[10], p14 = P[14], lo = fd->zero_to_one ? 0.0 : -1.0;
    /* view depth at NDC z = a: perspective p14 / (a + p10), orthographic (p14 - a) / p10 */
    double d_lo = persp ? (lo + p10 == 0 ? INFINITY : p14 / (lo + p10)) : ortho ? (p14 - lo) / p10 : 0;
    double d_hi = persp ? (1 + p10 == 0 ? INFINITY : p14 / (1 + p10)) : ortho ? (p14 - 1) / p10 : 0;
    /* reversed-Z only from a host that chained a vfx_frame_depth: without one a proj whose near
     * lies beyond its far stays the mistake check_planes refuses (as a 1.0 plugin does) */
    bool reversed = fd->chained && (persp || ortho) && d_lo > d_hi;
    if (fd->zero_to_one || reversed) {
        if ((!persp && !ortho) || P[2] != 0 || P[6] != 0)
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_DEPTH, "render: frame view proj is neither a perspective nor "
                              "an orthographic projection with z from view depth alone (proj[2], proj[6] 0): "
                              "its GL_ZERO_TO_ONE depth cannot be converted");
        double n = fmin(d_lo, d_hi), f = fmax(d_lo, d_hi);
        if (!(n > 0) || !(f > n) || (!persp && isinf(f)))
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_DEPTH, "render: frame view proj (%s clip depth) maps its depth "
                              "range to view depths %g and %g; need 0 < near < far", fd->zero_to_one ?
                              "GL_ZERO_TO_ONE" : "GL_NEGATIVE_ONE_TO_ONE", d_lo, d_hi);
        double s10, s14;
        if (persp && isinf(f))
            s10 = -1, s14 = -2 * n;
        else if (persp)
            s10 = -(f + n) / (f - n), s14 = -2 * f * n / (f - n);
        else
            s10 = -2 / (f - n), s14 = -(f + n) / (f - n);
        t->depth_convert = true;
        t->depth_host[0] = p10, t->depth_host[1] = p14, t->depth_host[2] = fd->zero_to_one, t->depth_host[3] = persp;
        t->depth_std[0] = s10, t->depth_std[1] = s14;
        P[10] = (float)s10, P[14] = (float)s14;
        /* the host's own planes must be the projection's (as check_planes asks of a standard one);
         * then the planes come from the new projection (far FLT_MAX when infinite) */
        if ((v->near_plane != 0 || v->far_plane != 0)
            && (fabs(v->near_plane - n) > 1e-3 * n || (!isinf(f) && fabs(v->far_plane - f) > 1e-3 * f)))
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_DEPTH, "render: frame view near_plane %g, far_plane %g, but "
                              "proj (%s clip depth) has near %g, far %g", (double)v->near_plane,
                              (double)v->far_plane, fd->zero_to_one ? "GL_ZERO_TO_ONE" : "GL_NEGATIVE_ONE_TO_ONE", n, f);
        v->near_plane = v->far_plane = 0;
    }
    if (fd->flip_y)
        for (int c = 0; c < 4; ++c)
            P[c * 4 + 1] = -P[c * 4 + 1];
    return VFX_OK;
}

/* Cofactors in double (volfx_mat4_invert), so near-singular projections keep their digits. */
static vfx_result derive_camera(vfx_context *ctx, const vfx_frame_view *checked, volfx_frame_targets *t)
{
    const vfx_frame_view *v = checked;
    volfx_mat4_mul(v->proj, v->view, t->view_proj);
    if (!volfx_mat4_invert(t->view_proj, t->inv_view_proj))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: view*projection is singular");
    if (!volfx_mat4_invert(v->view, t->inv_view))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: view matrix is singular");
    for (int i = 0; i < 3; ++i) {
        if (!isfinite(checked->origin[i]))
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                              "render: frame view origin[%d] is not finite", i);
        t->origin[i] = checked->origin[i];
    }
    t->color_hdr = checked->color_hdr != 0;
    t->environment_cubemap = checked->environment_cubemap;
    /* Camera-relative: the eye is the origin, so far-away geometry keeps float32 digits when
     * effects subtract the eye in double first. */
    float view_rot[16];
    memcpy(view_rot, v->view, sizeof view_rot);
    view_rot[12] = view_rot[13] = view_rot[14] = 0.f;
    volfx_mat4_mul(v->proj, view_rot, t->cam_view_proj);
    if (!volfx_mat4_invert(t->cam_view_proj, t->inv_cam_view_proj))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: camera rotation*projection is singular");
    /* eye = -R^T t from the view matrix (exact for the matrices used, whatever eye says) */
    for (int k = 0; k < 3; ++k)
        t->view_eye[k] = -((double)v->view[k * 4 + 0] * v->view[12] + (double)v->view[k * 4 + 1] * v->view[13]
                           + (double)v->view[k * 4 + 2] * v->view[14]);
    return VFX_OK;
}

vfx_result volfx_frame_gate(vfx_context *ctx, const vfx_frame_view *frame, volfx_frame_targets *t,
                            vfx_frame_view *checked)
{
    memset(t, 0, sizeof *t);
    memset(checked, 0, sizeof *checked);
    if (!frame)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW, "render: frame view is NULL");
    vfx_result r = read_view(ctx, frame, &t->view_id, checked);
    if (r)
        return r;
    /* the engine's own depth: this frame's chained vfx_frame_depth, or the standard depth */
    const vfx_frame_depth *fd = volfx_chain_find(frame->next, VFX_TYPE_FRAME_DEPTH);
    memset(&ctx->frame_depth, 0, sizeof ctx->frame_depth);
    if (fd) {
        if (fd->depth_convention > VFX_DEPTH_ZERO_TO_ONE)
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_DEPTH, "render: frame view's vfx_frame_depth depth_convention "
                              "%u is none of VFX_DEPTH_STANDARD (0), VFX_DEPTH_ZERO_TO_ONE (1)",
                              (unsigned)fd->depth_convention);
        if ((r = volfx_frame_depth_check_ranges(ctx, fd))) /* its rows (volfx_ranges.h) */
            return r;
        if (fd->depth_renderbuffer && fd->depth_framebuffer)
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_DEPTH, "render: frame view's vfx_frame_depth names both "
                              "depth_renderbuffer %u and depth_framebuffer %u: give one", fd->depth_renderbuffer,
                              fd->depth_framebuffer);
        ctx->frame_depth = (volfx_frame_depth){.depth_renderbuffer = fd->depth_renderbuffer,
                                               .depth_framebuffer = fd->depth_framebuffer,
                                               .flip_y = fd->flip_y != 0,
                                               .zero_to_one = fd->depth_convention == VFX_DEPTH_ZERO_TO_ONE,
                                               .chained = true};
    }
    if ((r = standardize(ctx, checked, t)))
        return r;
    if ((r = derive_camera(ctx, checked, t)))
        return r;
    vfx_frame_view *v = checked;
    for (int k = 0; k < 3; ++k)
        if (!isfinite(v->eye[k]))
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                              "render: frame view eye[%d] is not finite", k);
    /* eye against the view matrix's own (inverse translation, double cofactors rounded once to
     * float): a host's float32 lookAt rounds R and t (~1 ulp each), leaves R^T R - I at a few
     * ulps and t's dot products at ~3, so the two differ by <~ 20 FLT_EPSILON max(|eye|, |t|, 1);
     * 256 FLT_EPSILON (3.1e-5 relative, at least 3.1e-5 units) keeps >10x margin and refuses a
     * wrong eye (the water's rays then missed everywhere). Large worlds: with view 2 positions are
     * relative to origin, so |eye| stays small; without it, at 1e6 units float32 itself resolves
     * only 0.06 and the bound is 31 units. An eye of exactly (0, 0, 0) is taken from the view. */
    double scale = 1, off = 0;
    for (int k = 0; k < 3; ++k) {
        scale = fmax(scale, fmax(fabs((double)v->eye[k]), fabs((double)v->view[12 + k])));
        off = fmax(off, fabs((double)v->eye[k] - t->inv_view[12 + k]));
    }
    bool unset = v->eye[0] == 0 && v->eye[1] == 0 && v->eye[2] == 0; /* zero means default */
    if (unset)
        for (int k = 0; k < 3; ++k)
            v->eye[k] = t->inv_view[12 + k];
    if (!unset && off > 256 * FLT_EPSILON * scale)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: frame view eye (%g, %g, %g) is not the view "
                          "matrix's eye (%g, %g, %g): off by %g, more than %g", (double)v->eye[0], (double)v->eye[1],
                          (double)v->eye[2], (double)t->inv_view[12], (double)t->inv_view[13],
                          (double)t->inv_view[14], off, 256 * FLT_EPSILON * scale);
    if (!isfinite(v->fov_y) || v->fov_y < 0 || v->fov_y >= 3.14159265f)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: frame view fov_y %g outside [0, pi) radians",
                          (double)v->fov_y);
    if (v->effects & ~((1u << VFX_EFFECT_COUNT) - 1))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: frame view effects 0x%x has bits of no effect "
                          "(known: 0x%x)", v->effects, (1u << VFX_EFFECT_COUNT) - 1);
    if ((r = check_planes(ctx, v)))
        return r;
    if ((r = volfx_frame_view_check_ranges(ctx, v))) /* every number against its row (volfx_ranges.h) */
        return r;
    t->scene_depth = v->depth_texture;
    t->scene_color = v->color_texture;
    t->framebuffer = v->framebuffer;
    t->layer_texture = v->layer_texture;
    t->width = v->width, t->height = v->height;
    t->effects = v->effects ? v->effects : 0xffffffffu;
    memcpy(t->view, v->view, sizeof t->view);
    memcpy(t->proj, v->proj, sizeof t->proj);
    memcpy(t->eye, v->eye, sizeof t->eye);
    t->near_plane = v->near_plane, t->far_plane = v->far_plane;
    t->fov_y = v->fov_y;
    return VFX_OK;
}

/* std140 of shaders/common/frame.glsl: seven mat4 then four vec4/uvec4, no padding */
_Static_assert(sizeof(volfx_frame_block) == 7 * 64 + 4 * 16, "volfx_frame_block mirrors VolfxFrame (std140)");

/* Fills and uploads the VolfxFrame block (made on first use) and binds it for the frame. */
static vfx_result upload_block(vfx_context *ctx, const volfx_frame_targets *t)
{
    if (!ctx->frame_block) {
        volfx_ubo u = {0};
        if (!volfx_ubo_create(ctx, &u, sizeof(volfx_frame_block), "volfx.frame_block"))
            return VFX_ERR_GL;
        ctx->frame_block = u.buffer;
    }
    volfx_frame_block b;
    memcpy(b.view_proj, t->view_proj, sizeof b.view_proj);
    memcpy(b.inv_view_proj, t->inv_view_proj, sizeof b.inv_view_proj);
    memcpy(b.cam_view_proj, t->cam_view_proj, sizeof b.cam_view_proj);
    memcpy(b.inv_cam_view_proj, t->inv_cam_view_proj, sizeof b.inv_cam_view_proj);
    memcpy(b.view, t->view, sizeof b.view);
    memcpy(b.proj, t->proj, sizeof b.proj);
    memcpy(b.inv_view, t->inv_view, sizeof b.inv_view);
    b.eye_fov[0] = t->eye[0], b.eye_fov[1] = t->eye[1], b.eye_fov[2] = t->eye[2], b.eye_fov[3] = t->fov_y;
    b.planes_size[0] = t->near_plane, b.planes_size[1] = t->far_plane;
    b.planes_size[2] = (float)t->width, b.planes_size[3] = (float)t->height;
    for (int k = 0; k < 3; ++k)
        b.origin_hdr[k] = (float)t->origin[k];
    b.origin_hdr[3] = t->color_hdr ? 1.f : 0.f;
    b.flags[0] = t->environment_cubemap != 0, b.flags[1] = t->view_id, b.flags[2] = t->effects, b.flags[3] = 0;
    volfx_ubo u = {ctx->frame_block, sizeof(volfx_frame_block)};
    volfx_ubo_update(&u, &b, sizeof b);
    volfx_ubo_bind(&u, VOLFX_FRAME_BINDING);
    return VFX_OK;
}

/* The effects layer: an RGBA16F 2D texture of the frame's size, attached (every frame: the host
 * may have made a new texture under the same name) to the context's framebuffer, cleared to
 * transparent black; the effects draw into it instead of the host's framebuffer. */
static vfx_result layer_target(vfx_context *ctx, volfx_frame_targets *t)
{
    GLuint name = t->layer_texture;
    if (!glIsTexture(name))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_LAYER_TEXTURE,
                          "render: frame view layer_texture %u is not a texture name "
                          "of this GL context", name);
    GLint target = 0, tw = 0, th = 0, fmt = 0;
    glGetTextureParameteriv(name, GL_TEXTURE_TARGET, &target);
    if (target != GL_TEXTURE_2D)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_LAYER_TEXTURE,
                          "render: frame view layer_texture %u is a %s texture, need %s",
                          name, target_name(target), target_name(GL_TEXTURE_2D));
    glGetTextureLevelParameteriv(name, 0, GL_TEXTURE_WIDTH, &tw);
    glGetTextureLevelParameteriv(name, 0, GL_TEXTURE_HEIGHT, &th);
    glGetTextureLevelParameteriv(name, 0, GL_TEXTURE_INTERNAL_FORMAT, &fmt);
    if (fmt != GL_RGBA16F)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_LAYER_TEXTURE,
                          "render: frame view layer_texture %u has internal format "
                          "0x%04x, need GL_RGBA16F (0x%04x)", name, (unsigned)fmt, (unsigned)GL_RGBA16F);
    if (tw != (GLint)t->width || th != (GLint)t->height)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_LAYER_TEXTURE,
                          "render: frame view layer_texture %u is %dx%d, the frame view "
                          "%ux%u (they must match)", name, tw, th, t->width, t->height);
    if (!ctx->layer_fbo) {
        GLuint fb = 0;
        glCreateFramebuffers(1, &fb);
        volfx_gpu_label(GL_FRAMEBUFFER, fb, "volfx.effects_layer");
        ctx->layer_fbo = fb;
    }
    glNamedFramebufferTexture(ctx->layer_fbo, GL_COLOR_ATTACHMENT0, name, 0);
    if (glCheckNamedFramebufferStatus(ctx->layer_fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        return volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_LAYER_TEXTURE,
                          "render: frame view layer_texture %u cannot be rendered to", name);
    t->framebuffer = ctx->layer_fbo;
    /* the clear honours the scissor test and the colour mask: the host's, put back after */
    GLboolean scissor = glIsEnabled(GL_SCISSOR_TEST), mask[4];
    glGetBooleani_v(GL_COLOR_WRITEMASK, 0, mask);
    glDisable(GL_SCISSOR_TEST);
    glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    const float zero[4] = {0, 0, 0, 0};
    glClearNamedFramebufferfv(ctx->layer_fbo, GL_COLOR, 0, zero);
    glColorMaski(0, mask[0], mask[1], mask[2], mask[3]);
    if (scissor)
        glEnable(GL_SCISSOR_TEST);
    return VFX_OK;
}

/* Makes (or keeps, at the same size and format) a depth texture and a depth-only framebuffer. */
static vfx_result depth_target(vfx_context *ctx, unsigned *tex, unsigned *fbo, GLenum format, uint32_t w,
                               uint32_t h, const char *label)
{
    if (*tex)
        return VFX_OK;
    GLuint t = 0, f = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &t);
    glTextureStorage2D(t, 1, format, (GLsizei)w, (GLsizei)h);
    glCreateFramebuffers(1, &f);
    glNamedFramebufferTexture(f, GL_DEPTH_ATTACHMENT, t, 0);
    glNamedFramebufferDrawBuffer(f, GL_NONE);
    glNamedFramebufferReadBuffer(f, GL_NONE);
    volfx_gpu_label(GL_TEXTURE, t, label);
    *tex = t, *fbo = f;
    return volfx_gpu_check_target(ctx, f, label, w, h);
}

static void drop_depth_targets(vfx_context *ctx)
{
    volfx_depth_targets *d = &ctx->depth;
    GLuint tex[2] = {d->copy_tex, d->std_tex}, fbo[3] = {d->copy_fbo, d->std_fbo, d->src_fbo};
    glDeleteTextures(2, tex);
    glDeleteFramebuffers(3, fbo);
    memset(d, 0, sizeof *d);
}

/* The internal format of a depth renderbuffer, or of a framebuffer's depth attachment; 0 with an
 * error naming the field when there is none. */
static GLint depth_source_format(vfx_context *ctx, GLuint *read_fb)
{
    const volfx_frame_depth *fd = &ctx->frame_depth;
    GLint format = 0;
    if (fd->depth_renderbuffer) {
        if (!glIsRenderbuffer(fd->depth_renderbuffer)) {
            volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_DEPTH, "render: frame depth depth_renderbuffer %u is not a "
                       "renderbuffer name of this GL context", fd->depth_renderbuffer);
            return 0;
        }
        glGetNamedRenderbufferParameteriv(fd->depth_renderbuffer, GL_RENDERBUFFER_INTERNAL_FORMAT, &format);
        if (!ctx->depth.src_fbo)
            glCreateFramebuffers(1, &ctx->depth.src_fbo);
        GLint dbits = 0, sbits = 0;
        glGetNamedRenderbufferParameteriv(fd->depth_renderbuffer, GL_RENDERBUFFER_DEPTH_SIZE, &dbits);
        glGetNamedRenderbufferParameteriv(fd->depth_renderbuffer, GL_RENDERBUFFER_STENCIL_SIZE, &sbits);
        if (!dbits) {
            volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_DEPTH, "render: frame depth depth_renderbuffer %u has internal format "
                       "0x%04x, not a depth format", fd->depth_renderbuffer, (unsigned)format);
            return 0;
        }
        glNamedFramebufferRenderbuffer(ctx->depth.src_fbo, sbits ? GL_DEPTH_STENCIL_ATTACHMENT : GL_DEPTH_ATTACHMENT,
                                       GL_RENDERBUFFER, fd->depth_renderbuffer);
        *read_fb = ctx->depth.src_fbo;
        return format;
    }
    if (!glIsFramebuffer(fd->depth_framebuffer)) {
        volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_DEPTH, "render: frame depth depth_framebuffer %u is not a framebuffer "
                   "name of this GL context", fd->depth_framebuffer);
        return 0;
    }
    GLint type = GL_NONE, obj = 0;
    glGetNamedFramebufferAttachmentParameteriv(fd->depth_framebuffer, GL_DEPTH_ATTACHMENT,
                                               GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &type);
    glGetNamedFramebufferAttachmentParameteriv(fd->depth_framebuffer, GL_DEPTH_ATTACHMENT,
                                               GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME, &obj);
    if (type == GL_RENDERBUFFER)
        glGetNamedRenderbufferParameteriv((GLuint)obj, GL_RENDERBUFFER_INTERNAL_FORMAT, &format);
    else if (type == GL_TEXTURE)
        glGetTextureLevelParameteriv((GLuint)obj, 0, GL_TEXTURE_INTERNAL_FORMAT, &format);
    if (!format)
        volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_DEPTH, "render: frame depth depth_framebuffer %u has no depth attachment",
                   fd->depth_framebuffer);
    *read_fb = fd->depth_framebuffer;
    return format;
}

/* The engine's own depth, step 2: a renderbuffer's (or a framebuffer's) depth blitted into a
 * texture of its format, then, for another convention, rewritten in the standard one
 * (shaders/common/depth_convert.frag) into a DEPTH_COMPONENT32F texture; t->scene_depth is what
 * the effects read. */
static vfx_result own_depth(vfx_context *ctx, volfx_frame_targets *t)
{
    const volfx_frame_depth *fd = &ctx->frame_depth;
    volfx_depth_targets *d = &ctx->depth;
    if (d->w != t->width || d->h != t->height)
        drop_depth_targets(ctx);
    d->w = t->width, d->h = t->height;
    vfx_result r;
    if (fd->depth_renderbuffer || fd->depth_framebuffer) {
        GLuint read_fb = 0;
        GLint format = depth_source_format(ctx, &read_fb);
        if (!format)
            return VFX_ERR_INVALID_ARGUMENT;
        if (d->copy_tex && d->copy_format != format) {
            GLuint tex = d->copy_tex, fbo = d->copy_fbo;
            glDeleteTextures(1, &tex);
            glDeleteFramebuffers(1, &fbo);
            d->copy_tex = d->copy_fbo = 0;
        }
        if ((r = depth_target(ctx, &d->copy_tex, &d->copy_fbo, (GLenum)format, d->w, d->h, "volfx.depth_copy")))
            return r;
        d->copy_format = format;
        glBlitNamedFramebuffer(read_fb, d->copy_fbo, 0, 0, (GLint)d->w, (GLint)d->h, 0, 0, (GLint)d->w, (GLint)d->h,
                               GL_DEPTH_BUFFER_BIT, GL_NEAREST);
        const char *e = volfx_gpu_error_string();
        if (e)
            return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_DEPTH, "render: the frame's depth (%s %u, format 0x%04x) cannot be "
                              "copied at %ux%u: %s", fd->depth_renderbuffer ? "depth_renderbuffer" : "depth_framebuffer",
                              fd->depth_renderbuffer ? fd->depth_renderbuffer : fd->depth_framebuffer,
                              (unsigned)format, d->w, d->h, e);
        t->scene_depth = d->copy_tex;
    }
    if (!t->depth_convert)
        return VFX_OK;
    if ((r = depth_target(ctx, &d->std_tex, &d->std_fbo, GL_DEPTH_COMPONENT32F, d->w, d->h, "volfx.depth_standard")))
        return r;
    GLuint prog = volfx_gpu_program(ctx, "common/fullscreen.vert", "common/depth_convert.frag", NULL);
    if (!prog)
        return VFX_ERR_GL;
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "volfx.depth_convert", .framebuffer = d->std_fbo,
                                             .width = d->w, .height = d->h, .clear_depth = true,
                                             .depth = VOLFX_DEPTH_TEST_WRITE});
    glDepthFunc(GL_ALWAYS);
    glUseProgram(prog);
    glUniform4d(volfx_gpu_uniform(ctx, prog, "u_host"), t->depth_host[0], t->depth_host[1], t->depth_host[2],
                t->depth_host[3]);
    glUniform2d(volfx_gpu_uniform(ctx, prog, "u_std"), t->depth_std[0], t->depth_std[1]);
    glBindTextureUnit(0, t->scene_depth);
    volfx_gpu_fullscreen(ctx);
    glUseProgram(0);
    glDepthFunc(GL_LESS);
    volfx_pass_end(ctx);
    t->scene_depth = d->std_tex;
    return VFX_OK;
}

vfx_result volfx_frame_gate_gl(vfx_context *ctx, bool drawing, volfx_frame_targets *t)
{
    vfx_result r;
    /* an empty frame still clears the layer: the host composites it whatever was drawn */
    if (t->layer_texture && (r = layer_target(ctx, t)))
        return r;
    if (!drawing)
        return VFX_OK;
    if (!t->layer_texture && t->framebuffer
        && (r = check_framebuffer(ctx, t->framebuffer, t->width, t->height, &t->output_srgb)))
        return r;
    /* linear shading: an sRGB output attachment gets encoded writes and decoded blending; the
     * plugin's own targets are float, which sRGB encoding leaves alone (the baseline had it off) */
    if (t->output_srgb)
        glEnable(GL_FRAMEBUFFER_SRGB);
    if (t->scene_color && (r = check_texture(ctx, "color_texture", t->scene_color, WANT_COLOR, t->width, t->height)))
        return r;
    const volfx_frame_depth *fd = &ctx->frame_depth;
    bool own = fd->depth_renderbuffer || fd->depth_framebuffer;
    if (!own && t->scene_depth
        && (r = check_texture(ctx, "depth_texture", t->scene_depth, WANT_DEPTH, t->width, t->height)))
        return r;
    if (t->environment_cubemap &&
        (r = check_texture(ctx, "environment_cubemap", t->environment_cubemap, WANT_CUBE, 0, 0)))
        return r;
    /* framebuffer 0 is the default framebuffer, which a surfaceless context lacks: the first draw
     * into it failed with a GL error that named nothing (issue 28) */
    if (!t->layer_texture && !t->framebuffer &&
        glCheckNamedFramebufferStatus(0, GL_DRAW_FRAMEBUFFER) == GL_FRAMEBUFFER_UNDEFINED)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_FRAME_VIEW,
                          "render: frame view framebuffer 0 is the default "
                          "framebuffer, and the current context has none (surfaceless): name a framebuffer object");
    if ((own || (t->depth_convert && t->scene_depth)) && (r = own_depth(ctx, t)))
        return r;
    if (!t->scene_depth && (r = far_depth(ctx, t->width, t->height, &t->scene_depth)))
        return r;
    return upload_block(ctx, t);
}

void volfx_frame_check_destroy(vfx_context *ctx)
{
    if (ctx->frame_block) {
        GLuint b = ctx->frame_block;
        glDeleteBuffers(1, &b);
        ctx->frame_block = 0;
    }
    drop_far_depth(ctx);
    if (ctx->layer_fbo) {
        GLuint fb = ctx->layer_fbo;
        glDeleteFramebuffers(1, &fb);
        ctx->layer_fbo = 0;
    }
    drop_depth_targets(ctx);
}
