/* demo_scene.h — the sample game's scene: the built-in default scene or a scene file, and
 * the animation that moves and deforms every effect each frame. */
#ifndef GAME_DEMO_SCENE_H
#define GAME_DEMO_SCENE_H

#include <stdio.h>
#include "app.h"
#include "scene/scene.h"
#include "sim/sim_gpu.h"
#include "sim/sim_system.h"
#include "spawn/scene_spawn.h"

typedef struct game_demo {
    char description[256];
    uint32_t effects_off;      /* VFX_EFFECT_BIT mask switched off by options or keys */
    rt_scene *scene;          /* the loaded scene (beams are re-evaluated from it each frame) */
    rt_scene_spawned spawned;  /* what the scene spawned: the simulation, the volume and its arrays */
    rt_sim_gpu *sim_gpu;       /* the simulation's GPU device (water.simulation.device; NULL: the CPU) */
    uint32_t beam_base_count;  /* beams in the scene (restored when toggled back on) */
    bool key_latch[8];
    bool mouse_down;
    double mouse_x, mouse_y;
    float impact_strength, impact_radius; /* water.simulation.impact_*: the push where a beam strikes */
    uint32_t impacts_applied;  /* pushes so far, and where the last one was (tests) */
    float last_impact[3];
    /* the volume's table with the animated pulse's 3 entries and, when the scene animates the
     * volume, its spawned points and scalars that each frame starts from */
    float vol_anim_transfer[(RT_SCENE_MAX_TRANSFER + 3) * 4], vol_anim_pos[RT_SCENE_MAX_TRANSFER + 3];
    float *vol_base_points, *vol_base_scalar, vol_center[3], vol_radius;
    struct game_shield *vol_shield; /* rim and hit ripples (volume_shield.h); NULL when off */
    bool vol_animated;
    vfx_volume_view vol_view;  /* the volume's view while switched off */
} game_demo;

/* Loads the scene file `scene_path` (NULL -> the built-in default, sample_game/scenes/
 * default.json embedded at build time; a bare name -> one of the shipped scenes, scene_dir.h),
 * sets the camera and environment, and spawns its content into the world with rt_scene_spawn
 * (meshes, water particles and their SPH system, beams, the volume). Effects in `effects_off`,
 * or not built into the plugin, are left out entirely. On an error nothing is left to free. */
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
