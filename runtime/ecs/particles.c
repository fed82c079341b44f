/* particles.c — see particles.h. */
#include "ecs/particles.h"

#include <math.h>

vfx_result rt_particles_register(rt_world *w, rt_particle_components *out)
{
    static const struct { const char *name; uint32_t fields; } defs[4] = {
        {RT_PARTICLE_POSITION, 3}, {RT_PARTICLE_VELOCITY, 3},
        {RT_PARTICLE_DENSITY, 1}, {RT_PARTICLE_RADIUS, 1}};
    rt_component ids[4];
    for (int i = 0; i < 4; ++i) {
        ids[i] = rt_world_lookup(w, defs[i].name);
        if (ids[i] != RT_COMPONENT_NONE)
            continue;
        rt_component_desc d = {defs[i].name, 4 * defs[i].fields, 4, defs[i].fields};
        vfx_result r = rt_world_register(w, &d, &ids[i]);
        if (r)
            return r;
    }
    out->position = ids[0];
    out->velocity = ids[1];
    out->density = ids[2];
    out->radius = ids[3];
    return VFX_OK;
}

vfx_result rt_particles_spawn(rt_world *w, const rt_particle_components *pc, uint32_t n,
                               const float *x, const float *y, const float *z, bool with_radius)
{
    if (!w || !pc)
        return VFX_ERR_INVALID_ARGUMENT;
    for (uint32_t i = 0; i < n; ++i) {
        float v[3] = {x ? x[i] : 0.f, y ? y[i] : 0.f, z ? z[i] : 0.f};
        for (int k = 0; k < 3; ++k)
            if (!isfinite(v[k]))
                return rt_world_fail(w, VFX_ERR_INVALID_ARGUMENT,
                                  "particles: position %c of particle %u is not finite",
                                  "xyz"[k], i);
    }
    rt_component comps[4] = {pc->position, pc->velocity, pc->density, pc->radius};
    /* Spawn in bulk, then fill the new rows (the last n of the particle table). */
    vfx_result r = rt_world_spawn(w, n, comps, with_radius ? 4 : 3, NULL);
    if (r || n == 0)
        return r;
    rt_query_iter it = rt_query_begin(w, comps, with_radius ? 4 : 3);
    while (rt_query_next(&it)) {
        if (rt_world_table_component_count(w, it.table) != (with_radius ? 4u : 3u))
            continue;
        uint32_t base = it.rows - n;
        float *px = rt_query_column(&it, pc->position, 0);
        float *py = rt_query_column(&it, pc->position, 1);
        float *pz = rt_query_column(&it, pc->position, 2);
        for (uint32_t i = 0; i < n; ++i) {
            px[base + i] = x ? x[i] : 0.f;
            py[base + i] = y ? y[i] : 0.f;
            pz[base + i] = z ? z[i] : 0.f;
        }
        if (with_radius) {
            float *rad = rt_query_column(&it, pc->radius, 0);
            for (uint32_t i = 0; i < n; ++i)
                rad[base + i] = 1.f;
        }
        return VFX_OK;
    }
    return rt_world_fail(w, VFX_ERR_NOT_FOUND, "particles: spawned table not found");
}
