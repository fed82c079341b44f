/* pass.c — see pass.h. */
#include "gpu/pass.h"
#include "effect.h"

static void apply_blend(volfx_blend b)
{
    if (b == VOLFX_BLEND_NONE) {
        glDisable(GL_BLEND);
        return;
    }
    glEnable(GL_BLEND);
    switch (b) {
    case VOLFX_BLEND_ADD:
        glBlendEquation(GL_FUNC_ADD);
        glBlendFunc(GL_ONE, GL_ONE);
        break;
    case VOLFX_BLEND_OVER_PREMUL:
        glBlendEquation(GL_FUNC_ADD);
        glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
        break;
    case VOLFX_BLEND_MAX:
        glBlendEquation(GL_MAX);
        break;
    case VOLFX_BLEND_MIN:
        glBlendEquation(GL_MIN);
        break;
    default:
        break;
    }
}

void volfx_pass_apply(vfx_context *ctx, const volfx_pass_desc *d)
{
    glBindFramebuffer(GL_FRAMEBUFFER, d->framebuffer);
    glViewport(0, 0, (GLsizei)(d->width ? d->width : ctx->width),
               (GLsizei)(d->height ? d->height : ctx->height));
    if (d->clear_color)
        glClearNamedFramebufferfv(d->framebuffer, GL_COLOR, 0, d->clear_rgba);
    if (d->clear_depth) {
        glDepthMask(GL_TRUE); /* a clear honours the mask a DEPTH_NONE pass left off */
        float one = d->clear_depth_value != 0.f ? d->clear_depth_value : 1.f;
        glClearNamedFramebufferfv(d->framebuffer, GL_DEPTH, 0, &one);
    }
    apply_blend(d->blend);
    if (d->depth == VOLFX_DEPTH_NONE) {
        glDisable(GL_DEPTH_TEST);
        glDepthMask(GL_FALSE);
    } else {
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDepthMask(d->depth == VOLFX_DEPTH_TEST_WRITE ? GL_TRUE : GL_FALSE);
    }
}

void volfx_pass_begin(vfx_context *ctx, const volfx_pass_desc *d)
{
    volfx_gpu_timer_begin(ctx, d->name);
    if (!d->compute)
        volfx_pass_apply(ctx, d);
}

void volfx_pass_reset(void)
{
    glDisable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
}

void volfx_pass_end(vfx_context *ctx)
{
    volfx_pass_reset();
    volfx_gpu_timer_end(ctx);
}

bool volfx_ubo_create(vfx_context *ctx, volfx_ubo *ubo, uint32_t bytes, const char *label)
{
    ubo->bytes = (bytes + 15u) & ~15u;
    glCreateBuffers(1, &ubo->buffer);
    if (!ubo->buffer) {
        volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR, "%s: cannot create a uniform buffer", label);
        return false;
    }
    glNamedBufferStorage(ubo->buffer, ubo->bytes, NULL, GL_DYNAMIC_STORAGE_BIT);
    volfx_gpu_label(GL_BUFFER, ubo->buffer, label);
    return true;
}

void volfx_ubo_update(const volfx_ubo *ubo, const void *data, uint32_t bytes)
{
    glNamedBufferSubData(ubo->buffer, 0, bytes < ubo->bytes ? bytes : ubo->bytes, data);
}

void volfx_ubo_bind(const volfx_ubo *ubo, uint32_t binding)
{
    glBindBufferBase(GL_UNIFORM_BUFFER, binding, ubo->buffer);
}

void volfx_ubo_destroy(volfx_ubo *ubo)
{
    if (ubo->buffer)
        glDeleteBuffers(1, &ubo->buffer);
    ubo->buffer = 0;
}

void volfx_program_uniforms(GLuint prog, const char *const *names, GLint *locs, uint32_t n)
{
    for (uint32_t i = 0; i < n; ++i)
        locs[i] = prog ? glGetUniformLocation(prog, names[i]) : -1;
}

void volfx_composite_targets(vfx_context *ctx, const volfx_frame_targets *t, const char *name,
                             GLuint prog, volfx_blend blend)
{
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = name, .framebuffer = t->framebuffer,
                                             .width = t->width, .height = t->height, .blend = blend});
    glUseProgram(prog);
    volfx_gpu_fullscreen(ctx);
    glUseProgram(0);
    volfx_pass_end(ctx);
}
