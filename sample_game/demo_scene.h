/* demo_scene.h — the sample game's scene: the built-in default scene or a scene file, and
 * the animation that moves and deforms every effect each frame. */
#ifndef VFX_DEMO_SCENE_H
#define VFX_DEMO_SCENE_H

#include <stdio.h>
#include "app.h"
#include "sim/sim_system.h"

typedef struct vfx_demo {
    char description[160];
    uint32_t effects_off;      /* VFX_EFFECT_BIT mask switched off by options or keys */
    uint32_t particle_count;
    vfx_beam beam_base[8];
    uint32_t beam_base_count;
    bool key_latch[8];
    bool mouse_down;
    double mouse_x, mouse_y;
    vfx_sim_system *sim;       /* SPH writing the particle columns (NULL without water) */
} vfx_demo;

/* Loads `scene_path` (NULL -> the built-in default) into the app; effects in `effects_off`
 * are left out entirely (nothing allocated for them). */
vfx_result vfx_demo_load(vfx_app *app, vfx_demo *demo, const char *scene_path, uint32_t effects_off);
/* Advances the animation by dt (0 = paused). */
void vfx_demo_animate(vfx_app *app, vfx_demo *demo, float dt);
/* Switches an effect on or off at run time (off = absent from the world). */
void vfx_demo_toggle(vfx_app *app, vfx_demo *demo, vfx_effect_kind kind);
/* Prints median CPU ms per system and GPU ms per pass. */
void vfx_demo_print_profile(vfx_app *app, FILE *out);
/* Frees what load made. */
void vfx_demo_free(vfx_app *app, vfx_demo *demo);

#endif
