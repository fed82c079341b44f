/* app.c — a complete host of the plugin, written against the ABI only (volfx.h): what a game
 * engine would do, with our runtime underneath. */
#include "app.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gfx/image.h"
#include <epoxy/gl.h>

/* ------------------------------------------------------------ host api callbacks */

static void host_log(void *user, vfx_log_level level, vfx_log_id id, const char *message)
{
    game_app *app = user;
    (void)id;
    rt_logf(&app->log, level, "%s", message);
}

static void *host_proc(void *user, const char *name)
{
    game_app *app = user;
    return rt_gl_context_get_proc(app->gl, name);
}

static rt_component particle_terms(const game_app *app) { return app->particles.position; }

/* The plugin asks for the count and then for each chunk in turn: one query walk per frame
 * fills the views, and each chunk call reads its slot (no walk per index). */
static vfx_result particle_chunks_collect(game_app *app)
{
    rt_component t = particle_terms(app);
    uint32_t n = 0;
    if (app->particle_source) { /* a GPU simulation's buffers: one chunk, nothing to copy */
        if (!app->chunk_cap) {
            if (!(app->chunks = calloc(1, sizeof *app->chunks)))
                return VFX_ERR_OUT_OF_MEMORY;
            app->chunk_cap = 1;
        }
        app->chunk_count = app->particle_source(app->particle_source_user, &app->chunks[0]) ? 1 : 0;
        app->chunks_valid = true;
        return VFX_OK;
    }
    rt_query_iter it = rt_query_begin(app->world, &t, 1);
    while (rt_query_next(&it)) {
        if (n == app->chunk_cap) {
            uint32_t cap = app->chunk_cap ? app->chunk_cap * 2 : 8;
            vfx_particle_view *p = realloc(app->chunks, cap * sizeof *p);
            if (!p)
                return VFX_ERR_OUT_OF_MEMORY;
            app->chunks = p;
            app->chunk_cap = cap;
        }
        vfx_particle_view *out = &app->chunks[n++];
        memset(out, 0, sizeof *out);
        out->type = VFX_TYPE_PARTICLE_VIEW;
        out->count = it.rows;
        for (uint32_t k = 0; k < 3; ++k) {
            out->pos[k] = rt_query_column(&it, app->particles.position, k);
            out->vel[k] = rt_query_column(&it, app->particles.velocity, k);
        }
        out->radius = rt_query_column(&it, app->particles.radius, 0);
        out->revision = rt_world_table_revision(app->world, it.table);
    }
    app->chunk_count = n;
    app->chunks_valid = true;
    if (app->desc.gpu_particles) { /* the columns copied into one GL buffer, the views naming it */
        double t0 = rt_now_ms();
        vfx_result r = game_gpu_particles_upload(&app->gpu, app->chunks, n);
        rt_profiler_cpu(app->profiler, "host.gpu_particles", rt_now_ms() - t0);
        if (r) {
            app->chunks_valid = false;
            return r;
        }
    }
    return VFX_OK;
}

static uint32_t host_particle_chunk_count(void *user)
{
    game_app *app = user;
    if (!app->water_enabled)
        return 0;
    /* collected already this frame (the GL buffer upload, before update) or collected now */
    if (!app->chunks_valid && particle_chunks_collect(app) != VFX_OK) {
        rt_logf(&app->log, VFX_LOG_ERROR, "particle chunks: out of memory or no GL buffer");
        return 0;
    }
    return app->chunk_count;
}

static vfx_result host_particle_chunk(void *user, uint32_t index, vfx_particle_view *out)
{
    game_app *app = user;
    if (!out || out->type != VFX_TYPE_PARTICLE_VIEW)
        return VFX_ERR_ABI;
    if (!app->chunks_valid) {
        vfx_result r = particle_chunks_collect(app);
        if (r)
            return r;
    }
    if (index >= app->chunk_count)
        return VFX_ERR_NOT_FOUND;
    *out = app->chunks[index];
    return VFX_OK;
}

static vfx_result host_water_params(void *user, vfx_water_params *out)
{
    game_app *app = user;
    if (!out || out->type != VFX_TYPE_WATER_PARAMS)
        return VFX_ERR_ABI;
    *out = app->water;
    out->type = VFX_TYPE_WATER_PARAMS;
    out->next = NULL;
    vfx_water_foam *foam = &app->water_foam;
    if (foam->layer || foam->impacts || foam->lifetime != 0 || foam->cell != 0 || foam->diffusion != 0 ||
        foam->deposit != 0 || foam->impact_rate != 0 || foam->impact_speed != 0) {
        foam->type = VFX_TYPE_WATER_FOAM;
        foam->next = out->next;
        out->next = foam;
    }
    /* the anisotropic kernel is TILE's; the paper method (Tab cycles to it) draws the seed's */
    out->kernel = app->water.method == VFX_WATER_METHOD_TILE ? app->water.kernel : VFX_WATER_KERNEL_ISOTROPIC;
    return VFX_OK;
}

/* The beam entities' column is the view's array (no copy). */
static vfx_result host_beams(void *user, vfx_beams_view *out)
{
    game_app *app = user;
    if (!out || out->type != VFX_TYPE_BEAMS_VIEW)
        return VFX_ERR_ABI;
    uint32_t n;
    vfx_beam *beams = game_app_beams(app, &n);
    if (n == 0)
        return VFX_ERR_NOT_FOUND;
    *out = app->beams_view;
    out->type = VFX_TYPE_BEAMS_VIEW;
    out->next = app->beams_next;
    out->count = n;
    out->beams = beams;
    out->joints = &app->joints[0][0];
    out->joint_count = app->joint_count;
    return VFX_OK;
}

static uint32_t host_volume_count(void *user) { return game_app_volume_count(user); }

/* The index-th volume entity's view, in query order. */
static const vfx_volume_view *volume_at(game_app *app, uint32_t index)
{
    rt_query_iter it = rt_query_begin(app->world, &app->effects.volume, 1);
    while (rt_query_next(&it)) {
        if (index < it.rows)
            return (const vfx_volume_view *)rt_query_column(&it, app->effects.volume, 0) + index;
        index -= it.rows;
    }
    return NULL;
}

static vfx_result host_volume(void *user, uint32_t index, vfx_volume_view *out)
{
    game_app *app = user;
    if (!out || out->type != VFX_TYPE_VOLUME_VIEW)
        return VFX_ERR_ABI;
    const vfx_volume_view *v = volume_at(app, index);
    if (!v)
        return VFX_ERR_NOT_FOUND;
    *out = *v;
    out->type = VFX_TYPE_VOLUME_VIEW;
    return VFX_OK;
}

/* -------------------------------------------------------------------- lifecycle */

vfx_result game_app_set_camera(game_app *app, const rt_camera *cam)
{
    char err[256];
    vfx_result r = rt_camera_check(cam, err, sizeof err);
    if (r) {
        rt_logf(&app->log, VFX_LOG_ERROR, "%s", err);
        return r;
    }
    app->camera = *cam;
    return rt_renderer_resize(app->renderer, cam->width, cam->height);
}

vfx_result game_app_set_environment(game_app *app, bool sky, const float sun_dir[3], float fog)
{
    rt_renderer_environment env = {.sky = sky, .fog_density = fog};
    if (sun_dir)
        memcpy(env.sun_dir, sun_dir, sizeof env.sun_dir);
    vfx_result r = rt_renderer_set_environment(app->renderer, &env);
    if (r)
        rt_logf(&app->log, VFX_LOG_ERROR, "environment: the sky's shader could not be made");
    else
        app->environment = env;
    return r;
}

/* --program-cache: the plugin's binary cache in the host's folder */
static vfx_result set_program_cache(game_app *app)
{
    vfx_result r = app->api->set_program_cache(app->ctx, app->desc.program_cache);
    if (r)
        rt_logf(&app->log, VFX_LOG_ERROR, "app: --program-cache %s: %s", app->desc.program_cache,
                app->api->last_error(app->ctx, NULL));
    return r;
}

vfx_result game_app_create(const game_app_desc *desc, game_app **out)
{
    *out = NULL;
    game_app *app = calloc(1, sizeof *app);
    if (!app)
        return VFX_ERR_OUT_OF_MEMORY;
    if (desc)
        app->desc = *desc;
    app->log = app->desc.logger;
    uint32_t w = app->desc.width ? app->desc.width : 640, h = app->desc.height ? app->desc.height : 360;
#ifndef VFX_GL_DEBUG_DEFAULT
#define VFX_GL_DEBUG_DEFAULT 0
#endif
    rt_gl_context_desc gd = {.mode = app->desc.mode, .width = w, .height = h, .title = "volfx",
                              .debug = app->desc.debug_gl || VFX_GL_DEBUG_DEFAULT,
                              .compat_profile = app->desc.gl_compat, .logger = app->log};
    vfx_result r = rt_gl_context_create(&gd, &app->gl);
    if (r)
        goto fail;
    app->profiler = rt_profiler_create(app->desc.profile_frames ? app->desc.profile_frames : 4096);
    rt_world_desc wd = {.logger = app->log, .on_system_done = rt_profiler_on_system,
                         .on_system_user = app->profiler};
    app->world = rt_world_create(&wd);
    if (!app->profiler || !app->world) {
        r = VFX_ERR_OUT_OF_MEMORY;
        goto fail;
    }
    if ((r = rt_particles_register(app->world, &app->particles)) || (r = rt_effects_register(app->world, &app->effects)))
        goto fail;
    if ((r = rt_mesh_components_register(app->world, &app->meshes)))
        goto fail;
    if ((r = rt_renderer_create(&app->log, &app->renderer)))
        goto fail;
    app->camera = (rt_camera){{0, 2, 6}, {0, 0.5, 0}, {0, 1, 0}, 60.0 * M_PI / 180.0, w, h, 0.05, 200.0};
    if ((r = rt_renderer_set_hdr(app->renderer, !app->desc.ldr, app->desc.exposure))
        || (r = rt_renderer_resize(app->renderer, w, h)))
        goto fail;
    app->clear_color[0] = 0.05f, app->clear_color[1] = 0.06f, app->clear_color[2] = 0.09f;
    app->host = (vfx_context_desc){
        .type = VFX_TYPE_CONTEXT_DESC, .user = app,
        .gl_get_proc_address = host_proc, .log = host_log,
        .particle_chunk_count = host_particle_chunk_count, .particle_chunk = host_particle_chunk,
        .water_params = host_water_params, .beams = host_beams,
        .volume_count = host_volume_count, .volume = host_volume};
    if (app->desc.plugin_path)
        r = rt_plugin_host_load(app->desc.plugin_path, &app->host, &app->log, &app->plugin);
    else
        r = rt_plugin_host_load_static(vfx_plugin_entry, &app->host, &app->log, &app->plugin);
    if (r)
        goto fail;
    app->api = rt_plugin_host_api(app->plugin);
    if ((r = app->api->create(&app->host, &app->ctx)))
        goto fail;
    if (app->desc.program_cache && (r = set_program_cache(app)))
        goto fail;
    *out = app;
    return VFX_OK;
fail:
    rt_logf(&app->log, VFX_LOG_ERROR, "app: start-up failed: %s", vfx_result_name(r));
    game_app_destroy(app);
    return r;
}

void game_app_destroy(game_app *app)
{
    if (!app)
        return;
    if (app->ctx)
        app->api->destroy(app->ctx);
    rt_plugin_host_unload(app->plugin);
    free(app->chunks);
    game_gpu_particles_free(&app->gpu);
    if (app->world) {
        rt_query_iter it = rt_query_begin(app->world, &app->meshes.mesh, 1);
        while (rt_query_next(&it)) {
            rt_mesh_component *m = rt_query_column(&it, app->meshes.mesh, 0);
            for (uint32_t i = 0; i < it.rows; ++i)
                rt_mesh_gpu_destroy(&m[i].gpu);
        }
    }
    rt_renderer_destroy(app->renderer);
    rt_world_destroy(app->world);
    rt_profiler_destroy(app->profiler);
    rt_gl_context_destroy(app->gl);
    free(app);
}

vfx_result game_app_add_mesh_file(game_app *app, const char *path, const float model[16],
                                 const float rgb[3], rt_entity *out)
{
    rt_mesh_data data;
    char err[512];
    vfx_result r = rt_mesh_import(path, &data, err, sizeof err);
    if (r) {
        rt_logf(&app->log, VFX_LOG_ERROR, "%s", err);
        return r;
    }
    return rt_mesh_spawn(app->world, &app->meshes, &data, model, rgb, out);
}

vfx_result game_app_add_box(game_app *app, const float mn[3], const float mx[3], const float rgb[3],
                           rt_entity *out)
{
    rt_mesh_data data;
    vfx_result r = rt_mesh_make_box(mn, mx, &data);
    return r ? r : rt_mesh_spawn(app->world, &app->meshes, &data, NULL, rgb, out);
}

vfx_result game_app_add_beams(game_app *app, const vfx_beam *beams, uint32_t n)
{
    return rt_beams_spawn(app->world, &app->effects, n, beams, NULL);
}

vfx_beam *game_app_beams(game_app *app, uint32_t *count)
{
    return rt_beams_column(app->world, &app->effects, count);
}

void game_app_clear_beams(game_app *app)
{
    /* ids first: despawning reorders the table under a walk */
    rt_query_iter it = rt_query_begin(app->world, &app->effects.beam, 1);
    uint32_t n = 0;
    while (rt_query_next(&it))
        n += it.rows;
    rt_entity *ids = malloc((n ? n : 1) * sizeof *ids);
    if (!ids)
        return;
    uint32_t k = 0;
    it = rt_query_begin(app->world, &app->effects.beam, 1);
    while (rt_query_next(&it))
        for (uint32_t i = 0; i < it.rows; ++i)
            ids[k++] = it.entities[i];
    for (uint32_t i = 0; i < k; ++i)
        rt_world_despawn(app->world, ids[i]);
    free(ids);
}

vfx_result game_app_add_volume(game_app *app, const vfx_volume_view *view, rt_entity *out)
{
    rt_entity e;
    vfx_result r = rt_world_spawn(app->world, 1, &app->effects.volume, 1, &e);
    if (r)
        return r;
    *(vfx_volume_view *)rt_world_get(app->world, e, app->effects.volume, 0) = *view;
    if (out)
        *out = e;
    return VFX_OK;
}

vfx_volume_view *game_app_volume(game_app *app, rt_entity e)
{
    return rt_world_get(app->world, e, app->effects.volume, 0);
}

uint32_t game_app_volume_count(game_app *app)
{
    return rt_query_count(app->world, &app->effects.volume, 1);
}

vfx_result game_app_remove(game_app *app, rt_entity e)
{
    rt_mesh_component *m = rt_world_get(app->world, e, app->meshes.mesh, 0);
    if (m)
        rt_mesh_gpu_destroy(&m->gpu);
    return rt_world_despawn(app->world, e);
}

vfx_result game_app_frame(game_app *app, float dt)
{
    rt_profiler_frame_begin(app->profiler);
    app->time += dt;
    vfx_result r = rt_world_run_phase(app->world, RT_PHASE_SIMULATE, app->time, dt);
    if (!r)
        r = rt_world_run_phase(app->world, RT_PHASE_PRE_RENDER, app->time, dt);
    if (r)
        return r;
    double t0 = rt_now_ms();
    app->chunks_valid = false; /* the systems above may have moved or resized tables */
    /* GPU particles: the host's copy into its GL buffer is its own cost, outside plugin.update */
    if (app->desc.gpu_particles && !app->particle_source && app->water_enabled && (r = particle_chunks_collect(app))) {
        rt_logf(&app->log, VFX_LOG_ERROR, "particle chunks: GL buffer upload failed: %s", vfx_result_name(r));
        return r;
    }
    r = app->api->update(app->ctx, app->time, dt);
    app->chunks_valid = false; /* render-phase systems may change tables before the next call */
    if (r) {
        rt_logf(&app->log, VFX_LOG_ERROR, "plugin update: %s", app->api->last_error(app->ctx, NULL));
        return r;
    }
    rt_profiler_cpu(app->profiler, "plugin.update", rt_now_ms() - t0);
    /* the frame view is filled in place: camera first (the host scene draws with the same
     * matrices), then the targets the scene pass reports; version 2 says whether the output
     * is an HDR target */
    vfx_frame_view frame = {.type = VFX_TYPE_FRAME_VIEW,
                            .near_plane = (float)app->camera.near_plane,
                            .far_plane = (float)app->camera.far_plane,
                            .fov_y = (float)app->camera.fov_y,
                            .origin = {app->origin[0], app->origin[1], app->origin[2]}};
    rt_camera_view(&app->camera, frame.view);
    rt_camera_proj(&app->camera, frame.proj);
    for (int k = 0; k < 3; ++k)
        frame.eye[k] = (float)app->camera.eye[k];
    t0 = rt_now_ms();
    if (app->environment.sky) { /* the fog is seen from the camera */
        memcpy(app->environment.eye, frame.eye, sizeof app->environment.eye);
        rt_renderer_set_environment(app->renderer, &app->environment);
    }
    rt_renderer_set_origin(app->renderer, app->origin);
    { /* the effects' lights on the meshes: beams' trails, heads and impacts */
        vfx_light lights[RT_RENDERER_MAX_LIGHTS];
        /* and where beams struck the water (ABI 1.1), for the scene's fluid (game_demo_animate) */
        vfx_impact_events ev = {.type = VFX_TYPE_IMPACT_EVENTS, .capacity = GAME_APP_MAX_IMPACTS,
                                .events = app->impacts};
        vfx_lights l = {.type = VFX_TYPE_LIGHTS, .next = &ev, .capacity = RT_RENDERER_MAX_LIGHTS, .lights = lights};
        app->impact_count = 0;
        if (app->api->get_lights(app->ctx, &l) == VFX_OK) {
            rt_renderer_set_lights(app->renderer, lights, l.count);
            app->impact_count = ev.count;
        }
    }
    rt_renderer_begin_scene(app->renderer, frame.view, frame.proj, app->clear_color);
    rt_component draw_terms[2] = {app->meshes.mesh, app->meshes.transform};
    rt_query_iter it = rt_query_begin(app->world, draw_terms, 2);
    while (rt_query_next(&it)) {
        const rt_mesh_component *m = rt_query_column(&it, app->meshes.mesh, 0);
        const float *xf = rt_query_column(&it, app->meshes.transform, 0);
        for (uint32_t i = 0; i < it.rows; ++i)
            rt_renderer_draw_mesh(app->renderer, &m[i].gpu, xf + 16 * (size_t)i, m[i].color);
    }
    rt_renderer_targets tg;
    rt_renderer_end_scene(app->renderer, &tg);
    frame.framebuffer = tg.output_framebuffer;
    frame.color_texture = tg.scene_color;
    frame.depth_texture = tg.scene_depth;
    frame.width = tg.width;
    frame.height = tg.height;
    frame.color_hdr = tg.color_hdr;
    if (app->desc.effects_layer && (r = rt_renderer_layer(app->renderer, &frame.layer_texture)))
        return r;
    rt_profiler_cpu(app->profiler, "host.scene", rt_now_ms() - t0);
    t0 = rt_now_ms();
    if ((r = rt_world_run_phase(app->world, RT_PHASE_RENDER, app->time, dt)))
        return r;
    double c0 = rt_thread_cpu_ms();
    if ((r = app->api->render(app->ctx, &frame))) {
        rt_logf(&app->log, VFX_LOG_ERROR, "plugin render: %s", app->api->last_error(app->ctx, NULL));
        return r;
    }
    /* plugin.render: wall time of the call (with the render phase); plugin.render_thread_cpu:
     * the render call's CPU time on this thread (all of llvmpipe's work under LP_NUM_THREADS=0) */
    rt_profiler_cpu(app->profiler, "plugin.render_thread_cpu", rt_thread_cpu_ms() - c0);
    rt_profiler_cpu(app->profiler, "plugin.render", rt_now_ms() - t0);
    if (app->desc.effects_layer) /* the host's own composite: out = layer.rgb + out (1 - layer.a) */
        rt_renderer_composite_layer(app->renderer);
    if ((r = rt_world_run_phase(app->world, RT_PHASE_POST_RENDER, app->time, dt)))
        return r;
    if (rt_gl_context_has_window(app->gl)) {
        uint32_t ww, wh;
        rt_gl_context_size(app->gl, &ww, &wh);
        rt_renderer_present(app->renderer, ww, wh);
        rt_gl_context_swap(app->gl);
    } else {
        glFinish(); /* headless: make the frame time include the GPU work */
    }
    vfx_stats stats = {.type = VFX_TYPE_STATS};
    if (app->api->get_stats(app->ctx, &stats) == VFX_OK)
        rt_profiler_gpu_stats(app->profiler, &stats);
    rt_profiler_frame_end(app->profiler);
    app->frame++;
    return VFX_OK;
}

vfx_result game_app_screenshot(game_app *app, const char *path)
{
    uint32_t w = app->camera.width, h = app->camera.height;
    uint8_t *rgba = malloc((size_t)w * h * 4);
    if (!rgba)
        return VFX_ERR_OUT_OF_MEMORY;
    vfx_result r = rt_renderer_read_rgba(app->renderer, rgba);
    char err[256];
    if (!r && (r = rt_write_png(path, w, h, rgba, err, sizeof err)))
        rt_logf(&app->log, VFX_LOG_ERROR, "%s", err);
    free(rgba);
    return r;
}

vfx_result game_app_dump_raw(game_app *app, vfx_effect_kind effect, const char *path)
{
    uint32_t w = app->camera.width, h = app->camera.height;
    float *data = malloc((size_t)w * h * sizeof(float));
    if (!data)
        return VFX_ERR_OUT_OF_MEMORY;
    vfx_result r = app->api->read_raw(app->ctx, effect, data, (size_t)w * h);
    char err[256];
    if (r)
        rt_logf(&app->log, VFX_LOG_ERROR, "dump raw: %s", app->api->last_error(app->ctx, NULL));
    else if ((r = rt_write_pfm(path, w, h, data, err, sizeof err)))
        rt_logf(&app->log, VFX_LOG_ERROR, "%s", err);
    free(data);
    return r;
}

void game_app_set_particle_source(game_app *app, bool (*source)(void *user, vfx_particle_view *out), void *user)
{
    app->particle_source = source;
    app->particle_source_user = user;
    app->chunks_valid = false;
}
