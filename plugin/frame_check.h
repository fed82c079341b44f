/* frame_check.h — what the plugin checks of the host's input at the ABI before any effect sees
 * it: the host api's callback pairs, and a frame view's fields (texture and framebuffer names,
 * their targets, formats and sizes by GL queries, near/far against the projection). Every error
 * names the field. */
#ifndef VOLFX_FRAME_CHECK_H
#define VOLFX_FRAME_CHECK_H

#include <stddef.h>

#include "effect.h"

/* VFX_ERR_INVALID_ARGUMENT with "host api: particle_chunk_count is set but particle_chunk is
 * NULL" (and the same for volume_count/volume, alloc/free) into msg; VFX_OK when every pair is
 * complete or absent. */
vfx_result volfx_check_host(const vfx_host_api *host, char *msg, size_t msglen);

/* Checks `frame` (version 1 or 2; size and version already checked) and writes the view the
 * effects get into *out (version kept; near_plane/far_plane filled from the projection when the
 * host gave both 0). `drawing` true: some effect will draw, so its GL names are queried too.
 * A depth_texture of 0 (no host depth: nothing occludes) becomes a far-depth texture of the
 * frame's size in targets->scene_depth, owned by the context. Errors go through volfx_fail. */
vfx_result volfx_check_frame(vfx_context *ctx, const vfx_frame_view *frame, bool drawing,
                             vfx_frame_view2 *out, volfx_frame_targets *targets);

/* Deletes the context's far-depth texture (if any). */
void volfx_frame_check_destroy(vfx_context *ctx);

#endif
