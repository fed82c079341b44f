/* scan.h — the plugin's one GPU prefix sum (shaders/common/scan.comp): the exclusive scan of a
 * buffer of uint32 counts, the middle step of every counting sort on the GPU (the water's tile
 * bins, its anisotropy pass's hashed grid, the lab's GRID baseline). Two levels of 1024
 * entries; the programs are made once per context and the block sums live in the context. */
#ifndef VOLFX_GPU_SCAN_H
#define VOLFX_GPU_SCAN_H

#include <stdint.h>

#include "gpu/gl.h"
#include "context.h"

/* The most entries one scan takes: 1024 blocks of 1024. */
#define VOLFX_SCAN_MAX (1u << 20)

/* starts[i] = counts[0] + ... + counts[i - 1] for i < n, on the GPU; counts and starts are
 * distinct storage buffers of at least n uint32. n = 0 does nothing; n > VOLFX_SCAN_MAX fails
 * with VFX_ERR_UNSUPPORTED naming `what` and n, running nothing. Binds its own program and SSBO
 * points 0 to 2 (the caller binds its own again after); writes to counts made before it need
 * the caller's GL_SHADER_STORAGE_BARRIER_BIT; its writes are visible to shader storage reads and
 * buffer updates (clears) issued after it returns. */
vfx_result volfx_gpu_scan(vfx_context *ctx, GLuint counts, GLuint starts, uint32_t n, const char *what);
/* Frees the context's scan state (its block sums); the programs belong to the program cache. */
void volfx_gpu_scan_destroy(vfx_context *ctx);

#endif
