/* volume_shield.h — the game's energy-shield look for a scene volume (volume.animate.rim and
 * hit_ripple): a Fresnel-like rim on the mesh's boundary faces where the view grazes them, and
 * rings running out from where a beam strikes the shell. Both are added to the volume's scalar
 * each frame, so the plugin's transfer function lights them (the plugin sees only a mesh, a
 * scalar and a table through the ABI). */
#ifndef GAME_VOLUME_SHIELD_H
#define GAME_VOLUME_SHIELD_H

#include <stdint.h>
#include "volfx/volfx.h"
#include "scene/scene.h"

typedef struct game_shield game_shield;

/* Finds the boundary faces of the tet mesh (faces of one tet only), oriented outwards, less
 * those lying in the floor plane y = floor_y (a dome's floor is no part of its shell). Returns
 * VFX_OK, VFX_ERR_OUT_OF_MEMORY, or VFX_ERR_INVALID_ARGUMENT for an index out of range. */
vfx_result game_shield_create(const float *points, uint32_t point_count, const uint32_t *tets,
                              uint32_t tet_count, float floor_y, game_shield **out);
/* Frees the shield; NULL allowed. */
void game_shield_destroy(game_shield *s);
/* Boundary faces kept (for the log and the test). */
uint32_t game_shield_faces(const game_shield *s);

/* One frame's inputs: the model-space points as deformed this frame, the model matrix (all
 * zero = identity), the eye in world space, the beams, the time, the dome's centre (model
 * space) and its radius. */
typedef struct game_shield_frame {
    const float *points;
    const float *model;
    double eye[3];
    const vfx_beam *beams;
    uint32_t beam_count;
    double time;
    float center[3], radius;
} game_shield_frame;

/* Adds to scalar[i] the rim term w gain (1 - |n.v|)^power at the shell's vertices (n the
 * normal from this frame's boundary faces in world space of the vertex, or inside of its
 * nearest boundary vertex in tet edges; v the unit vector to the eye; w 1 on the boundary,
 * inside fading out over 15% of the radius from the sphere) and the hit ripples of every beam
 * whose axis enters the dome's bounding sphere. */
void game_shield_apply(game_shield *s, const rt_scene_volume_animation *an, const game_shield_frame *f,
                       float *scalar);

#endif
