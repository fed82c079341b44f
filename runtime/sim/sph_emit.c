/* sph_emit.c — emitters: nozzles that inject disc-shaped layers of particles. */
#include "sim/sph_internal.h"

#include <string.h>

vfx_result rt_sph_add_emitter(rt_sph *s, const rt_sph_emitter *e, char *err, size_t errlen)
{
    if (!s || !e)
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_emitter: NULL solver or emitter");
    if (s->nem >= SPH_MAX_EMITTERS) {
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_emitter: at most %u emitters", SPH_MAX_EMITTERS);
    }
    rt_sph_emitter k = *e;
    float l = sqrtf(k.direction[0] * k.direction[0] + k.direction[1] * k.direction[1] +
                    k.direction[2] * k.direction[2]);
    if (!sph_finite3(k.center) || !(l > 1e-6f) || !isfinite(l) || !(k.speed > 0.f) || !isfinite(k.speed) ||
        !(k.radius >= 0.5f * s->p.spacing) || !isfinite(k.radius)) {
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_emitter: emitter %u needs finite centre, non-zero direction, "
                "speed > 0 and radius >= spacing/2", s->nem);
    }
    sph_emitter_state *st = &s->em[s->nem++];
    memset(st, 0, sizeof *st);
    for (int a = 0; a < 3; ++a)
        k.direction[a] /= l;
    st->e = k;
    /* nozzle plane basis: any vector not parallel to the direction, orthogonalised */
    const float *d = k.direction;
    float t[3] = {1.f, 0.f, 0.f};
    if (fabsf(d[0]) > 0.9f)
        t[0] = 0.f, t[1] = 1.f;
    float u[3] = {d[1] * t[2] - d[2] * t[1], d[2] * t[0] - d[0] * t[2], d[0] * t[1] - d[1] * t[0]};
    float ul = sqrtf(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int a = 0; a < 3; ++a)
        u[a] /= ul;
    float w[3] = {d[1] * u[2] - d[2] * u[1], d[2] * u[0] - d[0] * u[2], d[0] * u[1] - d[1] * u[0]};
    memcpy(st->u, u, sizeof u);
    memcpy(st->w, w, sizeof w);
    return VFX_OK;
}

vfx_result rt_sph_emit(rt_sph *s, double dt, uint32_t *emitted, char *err, size_t errlen)
{
    float dx = s->p.spacing;
    for (uint32_t k = 0; k < s->nem; ++k) {
        sph_emitter_state *st = &s->em[k];
        const rt_sph_emitter *e = &st->e;
        if (!st->started) {
            st->started = true;
            st->travelled = dx; /* first layer at once */
        } else {
            st->travelled += e->speed * dt;
        }
        while (st->travelled >= dx) {
            st->travelled -= dx;
            int R = (int)floorf(e->radius / dx);
            float off = (float)st->travelled; /* the layer has already moved this far */
            for (int a = -R; a <= R; ++a)
                for (int b = -R; b <= R; ++b) {
                    if (((float)(a * a + b * b)) * dx * dx > e->radius * e->radius)
                        continue;
                    if (e->max_emit && st->emitted >= e->max_emit)
                        return VFX_OK;
                    if (s->n >= s->p.max_particles)
                        return VFX_OK; /* capacity reached: the emitter just stops */
                    float p[3], v[3];
                    for (int c = 0; c < 3; ++c) {
                        p[c] = e->center[c] + (float)a * dx * st->u[c] + (float)b * dx * st->w[c] +
                               off * e->direction[c];
                        v[c] = e->speed * e->direction[c];
                    }
                    vfx_result r = rt_sph_add_particles(s, 1, &p[0], &p[1], &p[2], &v[0], &v[1], &v[2], err, errlen);
                    if (r)
                        return r;
                    st->emitted++;
                    (*emitted)++;
                }
        }
    }
    return VFX_OK;
}
