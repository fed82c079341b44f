/* gl_state.c — see gl_state.h. Queries only (glGet*, glIsEnabled*): no pipeline stall. */
#include "gpu/gl_state.h"

/* Capabilities the baseline turns off (GL_BLEND is per draw buffer, in blend[]). */
static const GLenum enables[] = {
    GL_CULL_FACE, GL_DEPTH_TEST, GL_SCISSOR_TEST, GL_STENCIL_TEST, GL_PRIMITIVE_RESTART,
    GL_PRIMITIVE_RESTART_FIXED_INDEX, GL_RASTERIZER_DISCARD, GL_FRAMEBUFFER_SRGB, GL_POLYGON_OFFSET_FILL,
    GL_DEPTH_CLAMP, GL_SAMPLE_ALPHA_TO_COVERAGE, GL_SAMPLE_ALPHA_TO_ONE, GL_SAMPLE_MASK, GL_COLOR_LOGIC_OP,
    GL_SAMPLE_SHADING,
};
_Static_assert(sizeof enables / sizeof enables[0] <= 32, "enables fit volfx_gl_saved.enables");

static const GLenum pack_names[7] = {GL_PACK_ALIGNMENT, GL_PACK_ROW_LENGTH, GL_PACK_IMAGE_HEIGHT,
                                     GL_PACK_SKIP_ROWS, GL_PACK_SKIP_PIXELS, GL_PACK_SKIP_IMAGES,
                                     GL_PACK_SWAP_BYTES};
static const GLenum unpack_names[7] = {GL_UNPACK_ALIGNMENT, GL_UNPACK_ROW_LENGTH, GL_UNPACK_IMAGE_HEIGHT,
                                       GL_UNPACK_SKIP_ROWS, GL_UNPACK_SKIP_PIXELS, GL_UNPACK_SKIP_IMAGES,
                                       GL_UNPACK_SWAP_BYTES};
static const GLint store_defaults[7] = {4, 0, 0, 0, 0, 0, 0};
/* volfx_gl_saved.stencil's order, front and back (the beams' integrate pass draws with a stencil) */
static const GLenum stencil_names[2][7] = {
    {GL_STENCIL_FUNC, GL_STENCIL_REF, GL_STENCIL_VALUE_MASK, GL_STENCIL_FAIL, GL_STENCIL_PASS_DEPTH_FAIL,
     GL_STENCIL_PASS_DEPTH_PASS, GL_STENCIL_WRITEMASK},
    {GL_STENCIL_BACK_FUNC, GL_STENCIL_BACK_REF, GL_STENCIL_BACK_VALUE_MASK, GL_STENCIL_BACK_FAIL,
     GL_STENCIL_BACK_PASS_DEPTH_FAIL, GL_STENCIL_BACK_PASS_DEPTH_PASS, GL_STENCIL_BACK_WRITEMASK}};

static GLint get_i(GLenum e)
{
    GLint v = 0;
    glGetIntegerv(e, &v);
    return v;
}

static void save_range(GLenum binding, GLenum start, GLenum size, GLuint i, volfx_gl_range *r)
{
    glGetIntegeri_v(binding, i, &r->name);
    glGetInteger64i_v(start, i, &r->start);
    glGetInteger64i_v(size, i, &r->size);
}

static void save_units(volfx_gl_saved *s)
{
    s->active_texture = get_i(GL_ACTIVE_TEXTURE);
    for (GLuint u = 0; u < VOLFX_GL_TEXTURE_UNITS; ++u) {
        glActiveTexture(GL_TEXTURE0 + u);
        s->tex_2d[u] = get_i(GL_TEXTURE_BINDING_2D);
        s->tex_cube[u] = get_i(GL_TEXTURE_BINDING_CUBE_MAP);
        s->sampler[u] = get_i(GL_SAMPLER_BINDING);
    }
    glActiveTexture((GLenum)s->active_texture);
    for (GLuint i = 0; i < VOLFX_GL_UBO_BINDINGS; ++i)
        save_range(GL_UNIFORM_BUFFER_BINDING, GL_UNIFORM_BUFFER_START, GL_UNIFORM_BUFFER_SIZE, i, &s->ubo[i]);
    for (GLuint i = 0; i < VOLFX_GL_SSBO_BINDINGS; ++i)
        save_range(GL_SHADER_STORAGE_BUFFER_BINDING, GL_SHADER_STORAGE_BUFFER_START, GL_SHADER_STORAGE_BUFFER_SIZE,
                   i, &s->ssbo[i]);
    for (GLuint i = 0; i < VOLFX_GL_IMAGE_UNITS; ++i) {
        volfx_gl_image *m = &s->image[i];
        glGetIntegeri_v(GL_IMAGE_BINDING_NAME, i, &m->name);
        glGetIntegeri_v(GL_IMAGE_BINDING_LEVEL, i, &m->level);
        glGetIntegeri_v(GL_IMAGE_BINDING_LAYERED, i, &m->layered);
        glGetIntegeri_v(GL_IMAGE_BINDING_LAYER, i, &m->layer);
        glGetIntegeri_v(GL_IMAGE_BINDING_ACCESS, i, &m->access);
        glGetIntegeri_v(GL_IMAGE_BINDING_FORMAT, i, &m->format);
    }
}

void volfx_gl_state_save(volfx_gl_saved *s, bool compat)
{
    s->draw_fb = get_i(GL_DRAW_FRAMEBUFFER_BINDING);
    s->read_fb = get_i(GL_READ_FRAMEBUFFER_BINDING);
    s->renderbuffer = get_i(GL_RENDERBUFFER_BINDING);
    s->program = get_i(GL_CURRENT_PROGRAM);
    s->vao = get_i(GL_VERTEX_ARRAY_BINDING);
    s->array_buf = get_i(GL_ARRAY_BUFFER_BINDING);
    s->draw_indirect = get_i(GL_DRAW_INDIRECT_BUFFER_BINDING);
    s->dispatch_indirect = get_i(GL_DISPATCH_INDIRECT_BUFFER_BINDING);
    s->pack_buf = get_i(GL_PIXEL_PACK_BUFFER_BINDING);
    s->unpack_buf = get_i(GL_PIXEL_UNPACK_BUFFER_BINDING);
    s->uniform_buf = get_i(GL_UNIFORM_BUFFER_BINDING);
    s->storage_buf = get_i(GL_SHADER_STORAGE_BUFFER_BINDING);
    save_units(s);
    glGetIntegerv(GL_VIEWPORT, s->viewport);
    glGetDoublev(GL_DEPTH_RANGE, s->depth_range);
    s->depth_func = get_i(GL_DEPTH_FUNC);
    glGetBooleanv(GL_DEPTH_WRITEMASK, &s->depth_mask);
    GLint modes[2] = {GL_FILL, GL_FILL}; /* a compatibility context answers front and back */
    glGetIntegerv(GL_POLYGON_MODE, modes);
    s->polygon_mode = modes[0];
    s->clip_origin = get_i(GL_CLIP_ORIGIN);
    s->clip_depth = get_i(GL_CLIP_DEPTH_MODE);
    GLint nbuf = get_i(GL_MAX_DRAW_BUFFERS);
    s->draw_buffers = nbuf < VOLFX_GL_DRAW_BUFFERS ? nbuf : VOLFX_GL_DRAW_BUFFERS;
    for (GLint i = 0; i < s->draw_buffers; ++i) {
        volfx_gl_blend_i *b = &s->blend[i];
        glGetIntegeri_v(GL_BLEND_SRC_RGB, (GLuint)i, &b->src_rgb);
        glGetIntegeri_v(GL_BLEND_DST_RGB, (GLuint)i, &b->dst_rgb);
        glGetIntegeri_v(GL_BLEND_SRC_ALPHA, (GLuint)i, &b->src_alpha);
        glGetIntegeri_v(GL_BLEND_DST_ALPHA, (GLuint)i, &b->dst_alpha);
        glGetIntegeri_v(GL_BLEND_EQUATION_RGB, (GLuint)i, &b->eq_rgb);
        glGetIntegeri_v(GL_BLEND_EQUATION_ALPHA, (GLuint)i, &b->eq_alpha);
        glGetBooleani_v(GL_COLOR_WRITEMASK, (GLuint)i, b->mask);
        b->enabled = glIsEnabledi(GL_BLEND, (GLuint)i);
    }
    for (int i = 0; i < 7; ++i) {
        s->pack[i] = get_i(pack_names[i]);
        s->unpack[i] = get_i(unpack_names[i]);
        s->stencil[0][i] = get_i(stencil_names[0][i]);
        s->stencil[1][i] = get_i(stencil_names[1][i]);
    }
    s->enables = 0;
    for (unsigned i = 0; i < sizeof enables / sizeof enables[0]; ++i)
        if (glIsEnabled(enables[i]))
            s->enables |= 1u << i;
    s->compat = compat;
    s->alpha_test = compat && glIsEnabled(GL_ALPHA_TEST);
}

static void restore_range(GLenum target, GLuint i, const volfx_gl_range *r)
{
    if (r->size > 0)
        glBindBufferRange(target, i, (GLuint)r->name, (GLintptr)r->start, (GLsizeiptr)r->size);
    else
        glBindBufferBase(target, i, (GLuint)r->name);
}

static void restore_units(const volfx_gl_saved *s)
{
    for (GLuint u = 0; u < VOLFX_GL_TEXTURE_UNITS; ++u) {
        glActiveTexture(GL_TEXTURE0 + u);
        glBindTexture(GL_TEXTURE_2D, (GLuint)s->tex_2d[u]);
        glBindTexture(GL_TEXTURE_CUBE_MAP, (GLuint)s->tex_cube[u]);
        glBindSampler(u, (GLuint)s->sampler[u]);
    }
    glActiveTexture((GLenum)s->active_texture);
    for (GLuint i = 0; i < VOLFX_GL_UBO_BINDINGS; ++i)
        restore_range(GL_UNIFORM_BUFFER, i, &s->ubo[i]);
    for (GLuint i = 0; i < VOLFX_GL_SSBO_BINDINGS; ++i)
        restore_range(GL_SHADER_STORAGE_BUFFER, i, &s->ssbo[i]);
    /* the indexed binds above moved the generic bindings: those go back after them */
    glBindBuffer(GL_UNIFORM_BUFFER, (GLuint)s->uniform_buf);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, (GLuint)s->storage_buf);
    for (GLuint i = 0; i < VOLFX_GL_IMAGE_UNITS; ++i) {
        const volfx_gl_image *m = &s->image[i];
        /* an unbound unit answers its last access and format (READ_ONLY and R8 at first); a
         * driver answering 0 gets those defaults, since 0 is no valid format to bind */
        glBindImageTexture(i, (GLuint)m->name, m->level, (GLboolean)m->layered, m->layer,
                           m->access ? (GLenum)m->access : GL_READ_ONLY, m->format ? (GLenum)m->format : GL_R8);
    }
}

void volfx_gl_state_restore(const volfx_gl_saved *s)
{
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, (GLuint)s->draw_fb);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, (GLuint)s->read_fb);
    glBindRenderbuffer(GL_RENDERBUFFER, (GLuint)s->renderbuffer);
    glUseProgram((GLuint)s->program);
    glBindVertexArray((GLuint)s->vao);
    glBindBuffer(GL_ARRAY_BUFFER, (GLuint)s->array_buf);
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, (GLuint)s->draw_indirect);
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, (GLuint)s->dispatch_indirect);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, (GLuint)s->pack_buf);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, (GLuint)s->unpack_buf);
    restore_units(s);
    glViewport(s->viewport[0], s->viewport[1], s->viewport[2], s->viewport[3]);
    glDepthRange(s->depth_range[0], s->depth_range[1]);
    glDepthFunc((GLenum)s->depth_func);
    glDepthMask(s->depth_mask);
    glPolygonMode(GL_FRONT_AND_BACK, (GLenum)s->polygon_mode);
    glClipControl((GLenum)s->clip_origin, (GLenum)s->clip_depth);
    for (GLint i = 0; i < s->draw_buffers; ++i) {
        const volfx_gl_blend_i *b = &s->blend[i];
        glBlendFuncSeparatei((GLuint)i, (GLenum)b->src_rgb, (GLenum)b->dst_rgb, (GLenum)b->src_alpha,
                             (GLenum)b->dst_alpha);
        glBlendEquationSeparatei((GLuint)i, (GLenum)b->eq_rgb, (GLenum)b->eq_alpha);
        glColorMaski((GLuint)i, b->mask[0], b->mask[1], b->mask[2], b->mask[3]);
        if (b->enabled)
            glEnablei(GL_BLEND, (GLuint)i);
        else
            glDisablei(GL_BLEND, (GLuint)i);
    }
    for (int i = 0; i < 7; ++i) {
        glPixelStorei(pack_names[i], s->pack[i]);
        glPixelStorei(unpack_names[i], s->unpack[i]);
    }
    for (int f = 0; f < 2; ++f) {
        const GLint *st = s->stencil[f];
        GLenum face = f ? GL_BACK : GL_FRONT;
        glStencilFuncSeparate(face, (GLenum)st[0], st[1], (GLuint)st[2]);
        glStencilOpSeparate(face, (GLenum)st[3], (GLenum)st[4], (GLenum)st[5]);
        glStencilMaskSeparate(face, (GLuint)st[6]);
    }
    for (unsigned i = 0; i < sizeof enables / sizeof enables[0]; ++i)
        if (s->enables & (1u << i))
            glEnable(enables[i]);
        else
            glDisable(enables[i]);
    if (s->compat && s->alpha_test)
        glEnable(GL_ALPHA_TEST);
}

void volfx_gl_state_baseline(bool compat)
{
    for (unsigned i = 0; i < sizeof enables / sizeof enables[0]; ++i)
        glDisable(enables[i]);
    glDisable(GL_BLEND);
    if (compat)
        glDisable(GL_ALPHA_TEST);
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
    glDepthRange(0.0, 1.0);
    glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ZERO);
    glBindSamplers(0, VOLFX_GL_TEXTURE_UNITS, NULL);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    for (int i = 0; i < 7; ++i) {
        glPixelStorei(pack_names[i], store_defaults[i]);
        glPixelStorei(unpack_names[i], store_defaults[i]);
    }
}
