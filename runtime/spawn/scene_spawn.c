/* scene_spawn.c — a scene's content into the world (scene_spawn.h). */
#include "spawn/scene_spawn.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/file.h"
#include "scene/volume_file.h"

vfx_result rt_mesh_components_register(rt_world *world, rt_mesh_components *out)
{
    vfx_result r = rt_world_register(world, &(rt_component_desc){RT_MESH_COMPONENT, sizeof(rt_mesh_component), 8, 1},
                                     &out->mesh);
    return r ? r : rt_world_register(world, &(rt_component_desc){RT_TRANSFORM_COMPONENT, 64, 16, 1}, &out->transform);
}

vfx_result rt_mesh_spawn(rt_world *world, const rt_mesh_components *mc, rt_mesh_data *data, const float model[16],
                         const float rgb[3], rt_entity *out)
{
    rt_mesh_component m;
    memset(&m, 0, sizeof m);
    vfx_result r = rt_mesh_upload(data, &m.gpu);
    memcpy(m.bounds_min, data->bounds_min, sizeof m.bounds_min);
    memcpy(m.bounds_max, data->bounds_max, sizeof m.bounds_max);
    rt_mesh_data_free(data);
    if (r)
        return r;
    memcpy(m.color, rgb, sizeof m.color);
    rt_component comps[2] = {mc->mesh, mc->transform};
    rt_entity e;
    if ((r = rt_world_spawn(world, 1, comps, 2, &e))) {
        rt_mesh_gpu_destroy(&m.gpu);
        return r;
    }
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    memcpy(rt_world_get(world, e, mc->mesh, 0), &m, sizeof m);
    memcpy(rt_world_get(world, e, mc->transform, 0), model ? model : identity, 64);
    if (out)
        *out = e;
    return VFX_OK;
}

static vfx_result spawn_meshes(const rt_scene *sc, const rt_scene_spawn_desc *d, rt_scene_spawned *out, char *err,
                               size_t errlen)
{
    for (uint32_t i = 0; i < sc->mesh_count; ++i) {
        const rt_scene_mesh *m = &sc->meshes[i];
        rt_mesh_data data;
        vfx_result r;
        if (m->is_box) {
            rt_entity e;
            if ((r = rt_mesh_make_box(m->box_min, m->box_max, &data))
                || (r = rt_mesh_spawn(d->world, d->meshes, &data, NULL, m->color, &e)))
                return rt_errf(err, errlen, r, "scene meshes[%u]: the box could not be made", i);
            memcpy(rt_world_get(d->world, e, d->meshes->transform, 0), m->model, sizeof m->model);
            out->mesh_count++;
            continue;
        }
        /* a missing decoration is not worth refusing the scene for; stat, not fopen: opening
         * a FIFO for reading blocks forever */
        char why[RT_SCENE_PATH_MAX + 64];
        if (rt_check_regular_file(m->path, why, sizeof why)) {
            rt_logf(d->log, VFX_LOG_WARN, "scene meshes[%u]: %s, skipped", i, why);
            continue;
        }
        if ((r = rt_mesh_import(m->path, &data, err, errlen)))
            return r;
        if ((r = rt_mesh_spawn(d->world, d->meshes, &data, m->model, m->color, NULL)))
            return rt_errf(err, errlen, r, "scene meshes[%u]: %s could not be uploaded", i, m->path);
        out->mesh_count++;
    }
    return VFX_OK;
}

/* The simulation's block on the solver's calibrated lattice (the scene's lattice left the floor
 * layer 2 cm from the floor where the solver's wall term is calibrated for dx/2, ~6% compressed,
 * and put ~1,300 particles behind the paddle): cell centres dx/2 from every tank wall the fluid
 * box comes within dx of, in front of the paddle's plate at t = 0, filled from the bottom (y) up
 * with the scene's count. */
static void sim_lattice(const rt_scene_water *w, float dx, float *px, float *py, float *pz, uint32_t n)
{
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
        lo[k] = w->box_min[k] - w->tank_min[k] < dx ? w->tank_min[k] : w->box_min[k];
        hi[k] = w->tank_max[k] - w->box_max[k] < dx ? w->tank_max[k] : w->box_max[k];
    }
    if (w->paddle) {
        uint32_t ax = w->paddle_axis < 3 ? w->paddle_axis : 0;
        double face = w->tank_min[ax] + w->paddle_amplitude + 1.5 * dx; /* as add_paddle's plate */
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

/* A thin plate at the low end of the paddle's axis, pushing the fluid along it. */
static vfx_result add_paddle(rt_sim_system *sim, const rt_scene_water *w, float spacing, char *err, size_t errlen)
{
    uint32_t ax = w->paddle_axis < 3 ? w->paddle_axis : 0;
    rt_sph_collider paddle = {.kind = RT_SPH_BOX, .motion_amplitude = w->paddle_amplitude,
                               .motion_frequency = w->paddle_period_s > 0 ? 1.0f / w->paddle_period_s : 0,
                               .motion_ramp_s = w->paddle_ramp_s};
    for (int k = 0; k < 3; ++k) {
        paddle.center[k] = 0.5f * (w->tank_min[k] + w->tank_max[k]);
        paddle.half[k] = 0.5f * (w->tank_max[k] - w->tank_min[k]);
    }
    paddle.half[ax] = 0.5f * spacing;
    paddle.center[ax] = w->tank_min[ax] + w->paddle_amplitude + spacing;
    paddle.motion_axis[ax] = 1.0f;
    char why[256];
    vfx_result r = rt_sph_add_collider(rt_sim_system_solver(sim), &paddle, NULL, why, sizeof why);
    return r ? rt_errf(err, errlen, r, "scene water paddle: %s", why) : VFX_OK;
}

/* The simulated tank: the SPH system over the particle columns, its clock, label, settling and
 * paddle; the particles are laid out on its lattice first. */
static vfx_result spawn_simulation(const rt_scene *sc, const rt_scene_spawn_desc *d, rt_scene_spawned *out,
                                   float *px, float *py, float *pz, uint32_t n, char *err, size_t errlen)
{
    const rt_scene_water *w = &sc->water;
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
    char why[256];
    vfx_result r = rt_sim_system_create(d->world, &sd, &out->sim, why, sizeof why);
    if (r)
        return rt_errf(err, errlen, r, "scene water simulation: %s", why);
    /* the scene's dt is the clock's step: whole steps follow the frame clock (up to 4 a frame) */
    if (d->sim_stats)
        rt_sim_system_set_stats_sink(out->sim, d->sim_stats, d->sim_stats_user);
    if ((r = rt_sim_system_set_clock(out->sim, w->dt, 4)))
        return rt_errf(err, errlen, r, "scene water.simulation.dt: %g s refused by the clock", (double)w->dt);
    /* a step of more than 0.5 s (under 2 frames a second) is said once, naming the count and
     * the tank (200,000 particles in a 1 m tank took 14 s a step) */
    if ((r = rt_sim_system_warn_slow(out->sim, 0.5, d->log))
        || (r = rt_sim_system_set_label(out->sim, "scene water.simulation", sc->origin)))
        return rt_errf(err, errlen, r, "scene water.simulation: could not label the simulation");
    /* the block starts on the calibrated lattice at rho0, which neither solver holds at rest:
     * settled into the solver's hydrostatic state before frame 0, it does not sink into it
     * during the first second (docs/simulation.md "Start at rest"; water.simulation.settle_steps) */
    rt_sph_settle_desc settle = {.max_steps = w->settle_steps};
    if (w->settle_steps && (r = rt_sim_system_settle_next(out->sim, &settle, d->log)))
        return rt_errf(err, errlen, r, "scene water.simulation.settle_steps: could not settle");
    return w->paddle ? add_paddle(out->sim, w, spacing, err, errlen) : VFX_OK;
}

static vfx_result spawn_water(const rt_scene *sc, const rt_scene_spawn_desc *d, rt_scene_spawned *out, char *err,
                              size_t errlen)
{
    const rt_scene_water *w = &sc->water;
    float *xyz = NULL;
    uint32_t n = 0;
    char why[256];
    vfx_result r = rt_scene_water_particles(w, &xyz, &n, why, sizeof why);
    if (r)
        return rt_errf(err, errlen, r, "scene water: %s", why);
    if (n == 0 && w->source == RT_SCENE_WATER_FILE) /* valid, but drawn as nothing: say so */
        rt_logf(d->log, VFX_LOG_WARN, "scene water.path %s: the file holds no particles (0 bytes); no water is "
                "drawn", w->path);
    float *px = malloc((n ? n : 1) * sizeof(float)), *py = malloc((n ? n : 1) * sizeof(float)),
          *pz = malloc((n ? n : 1) * sizeof(float));
    if (!px || !py || !pz) {
        free(px), free(py), free(pz), free(xyz);
        return rt_errf(err, errlen, VFX_ERR_OUT_OF_MEMORY, "scene water: out of memory for %u particles", n);
    }
    for (uint32_t i = 0; i < n; ++i)
        px[i] = xyz[3 * i], py[i] = xyz[3 * i + 1], pz[i] = xyz[3 * i + 2];
    free(xyz);
    if (w->source == RT_SCENE_WATER_SIMULATION && n > 0)
        r = spawn_simulation(sc, d, out, px, py, pz, n, err, errlen);
    if (!r && (r = rt_particles_spawn(d->world, d->particles, n, px, py, pz, false)))
        rt_errf(err, errlen, r, "scene water: %u particles could not be spawned", n);
    if (!r)
        out->particle_count = n;
    free(px), free(py), free(pz);
    return r;
}

/* The volume's mesh: a generated grid, or a .vtu / TetGen file through the host-side loaders.
 * A missing or malformed file is an error naming it that stops the spawn. */
static vfx_result volume_mesh(const rt_scene_volume *v, const rt_scene_spawn_desc *d, rt_scene_spawned *out,
                              char *err, size_t errlen)
{
    char why[512];
    vfx_result r;
    if (v->generated) {
        r = rt_scene_volume_generate(v, &out->vol_points, &out->vol_point_count, &out->vol_tets, &out->vol_tet_count,
                                     &out->vol_scalar, why, sizeof why);
        return r ? rt_errf(err, errlen, r, "scene volume: %s", why) : VFX_OK;
    }
    tet_mesh m;
    size_t len = strlen(v->path);
    if (len > 4 && !strcmp(v->path + len - 4, ".vtu")) {
        r = rt_volume_load_vtu(v->path, v->scalar, &m, why, sizeof why);
        if (r == VFX_ERR_NOT_FOUND && !v->scalar[0]) /* the loader lists the point fields */
            return rt_errf(err, errlen, r, "scene volume.scalar: name the point field of %s (%s)", v->path,
                           strstr(why, "present:") ? strstr(why, "present:") : why);
    } else {
        char base[RT_SCENE_PATH_MAX];
        snprintf(base, sizeof base, "%.*s", (int)(len - 5), v->path); /* without ".node" */
        r = rt_volume_load_tetgen(base, v->scalar, &m, why, sizeof why);
    }
    if (r)
        return rt_errf(err, errlen, r, "scene volume.path: %s", why);
    if (!m.scalar) {
        tet_mesh_free(&m);
        return rt_errf(err, errlen, VFX_ERR_FORMAT, "scene volume.path: %s has no point field to render", v->path);
    }
    out->vol_points = m.points, out->vol_tets = m.tets, out->vol_scalar = m.scalar;
    out->vol_point_count = m.point_count, out->vol_tet_count = m.tet_count;
    rt_logf(d->log, VFX_LOG_INFO, "scene volume %s: %u points, %u tets, field %s in [%g, %g]", v->path,
            m.point_count, m.tet_count, m.scalar_name, (double)m.scalar_min, (double)m.scalar_max);
    return VFX_OK;
}

/* The scene's transfer function as the plugin's table: every control point (one point is a
 * constant), at its position in [0,1] of the domain (version-2 view). */
static void volume_transfer(rt_scene_spawned *out, const rt_scene_volume *v, vfx_volume_view *vv)
{
    uint32_t n = v->transfer_count;
    if (n == 0)
        return;
    const rt_scene_transfer_point *tp = v->transfer;
    double lo = tp[0].scalar, hi = tp[n - 1].scalar;
    if (!v->transfer_normalized)
        vv->scalar_min = (float)lo, vv->scalar_max = (float)hi;
    for (uint32_t i = 0; i < n; ++i) {
        memcpy(&out->vol_transfer[4 * i], tp[i].rgba, 4 * sizeof(float));
        out->vol_transfer_pos[i] = v->transfer_normalized ? tp[i].scalar
                                   : n > 1 ? (float)((tp[i].scalar - lo) / (hi - lo)) : 0.f;
    }
    if (!v->transfer_normalized && n > 1)
        out->vol_transfer_pos[0] = 0.f, out->vol_transfer_pos[n - 1] = 1.f;
    if (n == 1) { /* a constant: the same entry at both ends */
        memcpy(&out->vol_transfer[4], tp[0].rgba, 4 * sizeof(float));
        out->vol_transfer_pos[0] = 0.f, out->vol_transfer_pos[1] = 1.f;
        n = 2;
    }
    vv->transfer_rgba = out->vol_transfer;
    vv->transfer_count = n;
    vv->transfer_scalar = out->vol_transfer_pos;
    out->vol_transfer_count = n;
}

/* The volume entity; its view points into the arrays kept in *out. */
static vfx_result spawn_volume(const rt_scene *sc, const rt_scene_spawn_desc *d, rt_scene_spawned *out, char *err,
                               size_t errlen)
{
    const rt_scene_volume *v = &sc->volume;
    vfx_result r = volume_mesh(v, d, out, err, errlen);
    if (r)
        return r;
    vfx_volume_view vv;
    memset(&vv, 0, sizeof vv);
    vv.type = VFX_TYPE_VOLUME_VIEW;
    vv.point_count = out->vol_point_count;
    vv.tet_count = out->vol_tet_count;
    vv.points = out->vol_points;
    vv.tets = out->vol_tets;
    vv.scalar = out->vol_scalar;
    volume_transfer(out, v, &vv);
    vv.transfer_method = v->transfer_method;
    vv.ert_threshold = v->ert_threshold;
    vv.tiles = v->tiles;
    vv.update_c = v->update_c;
    vv.workers = v->workers;
    memcpy(vv.model, v->model, sizeof vv.model);
    vv.revision = 1;
    if ((r = rt_world_spawn(d->world, 1, &d->effects->volume, 1, &out->volume)))
        return rt_errf(err, errlen, r, "scene volume: the entity could not be spawned");
    *(vfx_volume_view *)rt_world_get(d->world, out->volume, d->effects->volume, 0) = vv;
    out->has_volume = true;
    return VFX_OK;
}

/* The scene's beams (capped at max_beams) as entities, their keyframes at t = 0 written in. */
static vfx_result spawn_beams(const rt_scene *sc, const rt_scene_spawn_desc *d, rt_scene_spawned *out, char *err,
                              size_t errlen)
{
    uint32_t n = sc->beam_count < d->max_beams ? sc->beam_count : d->max_beams;
    vfx_result r = rt_beams_spawn(d->world, d->effects, n, NULL, NULL);
    if (r)
        return rt_errf(err, errlen, r, "scene beams: %u beams could not be spawned", n);
    uint32_t m;
    vfx_beam *beams = rt_beams_column(d->world, d->effects, &m);
    if (m)
        rt_scene_beams_at(sc, 0.0, beams, m < n ? m : n, d->joints, d->joint_cap, &out->joint_count);
    out->beam_count = n;
    return VFX_OK;
}

vfx_result rt_scene_spawn(const rt_scene *sc, const rt_scene_spawn_desc *d, rt_scene_spawned *out, char *err,
                          size_t errlen)
{
    memset(out, 0, sizeof *out);
    const uint32_t off = d->effects_off;
    vfx_result r = spawn_meshes(sc, d, out, err, errlen);
    if (!r && sc->has_water && !(off & VFX_EFFECT_BIT(VFX_EFFECT_WATER)))
        r = spawn_water(sc, d, out, err, errlen);
    if (!r && sc->beam_count && !(off & VFX_EFFECT_BIT(VFX_EFFECT_BEAMS)))
        r = spawn_beams(sc, d, out, err, errlen);
    if (!r && sc->has_volume && !(off & VFX_EFFECT_BIT(VFX_EFFECT_VOLUME)))
        r = spawn_volume(sc, d, out, err, errlen);
    else if (!r && sc->has_volume)
        rt_logf(d->log, VFX_LOG_INFO, "scene volume left out (effect switched off or not built)");
    return r;
}

void rt_scene_despawn(rt_world *world, rt_scene_spawned *sp)
{
    if (!sp)
        return;
    if (sp->has_volume) /* its view points into the arrays freed here */
        rt_world_despawn(world, sp->volume);
    rt_sim_system_destroy(sp->sim);
    free(sp->vol_points);
    free(sp->vol_tets);
    free(sp->vol_scalar);
    memset(sp, 0, sizeof *sp);
}
