/* program_cache.c — program binaries on disk, never trusted (program_cache.h). */
#include "gpu/program_cache.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define CACHE_MAGIC "VFXPROG1"
#define CACHE_HEADER_VERSION 1u
#define CACHE_MAX_BYTES (64u << 20) /* a program binary larger than this is not ours */

struct volfx_program_cache {
    char *dir;       /* as the host named it, for messages */
    int dirfd;       /* the folder, held open: entries are opened relative to it */
    uint64_t tmp_seed; /* temporary names: unpredictable, and made with O_EXCL */
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

/* The folder is resolved once, here: the host named it, so a symbolic link to a folder is
 * followed at this moment (a ~/.cache link is common). From then on it is held open and every
 * entry and temporary file is opened relative to it, never through a name that can lead
 * elsewhere: entries with O_NOFOLLOW, temporaries created fresh (O_EXCL). */
vfx_result volfx_program_cache_open(vfx_context *ctx, const char *dir, volfx_program_cache **out)
{
    *out = NULL;
    GLint formats = 0;
    glGetIntegerv(GL_NUM_PROGRAM_BINARY_FORMATS, &formats);
    if (formats <= 0) {
        volfx_log(ctx, VFX_LOG_INFO, VFX_LOG_ID_PROGRAM_CACHE_OFF,
                  "program cache %s: the driver offers no program binary format; off", dir);
        return VFX_OK;
    }
    struct stat st;
    if (mkdir(dir, 0755) != 0 && errno != EEXIST)
        return volfx_fail(ctx, VFX_ERR_IO, VFX_LOG_ID_PROGRAM_CACHE_DIR,
                          "program cache %s: cannot make the folder: %s", dir, strerror(errno));
    /* O_NONBLOCK: a FIFO of that name must not block the open (O_DIRECTORY refuses it after) */
    int fd = open(dir, O_RDONLY | O_DIRECTORY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0 || fstat(fd, &st) != 0 || !S_ISDIR(st.st_mode)) {
        int e = errno;
        if (fd >= 0)
            close(fd);
        return volfx_fail(ctx, VFX_ERR_IO, VFX_LOG_ID_PROGRAM_CACHE_DIR,
                          "program cache %s: not a folder (%s)", dir, strerror(e));
    }
    if ((st.st_mode & S_IWOTH) && !(st.st_mode & S_ISVTX))
        volfx_log(ctx, VFX_LOG_WARN, VFX_LOG_ID_PROGRAM_CACHE_UNSAFE,
                  "program cache %s: the folder is writable by every user and not sticky: another "
                  "user can replace entries (each is still checked before use)", dir);
    volfx_program_cache *pc = volfx_alloc(ctx, sizeof *pc);
    char *copy = volfx_alloc(ctx, strlen(dir) + 1);
    if (!pc || !copy) {
        volfx_free(ctx, pc);
        volfx_free(ctx, copy);
        close(fd);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    memcpy(copy, dir, strlen(dir) + 1);
    pc->dir = copy;
    pc->dirfd = fd;
    uint64_t h = FNV_BASIS;
    const GLenum names[3] = {GL_VENDOR, GL_RENDERER, GL_VERSION};
    for (int i = 0; i < 3; ++i) {
        const char *s = (const char *)glGetString(names[i]);
        h = fnv1a(h, s ? s : "", s ? strlen(s) + 1 : 1);
    }
    pc->driver_hash = h;
    pc->tmp_seed = fnv1a(FNV_BASIS, &pc, sizeof pc) ^ (uint64_t)getpid() ^ (uint64_t)time(NULL);
    *out = pc;
    return VFX_OK;
}

void volfx_program_cache_close(vfx_context *ctx, volfx_program_cache *pc)
{
    if (!pc)
        return;
    close(pc->dirfd);
    volfx_free(ctx, pc->dir);
    volfx_free(ctx, pc);
}

volfx_program_cache_counts volfx_program_cache_counts_of(const volfx_program_cache *pc)
{
    return pc ? pc->counts : (volfx_program_cache_counts){0};
}

/* <driver hash>-<source hash>.bin, inside the folder */
static void entry_name(const volfx_program_cache *pc, uint64_t src, char *out, size_t cap)
{
    snprintf(out, cap, "%016llx-%016llx.bin", (unsigned long long)pc->driver_hash, (unsigned long long)src);
}

static void put_u32(unsigned char *p, uint32_t v) { memcpy(p, &v, 4); }
static void put_u64(unsigned char *p, uint64_t v) { memcpy(p, &v, 8); }
static uint32_t get_u32(const unsigned char *p) { uint32_t v; memcpy(&v, p, 4); return v; }
static uint64_t get_u64(const unsigned char *p) { uint64_t v; memcpy(&v, p, 8); return v; }

/* The whole entry, at most CACHE_MAX_BYTES + header; NULL when absent or not usable, with *why
 * set when it exists but is not read. O_NOFOLLOW: a link is never followed out of the folder;
 * O_NONBLOCK: a FIFO planted under the name does not block the open, and fstat refuses it. */
static unsigned char *read_entry(const volfx_program_cache *pc, const char *name, size_t *len, const char **why)
{
    *why = NULL;
    int fd = openat(pc->dirfd, name, O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        if (errno != ENOENT)
            *why = errno == ELOOP ? "a symbolic link (not followed)" : "cannot be opened";
        return NULL;
    }
    unsigned char *buf = NULL;
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
        *why = "not a regular file (a FIFO, device or folder; not read)";
    else if (st.st_size < HEADER_BYTES || (uint64_t)st.st_size > (uint64_t)CACHE_MAX_BYTES + HEADER_BYTES)
        *why = "its size is not that of an entry";
    else if (!(buf = malloc((size_t)st.st_size)))
        *why = "out of memory reading it";
    size_t got = 0;
    while (buf && got < (size_t)st.st_size) {
        ssize_t n = read(fd, buf + got, (size_t)st.st_size - got);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0) {
            free(buf);
            buf = NULL;
            *why = "cannot be read whole";
            break;
        }
        got += (size_t)n;
    }
    close(fd);
    *len = got;
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
    char name[64];
    entry_name(pc, src, name, sizeof name);
    size_t len = 0;
    const char *why = NULL;
    unsigned char *b = read_entry(pc, name, &len, &why);
    entry_header h;
    if (b)
        why = check_entry(pc, src, b, len, &h);
    else if (!why)
        return 0; /* absent: compiled and stored by the caller */
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
        volfx_log(ctx, VFX_LOG_WARN, VFX_LOG_ID_PROGRAM_CACHE_ENTRY,
                  "program cache %s/%s: %s; rebuilt from source", pc->dir, name, why);
        return 0;
    }
    pc->counts.loaded++;
    return prog;
}

/* A fresh temporary file in the folder, as mkstemp makes one but relative to the held folder:
 * an unpredictable name created with O_EXCL (which also refuses a link or FIFO of that name),
 * tried a few times. -1 when none could be made. */
static int make_temp(volfx_program_cache *pc, char *name, size_t cap)
{
    for (int tries = 0; tries < 16; ++tries) {
        pc->tmp_seed = (pc->tmp_seed ^ (uint64_t)clock()) * 6364136223846793005ull + 1442695040888963407ull;
        snprintf(name, cap, ".tmp-%ld-%016llx", (long)getpid(), (unsigned long long)pc->tmp_seed);
        int fd = openat(pc->dirfd, name, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0644);
        if (fd >= 0 || errno != EEXIST)
            return fd;
    }
    return -1;
}

static bool write_all(int fd, const unsigned char *b, size_t n)
{
    while (n > 0) {
        ssize_t w = write(fd, b, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return false;
        b += w, n -= (size_t)w;
    }
    return true;
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
    char name[64], tmp[64];
    entry_name(pc, src, name, sizeof name);
    const char *why = got > 0 ? NULL : "the driver gave no binary";
    int err = 0;
    if (!why) {
        memcpy(b, CACHE_MAGIC, 8);
        put_u32(b + 8, CACHE_HEADER_VERSION), put_u32(b + 12, format);
        put_u64(b + 16, pc->driver_hash), put_u64(b + 24, src);
        put_u64(b + 32, (uint64_t)got), put_u64(b + 40, fnv1a(FNV_BASIS, b + HEADER_BYTES, (size_t)got));
        int fd = make_temp(pc, tmp, sizeof tmp);
        if (fd < 0) {
            why = "cannot make a temporary file in the folder", err = errno;
        } else {
            bool ok = write_all(fd, b, HEADER_BYTES + (size_t)got);
            ok = close(fd) == 0 && ok;
            /* a reader sees the old entry or the whole new one, never half of it; renameat
             * replaces whatever has the entry's name (a link or FIFO itself, not its target) */
            if (!ok || renameat(pc->dirfd, tmp, pc->dirfd, name) != 0) {
                err = errno;
                why = ok ? "cannot rename the temporary file into place" : "cannot write the temporary file";
                unlinkat(pc->dirfd, tmp, 0);
            }
        }
    }
    free(b);
    if (!why)
        pc->counts.stored++;
    else
        volfx_log(ctx, VFX_LOG_WARN, VFX_LOG_ID_PROGRAM_CACHE_STORE,
                  "program cache %s/%s: binary not stored: %s%s%s", pc->dir, name, why,
                  err ? ": " : "", err ? strerror(err) : "");
}
