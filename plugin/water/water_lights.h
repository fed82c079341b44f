/* water_lights.h — the plugin's own lights on the water (docs/water-look.md "Beams in the water,
 * and the water lit by them"): the beams' get_lights (a line light per segment, a point per head and impact) packed once a frame
 * into the uniform block WaterLights of shaders/water/effect_lights.glsl. A frame with no light
 * makes no buffer and builds the shading program without the light loop. */
#ifndef VOLFX_WATER_LIGHTS_H
#define VOLFX_WATER_LIGHTS_H

#include <stdint.h>

#include "context.h"

#define VOLFX_WATER_MAX_LIGHTS 32u   /* lights past this are left out (stat water.effect_lights_dropped) */
#define VOLFX_WATER_LIGHT_HMIN 0.1f  /* a line or point light's distance is clamped below this (m): a
                                      * beam is a tube of about this radius, not a line */
#define VOLFX_WATER_LIGHT_LOBE 0.12f /* the surface's reflection lobe width (radians), effect_lights.glsl */

/* std140 mirror of one WaterLight (shaders/water/effect_lights.glsl). */
typedef struct volfx_water_light_gpu {
    float p0_kind[4], p1_hmin[4], color_i[4];
} volfx_water_light_gpu;

typedef struct volfx_water_lights {
    unsigned buffer;  /* GL uniform buffer, made the first frame with a light */
    uint32_t count;   /* lights this frame */
} volfx_water_lights;

/* Packs this frame's effect lights (the beams', when present) and uploads them; *count is 0 when
 * there are none (then nothing is made or bound). Binds the block at binding 7 otherwise. Stats
 * water.effect_lights, and water.effect_lights_dropped past VOLFX_WATER_MAX_LIGHTS. */
vfx_result volfx_water_lights_frame(vfx_context *ctx, volfx_water_lights *wl, uint32_t *count);
/* Frees the buffer; a zeroed struct is allowed. */
void volfx_water_lights_destroy(volfx_water_lights *wl);

#endif
