/* effects.c — see effects.h. */
#include "ecs/effects.h"

#include <string.h>

vfx_result rt_effects_register(rt_world *w, rt_effect_components *out)
{
    const rt_component_desc defs[2] = {{RT_EFFECT_BEAM, sizeof(vfx_beam), _Alignof(vfx_beam), 1},
                                       {RT_EFFECT_VOLUME, sizeof(vfx_volume_view), _Alignof(vfx_volume_view), 1}};
    rt_component ids[2];
    for (int i = 0; i < 2; ++i) {
        ids[i] = rt_world_lookup(w, defs[i].name);
        if (ids[i] != RT_COMPONENT_NONE)
            continue;
        vfx_result r = rt_world_register(w, &defs[i], &ids[i]);
        if (r)
            return r;
    }
    out->beam = ids[0];
    out->volume = ids[1];
    return VFX_OK;
}

vfx_result rt_beams_spawn(rt_world *w, const rt_effect_components *ec, uint32_t n, const vfx_beam *beams,
                          rt_entity *out_ids)
{
    if (!w || !ec)
        return VFX_ERR_INVALID_ARGUMENT;
    if (n == 0)
        return VFX_OK;
    uint32_t before = 0;
    rt_beams_column(w, ec, &before);
    vfx_result r = rt_world_spawn(w, n, &ec->beam, 1, out_ids);
    if (r)
        return r;
    /* spawned rows are appended to the one beam table */
    uint32_t count;
    vfx_beam *col = rt_beams_column(w, ec, &count);
    if (beams)
        memcpy(col + before, beams, (size_t)n * sizeof *beams);
    else
        for (uint32_t i = 0; i < n; ++i)
            col[before + i] = (vfx_beam){.type = VFX_TYPE_BEAM};
    return VFX_OK;
}

vfx_beam *rt_beams_column(rt_world *w, const rt_effect_components *ec, uint32_t *count)
{
    *count = 0;
    rt_query_iter it = rt_query_begin(w, &ec->beam, 1);
    while (rt_query_next(&it))
        if (it.rows) {
            *count = it.rows;
            return rt_query_column(&it, ec->beam, 0);
        }
    return NULL;
}
