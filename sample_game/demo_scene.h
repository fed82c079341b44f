/* demo_scene.h — the sample game's scene: the built-in default scene or a scene file, and
 * the animation that moves and deforms every effect each frame. */
#ifndef GAME_DEMO_SCENE_H
#define GAME_DEMO_SCENE_H

#include <stdio.h>
#include "app.h"
#include "scene/scene.h"
#include "sim/sim_system.h"

typedef struct game_demo {
    char description[256];
    uint32_t effects_off;      /* VFX_EFFECT_BIT mask switched off by options or keys */
    uint32_t particle_count;
    rt_scene *scene;          /* the loaded scene (beams are re-evaluated from it each frame) */
    uint32_t beam_base_count;  /* beams in the scene (restored when toggled back on) */
    bool key_latch[8];
    bool mouse_down;
    double mouse_x, mouse_y;
    rt_sim_system *sim;       /* SPH writing the particle columns (NULL without water) */
    float impact_strength, impact_radius; /* water.simulation.impact_*: the push where a beam strikes */
    uint32_t impacts_applied;  /* pushes so far, and where the last one was (tests) */
    float last_impact[3];
    float *vol_points, *vol_scalar;
    /* the volume's table (the animated pulse adds 3 entries) and, when the scene animates the
     * volume, its loaded points and scalars that each frame starts from */
    float vol_transfer[RT_SCENE_MAX_TRANSFER * 4], vol_transfer_pos[RT_SCENE_MAX_TRANSFER];
    uint32_t vol_transfer_count;
    float vol_anim_transfer[(RT_SCENE_MAX_TRANSFER + 3) * 4], vol_anim_pos[RT_SCENE_MAX_TRANSFER + 3];
    float *vol_base_points, *vol_base_scalar, vol_center[3], vol_radius;
    struct game_shield *vol_shield; /* rim and hit ripples (volume_shield.h); NULL when off */
    bool vol_animated;
    rt_entity vol_entity;     /* the volume's entity (stale while the volume is switched off) */
    vfx_volume_view vol_view;  /* its view while switched off */
    vfx_lab_volume vol_lab;    /* the scene's volume.disable (lab switches), chained into its view */
    uint32_t *vol_tets, vol_point_count, vol_tet_count;
} game_demo;

/* Loads the scene file `scene_path` (NULL -> the built-in default, sample_game/scenes/
 * default.json embedded at build time; a bare name -> one of the shipped scenes, scene_dir.h)
 * into the app: meshes as entities, water particles (an
 * SPH system when the scene sets up a simulation), beams with their keyframes, the volume.
 * Effects in `effects_off`, or not built into the plugin, are left out entirely. */
vfx_result game_demo_load(game_app *app, game_demo *demo, const char *scene_path, uint32_t effects_off);
/* Advances the animation by dt (0 = paused). */
void game_demo_animate(game_app *app, game_demo *demo, float dt);
/* Switches an effect on or off at run time (off = absent from the world). */
void game_demo_toggle(game_app *app, game_demo *demo, vfx_effect_kind kind);
/* Prints median CPU ms per system and GPU ms per pass. */
void game_demo_print_profile(game_app *app, FILE *out);
/* Frees what load made. */
void game_demo_free(game_app *app, game_demo *demo);

#endif
