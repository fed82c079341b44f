/* program_cache.h — linked program binaries in a folder the host gives (GL_ARB_get_program_binary),
 * keyed by the driver (GL_VENDOR, GL_RENDERER, GL_VERSION) and the program's full source. An
 * entry is used only when its header, its driver and source hashes, its length and its checksum
 * all agree and the driver then accepts the binary (GL_LINK_STATUS); anything else is rebuilt
 * from source and rewritten. The folder is opened once and held; entries are opened in it with
 * O_NOFOLLOW and O_NONBLOCK and must be regular files; a binary is written to a fresh temporary
 * file (O_EXCL, unpredictable name) in the folder and renamed over the entry. */
#ifndef VOLFX_PROGRAM_CACHE_H
#define VOLFX_PROGRAM_CACHE_H

#include <stdint.h>

#include "gpu/gl.h"
#include "context.h"

typedef struct volfx_program_cache volfx_program_cache;

/* Counts since the cache was opened (the stats gpu.programs_*). */
typedef struct volfx_program_cache_counts {
    uint32_t loaded;   /* programs made from a cached binary */
    uint32_t stored;   /* binaries written */
    uint32_t rejected; /* entries found but not used (foreign driver, stale, corrupt, refused) */
} volfx_program_cache_counts;

/* Opens (makes when absent) the folder. *out stays NULL, with VFX_OK and an info message, when
 * the driver offers no binary format (GL_NUM_PROGRAM_BINARY_FORMATS 0: nothing can be cached);
 * VFX_ERR_IO when the folder cannot be made or is not a folder. */
vfx_result volfx_program_cache_open(vfx_context *ctx, const char *dir, volfx_program_cache **out);
/* NULL allowed. */
void volfx_program_cache_close(vfx_context *ctx, volfx_program_cache *pc);
/* A program linked from the binary cached for these stage sources, or 0 (none, or rejected). */
GLuint volfx_program_cache_load(vfx_context *ctx, volfx_program_cache *pc, int n, const GLenum *stages,
                                const char *const *sources);
/* Writes the binary of a program linked from these sources (failures only logged: the cache is
 * an optimisation). */
void volfx_program_cache_store(vfx_context *ctx, volfx_program_cache *pc, int n, const GLenum *stages,
                               const char *const *sources, GLuint prog);
/* The counts so far. */
volfx_program_cache_counts volfx_program_cache_counts_of(const volfx_program_cache *pc);

#endif
