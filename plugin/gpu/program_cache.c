/* program_cache.c — program binaries on disk, never trusted (program_cache.h). */
#include "gpu/program_cache.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define CACHE_MAGIC "VFXPROG1"
#define CACHE_HEADER_VERSION 1u
#define CACHE_MAX_BYTES (64u << 20) /* a program binary larger than this is not ours */

struct volfx_program_cache {
    char *dir;
    uint64_t driver_hash;
    volfx_program_cache_counts counts;
};

/* The file's header, written and read field by field (no struct padding on disk). */
typedef struct entry_header {
    uint32_t version, format;
    uint64_t driver_hash, source_hash, length, checksum;
} entry_header;
#define HEADER_BYTES (8 + 2 * 4 + 4 * 8)

static uint64_t fnv1a(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; ++i)
        h = (h ^ p[i]) * 1099511628211ull;
    return h;
}
#define FNV_BASIS 14695981039346656037ull

static uint64_t source_hash(int n, const GLenum *stages, const char *const *sources)
{
    uint64_t h = fnv1a(FNV_BASIS, &n, sizeof n);
    for (int i = 0; i < n; ++i) {
        h = fnv1a(h, &stages[i], sizeof stages[i]);
        h = fnv1a(h, sources[i], strlen(sources[i]) + 1); /* the NUL separates the stages */
    }
    return h;
}

vfx_result volfx_program_cache_open(vfx_context *ctx, const char *dir, volfx_program_cache **out)
{
    *out = NULL;
    GLint formats = 0;
    glGetIntegerv(GL_NUM_PROGRAM_BINARY_FORMATS, &formats);
    if (formats <= 0) {
        volfx_log(ctx, VFX_LOG_INFO, "program cache %s: the driver offers no program binary format; off", dir);
        return VFX_OK;
    }
    struct stat st;
    if (mkdir(dir, 0755) != 0 && errno != EEXIST)
        return volfx_fail(ctx, VFX_ERR_IO, "program cache %s: cannot make the folder: %s", dir, strerror(errno));
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
        return volfx_fail(ctx, VFX_ERR_IO, "program cache %s: not a folder", dir);
    volfx_program_cache *pc = volfx_alloc(ctx, sizeof *pc);
    char *copy = volfx_alloc(ctx, strlen(dir) + 1);
    if (!pc || !copy) {
        volfx_free(ctx, pc);
        volfx_free(ctx, copy);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    memcpy(copy, dir, strlen(dir) + 1);
    pc->dir = copy;
    uint64_t h = FNV_BASIS;
    const GLenum names[3] = {GL_VENDOR, GL_RENDERER, GL_VERSION};
    for (int i = 0; i < 3; ++i) {
        const char *s = (const char *)glGetString(names[i]);
        h = fnv1a(h, s ? s : "", s ? strlen(s) + 1 : 1);
    }
    pc->driver_hash = h;
    *out = pc;
    return VFX_OK;
}

void volfx_program_cache_close(vfx_context *ctx, volfx_program_cache *pc)
{
    if (!pc)
        return;
    volfx_free(ctx, pc->dir);
    volfx_free(ctx, pc);
}

volfx_program_cache_counts volfx_program_cache_counts_of(const volfx_program_cache *pc)
{
    return pc ? pc->counts : (volfx_program_cache_counts){0};
}

/* <dir>/<driver hash>-<source hash>.bin */
static void entry_path(const volfx_program_cache *pc, uint64_t src, char *out, size_t cap)
{
    snprintf(out, cap, "%s/%016llx-%016llx.bin", pc->dir, (unsigned long long)pc->driver_hash,
             (unsigned long long)src);
}

static void put_u32(unsigned char *p, uint32_t v) { memcpy(p, &v, 4); }
static void put_u64(unsigned char *p, uint64_t v) { memcpy(p, &v, 8); }
static uint32_t get_u32(const unsigned char *p) { uint32_t v; memcpy(&v, p, 4); return v; }
static uint64_t get_u64(const unsigned char *p) { uint64_t v; memcpy(&v, p, 8); return v; }

/* The whole file, at most CACHE_MAX_BYTES + header; NULL when absent or unreadable. */
static unsigned char *read_entry(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    unsigned char *buf = NULL;
    struct stat st;
    if (fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode) && st.st_size >= HEADER_BYTES
        && (uint64_t)st.st_size <= (uint64_t)CACHE_MAX_BYTES + HEADER_BYTES && (buf = malloc((size_t)st.st_size))) {
        *len = fread(buf, 1, (size_t)st.st_size, f);
        if (*len != (size_t)st.st_size) {
            free(buf);
            buf = NULL;
        }
    }
    fclose(f);
    return buf;
}

/* Why an entry's bytes cannot be used, or NULL when its header, hashes, length and checksum
 * agree with what this driver and these sources expect. */
static const char *check_entry(const volfx_program_cache *pc, uint64_t src, const unsigned char *b, size_t len,
                               entry_header *h)
{
    if (len < HEADER_BYTES || memcmp(b, CACHE_MAGIC, 8) != 0)
        return "not a volfx program binary";
    h->version = get_u32(b + 8), h->format = get_u32(b + 12);
    h->driver_hash = get_u64(b + 16), h->source_hash = get_u64(b + 24);
    h->length = get_u64(b + 32), h->checksum = get_u64(b + 40);
    if (h->version != CACHE_HEADER_VERSION)
        return "another header version";
    if (h->driver_hash != pc->driver_hash)
        return "made by another driver";
    if (h->source_hash != src)
        return "made from other sources";
    if (h->length != len - HEADER_BYTES)
        return "truncated or padded";
    if (fnv1a(FNV_BASIS, b + HEADER_BYTES, (size_t)h->length) != h->checksum)
        return "checksum mismatch";
    return NULL;
}

GLuint volfx_program_cache_load(vfx_context *ctx, volfx_program_cache *pc, int n, const GLenum *stages,
                                const char *const *sources)
{
    if (!pc)
        return 0;
    uint64_t src = source_hash(n, stages, sources);
    char path[4096];
    entry_path(pc, src, path, sizeof path);
    size_t len = 0;
    unsigned char *b = read_entry(path, &len);
    if (!b)
        return 0; /* absent: compiled and stored by the caller */
    entry_header h;
    const char *why = check_entry(pc, src, b, len, &h);
    GLuint prog = 0;
    if (!why) {
        prog = glCreateProgram();
        glProgramBinary(prog, h.format, b + HEADER_BYTES, (GLsizei)h.length);
        GLint ok = 0;
        glGetProgramiv(prog, GL_LINK_STATUS, &ok);
        if (!ok) {
            glDeleteProgram(prog);
            prog = 0;
            why = "refused by the driver";
        }
        while (glGetError() != GL_NO_ERROR) /* an unknown format is GL_INVALID_ENUM: rejected above */
            ;
    }
    free(b);
    if (why) {
        pc->counts.rejected++;
        volfx_log(ctx, VFX_LOG_WARN, "program cache %s: %s; rebuilt from source", path, why);
        return 0;
    }
    pc->counts.loaded++;
    return prog;
}

void volfx_program_cache_store(vfx_context *ctx, volfx_program_cache *pc, int n, const GLenum *stages,
                               const char *const *sources, GLuint prog)
{
    if (!pc || !prog)
        return;
    GLint len = 0;
    glGetProgramiv(prog, GL_PROGRAM_BINARY_LENGTH, &len);
    if (len <= 0 || (uint32_t)len > CACHE_MAX_BYTES)
        return;
    unsigned char *b = malloc(HEADER_BYTES + (size_t)len);
    if (!b)
        return;
    GLenum format = 0;
    GLsizei got = 0;
    glGetProgramBinary(prog, len, &got, &format, b + HEADER_BYTES);
    uint64_t src = source_hash(n, stages, sources);
    char path[4096], tmp[4200];
    entry_path(pc, src, path, sizeof path);
    snprintf(tmp, sizeof tmp, "%s.%ld.tmp", path, (long)getpid());
    bool ok = got > 0;
    if (ok) {
        memcpy(b, CACHE_MAGIC, 8);
        put_u32(b + 8, CACHE_HEADER_VERSION), put_u32(b + 12, format);
        put_u64(b + 16, pc->driver_hash), put_u64(b + 24, src);
        put_u64(b + 32, (uint64_t)got), put_u64(b + 40, fnv1a(FNV_BASIS, b + HEADER_BYTES, (size_t)got));
        FILE *f = fopen(tmp, "wb");
        ok = f && fwrite(b, 1, HEADER_BYTES + (size_t)got, f) == HEADER_BYTES + (size_t)got;
        ok = (f && fclose(f) == 0) && ok;
        /* a reader sees the old file or the whole new one, never half of it */
        ok = ok && rename(tmp, path) == 0;
        if (!ok)
            remove(tmp);
    }
    free(b);
    if (ok)
        pc->counts.stored++;
    else
        volfx_log(ctx, VFX_LOG_WARN, "program cache %s: cannot write the binary", path);
}
