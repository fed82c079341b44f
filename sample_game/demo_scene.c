/* demo_scene.c — turns a scene (runtime/scene) into app content and animates it. */
#include "demo_scene.h"
#include "scene_dir.h"
#include "core/file.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene/volume_file.h"
#include "volume_shield.h"

extern const char game_default_scene_json[];
extern const unsigned long game_default_scene_json_len;

static vfx_result load_meshes(game_app *app, const rt_scene *sc)
{
    for (uint32_t i = 0; i < sc->mesh_count; ++i) {
        const rt_scene_mesh *m = &sc->meshes[i];
        rt_entity e;
        vfx_result r;
        if (m->is_box) {
            if ((r = game_app_add_box(app, m->box_min, m->box_max, m->color, &e)))
                return r;
            memcpy(rt_world_get(app->world, e, app->transform_comp, 0), m->model, sizeof m->model);
            continue;
        }
        /* a missing decoration is not worth refusing the scene for; stat, not fopen: opening
         * a FIFO for reading blocks forever */
        char why[RT_SCENE_PATH_MAX + 64];
        if (rt_check_regular_file(m->path, why, sizeof why)) {
            rt_logf(&app->log, VFX_LOG_WARN, "scene meshes[%u]: %s, skipped", i, why);
            continue;
        }
        if ((r = game_app_add_mesh_file(app, m->path, m->model, m->color, NULL)))
            return r;
    }
    return VFX_OK;
}

/* The simulation's block on the solver's calibrated lattice (issue 22: the scene's lattice left
 * the floor layer 2 cm from the floor where the solver's wall term is calibrated for dx/2, ~6%
 * compressed, and put ~1,300 particles behind the paddle): cell centres dx/2 from every tank
 * wall the fluid box comes within dx of, in front of the paddle's plate at t = 0, filled from
 * the bottom (y) up with the scene's count. */
static void sim_lattice(const rt_scene_water *w, float dx, float *px, float *py, float *pz, uint32_t n)
{
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
        lo[k] = w->box_min[k] - w->tank_min[k] < dx ? w->tank_min[k] : w->box_min[k];
        hi[k] = w->tank_max[k] - w->box_max[k] < dx ? w->tank_max[k] : w->box_max[k];
    }
    if (w->paddle) {
        uint32_t ax = w->paddle_axis < 3 ? w->paddle_axis : 0;
        double face = w->tank_min[ax] + w->paddle_amplitude + 1.5 * dx; /* as load_water's plate */
        if (lo[ax] < face)
            lo[ax] = face;
        if (hi[ax] < lo[ax] + dx)
            hi[ax] = lo[ax] + dx;
    }
    uint32_t nx = (uint32_t)fmax(1.0, floor((hi[0] - lo[0]) / dx));
    uint32_t nz = (uint32_t)fmax(1.0, floor((hi[2] - lo[2]) / dx));
    for (uint32_t i = 0; i < n; ++i) {
        uint32_t layer = i / (nx * nz), q = i % (nx * nz);
        px[i] = (float)(lo[0] + ((double)(q % nx) + 0.5) * dx);
        pz[i] = (float)(lo[2] + ((double)(q / nx) + 0.5) * dx);
        py[i] = (float)(lo[1] + ((double)layer + 0.5) * dx);
    }
}

static vfx_result load_water(game_app *app, game_demo *demo, const rt_scene *sc)
{
    const rt_scene_water *w = &sc->water;
    float *xyz = NULL;
    uint32_t n = 0;
    char err[256];
    vfx_result r = rt_scene_water_particles(w, &xyz, &n, err, sizeof err);
    if (r) {
        rt_logf(&app->log, VFX_LOG_ERROR, "scene water: %s", err);
        return r;
    }
    if (n == 0 && w->source == RT_SCENE_WATER_FILE) /* valid, but drawn as nothing: say so */
        rt_logf(&app->log, VFX_LOG_WARN, "scene water.path %s: the file holds no particles (0 bytes); no water is "
                "drawn", w->path);
    float *px = malloc((n ? n : 1) * sizeof(float)), *py = malloc((n ? n : 1) * sizeof(float)),
          *pz = malloc((n ? n : 1) * sizeof(float));
    if (!px || !py || !pz) {
        free(px), free(py), free(pz), free(xyz);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t i = 0; i < n; ++i)
        px[i] = xyz[3 * i], py[i] = xyz[3 * i + 1], pz[i] = xyz[3 * i + 2];
    free(xyz);
    if (w->source == RT_SCENE_WATER_SIMULATION && n > 0) {
        /* the particle spacing follows from the count filling the initial block */
        double vol = 1.0;
        for (int k = 0; k < 3; ++k)
            vol *= fmax(w->box_max[k] - w->box_min[k], 1e-6);
        float spacing = (float)cbrt(vol / n);
        sim_lattice(w, spacing, px, py, pz, n);
        rt_sph_desc sd = {.spacing = spacing, .max_substeps = 64,
                           /* ~0.6 m of water moves at ~3.4 m/s: c0 = 25 m/s keeps the compression
                            * near (3.4/25)^2 = 2% with half the substeps of the default */
                           .sound_speed = 25.0f, .solver = w->solver};
        memcpy(sd.domain_min, w->tank_min, sizeof sd.domain_min);
        memcpy(sd.domain_max, w->tank_max, sizeof sd.domain_max);
        memcpy(sd.gravity, w->gravity, sizeof sd.gravity);
        if (w->gravity[0] == 0 && w->gravity[1] == 0 && w->gravity[2] == 0)
            sd.flags |= RT_SPH_NO_GRAVITY;
        if (w->no_slip)
            sd.no_slip_faces = 0x3fu; /* every tank face */
        demo->impact_strength = w->impact_strength, demo->impact_radius = w->impact_radius;
        if ((r = rt_sim_system_create(app->world, &sd, &demo->sim, err, sizeof err))) {
            rt_logf(&app->log, VFX_LOG_ERROR, "scene water simulation: %s", err);
            goto done;
        }
        /* the scene's dt is the clock's step: whole steps follow the frame clock (up to 4 a
         * frame); the profiler records the sim.* figures every frame */
        rt_sim_system_set_stats_sink(demo->sim, rt_profiler_counter, app->profiler);
        if ((r = rt_sim_system_set_clock(demo->sim, w->dt, 4)))
            goto done;
        /* a step of more than 0.5 s (under 2 frames a second) is said once, naming the count and
         * the tank (200,000 particles in a 1 m tank took 14 s a step) */
        if ((r = rt_sim_system_warn_slow(demo->sim, 0.5, &app->log)))
            goto done;
        if ((r = rt_sim_system_set_label(demo->sim, "scene water.simulation", sc->origin)))
            goto done;
        /* the block starts on the calibrated lattice at rho0, which neither solver holds at rest:
         * settled into the solver's hydrostatic state before frame 0, it does not sink into it
         * during the first second (docs/simulation.md "Start at rest"; water.simulation.settle_steps) */
        rt_sph_settle_desc settle = {.max_steps = w->settle_steps};
        if (w->settle_steps && (r = rt_sim_system_settle_next(demo->sim, &settle, &app->log)))
            goto done;
        if (w->paddle) {
            uint32_t ax = w->paddle_axis < 3 ? w->paddle_axis : 0;
            rt_sph_collider paddle = {.kind = RT_SPH_BOX, .motion_amplitude = w->paddle_amplitude,
                                       .motion_frequency = w->paddle_period_s > 0 ? 1.0f / w->paddle_period_s : 0,
                                       .motion_ramp_s = w->paddle_ramp_s};
            for (int k = 0; k < 3; ++k) {
                paddle.center[k] = 0.5f * (w->tank_min[k] + w->tank_max[k]);
                paddle.half[k] = 0.5f * (w->tank_max[k] - w->tank_min[k]);
            }
            /* a thin plate at the low end of the axis, pushing the fluid along it */
            paddle.half[ax] = 0.5f * spacing;
            paddle.center[ax] = w->tank_min[ax] + w->paddle_amplitude + spacing;
            paddle.motion_axis[ax] = 1.0f;
            if ((r = rt_sph_add_collider(rt_sim_system_solver(demo->sim), &paddle, NULL, err, sizeof err))) {
                rt_logf(&app->log, VFX_LOG_ERROR, "scene water paddle: %s", err);
                goto done;
            }
        }
    }
    if ((r = rt_particles_spawn(app->world, &app->particles, n, px, py, pz, false)))
        goto done;
    demo->particle_count = n;
    app->water = w->params;
    app->water_lab = w->lab;
    app->water_foam = w->foam;
    app->water_enabled = n > 0;
done:
    free(px), free(py), free(pz);
    return r;
}

/* The volume's mesh: a generated grid, or a .vtu / TetGen file through the host-side loaders.
 * A missing or malformed file is an error naming it that stops the load. */
static vfx_result volume_mesh(game_app *app, game_demo *demo, const rt_scene_volume *v)
{
    char err[512];
    vfx_result r;
    if (v->generated) {
        r = rt_scene_volume_generate(v, &demo->vol_points, &demo->vol_point_count, &demo->vol_tets,
                                     &demo->vol_tet_count, &demo->vol_scalar, err, sizeof err);
        if (r)
            rt_logf(&app->log, VFX_LOG_ERROR, "scene volume: %s", err);
        return r;
    }
    tet_mesh m;
    size_t len = strlen(v->path);
    bool vtu = len > 4 && !strcmp(v->path + len - 4, ".vtu");
    if (vtu) {
        r = rt_volume_load_vtu(v->path, v->scalar, &m, err, sizeof err);
        if (r == VFX_ERR_NOT_FOUND && !v->scalar[0]) /* the loader lists the point fields */
            rt_logf(&app->log, VFX_LOG_ERROR, "scene volume.scalar: name the point field of %s (%s)", v->path,
                    strstr(err, "present:") ? strstr(err, "present:") : err);
        else if (r)
            rt_logf(&app->log, VFX_LOG_ERROR, "scene volume.path: %s", err);
    } else {
        char base[RT_SCENE_PATH_MAX];
        snprintf(base, sizeof base, "%.*s", (int)(len - 5), v->path); /* without ".node" */
        r = rt_volume_load_tetgen(base, v->scalar, &m, err, sizeof err);
        if (r)
            rt_logf(&app->log, VFX_LOG_ERROR, "scene volume.path: %s", err);
    }
    if (r)
        return r;
    if (!m.scalar) {
        rt_logf(&app->log, VFX_LOG_ERROR, "scene volume.path: %s has no point field to render", v->path);
        tet_mesh_free(&m);
        return VFX_ERR_FORMAT;
    }
    demo->vol_points = m.points, demo->vol_tets = m.tets, demo->vol_scalar = m.scalar;
    demo->vol_point_count = m.point_count, demo->vol_tet_count = m.tet_count;
    rt_logf(&app->log, VFX_LOG_INFO, "scene volume %s: %u points, %u tets, field %s in [%g, %g]", v->path,
            m.point_count, m.tet_count, m.scalar_name, (double)m.scalar_min, (double)m.scalar_max);
    return VFX_OK;
}

/* The scene's transfer function as the plugin's table: every control point (one point is a
 * constant), at its position in [0,1] of the domain (version-2 view). */
static void volume_transfer(game_demo *demo, const rt_scene_volume *v, vfx_volume_view *vv)
{
    uint32_t n = v->transfer_count;
    if (n == 0)
        return;
    const rt_scene_transfer_point *tp = v->transfer;
    double lo = tp[0].scalar, hi = tp[n - 1].scalar;
    if (!v->transfer_normalized)
        vv->scalar_min = (float)lo, vv->scalar_max = (float)hi;
    for (uint32_t i = 0; i < n; ++i) {
        memcpy(&demo->vol_transfer[4 * i], tp[i].rgba, 4 * sizeof(float));
        demo->vol_transfer_pos[i] = v->transfer_normalized ? tp[i].scalar
                                    : n > 1 ? (float)((tp[i].scalar - lo) / (hi - lo)) : 0.f;
    }
    if (!v->transfer_normalized && n > 1)
        demo->vol_transfer_pos[0] = 0.f, demo->vol_transfer_pos[n - 1] = 1.f;
    if (n == 1) { /* a constant: the same entry at both ends */
        memcpy(&demo->vol_transfer[4], tp[0].rgba, 4 * sizeof(float));
        demo->vol_transfer_pos[0] = 0.f, demo->vol_transfer_pos[1] = 1.f;
        n = 2;
    }
    vv->transfer_rgba = demo->vol_transfer;
    vv->transfer_count = n;
    vv->transfer_scalar = demo->vol_transfer_pos;
    demo->vol_transfer_count = n;
}

/* Keeps the loaded points and scalars when the scene animates them (each frame starts there). */
static vfx_result volume_prepare_animation(game_demo *demo, const rt_scene_volume *v)
{
    const rt_scene_volume_animation *an = &v->anim;
    const bool shield = an->rim_gain > 0 || an->hit_gain > 0;
    demo->vol_animated = an->ripple_amplitude > 0 || an->glow_gain > 0 || an->pulse_period_s > 0 || shield;
    if (!demo->vol_animated)
        return VFX_OK;
    size_t np = demo->vol_point_count;
    demo->vol_base_points = malloc(np * 3 * sizeof(float));
    demo->vol_base_scalar = malloc(np * sizeof(float));
    if (!demo->vol_base_points || !demo->vol_base_scalar)
        return VFX_ERR_OUT_OF_MEMORY;
    memcpy(demo->vol_base_points, demo->vol_points, np * 3 * sizeof(float));
    memcpy(demo->vol_base_scalar, demo->vol_scalar, np * sizeof(float));
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < np; ++i)
        for (int k = 0; k < 3; ++k)
            lo[k] = fminf(lo[k], demo->vol_points[3 * i + k]), hi[k] = fmaxf(hi[k], demo->vol_points[3 * i + k]);
    for (int k = 0; k < 3; ++k)
        demo->vol_center[k] = 0.5f * (lo[k] + hi[k]);
    demo->vol_center[1] = lo[1]; /* a dome ripples out from its floor */
    float r2 = 0;
    for (size_t i = 0; i < np; ++i) {
        float d2 = 0;
        for (int k = 0; k < 3; ++k)
            d2 += (demo->vol_points[3 * i + k] - demo->vol_center[k]) * (demo->vol_points[3 * i + k] - demo->vol_center[k]);
        r2 = fmaxf(r2, d2);
    }
    demo->vol_radius = sqrtf(r2);
    if (shield)
        return game_shield_create(demo->vol_points, demo->vol_point_count, demo->vol_tets, demo->vol_tet_count,
                                  lo[1], &demo->vol_shield);
    return VFX_OK;
}

/* The volume's mesh stays with the demo; the host api hands the plugin pointers into it. */
static vfx_result load_volume(game_app *app, game_demo *demo, const rt_scene *sc)
{
    const rt_scene_volume *v = &sc->volume;
    vfx_result r = volume_mesh(app, demo, v);
    if (r)
        return r;
    vfx_volume_view view, *vv = &view;
    memset(vv, 0, sizeof *vv);
    vv->type = VFX_TYPE_VOLUME_VIEW;
    vv->point_count = demo->vol_point_count;
    vv->tet_count = demo->vol_tet_count;
    vv->points = demo->vol_points;
    vv->tets = demo->vol_tets;
    vv->scalar = demo->vol_scalar;
    volume_transfer(demo, v, vv);
    vv->transfer_method = v->transfer_method;
    vv->ert_threshold = v->ert_threshold;
    vv->tiles = v->tiles;
    vv->update_c = v->update_c;
    vv->workers = v->workers;
    demo->vol_lab = (vfx_lab_volume){.type = VFX_TYPE_LAB_VOLUME, .disable = v->disable};
    vv->next = v->disable ? &demo->vol_lab : NULL; /* the lab's switches (the entity keeps the pointer) */
    memcpy(vv->model, v->model, sizeof vv->model);
    vv->revision = 1;
    if ((r = volume_prepare_animation(demo, v)))
        return r;
    return game_app_add_volume(app, vv, &demo->vol_entity);
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
    vfx_volume_view *vv = game_app_volume(app, demo->vol_entity);
    uint32_t beam_count;
    const vfx_beam *beams = game_app_beams(app, &beam_count);
    const double t = app->time;
    if (an->ripple_amplitude > 0 || an->glow_gain > 0 || demo->vol_shield) {
        const float *M = v->model, *c = demo->vol_center;
        const double w = 2 * M_PI / an->ripple_period_s, k = 2 * M_PI / an->ripple_wavelength;
        bool identity = true;
        for (int i = 0; i < 16; ++i)
            identity &= M[i] == 0;
        for (uint32_t i = 0; i < demo->vol_point_count; ++i) {
            const float *p = &demo->vol_base_points[3 * i];
            float *q = &demo->vol_points[3 * i];
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
            demo->vol_scalar[i] = s;
        }
        game_shield_frame sf = {demo->vol_points, M, {app->camera.eye[0], app->camera.eye[1], app->camera.eye[2]},
                                beams, beam_count, t,
                                {c[0], c[1], c[2]}, demo->vol_radius};
        game_shield_apply(demo->vol_shield, an, &sf, demo->vol_scalar);
        vv->revision++;
    }
    if (an->pulse_period_s > 0 && demo->vol_transfer_count >= 2) {
        /* the scene's table with 3 entries inserted: the band's edges (the table's own values
         * there) and its peak, sweeping the domain once per period */
        uint32_t n = demo->vol_transfer_count;
        float *rgba = demo->vol_transfer, *pos = demo->vol_transfer_pos, hw = an->pulse_width;
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

vfx_result game_demo_load(game_app *app, game_demo *demo, const char *scene_path, uint32_t effects_off)
{
    memset(demo, 0, sizeof *demo);
    demo->effects_off = effects_off | ~app->api->effects_built; /* what the plugin lacks is off too */
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
    if ((r = game_app_set_camera(app, &cam)) || (r = load_meshes(app, sc)))
        return r;
    if (sc->has_water && !(demo->effects_off & VFX_EFFECT_BIT(VFX_EFFECT_WATER)) && (r = load_water(app, demo, sc)))
        return r;
    if (sc->beam_count && !(demo->effects_off & VFX_EFFECT_BIT(VFX_EFFECT_BEAMS))) {
        demo->beam_base_count = sc->beam_count < GAME_APP_MAX_BEAMS ? sc->beam_count : GAME_APP_MAX_BEAMS;
        app->beams_view = sc->beams_view;
        app->beams_lab = sc->beams_lab;
        if ((r = game_app_add_beams(app, NULL, demo->beam_base_count)))
            return r;
        beams_at(app, demo, 0.0); /* the keyframes at t = 0 into the beam entities */
    }
    if (sc->has_volume && !(demo->effects_off & VFX_EFFECT_BIT(VFX_EFFECT_VOLUME)) && (r = load_volume(app, demo, sc)))
        return r;
    if (sc->has_volume && (demo->effects_off & VFX_EFFECT_BIT(VFX_EFFECT_VOLUME)))
        rt_logf(&app->log, VFX_LOG_INFO, "scene volume left out (effect switched off or not built)");
    snprintf(demo->description, sizeof demo->description,
             "scene '%.60s': %u meshes, %u particles%s, %u beams, %u volumes", sc->name, app->mesh_count,
             demo->particle_count, demo->sim ? " (SPH)" : "", beam_count_of(app), game_app_volume_count(app));
    return VFX_OK;
}

/* Where a beam struck the water (the plugin's impact events of the last frame), the fluid is
 * pushed (rt_sph_impulse; docs/simulation.md "Impacts"), before this frame's simulation step. */
static void strike_water(game_app *app, game_demo *demo)
{
    if (!demo->sim || !(demo->impact_strength > 0) || (demo->effects_off & VFX_EFFECT_BIT(VFX_EFFECT_WATER)))
        return;
    for (uint32_t i = 0; i < app->impact_count; ++i) {
        const vfx_impact_event *e = &app->impacts[i];
        if (rt_sph_impulse(rt_sim_system_solver(demo->sim), e->position, e->direction, demo->impact_radius,
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
    if (demo->scene && demo->vol_animated && game_app_volume(app, demo->vol_entity)) /* after the beams: they light it */
        animate_volume(app, demo);
}

void game_demo_toggle(game_app *app, game_demo *demo, vfx_effect_kind kind)
{
    demo->effects_off ^= VFX_EFFECT_BIT(kind);
    bool off = demo->effects_off & VFX_EFFECT_BIT(kind);
    if (kind == VFX_EFFECT_WATER)
        app->water_enabled = !off && demo->particle_count > 0;
    else if (kind == VFX_EFFECT_BEAMS && off)
        game_app_clear_beams(app);
    else if (kind == VFX_EFFECT_BEAMS && !beam_count_of(app)) /* back: the next animate fills them */
        game_app_add_beams(app, NULL, demo->beam_base_count);
    else if (kind == VFX_EFFECT_VOLUME && off && game_app_volume(app, demo->vol_entity)) {
        demo->vol_view = *game_app_volume(app, demo->vol_entity); /* as it was, for switching back */
        game_app_remove(app, demo->vol_entity);
    } else if (kind == VFX_EFFECT_VOLUME && !off && demo->vol_tets && !game_app_volume(app, demo->vol_entity))
        game_app_add_volume(app, &demo->vol_view, &demo->vol_entity);
}

void game_demo_print_profile(game_app *app, FILE *out)
{
    static const char *series[] = {"vfx.sim.sph", "plugin.update", "host.scene", "plugin.render",
                                   "plugin.render_thread_cpu"};
    static const char *sim[] = {"sim.steps", "sim.iterations", "sim.realtime_factor", "sim.max_speed",
                                "sim.density_error"};
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
    if (demo->sim) {
        const rt_sph_report *rep = rt_sim_system_report(demo->sim);
        if (rep->cap_hit)
            rt_logf(&app->log, VFX_LOG_WARN, "water simulation: substep cap hit in the last frame");
    }
    if (game_app_volume(app, demo->vol_entity)) /* its view points into the arrays freed here */
        game_app_remove(app, demo->vol_entity);
    rt_sim_system_destroy(demo->sim); /* the world must not run again after this */
    rt_scene_free(demo->scene);
    free(demo->vol_points);
    free(demo->vol_tets);
    free(demo->vol_scalar);
    free(demo->vol_base_points);
    free(demo->vol_base_scalar);
    game_shield_destroy(demo->vol_shield);
    memset(demo, 0, sizeof *demo);
}
