/* context.c — services every part of the plugin uses through its context: the host's logger,
 * errors recorded for last_error, allocation through the host allocator, per-frame counters, and
 * the two 4x4 helpers the frame set-up needs. */
#include "context.h"

#include <cglm/cglm.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------ logging, errors, memory */

void volfx_log(vfx_context *ctx, vfx_log_level level, vfx_log_id id, const char *fmt, ...)
{
    char buf[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    if (ctx && ctx->host.log)
        ctx->host.log(ctx->host.user, level, id, buf);
}

vfx_result volfx_fail(vfx_context *ctx, vfx_result code, vfx_log_id id, const char *fmt, ...)
{
    char buf[sizeof ctx->last_error];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    if (ctx) {
        memcpy(ctx->last_error, buf, sizeof buf);
        ctx->last_error_id = id;
        if (ctx->host.log)
            ctx->host.log(ctx->host.user, VFX_LOG_ERROR, id, buf);
    }
    return code;
}

vfx_result volfx_check_type(vfx_context *ctx, const void *p, vfx_struct_type want, const char *what)
{
    vfx_struct_type got = ((const vfx_chain *)p)->type;
    if (got == want)
        return VFX_OK;
    return volfx_fail(ctx, VFX_ERR_ABI, VFX_LOG_ID_STRUCT_TYPE,
                      "%s has type %u, need %u (VFX_TYPE_* of its struct)",
                         what, (unsigned)got, (unsigned)want);
}

const void *volfx_chain_find(const void *next, vfx_struct_type type)
{
    for (int i = 0; next && i < 64; ++i) {
        const vfx_chain *c = next;
        if (c->type == type)
            return c;
        next = c->next;
    }
    return NULL;
}

/* Header in front of each block so free() finds the original pointer whatever the host's
 * allocator aligned. */
typedef struct alloc_header {
    void *base;
    size_t size;
} alloc_header;

void *volfx_alloc(vfx_context *ctx, size_t size)
{
    const size_t align = 64;
    if (size > SIZE_MAX - align - sizeof(alloc_header)) {
        volfx_fail(ctx, VFX_ERR_OUT_OF_MEMORY, VFX_LOG_ID_OUT_OF_MEMORY,
                   "allocation of %zu bytes is too large", size);
        return NULL;
    }
    size_t total = size + align + sizeof(alloc_header);
    void *base = ctx->host.alloc ? ctx->host.alloc(ctx->host.user, total, 16) : malloc(total);
    if (!base) {
        volfx_fail(ctx, VFX_ERR_OUT_OF_MEMORY, VFX_LOG_ID_OUT_OF_MEMORY,
                   "out of memory allocating %zu bytes", size);
        return NULL;
    }
    uintptr_t p = ((uintptr_t)base + sizeof(alloc_header) + align - 1) & ~(uintptr_t)(align - 1);
    alloc_header *h = (alloc_header *)p - 1;
    h->base = base;
    h->size = size;
    memset((void *)p, 0, size);
    return (void *)p;
}

void volfx_free(vfx_context *ctx, void *ptr)
{
    if (!ptr)
        return;
    alloc_header *h = (alloc_header *)ptr - 1;
    if (ctx->host.free)
        ctx->host.free(ctx->host.user, h->base);
    else
        free(h->base);
}

static vfx_stat *stat_slot(vfx_context *ctx, const char *name)
{
    vfx_stats *s = &ctx->stats;
    for (uint32_t i = 0; i < s->count; ++i)
        if (strncmp(s->entries[i].name, name, sizeof s->entries[i].name - 1) == 0)
            return &s->entries[i];
    if (s->count >= VFX_STATS_MAX) {
        s->dropped++;
        return NULL;
    }
    vfx_stat *e = &s->entries[s->count++];
    snprintf(e->name, sizeof e->name, "%s", name);
    e->value = 0;
    return e;
}

void volfx_stat_set(vfx_context *ctx, const char *name, double value)
{
    vfx_stat *e = stat_slot(ctx, name);
    if (e)
        e->value = value;
}

bool volfx_stat_has(const vfx_context *ctx, const char *name)
{
    const vfx_stats *s = &ctx->stats;
    for (uint32_t i = 0; i < s->count; ++i)
        if (strncmp(s->entries[i].name, name, sizeof s->entries[i].name - 1) == 0)
            return true;
    return false;
}

void volfx_stat_add(vfx_context *ctx, const char *name, double value)
{
    vfx_stat *e = stat_slot(ctx, name);
    if (e)
        e->value += value;
}


/* Kept by hand: cglm's glm_mat4_inv works in float and never says "singular"; the plugin inverts
 * view*projection, whose cofactors lose their digits in float for near/far ratios of 1e5, and
 * must refuse a singular camera with an error. */
bool volfx_mat4_invert(const float m[16], float out[16])
{
    double a[16], inv[16];
    for (int i = 0; i < 16; ++i)
        a[i] = m[i];
    inv[0] = a[5]*a[10]*a[15] - a[5]*a[11]*a[14] - a[9]*a[6]*a[15] + a[9]*a[7]*a[14] + a[13]*a[6]*a[11] - a[13]*a[7]*a[10];
    inv[4] = -a[4]*a[10]*a[15] + a[4]*a[11]*a[14] + a[8]*a[6]*a[15] - a[8]*a[7]*a[14] - a[12]*a[6]*a[11] + a[12]*a[7]*a[10];
    inv[8] = a[4]*a[9]*a[15] - a[4]*a[11]*a[13] - a[8]*a[5]*a[15] + a[8]*a[7]*a[13] + a[12]*a[5]*a[11] - a[12]*a[7]*a[9];
    inv[12] = -a[4]*a[9]*a[14] + a[4]*a[10]*a[13] + a[8]*a[5]*a[14] - a[8]*a[6]*a[13] - a[12]*a[5]*a[10] + a[12]*a[6]*a[9];
    inv[1] = -a[1]*a[10]*a[15] + a[1]*a[11]*a[14] + a[9]*a[2]*a[15] - a[9]*a[3]*a[14] - a[13]*a[2]*a[11] + a[13]*a[3]*a[10];
    inv[5] = a[0]*a[10]*a[15] - a[0]*a[11]*a[14] - a[8]*a[2]*a[15] + a[8]*a[3]*a[14] + a[12]*a[2]*a[11] - a[12]*a[3]*a[10];
    inv[9] = -a[0]*a[9]*a[15] + a[0]*a[11]*a[13] + a[8]*a[1]*a[15] - a[8]*a[3]*a[13] - a[12]*a[1]*a[11] + a[12]*a[3]*a[9];
    inv[13] = a[0]*a[9]*a[14] - a[0]*a[10]*a[13] - a[8]*a[1]*a[14] + a[8]*a[2]*a[13] + a[12]*a[1]*a[10] - a[12]*a[2]*a[9];
    inv[2] = a[1]*a[6]*a[15] - a[1]*a[7]*a[14] - a[5]*a[2]*a[15] + a[5]*a[3]*a[14] + a[13]*a[2]*a[7] - a[13]*a[3]*a[6];
    inv[6] = -a[0]*a[6]*a[15] + a[0]*a[7]*a[14] + a[4]*a[2]*a[15] - a[4]*a[3]*a[14] - a[12]*a[2]*a[7] + a[12]*a[3]*a[6];
    inv[10] = a[0]*a[5]*a[15] - a[0]*a[7]*a[13] - a[4]*a[1]*a[15] + a[4]*a[3]*a[13] + a[12]*a[1]*a[7] - a[12]*a[3]*a[5];
    inv[14] = -a[0]*a[5]*a[14] + a[0]*a[6]*a[13] + a[4]*a[1]*a[14] - a[4]*a[2]*a[13] - a[12]*a[1]*a[6] + a[12]*a[2]*a[5];
    inv[3] = -a[1]*a[6]*a[11] + a[1]*a[7]*a[10] + a[5]*a[2]*a[11] - a[5]*a[3]*a[10] - a[9]*a[2]*a[7] + a[9]*a[3]*a[6];
    inv[7] = a[0]*a[6]*a[11] - a[0]*a[7]*a[10] - a[4]*a[2]*a[11] + a[4]*a[3]*a[10] + a[8]*a[2]*a[7] - a[8]*a[3]*a[6];
    inv[11] = -a[0]*a[5]*a[11] + a[0]*a[7]*a[9] + a[4]*a[1]*a[11] - a[4]*a[3]*a[9] - a[8]*a[1]*a[7] + a[8]*a[3]*a[5];
    inv[15] = a[0]*a[5]*a[10] - a[0]*a[6]*a[9] - a[4]*a[1]*a[10] + a[4]*a[2]*a[9] + a[8]*a[1]*a[6] - a[8]*a[2]*a[5];
    double det = a[0] * inv[0] + a[1] * inv[4] + a[2] * inv[8] + a[3] * inv[12];
    if (!(fabs(det) > 1e-300) || !isfinite(det))
        return false;
    for (int i = 0; i < 16; ++i)
        out[i] = (float)(inv[i] / det);
    return true;
}

void volfx_mat4_mul(const float a[16], const float b[16], float out[16])
{
    /* cglm, header-inline; through aligned copies (its SIMD loads want mat4 alignment) and a
     * temporary, so out may be a or b */
    mat4 A, B, C;
    memcpy(A, a, sizeof A);
    memcpy(B, b, sizeof B);
    glm_mat4_mul(A, B, C);
    memcpy(out, C, sizeof C);
}
