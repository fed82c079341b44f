/* water_gather.c — see water_gather.h. */
#include <string.h>

#include "water/water_gather.h"
#include "gpu/gpu.h"
#include "gpu/pass.h"

struct volfx_water_gather {
    GLuint box;                      /* this upload's reduction: 8 uints (gather.comp's Box) */
    GLuint ring[WATER_GATHER_RING];  /* copies of earlier uploads' boxes, read once fenced */
    GLsync fence[WATER_GATHER_RING];
    uint64_t ring_upload[WATER_GATHER_RING];
    uint64_t upload;                 /* uploads with GPU columns begun so far */
    GLint64 align;                   /* GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT */
    GLint64 block_max;               /* GL_MAX_SHADER_STORAGE_BLOCK_SIZE */
    float use_lo[3], use_hi[3];      /* the box this upload's passes use */
    bool have[2];                    /* newest, before */
    volfx_water_gather_box late[2];  /* newest, before */
};

volfx_water_gather *volfx_water_gather_create(vfx_context *ctx)
{
    return volfx_alloc(ctx, sizeof(volfx_water_gather));
}

void volfx_water_gather_destroy(vfx_context *ctx, volfx_water_gather *g)
{
    if (!g)
        return;
    for (int k = 0; k < WATER_GATHER_RING; ++k)
        if (g->fence[k])
            glDeleteSync(g->fence[k]);
    if (g->ring[0])
        glDeleteBuffers(WATER_GATHER_RING, g->ring);
    if (g->box)
        glDeleteBuffers(1, &g->box);
    volfx_free(ctx, g);
}

vfx_result volfx_water_gather_check(vfx_context *ctx, uint32_t chunk, const char *field, const volfx_gpu_column *col,
                                    uint32_t count, uint32_t elem)
{
    if (!glIsBuffer(col->buffer))
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_GPU_COLUMN,
                          "water: particle chunk %u: %s.buffer %u is not a buffer object of this GL context", chunk, field,
                          col->buffer);
    if (col->stride < elem || col->stride % 4u)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_GPU_COLUMN,
                          "water: particle chunk %u: %s.stride %u must be a multiple of 4 of at least the element's %u bytes",
                          chunk, field, col->stride, elem);
    if (col->offset % 4u)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_GPU_COLUMN,
                          "water: particle chunk %u: %s.offset %llu is not a multiple of 4",
                          chunk, field, (unsigned long long)col->offset);
    GLint64 size = 0;
    glGetNamedBufferParameteri64v(col->buffer, GL_BUFFER_SIZE, &size);
    /* count <= 2^30 and stride < 2^32: the product fits; the offset is compared first */
    uint64_t need = (uint64_t)col->stride * (count - 1u) + elem;
    if (col->offset > (uint64_t)size || need > (uint64_t)size - col->offset)
        return volfx_fail(ctx, VFX_ERR_INVALID_ARGUMENT, VFX_LOG_ID_GPU_COLUMN,
                          "water: particle chunk %u: %s.offset %llu + %s.stride %u x (%u - 1) + %u bytes passes the buffer's "
                          "GL_BUFFER_SIZE of %lld bytes", chunk, field, (unsigned long long)col->offset, field, col->stride,
                          count, elem, (long long)size);
    return VFX_OK;
}

/* key(a) < key(b) iff a < b for finite floats (gather.comp's order_key), and back */
static float key_float(uint32_t key)
{
    uint32_t u = (key & 0x80000000u) ? key & 0x7fffffffu : ~key;
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

/* Reads the fenced boxes that have finished, newest kept in late[0] and the one before in late[1]. */
static void collect(volfx_water_gather *g)
{
    for (int k = 0; k < WATER_GATHER_RING; ++k) {
        if (!g->fence[k])
            continue;
        GLenum st = glClientWaitSync(g->fence[k], 0, 0);
        if (st != GL_ALREADY_SIGNALED && st != GL_CONDITION_SATISFIED)
            continue;
        glDeleteSync(g->fence[k]);
        g->fence[k] = 0;
        uint32_t b[8];
        glGetNamedBufferSubData(g->ring[k], 0, sizeof b, b);
        if (g->have[0] && g->ring_upload[k] <= g->late[0].upload)
            continue; /* an exact box of a later upload is known already */
        volfx_water_gather_box nb = {.bad = b[6], .outside = b[7], .upload = g->ring_upload[k]};
        bool empty = b[0] > b[3] || b[1] > b[4] || b[2] > b[5]; /* no finite particle */
        for (int a = 0; a < 3; ++a) {
            nb.lo[a] = empty ? 0.0f : key_float(b[a]);
            nb.hi[a] = empty ? 0.0f : key_float(b[3 + a]);
        }
        g->late[1] = g->late[0], g->have[1] = g->have[0];
        g->late[0] = nb, g->have[0] = true;
    }
}

vfx_result volfx_water_gather_begin(vfx_context *ctx, volfx_water_gather *g, const float lo[3], const float hi[3])
{
    if (!g->box) {
        glGetInteger64v(GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT, &g->align);
        glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &g->block_max);
        if (g->align < 4)
            g->align = 4;
        g->box = volfx_gpu_storage(32, "water.gather_box");
        glCreateBuffers(WATER_GATHER_RING, g->ring);
        for (int k = 0; k < WATER_GATHER_RING; ++k)
            glNamedBufferStorage(g->ring[k], 32, NULL, 0);
        const char *e = volfx_gpu_error_string();
        if (e)
            return volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR, "water gather: box buffers: %s", e);
    }
    collect(g);
    ++g->upload;
    static const uint32_t init[8] = {0xffffffffu, 0xffffffffu, 0xffffffffu, 0, 0, 0, 0, 0};
    glNamedBufferSubData(g->box, 0, sizeof init, init);
    memcpy(g->use_lo, lo, sizeof g->use_lo);
    memcpy(g->use_hi, hi, sizeof g->use_hi);
    /* the host's own shader writes to its buffer are visible to the gather */
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    return VFX_OK;
}

/* One column through gather.comp in pieces whose bound range fits one storage block. */
static vfx_result gather(vfx_context *ctx, volfx_water_gather *g, const char *defines, const volfx_gpu_column *col,
                         uint32_t count, uint32_t first, bool pos, uint32_t elem)
{
    GLuint prog = volfx_gpu_compute(ctx, "water/gather.comp", defines);
    if (!prog)
        return VFX_ERR_GL;
    uint64_t per = ((uint64_t)g->block_max - (uint64_t)g->align - elem) / col->stride + 1u;
    if (per > 65535u * 256u)
        per = 65535u * 256u;
    glUseProgram(prog);
    if (pos) {
        glUniform3fv(volfx_gpu_uniform(ctx, prog, "u_lo"), 1, g->use_lo);
        glUniform3fv(volfx_gpu_uniform(ctx, prog, "u_hi"), 1, g->use_hi);
    }
    glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_stride"), col->stride / 4u);
    for (uint32_t done = 0; done < count;) {
        uint32_t n = count - done < per ? count - done : (uint32_t)per;
        uint64_t start = col->offset + (uint64_t)done * col->stride;
        uint64_t base = start - start % (uint64_t)g->align;
        uint64_t bytes = start - base + (uint64_t)col->stride * (n - 1u) + elem;
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 0, col->buffer, (GLintptr)base, (GLsizeiptr)bytes);
        glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_count"), n);
        glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_base"), (GLuint)((start - base) / 4u));
        glUniform1ui(volfx_gpu_uniform(ctx, prog, "u_first"), first + done);
        glDispatchCompute((n + 255u) / 256u, 1, 1);
        done += n;
    }
    glUseProgram(0);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    const char *e = volfx_gpu_error_string();
    if (e)
        return volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR,
                          "water gather of %u particles from buffer %u: %s", count, col->buffer, e);
    return VFX_OK;
}

vfx_result volfx_water_gather_positions(vfx_context *ctx, volfx_water_gather *g, const volfx_gpu_column *col,
                                        uint32_t count, const GLuint cols[3], uint32_t first)
{
    if (!count)
        return VFX_OK;
    for (int k = 0; k < 3; ++k)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1 + k, cols[k]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, g->box);
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.gather", .compute = true});
    vfx_result r = gather(ctx, g, "#define MODE_POS\n", col, count, first, true, 12);
    volfx_pass_end(ctx);
    return r;
}

/* A column copied as it is (velocities, kernels) into `out`, `bytes` a particle: no box. */
static vfx_result gather_copy(vfx_context *ctx, volfx_water_gather *g, const char *mode, const volfx_gpu_column *col,
                              uint32_t count, GLuint out, uint32_t first, uint32_t bytes)
{
    if (!count)
        return VFX_OK;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, out);
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.gather", .compute = true});
    vfx_result r = gather(ctx, g, mode, col, count, first, false, bytes);
    volfx_pass_end(ctx);
    return r;
}

vfx_result volfx_water_gather_velocities(vfx_context *ctx, volfx_water_gather *g, const volfx_gpu_column *col,
                                         uint32_t count, GLuint vel, uint32_t first)
{
    return gather_copy(ctx, g, "#define MODE_VEL\n", col, count, vel, first, 12);
}

vfx_result volfx_water_gather_kernels(vfx_context *ctx, volfx_water_gather *g, const volfx_gpu_column *col,
                                      uint32_t count, GLuint kern, uint32_t first)
{
    return gather_copy(ctx, g, "#define MODE_KERNEL\n", col, count, kern, first, 24);
}

void volfx_water_gather_end(volfx_water_gather *g)
{
    /* the slot of the oldest upload (a result never read by now is dropped) */
    int slot = (int)(g->upload % WATER_GATHER_RING);
    if (g->fence[slot])
        glDeleteSync(g->fence[slot]);
    glCopyNamedBufferSubData(g->box, g->ring[slot], 0, 0, 32);
    g->fence[slot] = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    g->ring_upload[slot] = g->upload;
}

bool volfx_water_gather_late(const volfx_water_gather *g, volfx_water_gather_box *newest,
                             volfx_water_gather_box *before, uint64_t *uploads)
{
    *uploads = g->upload;
    if (!g->have[0])
        return false;
    *newest = g->late[0];
    *before = g->have[1] ? g->late[1] : g->late[0];
    return true;
}

void volfx_water_gather_set_exact(volfx_water_gather *g, const float lo[3], const float hi[3], uint32_t bad)
{
    g->late[1] = g->late[0], g->have[1] = g->have[0];
    volfx_water_gather_box b = {.bad = bad, .upload = g->upload};
    memcpy(b.lo, lo, sizeof b.lo);
    memcpy(b.hi, hi, sizeof b.hi);
    g->late[0] = b, g->have[0] = true;
}
