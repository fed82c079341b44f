/* water_spray.h — spray and foam of the water effect: the particles that move fast (the
 * splash, the crests the paddle breaks) drawn as soft white billboards over the shaded water,
 * faded where they are under its surface and hidden behind the host's geometry (pass
 * water.spray). It reads the host's optional velocity columns; without them it draws nothing
 * and costs nothing. */
#ifndef VOLFX_WATER_SPRAY_H
#define VOLFX_WATER_SPRAY_H

#include "gpu/gl.h"
#include "effect.h"

typedef struct volfx_water_spray volfx_water_spray;

/* Makes the (empty) spray state; NULL on allocation failure. */
volfx_water_spray *volfx_water_spray_create(vfx_context *ctx);
/* Frees the buffers and the state; NULL allowed. */
void volfx_water_spray_destroy(vfx_context *ctx, volfx_water_spray *sp);
/* Starts an upload of `total` particles: sizes the speed column. */
vfx_result volfx_water_spray_begin(vfx_context *ctx, volfx_water_spray *sp, uint32_t total);
/* Uploads the speeds of particles [first, first + v->count) from v->vel (none: 0, no spray). */
vfx_result volfx_water_spray_chunk(vfx_context *ctx, volfx_water_spray *sp, uint32_t first,
                                   const vfx_particle_view *v);
/* Draws the spray over frame->framebuffer (pass water.spray) from the position columns `cols`
 * (`count` particles): the fast ones, and with a neighbour buffer (a uint a particle; 0: none)
 * the moving ones with fewer than min_neighbours (counted in slot 26 of the counter buffer bound
 * at SSBO binding 4). dist_tex is the water's distance image. Sets water.spray_particles. */
vfx_result volfx_water_spray_draw(vfx_context *ctx, volfx_water_spray *sp, const GLuint cols[3], uint32_t count,
                                  const vfx_water_params *p, const vfx_frame_view *frame,
                                  const volfx_frame_targets *targets, GLuint dist_tex, GLuint vao,
                                  GLuint neighbours, uint32_t min_neighbours);

#endif
