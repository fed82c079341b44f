/* water_lights.c — the beams' lights packed for the water's shading (water_lights.h). */
#include "water_lights.h"

#include <string.h>

#include "gpu/gl.h"
#include "gpu/gpu.h"
#include "effect.h"
#if VFX_WITH_BEAMS
#include "beams/beams_impact.h"
#endif

/* std140 block WaterLights: uvec4 count, then the lights */
typedef struct water_lights_block {
    uint32_t count[4];
    volfx_water_light_gpu lights[VOLFX_WATER_MAX_LIGHTS];
} water_lights_block;
_Static_assert(sizeof(volfx_water_light_gpu) == 48, "WaterLight is three vec4 in std140");
_Static_assert(VOLFX_WATER_MAX_LIGHTS == 32, "water_effect.c builds shade.frag with WATER_MAX_LIGHTS 32");

vfx_result volfx_water_lights_frame(vfx_context *ctx, volfx_water_lights *wl, uint32_t *count)
{
    *count = wl->count = 0;
#if VFX_WITH_BEAMS
    volfx_beams_impact *im = volfx_beams_impact_of(ctx);
    if (!im)
        return VFX_OK;
    vfx_light src[VOLFX_WATER_MAX_LIGHTS];
    vfx_lights l = {.type = VFX_TYPE_LIGHTS, .capacity = VOLFX_WATER_MAX_LIGHTS, .lights = src};
    volfx_beams_impact_lights(im, &l);
    volfx_stat_set(ctx, "water.effect_lights", l.count);
    if (l.total > l.count)
        volfx_stat_set(ctx, "water.effect_lights_dropped", l.total - l.count);
    if (l.count == 0)
        return VFX_OK;
    water_lights_block blk;
    memset(&blk, 0, sizeof blk);
    blk.count[0] = l.count;
    for (uint32_t i = 0; i < l.count; ++i) {
        volfx_water_light_gpu *g = &blk.lights[i];
        for (int k = 0; k < 3; ++k) {
            g->p0_kind[k] = src[i].p0[k];
            g->p1_hmin[k] = src[i].p1[k];
            g->color_i[k] = src[i].color[k] * src[i].intensity;
        }
        g->p0_kind[3] = src[i].kind == VFX_LIGHT_LINE ? 1.f : 0.f;
        g->p1_hmin[3] = VOLFX_WATER_LIGHT_HMIN;
    }
    if (!wl->buffer) {
        glCreateBuffers(1, &wl->buffer);
        if (!wl->buffer)
            return volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR,
                              "water lights: cannot create a uniform buffer");
        glNamedBufferStorage(wl->buffer, sizeof blk, NULL, GL_DYNAMIC_STORAGE_BIT);
        volfx_gpu_label(GL_BUFFER, wl->buffer, "water.effect_lights");
    }
    glNamedBufferSubData(wl->buffer, 0, (GLsizeiptr)(16 + l.count * sizeof blk.lights[0]), &blk);
    glBindBufferBase(GL_UNIFORM_BUFFER, 7, wl->buffer);
    *count = wl->count = l.count;
#else
    (void)ctx;
    (void)wl;
#endif
    return VFX_OK;
}

void volfx_water_lights_destroy(volfx_water_lights *wl)
{
    if (wl->buffer)
        glDeleteBuffers(1, &wl->buffer);
    wl->buffer = 0;
    wl->count = 0;
}
