/* frame_check.h — the frame gate: what the plugin checks of the host's input at the ABI before
 * any effect sees it (the host api's callback pairs; every field of a frame view: version,
 * size, finiteness, near/far against the projection, texture and framebuffer names, their
 * targets, formats and sizes by GL queries), and the one place the camera is derived for the
 * effects (volfx_frame_targets, and its GL block). Every error names the field. */
#ifndef VOLFX_FRAME_CHECK_H
#define VOLFX_FRAME_CHECK_H

#include <stddef.h>

#include "effect.h"

/* VFX_ERR_INVALID_ARGUMENT with "host api: particle_chunk_count is set but particle_chunk is
 * NULL" (and the same for volume_count/volume, alloc/free) into msg; VFX_OK when every pair is
 * complete or absent. */
vfx_result volfx_check_host(const vfx_context_desc *host, char *msg, size_t msglen);

/* The frame gate, step 1 (no GL): the frame view's type, its frame size, finite view, proj,
 * origin and eye, fov_y in [0, pi), effect bits, the reserved layer_texture (refused while
 * unsupported), near/far against the projection (filled from it when the host gave both 0);
 * then everything effects read of the camera into *t, the matrices multiplied and inverted here
 * once (a singular view or view*projection is refused), and the view effects still receive into
 * *checked (near/far filled, next cleared). Every error names the field, through volfx_fail. */
vfx_result volfx_frame_gate(vfx_context *ctx, const vfx_frame_view *frame, volfx_frame_targets *t,
                            vfx_frame_view *checked);

/* The frame gate, step 2, once the context has the frame's size and `drawing` says some effect
 * will draw (else nothing is done): the frame view's GL names (framebuffer, colour and depth
 * textures, cubemap: names, targets, formats, sizes by GL queries); a depth_texture of 0 becomes
 * a far-depth texture of the frame's size in t->scene_depth, owned by the context; then the
 * VolfxFrame block (volfx_frame_block) is uploaded and bound at VOLFX_FRAME_BINDING. */
vfx_result volfx_frame_gate_gl(vfx_context *ctx, bool drawing, volfx_frame_targets *t);

/* near/far the projection P maps to clip z = -w and +w (GL convention) when it is the usual
 * perspective or orthographic form (far may be +Inf), with far's tolerance; false otherwise. */
bool volfx_projection_planes(const float *P, double *n, double *f, double *far_tol);

/* Deletes the context's far-depth texture and frame block buffer (if any). */
void volfx_frame_check_destroy(vfx_context *ctx);

#endif
