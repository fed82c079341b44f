/* sph_collide.h — internal to runtime/sim: what the solver's files share of the colliders
 * (sph_collide.c): signed distances and their motion. Uses sph_internal.h only. */
#ifndef RT_SIM_SPH_COLLIDE_H
#define RT_SIM_SPH_COLLIDE_H

#include "sim/sph_internal.h"

/* Signed distance of p to a collider surface (positive on the fluid side), outward normal in n. */
float rt_sph_surface_distance(const sph_collider_state *st, float px, float py, float pz, float n[3]);
/* True when p is surely farther than limit (> 0) from a box's or a sphere's surface on the fluid
 * side, from one axis alone: the callers only act within H of a collider, and most particles are
 * far from every one (the default scene's paddle: rt_sph_surface_distance was 13% of all PBF
 * instructions, callgrind). The 1e-4 margin keeps the answer exact against the rounding of
 * rt_sph_surface_distance's sqrt (an ulp), so results are bitwise those of the full test. Planes
 * and meshes answer false (the full test is needed or cheap). */
static inline bool sph_collider_beyond(const sph_collider_state *st, float px, float py, float pz, float limit)
{
    const rt_sph_collider *c = &st->c;
    if (st->sdf || c->kind == RT_SPH_PLANE)
        return false;
    const float d[3] = {px - st->pos[0], py - st->pos[1], pz - st->pos[2]};
    for (int a = 0; a < 3; ++a) {
        float q = fabsf(d[a]) - (c->kind == RT_SPH_BOX ? c->half[a] : c->radius);
        if (q > 1.0001f * limit)
            return true;
    }
    return false;
}
/* Moves every collider to its position and velocity at time t. */
void rt_sph_update_colliders(rt_sph *s, double t);

#endif
