/* demo_scene.c — default scene: an arena (floor, walls, an Assimp model when installed), a
 * water block that sloshes, beams fired at targets that grow, thicken and turn. */
#include "demo_scene.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define ARENA_MODEL "/usr/share/assimp/models/OBJ/spider.obj"

vfx_result vfx_demo_load(vfx_app *app, vfx_demo *demo, const char *scene_path, uint32_t effects_off)
{
    memset(demo, 0, sizeof *demo);
    demo->effects_off = effects_off;
    if (scene_path) {
        vfx_logf(&app->log, VFX_LOG_ERROR, "scene files are not supported by this build yet: %s",
                 scene_path);
        return VFX_ERR_UNSUPPORTED;
    }
    static const float floor_c[3] = {0.55f, 0.5f, 0.45f}, wall_c[3] = {0.35f, 0.4f, 0.5f};
    vfx_result r = vfx_app_add_box(app, (float[3]){-4, -0.2f, -4}, (float[3]){4, 0, 4}, floor_c, NULL);
    if (!r) r = vfx_app_add_box(app, (float[3]){-4, 0, -4}, (float[3]){4, 2, -3.8f}, wall_c, NULL);
    if (!r) r = vfx_app_add_box(app, (float[3]){-1.7f, 0, -1.2f}, (float[3]){-1.6f, 0.7f, 1.2f}, wall_c, NULL);
    if (!r) r = vfx_app_add_box(app, (float[3]){1.6f, 0, -1.2f}, (float[3]){1.7f, 0.7f, 1.2f}, wall_c, NULL);
    if (r)
        return r;
    FILE *f = fopen(ARENA_MODEL, "rb");
    if (f) {
        fclose(f);
        float model[16] = {0.02f, 0, 0, 0, 0, 0.02f, 0, 0, 0, 0, 0.02f, 0, 2.6f, 0.4f, -2.2f, 1};
        static const float c[3] = {0.7f, 0.35f, 0.3f};
        if (vfx_app_add_mesh_file(app, ARENA_MODEL, model, c, NULL))
            vfx_logf(&app->log, VFX_LOG_WARN, "arena model skipped");
    }
    /* Water: an SPH pool between the two low walls, sloshed by a paddle; the simulation
     * system writes the particle columns the plugin reads. */
    if (!(effects_off & VFX_EFFECT_BIT(VFX_EFFECT_WATER))) {
        const float spacing = 0.1f;
        vfx_sph_desc sd = {.spacing = spacing, .domain_min = {-1.55f, 0.0f, -1.15f},
                           .domain_max = {1.55f, 1.4f, 1.15f}, .max_substeps = 64,
                           /* 0.6 m of water moves at ~3.4 m/s: c0 = 25 m/s keeps compression near
                            * (3.4/25)^2 = 2% with half the substeps of the default */
                           .sound_speed = 25.0f};
        char err[256];
        if ((r = vfx_sim_system_create(app->world, &sd, &demo->sim, err, sizeof err))) {
            vfx_logf(&app->log, VFX_LOG_ERROR, "water simulation: %s", err);
            return r;
        }
        vfx_sph_collider paddle = {.kind = VFX_SPH_BOX, .center = {-1.45f, 0.5f, 0}, .half = {0.05f, 0.5f, 1.1f},
                                   .motion_axis = {1, 0, 0}, .motion_amplitude = 0.25f,
                                   .motion_frequency = 0.45f};
        if ((r = vfx_sph_add_collider(vfx_sim_system_solver(demo->sim), &paddle, NULL)))
            return r;
        const int nx = 14, ny = 6, nz = 22;
        uint32_t n = (uint32_t)(nx * ny * nz), k = 0;
        float *px = malloc(n * sizeof(float)), *py = malloc(n * sizeof(float)), *pz = malloc(n * sizeof(float));
        if (!px || !py || !pz) {
            free(px), free(py), free(pz);
            return VFX_ERR_OUT_OF_MEMORY;
        }
        for (int a = 0; a < nx; ++a)
            for (int b = 0; b < ny; ++b)
                for (int c = 0; c < nz; ++c, ++k) {
                    px[k] = -1.2f + (a + 0.5f) * spacing;
                    py[k] = (b + 0.5f) * spacing;
                    pz[k] = -1.1f + (c + 0.5f) * spacing;
                }
        r = vfx_particles_spawn(app->world, &app->particles, n, px, py, pz, false);
        free(px), free(py), free(pz);
        if (r)
            return r;
        demo->particle_count = n;
        app->water_enabled = true;
        app->water = (vfx_water_params){.size = sizeof app->water, .version = VFX_WATER_PARAMS_VERSION,
                                        .h = 2.2f * spacing};
    }
    if (!(effects_off & VFX_EFFECT_BIT(VFX_EFFECT_BEAMS))) {
        static const vfx_beam base[3] = {
            {.head = {-3.0f, 1.2f, 0.5f}, .dir = {1, 0, 0}, .length = 2.0f, .radius = 0.6f, .a = 0.05f, .b = 0.03f, .eps = 0.02f, .color = {0.4f, 0.8f, 1.0f, 1}},
            {.head = {2.5f, 1.6f, -1.5f}, .dir = {-1, 0, 0.3f}, .length = 1.5f, .radius = 0.5f, .a = 0.04f, .b = 0.02f, .eps = 0.02f, .color = {1.0f, 0.5f, 0.2f, 1}},
            {.head = {0.0f, 2.2f, 1.5f}, .dir = {0, -0.3f, -1}, .length = 1.0f, .radius = 0.4f, .a = 0.05f, .b = 0.03f, .eps = 0.02f, .color = {0.7f, 1.0f, 0.4f, 1}},
        };
        memcpy(demo->beam_base, base, sizeof base);
        demo->beam_base_count = 3;
        memcpy(app->beams, base, sizeof base);
        app->beam_count = 3;
        app->beams_view = (vfx_beams_view){.size = sizeof app->beams_view, .version = VFX_BEAMS_VIEW_VERSION,
                                           .saturation = VFX_SATURATE_SMOOTH, .saturate_c = 1.0f};
    }
    snprintf(demo->description, sizeof demo->description,
             "default scene: %u meshes, %u particles, %u beams, %u volumes", app->mesh_count,
             demo->particle_count, app->beam_count, app->volume_count);
    return VFX_OK;
}

void vfx_demo_animate(vfx_app *app, vfx_demo *demo, float dt)
{
    (void)dt;
    double t = app->time;
    for (uint32_t i = 0; i < demo->beam_base_count && i < app->beam_count; ++i) {
        const vfx_beam *b = &demo->beam_base[i];
        vfx_beam *o = &app->beams[i];
        /* fired at a target: the head travels, the trail grows and thickens, the beam turns */
        double phase = fmod(t * 0.5 + i * 0.33, 1.0);
        double turn = 0.4 * sin(t * 0.7 + i);
        double c = cos(turn), s = sin(turn);
        o->dir[0] = (float)(b->dir[0] * c - b->dir[2] * s);
        o->dir[1] = b->dir[1];
        o->dir[2] = (float)(b->dir[0] * s + b->dir[2] * c);
        for (int k = 0; k < 3; ++k)
            o->head[k] = b->head[k] + o->dir[k] * (float)(phase * 3.0);
        o->length = b->length * (float)(0.2 + phase);
        o->a = b->a * (float)(0.6 + 0.8 * phase);
        o->b = b->b * (float)(0.6 + 0.8 * phase);
        o->radius = b->radius * (float)(0.7 + 0.6 * phase);
    }
}

void vfx_demo_toggle(vfx_app *app, vfx_demo *demo, vfx_effect_kind kind)
{
    demo->effects_off ^= VFX_EFFECT_BIT(kind);
    bool off = demo->effects_off & VFX_EFFECT_BIT(kind);
    if (kind == VFX_EFFECT_WATER)
        app->water_enabled = !off && demo->particle_count > 0;
    else if (kind == VFX_EFFECT_BEAMS)
        app->beam_count = off ? 0 : demo->beam_base_count;
    else if (kind == VFX_EFFECT_VOLUME)
        app->volume_count = 0; /* volumes come back with the scene file support */
}

void vfx_demo_print_profile(vfx_app *app, FILE *out)
{
    static const char *series[] = {"vfx.sim.sph", "plugin.update", "host.scene", "plugin.render"};
    fprintf(out, "cpu ms (median):");
    for (size_t i = 0; i < sizeof series / sizeof series[0]; ++i) {
        double m = vfx_profiler_series_median(app->profiler, series[i]);
        if (!isnan(m))
            fprintf(out, " %s %.3f", series[i], m);
    }
    fprintf(out, "\n");
    vfx_stats st = {.size = sizeof st, .version = VFX_STATS_VERSION};
    if (app->api->get_stats(app->ctx, &st) == VFX_OK && st.count) {
        fprintf(out, "plugin stats (last frame):");
        for (uint32_t i = 0; i < st.count; ++i)
            fprintf(out, " %s=%.4g", st.entries[i].name, st.entries[i].value);
        fprintf(out, "\n");
    }
}

void vfx_demo_free(vfx_app *app, vfx_demo *demo)
{
    (void)app;
    if (demo->sim) {
        const vfx_sph_report *rep = vfx_sim_system_report(demo->sim);
        if (rep->cap_hit)
            vfx_logf(&app->log, VFX_LOG_WARN, "water simulation: substep cap hit in the last frame");
    }
    vfx_sim_system_destroy(demo->sim); /* the world is destroyed after: it must not run again */
    memset(demo, 0, sizeof *demo);
}
