/* scan.c — the GPU prefix sum (scan.h): three dispatches of shaders/common/scan.comp (the blocks
 * of 1024, the block sums in one workgroup, the sums added back). */
#include "gpu/scan.h"

#include "gpu/gpu.h"
#include "gpu/pass.h"

enum { SCAN_BLOCKS, SCAN_TOP, SCAN_ADD, SCAN_PROGS };

struct volfx_scan {
    GLuint prog[SCAN_PROGS];
    GLint n_loc[SCAN_PROGS]; /* u_n of each program */
    GLuint blocks;           /* 1024 block sums */
};

/* The context's scan state, made on first use; NULL with the error recorded. */
static volfx_scan *scan_state(vfx_context *ctx)
{
    if (ctx->scan)
        return ctx->scan;
    GLuint prog[SCAN_PROGS] = {
        volfx_gpu_compute(ctx, "common/scan.comp", "#define SCAN_BLOCKS\n"),
        volfx_gpu_compute(ctx, "common/scan.comp", "#define SCAN_TOP\n"),
        volfx_gpu_compute(ctx, "common/scan.comp", "#define SCAN_ADD\n"),
    };
    for (int k = 0; k < SCAN_PROGS; ++k)
        if (!prog[k])
            return NULL;
    volfx_scan *s = volfx_alloc(ctx, sizeof *s);
    if (!s)
        return NULL;
    static const char *const n_name[1] = {"u_n"};
    for (int k = 0; k < SCAN_PROGS; ++k) {
        s->prog[k] = prog[k];
        volfx_program_uniforms(prog[k], n_name, &s->n_loc[k], 1);
    }
    s->blocks = volfx_gpu_storage(1024 * sizeof(uint32_t), "gpu.scan_blocks");
    const char *e = volfx_gpu_error_string();
    if (e) {
        if (s->blocks)
            glDeleteBuffers(1, &s->blocks);
        volfx_free(ctx, s);
        volfx_fail(ctx, VFX_ERR_OUT_OF_MEMORY, VFX_LOG_ID_GPU_OUT_OF_MEMORY, "gpu scan: its block sums: %s", e);
        return NULL;
    }
    ctx->scan = s;
    return s;
}

static void scan_step(const volfx_scan *s, int k, uint32_t n, GLuint groups, GLbitfield barrier)
{
    glUseProgram(s->prog[k]);
    glUniform1ui(s->n_loc[k], n);
    glDispatchCompute(groups, 1, 1);
    glMemoryBarrier(barrier);
}

vfx_result volfx_gpu_scan(vfx_context *ctx, GLuint counts, GLuint starts, uint32_t n, const char *what)
{
    if (n > VOLFX_SCAN_MAX)
        return volfx_fail(ctx, VFX_ERR_UNSUPPORTED, VFX_LOG_ID_API_ARGUMENT,
                          "gpu scan (%s): %u entries, more than the scan's %u", what, n, VOLFX_SCAN_MAX);
    if (n == 0)
        return VFX_OK;
    volfx_scan *s = scan_state(ctx);
    if (!s)
        return ctx->last_error_id == VFX_LOG_ID_GPU_OUT_OF_MEMORY ? VFX_ERR_OUT_OF_MEMORY : VFX_ERR_GL;
    uint32_t blocks = (n + 1023u) / 1024u;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, counts);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, starts);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, s->blocks);
    scan_step(s, SCAN_BLOCKS, n, blocks, GL_SHADER_STORAGE_BARRIER_BIT);
    scan_step(s, SCAN_TOP, blocks, 1, GL_SHADER_STORAGE_BARRIER_BIT);
    scan_step(s, SCAN_ADD, n, (n + 255u) / 256u, GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    return VFX_OK;
}

void volfx_gpu_scan_destroy(vfx_context *ctx)
{
    if (!ctx->scan)
        return;
    if (ctx->scan->blocks)
        glDeleteBuffers(1, &ctx->scan->blocks);
    volfx_free(ctx, ctx->scan);
    ctx->scan = NULL;
}
