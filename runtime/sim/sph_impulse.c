/* sph_impulse.c — an impulse where something hit the fluid (sph.h rt_sph_impulse): the sample
 * game's answer to a beam striking the water (docs/simulation.md "Impacts"). */
#include <math.h>

#include "sph_internal.h"

uint32_t rt_sph_impulse(rt_sph *s, const float centre[3], const float dir[3], float radius, float speed)
{
    if (!s || !centre || !(radius > 0) || !(speed > 0) || !isfinite(radius) || !isfinite(speed)
        || !isfinite(centre[0]) || !isfinite(centre[1]) || !isfinite(centre[2]))
        return 0;
    float d[3] = {0, 0, 0};
    float dl = dir ? sqrtf(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]) : 0.f;
    if (dl > 0 && isfinite(dl))
        for (int k = 0; k < 3; ++k)
            d[k] = dir[k] / dl;
    uint32_t pushed = 0;
    float r2max = radius * radius;
    for (uint32_t i = 0; i < s->n; ++i) {
        float o[3] = {s->x[i] - centre[0], s->y[i] - centre[1], s->z[i] - centre[2]};
        float r2 = o[0] * o[0] + o[1] * o[1] + o[2] * o[2];
        if (!(r2 < r2max))
            continue;
        float r = sqrtf(r2), w = 1.f - r / radius;
        /* away from the hit, leaning back against the beam's travel: the water under the hit is
         * pushed down and out (a crater), the water beside it up and out (the crown of a splash) */
        float u[3];
        float ul = 0;
        for (int k = 0; k < 3; ++k) {
            u[k] = (r > 1e-6f * radius ? o[k] / r : d[k]) - 0.7f * d[k];
            ul += u[k] * u[k];
        }
        ul = sqrtf(ul);
        if (!(ul > 0))
            continue;
        float vu = (s->vx[i] * u[0] + s->vy[i] * u[1] + s->vz[i] * u[2]) / ul;
        float want = speed * w * w;
        if (vu >= want)
            continue; /* never faster than speed along u: repeated impulses stay bounded */
        float dv = (want - vu) / ul;
        s->vx[i] += dv * u[0], s->vy[i] += dv * u[1], s->vz[i] += dv * u[2];
        pushed++;
    }
    return pushed;
}
