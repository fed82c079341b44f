/* gpu.c — program cache over the embedded shaders, timestamp ring, debug groups. */
#include "gpu/gpu.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gpu/program_cache.h"
#include "lab_hooks.h"
#include "volfx_shaders.h"
#include "shader_text.h"

#define GPU_MAX_PROGRAMS 256
#define GPU_RING 4          /* frames in flight before a timer result is read */
#define GPU_MAX_PASSES 192  /* timed passes per frame (the paper method repeats 4 per sample step) */
#define GPU_PASS_DEPTH 8    /* nesting */

typedef struct program_entry {
    char *key; /* "vert|frag|defines", whole: ablation sweeps differ only late in the defines */
    GLuint program;
    /* every active uniform's name and location, read once when the program is linked, so the
     * frame path never asks GL by name (volfx_gpu_uniform) */
    uint32_t uniform_count;
    char (*uniform_names)[48];
    GLint *uniform_locs;
} program_entry;

typedef struct timer_frame {
    GLuint queries[GPU_MAX_PASSES * 2];
    char names[GPU_MAX_PASSES][40];
    uint8_t depth[GPU_MAX_PASSES]; /* passes open around it when it began */
    uint32_t count;
} timer_frame;

struct volfx_gpu {
    program_entry programs[GPU_MAX_PROGRAMS];
    uint32_t program_count;
    GLuint empty_vao;
    timer_frame ring[GPU_RING];
    uint32_t frame;                     /* ring slot being recorded */
    uint32_t open[GPU_PASS_DEPTH];      /* open pass slots */
    uint32_t open_count;
    bool has_debug;
    volfx_program_cache *cache; /* program binaries in the host's folder; NULL: off */
};

unsigned volfx_gl_command_count(void) { return VOLFX_GL_COMMAND_COUNT; }

const char *volfx_gpu_error_string(void)
{
    switch (glGetError()) {
    case GL_NO_ERROR: return NULL;
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    default: return "GL error";
    }
}

vfx_result volfx_gpu_check_target(vfx_context *ctx, GLuint fb, const char *what, uint32_t w, uint32_t h)
{
    const char *e = volfx_gpu_error_string();
    if (e && !strcmp(e, "GL_OUT_OF_MEMORY")) /* reported as "incomplete framebuffer" before (issue 28) */
        return volfx_fail(ctx, VFX_ERR_OUT_OF_MEMORY, VFX_LOG_ID_GPU_OUT_OF_MEMORY,
                          "%s %ux%u: out of memory making its textures (GL_OUT_OF_MEMORY)",
                          what, w, h);
    GLenum st = glCheckNamedFramebufferStatus(fb, GL_FRAMEBUFFER);
    if (st != GL_FRAMEBUFFER_COMPLETE || e)
        return volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_FRAMEBUFFER_INCOMPLETE,
                          "%s %ux%u: framebuffer status 0x%x%s%s", what, w, h, st, e ? ", " : "",
                          e ? e : "");
    return VFX_OK;
}

vfx_result volfx_gpu_create(vfx_context *ctx, volfx_gpu **out)
{
    *out = NULL;
    const GLubyte *version = glGetString(GL_VERSION);
    if (!version)
        return volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_NO_CONTEXT,
                          "volfx needs a current GL context on the calling thread");
    GLint major = 0, minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    if (major * 10 + minor < 45 || strncmp((const char *)version, "OpenGL ES", 9) == 0)
        return volfx_fail(ctx, VFX_ERR_GL_UNSUPPORTED, VFX_LOG_ID_GL_VERSION,
                             "volfx needs desktop GL 4.5, the current context is %s", (const char *)version);
    volfx_gpu *g = volfx_alloc(ctx, sizeof *g);
    if (!g)
        return VFX_ERR_OUT_OF_MEMORY;
    glCreateVertexArrays(1, &g->empty_vao);
    volfx_gpu_label(GL_VERTEX_ARRAY, g->empty_vao, "volfx.fullscreen_vao");
    for (int f = 0; f < GPU_RING; ++f)
        glCreateQueries(GL_TIMESTAMP, GPU_MAX_PASSES * 2, g->ring[f].queries);
    g->has_debug = true; /* KHR_debug is core in 4.3 */
    const char *err = volfx_gpu_error_string();
    if (err) {
        volfx_gpu_destroy(ctx, g);
        return volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR, "volfx gpu setup: %s", err);
    }
    *out = g;
    return VFX_OK;
}

void volfx_gpu_destroy(vfx_context *ctx, volfx_gpu *g)
{
    if (!g)
        return;
    for (uint32_t i = 0; i < g->program_count; ++i) {
        glDeleteProgram(g->programs[i].program);
        free(g->programs[i].key);
        volfx_free(ctx, g->programs[i].uniform_names);
        volfx_free(ctx, g->programs[i].uniform_locs);
    }
    for (int f = 0; f < GPU_RING; ++f)
        glDeleteQueries(GPU_MAX_PASSES * 2, g->ring[f].queries);
    glDeleteVertexArrays(1, &g->empty_vao);
    volfx_program_cache_close(ctx, g->cache);
    volfx_free(ctx, g);
}

void volfx_gpu_label(GLenum kind, GLuint object, const char *label)
{
    if (object)
        glObjectLabel(kind, object, -1, label);
}

/* volfx_gpu_link_sources with the table whose line numbers the driver's log decodes by. */
static GLuint link_sources(vfx_context *ctx, const volfx_shader_table *table, int stage_count, const GLenum *stages,
                           const char *const *sources, const char *const *names)
{
    GLuint prog = glCreateProgram();
    GLuint shaders[3] = {0};
    char log[4096], pretty[8192];
    bool ok = true;
    for (int i = 0; i < stage_count && ok; ++i) {
        shaders[i] = glCreateShader(stages[i]);
        glShaderSource(shaders[i], 1, &sources[i], NULL);
        glCompileShader(shaders[i]);
        GLint status = 0;
        glGetShaderiv(shaders[i], GL_COMPILE_STATUS, &status);
        if (!status) {
            glGetShaderInfoLog(shaders[i], sizeof log, NULL, log);
            volfx_shader_rewrite_log(table, log, pretty, sizeof pretty, names[i]);
            volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_SHADER_COMPILE, "shader compile failed: %s", pretty);
            ok = false;
        } else {
            glAttachShader(prog, shaders[i]);
        }
    }
    if (ok) {
        /* the program cache reads the binary back (a hint: drivers may keep it anyway) */
        glProgramParameteri(prog, GL_PROGRAM_BINARY_RETRIEVABLE_HINT, GL_TRUE);
        glLinkProgram(prog);
        GLint status = 0;
        glGetProgramiv(prog, GL_LINK_STATUS, &status);
        if (!status) {
            glGetProgramInfoLog(prog, sizeof log, NULL, log);
            volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_PROGRAM_LINK, "program link failed (%s%s%s): %s", names[0],
                     stage_count > 1 ? " + " : "", stage_count > 1 ? names[1] : "", log);
            ok = false;
        }
    }
    for (int i = 0; i < stage_count; ++i)
        if (shaders[i])
            glDeleteShader(shaders[i]);
    if (!ok) {
        glDeleteProgram(prog);
        return 0;
    }
    return prog;
}

/* Reads the linked program's active uniforms (arrays by their base name) into the entry. */
static void read_uniforms(vfx_context *ctx, program_entry *e)
{
    GLint n = 0;
    glGetProgramiv(e->program, GL_ACTIVE_UNIFORMS, &n);
    if (n <= 0)
        return;
    e->uniform_names = volfx_alloc(ctx, (size_t)n * sizeof *e->uniform_names);
    e->uniform_locs = volfx_alloc(ctx, (size_t)n * sizeof *e->uniform_locs);
    if (!e->uniform_names || !e->uniform_locs)
        return; /* error recorded; volfx_gpu_uniform then answers -1 */
    for (GLint k = 0; k < n; ++k) {
        char *name = e->uniform_names[e->uniform_count];
        glGetActiveUniformName(e->program, (GLuint)k, (GLsizei)sizeof e->uniform_names[0], NULL, name);
        GLint loc = glGetUniformLocation(e->program, name);
        if (loc < 0)
            continue; /* in a uniform block: set through its buffer */
        char *bracket = strstr(name, "[0]");
        if (bracket)
            *bracket = 0;
        e->uniform_locs[e->uniform_count++] = loc;
    }
}

GLuint volfx_gpu_link_sources(vfx_context *ctx, int stage_count, const GLenum *stages,
                            const char *const *sources, const char *const *names)
{
    return link_sources(ctx, &volfx_plugin_shaders, stage_count, stages, sources, names);
}

/* The product's table, or for a program with a stage it lacks the lab's when a lab is attached
 * (lab_hooks.h; the lab's table holds the product's pieces its stages include): libvolfx embeds
 * no lab shader. */
static const volfx_shader_table *table_of(const vfx_context *ctx, int n, const char *const *paths)
{
    for (int i = 0; i < n; ++i)
        if (volfx_shader_index(&volfx_plugin_shaders, paths[i]) < 0 && ctx->lab && ctx->lab->shaders)
            return ctx->lab->shaders;
    return &volfx_plugin_shaders;
}

static GLuint get_program(vfx_context *ctx, int n, const GLenum *stages, const char *const *paths,
                          const char *defines)
{
    volfx_gpu *g = ctx->gpu;
    size_t klen = strlen(paths[0]) + (n > 1 ? strlen(paths[1]) : 0) + (defines ? strlen(defines) : 0) + 3;
    char *key = malloc(klen);
    if (!key) {
        volfx_fail(ctx, VFX_ERR_OUT_OF_MEMORY, VFX_LOG_ID_OUT_OF_MEMORY, "program cache: out of memory");
        return 0;
    }
    snprintf(key, klen, "%s|%s|%s", paths[0], n > 1 ? paths[1] : "", defines ? defines : "");
    for (uint32_t i = 0; i < g->program_count; ++i)
        if (strcmp(g->programs[i].key, key) == 0) {
            free(key);
            return g->programs[i].program;
        }
    if (g->program_count >= GPU_MAX_PROGRAMS) {
        free(key);
        volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_PROGRAM_LIMIT,
                   "program cache full (%d programs)", GPU_MAX_PROGRAMS);
        return 0;
    }
    char *bufs[2] = {NULL, NULL};
    char err[256];
    GLuint prog = 0;
    bool ok = true;
    const volfx_shader_table *table = table_of(ctx, n, paths);
    for (int i = 0; i < n && ok; ++i)
        if (!(bufs[i] = volfx_shader_expand(table, paths[i], defines, err, sizeof err))) {
            volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_SHADER_COMPILE, "%s", err);
            ok = false;
        }
    if (ok && g->cache)
        prog = volfx_program_cache_load(ctx, g->cache, n, stages, (const char *const *)bufs);
    if (ok && !prog) {
        prog = link_sources(ctx, table, n, stages, (const char *const *)bufs, paths);
        if (prog && g->cache)
            volfx_program_cache_store(ctx, g->cache, n, stages, (const char *const *)bufs, prog);
    }
    for (int i = 0; i < n; ++i)
        free(bufs[i]);
    if (!prog) {
        free(key);
        return 0;
    }
    program_entry *e = &g->programs[g->program_count++];
    e->key = key;
    e->program = prog;
    read_uniforms(ctx, e);
    char label[96];
    snprintf(label, sizeof label, "volfx.%s", n > 1 ? paths[1] : paths[0]);
    volfx_gpu_label(GL_PROGRAM, prog, label);
    return prog;
}

vfx_result volfx_gpu_set_program_cache(vfx_context *ctx, const char *dir)
{
    volfx_gpu *g = ctx->gpu;
    volfx_program_cache_close(ctx, g->cache);
    g->cache = NULL;
    if (!dir || !*dir)
        return VFX_OK;
    return volfx_program_cache_open(ctx, dir, &g->cache);
}

GLint volfx_gpu_uniform(vfx_context *ctx, GLuint prog, const char *name)
{
    volfx_gpu *g = ctx->gpu;
    for (uint32_t i = g->program_count; i-- > 0;) {
        const program_entry *e = &g->programs[i];
        if (e->program != prog)
            continue;
        for (uint32_t k = 0; k < e->uniform_count; ++k)
            if (strcmp(e->uniform_names[k], name) == 0)
                return e->uniform_locs[k];
        return -1; /* optimised out or misspelt: GL ignores location -1 */
    }
    return -1;
}

GLuint volfx_gpu_program(vfx_context *ctx, const char *vert, const char *frag, const char *defines)
{
    const GLenum stages[2] = {GL_VERTEX_SHADER, GL_FRAGMENT_SHADER};
    const char *paths[2] = {vert, frag};
    return get_program(ctx, 2, stages, paths, defines);
}

GLuint volfx_gpu_compute(vfx_context *ctx, const char *comp, const char *defines)
{
    const GLenum stages[1] = {GL_COMPUTE_SHADER};
    const char *paths[1] = {comp};
    return get_program(ctx, 1, stages, paths, defines);
}

/* ------------------------------------------------------------------------ timers */

void volfx_gpu_timer_begin(vfx_context *ctx, const char *name)
{
    volfx_gpu *g = ctx->gpu;
    glPushDebugGroup(GL_DEBUG_SOURCE_APPLICATION, 0, -1, name);
    timer_frame *f = &g->ring[g->frame];
    if (f->count >= GPU_MAX_PASSES || g->open_count >= GPU_PASS_DEPTH) {
        if (g->open_count < GPU_PASS_DEPTH)
            g->open[g->open_count++] = UINT32_MAX; /* untimed */
        return;
    }
    uint32_t slot = f->count++;
    snprintf(f->names[slot], sizeof f->names[slot], "%s", name);
    f->depth[slot] = (uint8_t)g->open_count;
    glQueryCounter(f->queries[slot * 2], GL_TIMESTAMP);
    g->open[g->open_count++] = slot;
}

void volfx_gpu_timer_end(vfx_context *ctx)
{
    volfx_gpu *g = ctx->gpu;
    if (g->open_count == 0)
        return;
    uint32_t slot = g->open[--g->open_count];
    if (slot != UINT32_MAX)
        glQueryCounter(g->ring[g->frame].queries[slot * 2 + 1], GL_TIMESTAMP);
    glPopDebugGroup();
}

void volfx_gpu_frame_end(vfx_context *ctx)
{
    volfx_gpu *g = ctx->gpu;
    while (g->open_count)
        volfx_gpu_timer_end(ctx);
    /* The oldest slot was recorded GPU_RING-1 frames ago: read it only if it is ready. */
    uint32_t oldest = (g->frame + 1) % GPU_RING;
    timer_frame *f = &g->ring[oldest];
    for (uint32_t i = 0; i < f->count; ++i) {
        GLint ready = 0;
        glGetQueryObjectiv(f->queries[i * 2 + 1], GL_QUERY_RESULT_AVAILABLE, &ready);
        if (!ready)
            continue;
        GLuint64 t0 = 0, t1 = 0;
        glGetQueryObjectui64v(f->queries[i * 2], GL_QUERY_RESULT, &t0);
        glGetQueryObjectui64v(f->queries[i * 2 + 1], GL_QUERY_RESULT, &t1);
        char name[48];
        snprintf(name, sizeof name, "%s.gpu_ms", f->names[i]);
        /* A pass run several times in one frame (the paper's march loop) reports its total. The
         * stats keep the order of the first runs, and a pass opened inside another says how
         * deep: with these a profiler nests the passes, which the sums alone cannot tell. Start
         * times are not sent: the 64 stat slots are too few for one more entry per pass. */
        bool first = !volfx_stat_has(ctx, name);
        volfx_stat_add(ctx, name, t1 > t0 ? (double)(t1 - t0) * 1e-6 : 0.0);
        if (first && f->depth[i]) {
            snprintf(name, sizeof name, "%s.gpu_depth", f->names[i]);
            volfx_stat_set(ctx, name, f->depth[i]);
        }
    }
    if (f->count)
        volfx_stat_set(ctx, "gpu.timer_lag_frames", GPU_RING - 1);
    if (g->cache) {
        volfx_program_cache_counts c = volfx_program_cache_counts_of(g->cache);
        volfx_stat_set(ctx, "gpu.program_cache_loaded", c.loaded);
        volfx_stat_set(ctx, "gpu.program_cache_stored", c.stored);
        volfx_stat_set(ctx, "gpu.program_cache_rejected", c.rejected);
    }
    f->count = 0;
    g->frame = oldest;
}

void volfx_gpu_fullscreen(vfx_context *ctx)
{
    glBindVertexArray(ctx->gpu->empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
}

vfx_result volfx_gpu_read_top_first(vfx_context *ctx, GLuint tex, GLenum format, uint32_t comps,
                                  int channel, uint32_t w, uint32_t h, float *out)
{
    size_t n = (size_t)w * h * comps;
    float *tmp = volfx_alloc(ctx, n * sizeof *tmp);
    if (!tmp)
        return VFX_ERR_OUT_OF_MEMORY;
    glGetTextureImage(tex, 0, format, GL_FLOAT, (GLsizei)(n * sizeof *tmp), tmp);
    size_t row = (size_t)w * comps;
    for (uint32_t j = 0; j < h; ++j) {
        const float *src = tmp + (size_t)(h - 1 - j) * row;
        if (channel < 0)
            memcpy(out + j * row, src, row * sizeof *out);
        else
            for (uint32_t i = 0; i < w; ++i)
                out[(size_t)j * w + i] = src[(size_t)i * comps + (uint32_t)channel];
    }
    volfx_free(ctx, tmp);
    return VFX_OK;
}

GLuint volfx_gpu_storage(GLsizeiptr bytes, const char *label)
{
    GLuint b;
    glCreateBuffers(1, &b);
    glNamedBufferStorage(b, bytes, NULL, GL_DYNAMIC_STORAGE_BIT);
    volfx_gpu_label(GL_BUFFER, b, label);
    return b;
}
