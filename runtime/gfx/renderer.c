/* renderer.c — host scene target (RGBA8, or RGBA16F in HDR mode, + DEPTH32F textures) and
 * output target. The plugin samples the scene textures while drawing into the output, so it
 * never reads what it writes. In HDR mode the output holds linear radiance and is tone-mapped
 * (ACES) into an 8-bit display target for read-back and presenting. */
#include "gfx/renderer.h"

#include <cglm/cglm.h>
#include <epoxy/gl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "shader_text.h"

struct rt_renderer {
    rt_logger log;
    GLuint mesh_prog;
    GLint u_model, u_view_proj, u_color, u_light, u_environment, u_eye, u_fog, u_origin;
    GLint u_light_count, u_lights;
    float lights[RT_RENDERER_MAX_LIGHTS * 12]; /* mesh.frag's u_lights: p0 kind, p1 I, rgb radius */
    vfx_light src[RT_RENDERER_MAX_LIGHTS];     /* as given, for the per-mesh culling */
    uint32_t light_count;
    rt_renderer_environment env;
    float origin[3]; /* the scene's origin (rt_renderer_set_origin), for the meshes' patterns */
    GLuint sky_prog, sky_vao;
    GLint u_sky_inv_view_proj, u_sky_sun;
    GLuint scene_fbo, scene_color, scene_depth;
    GLuint out_fbo, out_color, out_depth;
    bool hdr;
    float exposure;
    GLuint tone_prog, tone_vao, disp_fbo, disp_color;
    GLuint layer_prog, layer_tex;    /* the effects layer's composite and texture (made on first use) */
    uint32_t layer_w, layer_h;
    GLint u_exposure;
    uint32_t width, height;
    float view[16], proj[16];
};

static GLuint compile(const rt_logger *log, GLenum stage, const char *path)
{
    char err[256], raw[4096], pretty[8192];
    char *src = volfx_shader_expand(&rt_host_shaders, path, NULL, err, sizeof err);
    if (!src) {
        rt_logf(log, VFX_LOG_ERROR, "host shader: %s", err);
        return 0;
    }
    GLuint s = glCreateShader(stage);
    glShaderSource(s, 1, (const char *const *)&src, NULL);
    glCompileShader(s);
    free(src);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        glGetShaderInfoLog(s, sizeof raw, NULL, raw);
        volfx_shader_rewrite_log(&rt_host_shaders, raw, pretty, sizeof pretty, path);
        rt_logf(log, VFX_LOG_ERROR, "host shader compile failed: %s", pretty);
        glDeleteShader(s);
        return 0;
    }
    return s;
}

/* Compiles and links an embedded vertex + fragment shader pair; 0 with the error logged. */
static GLuint link_program(const rt_logger *log, const char *vert, const char *frag, const char *label)
{
    GLuint vs = compile(log, GL_VERTEX_SHADER, vert);
    GLuint fs = compile(log, GL_FRAGMENT_SHADER, frag);
    if (!vs || !fs) {
        glDeleteShader(vs);
        glDeleteShader(fs);
        return 0;
    }
    GLuint p = glCreateProgram();
    glAttachShader(p, vs);
    glAttachShader(p, fs);
    glLinkProgram(p);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char text[2048];
        glGetProgramInfoLog(p, sizeof text, NULL, text);
        rt_logf(log, VFX_LOG_ERROR, "%s program link failed: %s", label, text);
        glDeleteProgram(p);
        return 0;
    }
    glObjectLabel(GL_PROGRAM, p, -1, label);
    return p;
}

vfx_result rt_renderer_create(const rt_logger *logger, rt_renderer **out)
{
    rt_renderer *r = calloc(1, sizeof *r);
    if (!r)
        return VFX_ERR_OUT_OF_MEMORY;
    if (logger)
        r->log = *logger;
    r->mesh_prog = link_program(&r->log, "host/mesh.vert", "host/mesh.frag", "host.mesh");
    if (!r->mesh_prog) {
        free(r);
        return VFX_ERR_GL;
    }
    r->exposure = 1.f;
    r->u_model = glGetUniformLocation(r->mesh_prog, "u_model");
    r->u_view_proj = glGetUniformLocation(r->mesh_prog, "u_view_proj");
    r->u_color = glGetUniformLocation(r->mesh_prog, "u_color");
    r->u_light = glGetUniformLocation(r->mesh_prog, "u_light_dir");
    r->u_environment = glGetUniformLocation(r->mesh_prog, "u_environment");
    r->u_eye = glGetUniformLocation(r->mesh_prog, "u_eye");
    r->u_fog = glGetUniformLocation(r->mesh_prog, "u_fog");
    r->u_origin = glGetUniformLocation(r->mesh_prog, "u_origin");
    r->u_light_count = glGetUniformLocation(r->mesh_prog, "u_light_count");
    r->u_lights = glGetUniformLocation(r->mesh_prog, "u_lights");
    *out = r;
    return VFX_OK;
}

static void free_targets(rt_renderer *r)
{
    GLuint tex[5] = {r->scene_color, r->scene_depth, r->out_color, r->out_depth, r->disp_color};
    glDeleteTextures(5, tex);
    GLuint fbo[3] = {r->scene_fbo, r->out_fbo, r->disp_fbo};
    glDeleteFramebuffers(3, fbo);
    r->scene_color = r->scene_depth = r->out_color = r->out_depth = r->disp_color = 0;
    r->scene_fbo = r->out_fbo = r->disp_fbo = 0;
}

/* The tone-mapping program (common/fullscreen.vert + host/tonemap.frag) and its empty VAO. */
static vfx_result make_tonemap(rt_renderer *r)
{
    r->tone_prog = link_program(&r->log, "common/fullscreen.vert", "host/tonemap.frag", "host.tonemap");
    if (!r->tone_prog)
        return VFX_ERR_GL;
    r->u_exposure = glGetUniformLocation(r->tone_prog, "u_exposure");
    glUseProgram(r->tone_prog);
    glUniform1i(glGetUniformLocation(r->tone_prog, "u_hdr"), 0);
    glUseProgram(0);
    glCreateVertexArrays(1, &r->tone_vao);
    return VFX_OK;
}

vfx_result rt_renderer_set_hdr(rt_renderer *r, bool hdr, float exposure)
{
    if (!r || !(exposure >= 0) || exposure > 1e6f)
        return VFX_ERR_INVALID_ARGUMENT;
    vfx_result res;
    if (hdr && !r->tone_prog && (res = make_tonemap(r)))
        return res;
    r->exposure = exposure > 0 ? exposure : 1.f;
    if (hdr == r->hdr)
        return VFX_OK;
    r->hdr = hdr;
    uint32_t w = r->width, h = r->height;
    r->width = r->height = 0; /* targets change format: remake them at the same size */
    return w ? rt_renderer_resize(r, w, h) : VFX_OK;
}

/* HDR mode: the output through the tone map into the display target. */
static void tonemap(rt_renderer *r)
{
    glPushDebugGroup(GL_DEBUG_SOURCE_APPLICATION, 0, -1, "host.tonemap");
    glBindFramebuffer(GL_FRAMEBUFFER, r->disp_fbo);
    glViewport(0, 0, (GLsizei)r->width, (GLsizei)r->height);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glUseProgram(r->tone_prog);
    glUniform1f(r->u_exposure, r->exposure);
    glBindTextureUnit(0, r->out_color);
    glBindVertexArray(r->tone_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glUseProgram(0);
    glPopDebugGroup();
}

vfx_result rt_renderer_layer(rt_renderer *r, unsigned *out)
{
    if (!r->layer_prog && !(r->layer_prog = link_program(&r->log, "common/fullscreen.vert", "host/layer.frag", "host.layer")))
        return VFX_ERR_GL;
    if (!r->tone_vao)
        glCreateVertexArrays(1, &r->tone_vao);
    if (!r->layer_tex || r->layer_w != r->width || r->layer_h != r->height) {
        if (r->layer_tex)
            glDeleteTextures(1, &r->layer_tex);
        glCreateTextures(GL_TEXTURE_2D, 1, &r->layer_tex);
        glTextureStorage2D(r->layer_tex, 1, GL_RGBA16F, (GLsizei)r->width, (GLsizei)r->height);
        glObjectLabel(GL_TEXTURE, r->layer_tex, -1, "host.effects_layer");
        r->layer_w = r->width, r->layer_h = r->height;
    }
    *out = r->layer_tex;
    return glGetError() == GL_NO_ERROR ? VFX_OK : VFX_ERR_GL;
}

void rt_renderer_composite_layer(rt_renderer *r)
{
    glPushDebugGroup(GL_DEBUG_SOURCE_APPLICATION, 0, -1, "host.layer");
    glBindFramebuffer(GL_FRAMEBUFFER, r->out_fbo);
    glViewport(0, 0, (GLsizei)r->width, (GLsizei)r->height);
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glUseProgram(r->layer_prog);
    glBindTextureUnit(0, r->layer_tex);
    glBindVertexArray(r->tone_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glUseProgram(0);
    glDisable(GL_BLEND);
    glPopDebugGroup();
}

void rt_renderer_destroy(rt_renderer *r)
{
    if (!r)
        return;
    free_targets(r);
    if (r->layer_tex)
        glDeleteTextures(1, &r->layer_tex);
    if (r->layer_prog)
        glDeleteProgram(r->layer_prog);
    glDeleteProgram(r->mesh_prog);
    glDeleteProgram(r->sky_prog);
    glDeleteVertexArrays(1, &r->sky_vao);
    glDeleteProgram(r->tone_prog);
    glDeleteVertexArrays(1, &r->tone_vao);
    free(r);
}

static GLuint make_tex(GLenum fmt, uint32_t w, uint32_t h, const char *label)
{
    GLuint t;
    glCreateTextures(GL_TEXTURE_2D, 1, &t);
    glTextureStorage2D(t, 1, fmt, (GLsizei)w, (GLsizei)h);
    glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTextureParameteri(t, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(t, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glObjectLabel(GL_TEXTURE, t, -1, label);
    return t;
}

static GLuint make_fbo(GLuint color, GLuint depth, const char *label)
{
    GLuint f;
    glCreateFramebuffers(1, &f);
    glNamedFramebufferTexture(f, GL_COLOR_ATTACHMENT0, color, 0);
    glNamedFramebufferTexture(f, GL_DEPTH_ATTACHMENT, depth, 0);
    glObjectLabel(GL_FRAMEBUFFER, f, -1, label);
    return f;
}

vfx_result rt_renderer_resize(rt_renderer *r, uint32_t w, uint32_t h)
{
    if (!r || w == 0 || h == 0 || w > 16384 || h > 16384)
        return VFX_ERR_INVALID_ARGUMENT;
    if (w == r->width && h == r->height && r->scene_fbo)
        return VFX_OK;
    free_targets(r);
    GLenum fmt = r->hdr ? GL_RGBA16F : GL_RGBA8;
    r->scene_color = make_tex(fmt, w, h, "host.scene_color");
    r->scene_depth = make_tex(GL_DEPTH_COMPONENT32F, w, h, "host.scene_depth");
    r->out_color = make_tex(fmt, w, h, "host.out_color");
    if (r->hdr) {
        r->disp_color = make_tex(GL_RGBA8, w, h, "host.display_color");
        glCreateFramebuffers(1, &r->disp_fbo);
        glNamedFramebufferTexture(r->disp_fbo, GL_COLOR_ATTACHMENT0, r->disp_color, 0);
        glObjectLabel(GL_FRAMEBUFFER, r->disp_fbo, -1, "host.display");
    }
    r->out_depth = make_tex(GL_DEPTH_COMPONENT32F, w, h, "host.out_depth");
    r->scene_fbo = make_fbo(r->scene_color, r->scene_depth, "host.scene");
    r->out_fbo = make_fbo(r->out_color, r->out_depth, "host.out");
    r->width = w;
    r->height = h;
    if (glCheckNamedFramebufferStatus(r->scene_fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE
        || glCheckNamedFramebufferStatus(r->out_fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE
        || (r->hdr && glCheckNamedFramebufferStatus(r->disp_fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)) {
        rt_logf(&r->log, VFX_LOG_ERROR, "host targets %ux%u incomplete", w, h);
        return VFX_ERR_GL;
    }
    return VFX_OK;
}

void rt_renderer_set_origin(rt_renderer *r, const double origin[3])
{
    for (int k = 0; k < 3; ++k)
        r->origin[k] = (float)origin[k];
}

vfx_result rt_renderer_set_environment(rt_renderer *r, const rt_renderer_environment *env)
{
    if (!r || !env)
        return VFX_ERR_INVALID_ARGUMENT;
    if (env->sky && !r->sky_prog) {
        r->sky_prog = link_program(&r->log, "common/fullscreen.vert", "host/sky.frag", "host.sky");
        if (!r->sky_prog)
            return VFX_ERR_GL;
        r->u_sky_inv_view_proj = glGetUniformLocation(r->sky_prog, "u_inv_view_proj");
        r->u_sky_sun = glGetUniformLocation(r->sky_prog, "u_sun_dir");
        glCreateVertexArrays(1, &r->sky_vao);
    }
    r->env = *env;
    return VFX_OK;
}

/* proj * view with cglm (column-major float[16] is cglm's mat4 layout). */
static void view_proj(const rt_renderer *r, mat4 vp)
{
    mat4 v, p;
    memcpy(v, r->view, sizeof v);
    memcpy(p, r->proj, sizeof p);
    glm_mat4_mul(p, v, vp);
}

/* The sky behind everything: depth stays at the far plane, so meshes and effects cover it. */
static void draw_sky(rt_renderer *r)
{
    mat4 vp, inv;
    view_proj(r, vp);
    glm_mat4_inv(vp, inv);
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glUseProgram(r->sky_prog);
    glUniformMatrix4fv(r->u_sky_inv_view_proj, 1, GL_FALSE, (const float *)inv);
    glUniform3fv(r->u_sky_sun, 1, r->env.sun_dir);
    glBindVertexArray(r->sky_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glDepthMask(GL_TRUE);
}

void rt_renderer_begin_scene(rt_renderer *r, const float view[16], const float proj[16],
                              const float clear_rgb[3])
{
    memcpy(r->view, view, sizeof r->view);
    memcpy(r->proj, proj, sizeof r->proj);
    glPushDebugGroup(GL_DEBUG_SOURCE_APPLICATION, 0, -1, "host.scene");
    glBindFramebuffer(GL_FRAMEBUFFER, r->scene_fbo);
    glViewport(0, 0, (GLsizei)r->width, (GLsizei)r->height);
    glClearColor(clear_rgb[0], clear_rgb[1], clear_rgb[2], 1.f);
    glClearDepth(1.0);
    glDepthMask(GL_TRUE);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    if (r->env.sky)
        draw_sky(r);
}

/* The distance past which a light adds less than RT_RENDERER_LIGHT_CUTOFF anywhere, squared.
 * At distance d from a light (from the nearest point of its segment) its irradiance is at most
 * I L cmax / d^2, L its length (1 for a point): every point p of the segment is at least d away
 * and cos(theta) / |p - x|^2 <= 1 / d^2. So past d0^2 = I L cmax / cutoff it adds under the
 * cutoff: dropping it there changes a pixel of albedo <= 1 by under 1/512 of white, and a light
 * crossing that distance as it moves changes it by no more (no visible pop, so no window). */
float rt_renderer_light_reach2(const vfx_light *l)
{
    float len = 1.f;
    if (l->kind == VFX_LIGHT_LINE) {
        float e[3] = {l->p1[0] - l->p0[0], l->p1[1] - l->p0[1], l->p1[2] - l->p0[2]};
        len = sqrtf(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    }
    float cmax = fmaxf(fmaxf(l->color[0], l->color[1]), l->color[2]);
    float w = fmaxf(l->intensity, 0.f) * len * fmaxf(cmax, 0.f) / RT_RENDERER_LIGHT_CUTOFF;
    w = isfinite(w) ? w : 3e38f; /* a NaN or inf light: never cut */
    if (l->kind == VFX_LIGHT_POINT && l->radius > 0)
        w = fminf(w, l->radius * l->radius); /* mesh.frag drops a point past its radius */
    return w;
}
uint32_t rt_renderer_lights_near_box(const vfx_light *lights, uint32_t n, const float lo[3],
                                     const float hi[3], uint32_t *keep)
{
    uint32_t kept = 0;
    for (uint32_t i = 0; i < n; ++i) {
        const vfx_light *l = &lights[i];
        /* the gap between the box and the segment's own box: no more than the distance from
         * any point of the mesh to any point of the segment, so the test never drops a light
         * that could reach the mesh */
        float d2 = 0;
        for (int k = 0; k < 3; ++k) {
            float a = fminf(l->p0[k], l->p1[k]), b = fmaxf(l->p0[k], l->p1[k]);
            float gap = fmaxf(fmaxf(lo[k] - b, a - hi[k]), 0.f);
            d2 += gap * gap;
        }
        if (!(d2 >= rt_renderer_light_reach2(l))) /* NaN positions: kept */
            keep[kept++] = i;
    }
    return kept;
}

vfx_result rt_renderer_set_lights(rt_renderer *r, const vfx_light *lights, uint32_t n)
{
    if (!r || (n && !lights))
        return VFX_ERR_INVALID_ARGUMENT;
    r->light_count = 0;
    if (n > RT_RENDERER_MAX_LIGHTS)
        n = RT_RENDERER_MAX_LIGHTS;
    for (uint32_t i = 0; i < n; ++i) {
        const vfx_light *l = &lights[i];
        if (l->kind != VFX_LIGHT_POINT && l->kind != VFX_LIGHT_LINE) {
            rt_logf(&r->log, VFX_LOG_ERROR, "lights[%u]: kind %u unknown (0 point, 1 line)", i, l->kind);
            return VFX_ERR_ABI;
        }
        float *o = r->lights + 12 * i;
        memcpy(o, l->p0, 12);
        o[3] = (float)l->kind;
        memcpy(o + 4, l->p1, 12);
        o[7] = l->intensity;
        memcpy(o + 8, l->color, 12);
        o[11] = l->radius > 0 ? l->radius : 3e38f;
        r->src[i] = *l;
    }
    r->light_count = n;
    return VFX_OK;
}

/* The draw with the lights listed in keep (n of them; keep NULL: all). */
static void draw(rt_renderer *r, const rt_mesh_gpu *mesh, const float model[16], const float rgb[3],
                 const uint32_t *keep, uint32_t n)
{
    mat4 vp;
    view_proj(r, vp);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE);
    glUseProgram(r->mesh_prog);
    glUniformMatrix4fv(r->u_model, 1, GL_FALSE, model);
    glUniformMatrix4fv(r->u_view_proj, 1, GL_FALSE, (const float *)vp);
    glUniform3fv(r->u_color, 1, rgb);
    glUniform3fv(r->u_origin, 1, r->origin);
    float packed[RT_RENDERER_MAX_LIGHTS * 12];
    const float *lights = r->lights;
    if (keep) {
        for (uint32_t i = 0; i < n; ++i)
            memcpy(packed + 12 * i, r->lights + 12 * keep[i], 12 * sizeof(float));
        lights = packed;
    }
    glUniform1i(r->u_light_count, (GLint)n);
    if (n)
        glUniform4fv(r->u_lights, (GLsizei)(3 * n), lights);
    if (r->env.sky) {
        glUniform3fv(r->u_light, 1, r->env.sun_dir);
        glUniform1i(r->u_environment, 1);
        glUniform3fv(r->u_eye, 1, r->env.eye);
        glUniform1f(r->u_fog, r->env.fog_density);
    } else {
        glUniform3f(r->u_light, 0.4f, 0.8f, 0.45f);
        glUniform1i(r->u_environment, 0);
    }
    glBindVertexArray(mesh->vao);
    glDrawElements(GL_TRIANGLES, (GLsizei)mesh->index_count, GL_UNSIGNED_INT, NULL);
    glBindVertexArray(0);
}

void rt_renderer_draw_mesh(rt_renderer *r, const rt_mesh_gpu *mesh, const float model[16],
                            const float rgb[3])
{
    draw(r, mesh, model, rgb, NULL, r->light_count);
}

void rt_renderer_draw_mesh_bounded(rt_renderer *r, const rt_mesh_gpu *mesh, const float model[16],
                                   const float rgb[3], const float lo[3], const float hi[3])
{
    /* the world box of the model box's 8 corners (model maps to origin-relative world) */
    float wlo[3] = {3e38f, 3e38f, 3e38f}, whi[3] = {-3e38f, -3e38f, -3e38f};
    for (int c = 0; c < 8; ++c) {
        float p[3] = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]};
        for (int k = 0; k < 3; ++k) {
            float w = model[12 + k] + model[k] * p[0] + model[4 + k] * p[1] + model[8 + k] * p[2];
            wlo[k] = fminf(wlo[k], w);
            whi[k] = fmaxf(whi[k], w);
        }
    }
    uint32_t keep[RT_RENDERER_MAX_LIGHTS];
    uint32_t n = rt_renderer_lights_near_box(r->src, r->light_count, wlo, whi, keep);
    draw(r, mesh, model, rgb, keep, n);
}

void rt_renderer_get_targets(const rt_renderer *r, rt_renderer_targets *out)
{
    *out = (rt_renderer_targets){.output_framebuffer = r->out_fbo, .scene_color = r->scene_color,
                                 .scene_depth = r->scene_depth, .width = r->width, .height = r->height,
                                 .color_hdr = r->hdr};
}

void rt_renderer_end_scene(rt_renderer *r, rt_renderer_targets *out)
{
    glPopDebugGroup();
    glBlitNamedFramebuffer(r->scene_fbo, r->out_fbo, 0, 0, (GLint)r->width, (GLint)r->height, 0, 0,
                           (GLint)r->width, (GLint)r->height, GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT,
                           GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, r->out_fbo);
    glDisable(GL_DEPTH_TEST);
    glUseProgram(0);
    rt_renderer_get_targets(r, out);
}

vfx_result rt_renderer_read_rgba(rt_renderer *r, uint8_t *rgba)
{
    if (!r || !rgba)
        return VFX_ERR_INVALID_ARGUMENT;
    size_t row = (size_t)r->width * 4;
    uint8_t *tmp = malloc(row * r->height);
    if (!tmp)
        return VFX_ERR_OUT_OF_MEMORY;
    if (r->hdr)
        tonemap(r);
    glGetTextureImage(r->hdr ? r->disp_color : r->out_color, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                      (GLsizei)(row * r->height), tmp);
    for (uint32_t y = 0; y < r->height; ++y) /* GL rows are bottom-up */
        memcpy(rgba + y * row, tmp + (r->height - 1 - y) * row, row);
    free(tmp);
    return glGetError() == GL_NO_ERROR ? VFX_OK : VFX_ERR_GL;
}

void rt_renderer_present(rt_renderer *r, uint32_t ww, uint32_t wh)
{
    if (r->hdr)
        tonemap(r);
    glBlitNamedFramebuffer(r->hdr ? r->disp_fbo : r->out_fbo, 0, 0, 0, (GLint)r->width, (GLint)r->height, 0, 0, (GLint)ww,
                           (GLint)wh, GL_COLOR_BUFFER_BIT, GL_LINEAR);
}
