/* sph_wall.h — internal to runtime/sim: the walls of the domain box and every collider
 * (sph_wall.c): which are near a particle, their kernel share and their terms of the force pass.
 * Uses sph_internal.h only (sph_wall.c itself asks the colliders, sph_collide.h). */
#ifndef RT_SIM_SPH_WALL_H
#define RT_SIM_SPH_WALL_H

#include "sim/sph_internal.h"

/* Walls of the domain box and every collider: density fraction and force integral. */
typedef struct sph_wall_hit {
    float n[3], d, vel[3];
    bool is_box, no_slip;
} sph_wall_hit;

#define SPH_MAX_WALLS (6 + SPH_MAX_COLLIDERS)

/* Number of leading box walls in a gather_walls list (they come before the colliders). */
static inline int sph_walls_box(const sph_wall_hit *w, int nw)
{
    int k = 0;
    while (k < nw && w[k].is_box)
        k++;
    return k;
}

/* The walls within H of p (box faces first, then colliders); their number. */
int rt_sph_gather_walls(const rt_sph *s, float px, float py, float pz, sph_wall_hit *w, int max);
/* Kernel share of the walls: inside = prod over box walls of (1 - f), extra = sum over
 * colliders of f; each wall's f in fr[] when fr is not NULL. Inline: it runs per particle in
 * the density and force passes (out of line it cost ~2% of a substep's instructions). */
static inline void sph_wall_share(const rt_sph *s, const sph_wall_hit *w, int nw, float *fr, float *inside,
                    float *extra)
{
    /* The box walls are perpendicular: the region beyond them is a union of half-spaces,
     * counted as 1 - prod(1 - f) (exact for a separable kernel, close for poly6) so the
     * edges and corners are not compressed by double counting. Colliders just add. */
    int nb = sph_walls_box(w, nw);
    float in = 1.f, ex = 0.f;
    for (int k = 0; k < nw; ++k) {
        float f = s->wall_scale * (float)rt_sph_wall_density_fraction(w[k].d, s->H);
        if (fr)
            fr[k] = f;
        if (k < nb)
            in *= 1.f - f;
        else
            ex += f;
    }
    *inside = in, *extra = ex;
}

/* Wall terms of the force pass for particle (p, v) with pressure term pri, density rhoi:
 * adds the mirror-image pressure and viscosity to a, divides by the fluid share, adds the
 * wall-law friction of no-slip walls (gravity not included). */
void rt_sph_wall_accel(const rt_sph *s, const float p[3], const float vel[3], float pri, float rhoi,
                    float a[3], sph_wall_hit *walls);

#endif
