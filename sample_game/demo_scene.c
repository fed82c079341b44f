/* demo_scene.c — reads the game's scene, spawns it into the world in one call (runtime/spawn) and
 * animates it. */
#include "demo_scene.h"
#include "scene_dir.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "volume_shield.h"

extern const char game_default_scene_json[];
extern const unsigned long game_default_scene_json_len;

/* Keeps the loaded points and scalars when the scene animates them (each frame starts there). */
static vfx_result volume_prepare_animation(game_demo *demo, const rt_scene_volume *v)
{
    const rt_scene_volume_animation *an = &v->anim;
    const bool shield = an->rim_gain > 0 || an->hit_gain > 0;
    demo->vol_animated = an->ripple_amplitude > 0 || an->glow_gain > 0 || an->pulse_period_s > 0 || shield;
    if (!demo->vol_animated)
        return VFX_OK;
    size_t np = demo->spawned.vol_point_count;
    demo->vol_base_points = malloc(np * 3 * sizeof(float));
    demo->vol_base_scalar = malloc(np * sizeof(float));
    if (!demo->vol_base_points || !demo->vol_base_scalar)
        return VFX_ERR_OUT_OF_MEMORY;
    memcpy(demo->vol_base_points, demo->spawned.vol_points, np * 3 * sizeof(float));
    memcpy(demo->vol_base_scalar, demo->spawned.vol_scalar, np * sizeof(float));
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < np; ++i)
        for (int k = 0; k < 3; ++k)
            lo[k] = fminf(lo[k], demo->spawned.vol_points[3 * i + k]), hi[k] = fmaxf(hi[k], demo->spawned.vol_points[3 * i + k]);
    for (int k = 0; k < 3; ++k)
        demo->vol_center[k] = 0.5f * (lo[k] + hi[k]);
    demo->vol_center[1] = lo[1]; /* a dome ripples out from its floor */
    float r2 = 0;
    for (size_t i = 0; i < np; ++i) {
        float d2 = 0;
        for (int k = 0; k < 3; ++k)
            d2 += (demo->spawned.vol_points[3 * i + k] - demo->vol_center[k]) * (demo->spawned.vol_points[3 * i + k] - demo->vol_center[k]);
        r2 = fmaxf(r2, d2);
    }
    demo->vol_radius = sqrtf(r2);
    if (shield)
        return game_shield_create(demo->spawned.vol_points, demo->spawned.vol_point_count, demo->spawned.vol_tets, demo->spawned.vol_tet_count,
                                  lo[1], &demo->vol_shield);
    return VFX_OK;
}

/* The beams' light on the volume: per point, a Gaussian of its distance to each beam's axis
 * segment [M, M + L D] (in beam radii), scaled by gain. */
static float beam_glow(const vfx_beam *beams, uint32_t beam_count, const rt_scene_volume_animation *an,
                       const float w[3])
{
    float g = 0;
    for (uint32_t b = 0; b < beam_count; ++b) {
        const vfx_beam *bm = &beams[b];
        float d[3] = {w[0] - bm->head[0], w[1] - bm->head[1], w[2] - bm->head[2]};
        float dl = sqrtf(bm->dir[0] * bm->dir[0] + bm->dir[1] * bm->dir[1] + bm->dir[2] * bm->dir[2]);
        if (!(dl > 0))
            continue;
        float u = (d[0] * bm->dir[0] + d[1] * bm->dir[1] + d[2] * bm->dir[2]) / dl;
        u = u < 0 ? 0 : u > bm->length ? bm->length : u;
        float r2 = 0;
        for (int k = 0; k < 3; ++k) {
            float e = d[k] - u * bm->dir[k] / dl;
            r2 += e * e;
        }
        float s = an->glow_reach * bm->radius;
        g += an->glow_gain * expf(-r2 / (s * s));
    }
    return g;
}

/* One frame of the volume's animation through the ABI: rippled points and beam-lit scalars
 * (new revision), and the transfer function with a bright band at this frame's position. */
static void animate_volume(game_app *app, game_demo *demo)
{
    const rt_scene_volume *v = &demo->scene->volume;
    const rt_scene_volume_animation *an = &v->anim;
    vfx_volume_view *vv = game_app_volume(app, demo->spawned.volume);
    uint32_t beam_count;
    const vfx_beam *beams = game_app_beams(app, &beam_count);
    const double t = app->time;
    if (an->ripple_amplitude > 0 || an->glow_gain > 0 || demo->vol_shield) {
        const float *M = v->model, *c = demo->vol_center;
        const double w = 2 * M_PI / an->ripple_period_s, k = 2 * M_PI / an->ripple_wavelength;
        bool identity = true;
        for (int i = 0; i < 16; ++i)
            identity &= M[i] == 0;
        for (uint32_t i = 0; i < demo->spawned.vol_point_count; ++i) {
            const float *p = &demo->vol_base_points[3 * i];
            float *q = &demo->spawned.vol_points[3 * i];
            float f = an->ripple_amplitude > 0
                          ? (float)(1 + an->ripple_amplitude * sin(k * (p[1] - c[1]) - w * t)) : 1.f;
            for (int j = 0; j < 3; ++j)
                q[j] = c[j] + (p[j] - c[j]) * f;
            float s = demo->vol_base_scalar[i];
            if (an->glow_gain > 0 && beam_count) {
                float wp[3];
                for (int r = 0; r < 3; ++r)
                    wp[r] = identity ? q[r] : M[r] * q[0] + M[4 + r] * q[1] + M[8 + r] * q[2] + M[12 + r];
                s += beam_glow(beams, beam_count, an, wp);
            }
            demo->spawned.vol_scalar[i] = s;
        }
        game_shield_frame sf = {demo->spawned.vol_points, M, {app->camera.eye[0], app->camera.eye[1], app->camera.eye[2]},
                                beams, beam_count, t,
                                {c[0], c[1], c[2]}, demo->vol_radius};
        game_shield_apply(demo->vol_shield, an, &sf, demo->spawned.vol_scalar);
        vv->revision++;
    }
    if (an->pulse_period_s > 0 && demo->spawned.vol_transfer_count >= 2) {
        /* the scene's table with 3 entries inserted: the band's edges (the table's own values
         * there) and its peak, sweeping the domain once per period */
        uint32_t n = demo->spawned.vol_transfer_count;
        float *rgba = demo->spawned.vol_transfer, *pos = demo->spawned.vol_transfer_pos, hw = an->pulse_width;
        float u = (float)(fmod(t / an->pulse_period_s, 1.0) * (1 + 4 * hw) - 2 * hw);
        float band[3] = {u - hw, u, u + hw}, out_rgba[3][4];
        for (int b = 0; b < 3; ++b) { /* the table at the band's points, before inserting */
            uint32_t j = 0;
            while (j + 2 < n && pos[j + 1] <= band[b])
                ++j;
            float f = (band[b] - pos[j]) / (pos[j + 1] - pos[j]);
            f = f < 0 ? 0 : f > 1 ? 1 : f;
            for (int q = 0; q < 4; ++q)
                out_rgba[b][q] = rgba[4 * j + q] + f * (rgba[4 * (j + 1) + q] - rgba[4 * j + q]);
        }
        memcpy(out_rgba[1], an->pulse_rgba, sizeof out_rgba[1]);
        float nr[(RT_SCENE_MAX_TRANSFER + 3) * 4], np_[RT_SCENE_MAX_TRANSFER + 3];
        uint32_t m = 0, b = 0;
        for (uint32_t j = 0; j < n; ++j) {
            for (; b < 3 && band[b] <= pos[j]; ++b)
                if (band[b] > 0 && band[b] < 1 && (m == 0 || band[b] > np_[m - 1])) {
                    np_[m] = band[b];
                    memcpy(&nr[4 * m++], out_rgba[b], 4 * sizeof(float));
                }
            if (m == 0 || pos[j] > np_[m - 1]) {
                np_[m] = pos[j];
                memcpy(&nr[4 * m++], &rgba[4 * j], 4 * sizeof(float));
            }
        }
        /* the animated table lives beside the scene's, which stays for the next frame */
        memcpy(demo->vol_anim_transfer, nr, (size_t)m * 4 * sizeof(float));
        memcpy(demo->vol_anim_pos, np_, (size_t)m * sizeof(float));
        vv->transfer_rgba = demo->vol_anim_transfer;
        vv->transfer_scalar = demo->vol_anim_pos;
        vv->transfer_count = m;
    }
}

static uint32_t beam_count_of(game_app *app)
{
    uint32_t n;
    game_app_beams(app, &n);
    return n;
}

/* The scene's beams at time t into the beam entities (their count is the scene's, capped). */
static void beams_at(game_app *app, game_demo *demo, double t)
{
    uint32_t n;
    vfx_beam *beams = game_app_beams(app, &n);
    if (!n)
        return;
    uint32_t m = n < demo->beam_base_count ? n : demo->beam_base_count;
    rt_scene_beams_at(demo->scene, t, beams, m, &app->joints[0][0], GAME_APP_MAX_JOINTS, &app->joint_count);
}

/* Reads the scene (a file, one of the shipped ones by name, or the built-in default) and sets the
 * app's origin, camera and environment from it. */
static vfx_result read_scene(game_app *app, game_demo *demo, const char *scene_path)
{
    char err[512], dir[4096], found[4096];
    /* a bare name is one of the scenes the game ships; the built-in default's relative paths
     * (its dome mesh) resolve against the same folder */
    scene_path = game_scene_resolve(scene_path, found, sizeof found);
    vfx_result r = scene_path
                       ? rt_scene_load_file(scene_path, &app->log, &demo->scene, err, sizeof err)
                       : rt_scene_load_mem(game_default_scene_json, game_default_scene_json_len,
                                            game_scene_dir(dir, sizeof dir), &app->log, &demo->scene, err, sizeof err);
    if (r) {
        rt_logf(&app->log, VFX_LOG_ERROR, "scene %s: %s", scene_path ? scene_path : "(built-in default)", err);
        return r;
    }
    const rt_scene *sc = demo->scene;
    memcpy(app->origin, sc->origin, sizeof app->origin);
    const rt_scene_camera *c = &sc->camera;
    rt_camera cam = {{c->eye[0], c->eye[1], c->eye[2]}, {c->target[0], c->target[1], c->target[2]},
                          {c->up[0], c->up[1], c->up[2]}, c->fov_y_deg * M_PI / 180.0,
                          app->desc.width ? app->desc.width : c->width, app->desc.height ? app->desc.height : c->height,
                          c->near_plane, c->far_plane};
    if (sc->environment.sky
        && (r = game_app_set_environment(app, true, sc->environment.sun_dir, sc->environment.fog)))
        return r;
    return game_app_set_camera(app, &cam);
}

/* game_app_set_particle_source: the GPU solver's buffers as the one particle chunk (none before
 * the first simulation run made them). */
static bool game_demo_gpu_view(void *user, vfx_particle_view *out)
{
    const game_demo *demo = user;
    return rt_sim_gpu_view(demo->sim_gpu, out);
}

vfx_result game_demo_load(game_app *app, game_demo *demo, const char *scene_path, uint32_t effects_off)
{
    memset(demo, 0, sizeof *demo);
    demo->effects_off = effects_off | ~app->api->effects_built; /* what the plugin lacks is off too */
    vfx_result r = read_scene(app, demo, scene_path);
    if (r) {
        game_demo_free(app, demo);
        return r;
    }
    const rt_scene *sc = demo->scene;
    /* the scene's content into the world, once (runtime/spawn) */
    rt_scene_spawn_desc sd = {.world = app->world, .particles = &app->particles, .effects = &app->effects,
                              .meshes = &app->meshes, .log = &app->log, .effects_off = demo->effects_off,
                              .max_beams = GAME_APP_MAX_BEAMS, .joints = &app->joints[0][0],
                              .joint_cap = GAME_APP_MAX_JOINTS, .sim_stats = rt_profiler_counter,
                              .sim_stats_user = app->profiler};
    char err[1024];
    if ((r = rt_scene_spawn(sc, &sd, &demo->spawned, err, sizeof err))) {
        rt_logf(&app->log, VFX_LOG_ERROR, "%s", err);
        game_demo_free(app, demo);
        return r;
    }
    const rt_scene_spawned *sp = &demo->spawned;
    /* water.simulation.device: "auto" is the GPU on a hardware GL driver (the CPU solver on a
     * software rasteriser such as llvmpipe, where the compute passes run on the same cores slower
     * than the C solver: docs/simulation-gpu.md); "cpu" compiles no compute program */
    const rt_scene_water *w = &sc->water;
    bool gpu = sp->sim && (w->device == RT_SCENE_SIM_GPU || (w->device == RT_SCENE_SIM_AUTO &&
                                                             w->solver == RT_SPH_SOLVER_PBF &&
                                                             !rt_sph_gpu_software_renderer()));
    if (gpu && (r = rt_sim_gpu_attach(sp->sim, &demo->sim_gpu, err, sizeof err))) {
        rt_logf(&app->log, VFX_LOG_ERROR, "scene water.simulation.device: %s", err);
        game_demo_free(app, demo);
        return r;
    }
    if (gpu) /* the plugin reads the solver's GL buffers instead of the particle table */
        game_app_set_particle_source(app, game_demo_gpu_view, demo);
    if (sc->has_water && !(demo->effects_off & VFX_EFFECT_BIT(VFX_EFFECT_WATER))) {
        app->water = sc->water.params;
        app->water_foam = sc->water.foam;
        app->water_enabled = sp->particle_count > 0;
        demo->impact_strength = sc->water.impact_strength, demo->impact_radius = sc->water.impact_radius;
    }
    if (sp->beam_count) {
        demo->beam_base_count = sp->beam_count;
        app->beams_view = sc->beams_view;
        app->joint_count = sp->joint_count;
    }
    if (sp->has_volume && (r = volume_prepare_animation(demo, &sc->volume))) {
        game_demo_free(app, demo);
        return r;
    }
    snprintf(demo->description, sizeof demo->description,
             "scene '%.60s': %u meshes, %u particles%s, %u beams, %u volumes", sc->name, sp->mesh_count,
             sp->particle_count, sp->sim ? " (SPH)" : "", beam_count_of(app), game_app_volume_count(app));
    return VFX_OK;
}

/* Where a beam struck the water (the plugin's impact events of the last frame), the fluid is
 * pushed (rt_sph_impulse; docs/simulation.md "Impacts"), before this frame's simulation step. */
static void strike_water(game_app *app, game_demo *demo)
{
    if (!demo->spawned.sim || !(demo->impact_strength > 0) || (demo->effects_off & VFX_EFFECT_BIT(VFX_EFFECT_WATER)))
        return;
    for (uint32_t i = 0; i < app->impact_count; ++i) {
        const vfx_impact_event *e = &app->impacts[i];
        if (rt_sim_system_impulse(demo->spawned.sim, e->position, e->direction, demo->impact_radius,
                           demo->impact_strength)) {
            demo->impacts_applied++;
            memcpy(demo->last_impact, e->position, sizeof demo->last_impact);
        }
    }
}

void game_demo_animate(game_app *app, game_demo *demo, float dt)
{
    if (dt > 0)
        strike_water(app, demo);
    if (demo->scene) /* keyframed: grow, thicken, move, turn */
        beams_at(app, demo, app->time);
    if (demo->scene && demo->vol_animated && game_app_volume(app, demo->spawned.volume)) /* after the beams: they light it */
        animate_volume(app, demo);
}

void game_demo_toggle(game_app *app, game_demo *demo, vfx_effect_kind kind)
{
    demo->effects_off ^= VFX_EFFECT_BIT(kind);
    bool off = demo->effects_off & VFX_EFFECT_BIT(kind);
    if (kind == VFX_EFFECT_WATER)
        app->water_enabled = !off && demo->spawned.particle_count > 0;
    else if (kind == VFX_EFFECT_BEAMS && off)
        game_app_clear_beams(app);
    else if (kind == VFX_EFFECT_BEAMS && !beam_count_of(app)) /* back: the next animate fills them */
        game_app_add_beams(app, NULL, demo->beam_base_count);
    else if (kind == VFX_EFFECT_VOLUME && off && game_app_volume(app, demo->spawned.volume)) {
        demo->vol_view = *game_app_volume(app, demo->spawned.volume); /* as it was, for switching back */
        game_app_remove(app, demo->spawned.volume);
    } else if (kind == VFX_EFFECT_VOLUME && !off && demo->spawned.vol_tets && !game_app_volume(app, demo->spawned.volume))
        game_app_add_volume(app, &demo->vol_view, &demo->spawned.volume);
}

void game_demo_print_profile(game_app *app, FILE *out)
{
    static const char *series[] = {"vfx.sim.sph", "plugin.update", "host.scene", "plugin.render",
                                   "plugin.render_thread_cpu"};
    static const char *sim[] = {"sim.steps", "sim.iterations", "sim.realtime_factor", "sim.max_speed",
                                "sim.density_error", "sim.device"};
    fprintf(out, "cpu ms (median):");
    for (size_t i = 0; i < sizeof series / sizeof series[0]; ++i) {
        double m = rt_profiler_series_median(app->profiler, series[i]);
        if (!isnan(m))
            fprintf(out, " %s %.3f", series[i], m);
    }
    fprintf(out, "\n");
    if (!isnan(rt_profiler_series_median(app->profiler, sim[0]))) {
        fprintf(out, "sim (median):");
        for (size_t i = 0; i < sizeof sim / sizeof sim[0]; ++i)
            fprintf(out, " %s %.4g", sim[i], rt_profiler_series_median(app->profiler, sim[i]));
        fprintf(out, "\n");
    }
    vfx_stats st = {.type = VFX_TYPE_STATS};
    if (app->api->get_stats(app->ctx, &st) == VFX_OK && st.count) {
        fprintf(out, "plugin stats (last frame):");
        for (uint32_t i = 0; i < st.count; ++i)
            fprintf(out, " %s=%.4g", st.entries[i].name, st.entries[i].value);
        fprintf(out, "\n");
    }
}

void game_demo_free(game_app *app, game_demo *demo)
{
    if (demo->spawned.sim) {
        const rt_sph_report *rep = rt_sim_system_report(demo->spawned.sim);
        if (rep->cap_hit)
            rt_logf(&app->log, VFX_LOG_WARN, "water simulation: substep cap hit in the last frame");
    }
    if (demo->sim_gpu)
        game_app_set_particle_source(app, NULL, NULL);
    rt_scene_despawn(app->world, &demo->spawned); /* the world must not run the simulation after this */
    rt_scene_free(demo->scene);
    free(demo->vol_base_points);
    free(demo->vol_base_scalar);
    game_shield_destroy(demo->vol_shield);
    memset(demo, 0, sizeof *demo);
}
