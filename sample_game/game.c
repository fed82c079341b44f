/* game.c — volfx-game: a GLFW game loop (or headless EGL run) over the built-in default
 * scene, printing fps and frame-time statistics and writing a PNG screenshot. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "app.h"
#include "demo_scene.h"
#include "core/args.h"
#include "profile/resources.h"

typedef struct game_options {
    uint32_t frames;
    double seconds;
    uint32_t width, height;
    const char *png, *csv, *trace, *plugin, *scene;
    const char *program_cache; /* the plugin's program binaries kept in this folder (NULL: off) */
    rt_gl_mode mode;
    bool debug;
    uint32_t effects_off;
    bool gpu_particles;        /* particles to the plugin as a GL buffer (gpu_pos / gpu_vel) */
    bool effects_layer;        /* effects into an RGBA16F layer the game composites (layer_texture) */
    bool hide_water;           /* simulate the water but draw none (as key 1): the rest of the frame's cost */
    uint32_t mem_every;        /* print RSS and GL object counts every N frames (0 = never) */
    double progress_s;         /* a progress line on stderr every this many seconds (0 = never) */
    const char *raw_effect, *raw_path;
    vfx_effect_kind raw_kind;
    uint32_t shots[16], shot_count; /* --shots: frames (1-based) whose image is written on the way */
    bool shot_variants;        /* --shot-variants: the last shot again without water / beams / both */
} game_options;

#define GAME_MAX_SHOTS 16

static void usage(void)
{
    puts("usage: volfx-game [--headless|--window] [--frames N] [--seconds S] [--size WxH]\n"
         "                  [--png FILE] [--csv FILE] [--trace FILE] [--plugin libvolfx.so.2|PATH]\n"
         "                  [--scene FILE.json] [--no-water] [--hide-water] [--no-beams] [--no-volume] [--debug-gl]\n"
         "                  [--mem-every N] [--progress S] [--dump-raw water|beams|volume FILE.pfm]\n"
         "                  [--program-cache DIR] [--gpu-particles] [--effects-layer]\n"
         "                  [--shots N,N,...] [--shot-variants]\n"
         "--shots writes STEM-fN.png (STEM: --png without .png) after frame N, up to 16 frames; with\n"
         "--shot-variants the last frame's shot is drawn again (no time passes) as it is (-again), with the beams off\n"
         "(-nobeams), the water hidden (-hidewater) and both (-nobeams-hidewater), and the water's raw\n"
         "distance is written to STEM-fN-water.pfm: what scripts/water-look.py measures. (Only the\n"
         "last: switching the beams off and on restarts their growth, hiding the water drops its foam.)\n"
         "Without a display it runs headless (EGL) for 30 frames and writes volfx-game.png.\n"
         "--gpu-particles hands the particles to the plugin as one GL buffer (positions and velocities\n"
         "interleaved) instead of CPU arrays; --effects-layer has the plugin render into an RGBA16F\n"
         "layer that the game composites over its scene itself (docs/integration.md).\n"
         "A run longer than S seconds (default 5; 0 = never) prints a progress line to stderr every S.\n"
         "Window keys: WASD/QE fly, mouse drag orbit, 1/2/3 toggle water/beams/volume,\n"
         "             Tab cycle water method (tile; paper at 16/32/54/64 samples), P pause, N single step, Esc quit.");
}

static vfx_effect_kind effect_named(const char *s)
{
    return !strcmp(s, "water") ? VFX_EFFECT_WATER : !strcmp(s, "beams") ? VFX_EFFECT_BEAMS
           : !strcmp(s, "volume") ? VFX_EFFECT_VOLUME : VFX_EFFECT_COUNT;
}

/* Everything is checked here, before the first frame: a bad value must not cost a whole run. */
static bool parse(int argc, char **argv, game_options *o)
{
    memset(o, 0, sizeof *o);
    o->progress_s = 5.0;
    char err[256];
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
#define NEED_ARG() do { if (!v) { fprintf(stderr, "volfx-game: %s needs a value\n", a); return false; } ++i; } while (0)
        if (!strcmp(a, "--headless")) o->mode = RT_GL_HEADLESS;
        else if (!strcmp(a, "--window")) o->mode = RT_GL_WINDOW;
#define CHECK(x) do { if (!(x)) { fprintf(stderr, "volfx-game: %s\n", err); return false; } } while (0)
        else if (!strcmp(a, "--frames")) { NEED_ARG(); CHECK(rt_arg_u32(a, v, 1, UINT32_MAX - 1, &o->frames, err, sizeof err)); }
        else if (!strcmp(a, "--seconds")) { NEED_ARG(); CHECK(rt_arg_double(a, v, 1e-3, 1e7, &o->seconds, err, sizeof err)); }
        else if (!strcmp(a, "--size")) { NEED_ARG(); CHECK(rt_arg_size(a, v, 16384, &o->width, &o->height, err, sizeof err)); }
        else if (!strcmp(a, "--png")) { NEED_ARG(); CHECK(rt_arg_writable(a, v, err, sizeof err)); o->png = v; }
        else if (!strcmp(a, "--csv")) { NEED_ARG(); CHECK(rt_arg_writable(a, v, err, sizeof err)); o->csv = v; }
        else if (!strcmp(a, "--trace")) { NEED_ARG(); CHECK(rt_arg_writable(a, v, err, sizeof err)); o->trace = v; }
        else if (!strcmp(a, "--plugin")) { NEED_ARG(); o->plugin = v; }
        else if (!strcmp(a, "--scene")) { NEED_ARG(); o->scene = v; }
        else if (!strcmp(a, "--program-cache")) { NEED_ARG(); o->program_cache = v; }
        else if (!strcmp(a, "--no-water")) o->effects_off |= VFX_EFFECT_BIT(VFX_EFFECT_WATER);
        else if (!strcmp(a, "--hide-water")) o->hide_water = true;
        else if (!strcmp(a, "--gpu-particles")) o->gpu_particles = true;
        else if (!strcmp(a, "--effects-layer")) o->effects_layer = true;
        else if (!strcmp(a, "--no-beams")) o->effects_off |= VFX_EFFECT_BIT(VFX_EFFECT_BEAMS);
        else if (!strcmp(a, "--no-volume")) o->effects_off |= VFX_EFFECT_BIT(VFX_EFFECT_VOLUME);
        else if (!strcmp(a, "--debug-gl")) o->debug = true;
        else if (!strcmp(a, "--progress")) { NEED_ARG(); CHECK(rt_arg_double(a, v, 0, 1e6, &o->progress_s, err, sizeof err)); }
        else if (!strcmp(a, "--mem-every")) { NEED_ARG(); CHECK(rt_arg_u32(a, v, 0, UINT32_MAX, &o->mem_every, err, sizeof err)); }
        else if (!strcmp(a, "--dump-raw")) {
            NEED_ARG();
            o->raw_effect = v;
            o->raw_kind = effect_named(v);
            if (o->raw_kind == VFX_EFFECT_COUNT) {
                fprintf(stderr, "volfx-game: --dump-raw wants water, beams or volume, got '%s'\n", v);
                return false;
            }
            if (i + 1 >= argc) { fprintf(stderr, "volfx-game: --dump-raw needs EFFECT FILE\n"); return false; }
            o->raw_path = argv[++i];
            CHECK(rt_arg_writable(a, o->raw_path, err, sizeof err));
        }
        else if (!strcmp(a, "--shots")) {
            NEED_ARG();
            const char *c = v;
            while (*c) {
                char *end;
                unsigned long n = strtoul(c, &end, 10);
                if (end == c || n < 1 || n > UINT32_MAX - 1 || (*end && *end != ',') || o->shot_count == GAME_MAX_SHOTS) {
                    fprintf(stderr, "volfx-game: --shots wants up to %d frame numbers >= 1 separated by commas, got '%s'\n",
                            GAME_MAX_SHOTS, v);
                    return false;
                }
                o->shots[o->shot_count++] = (uint32_t)n;
                c = *end ? end + 1 : end;
            }
        }
        else if (!strcmp(a, "--shot-variants")) o->shot_variants = true;
        else if (!strcmp(a, "--help") || !strcmp(a, "-h")) { usage(); exit(0); }
        else { fprintf(stderr, "volfx-game: unknown option '%s'\n", a); usage(); return false; }
#undef CHECK
#undef NEED_ARG
    }
    if (o->raw_effect && (o->effects_off & VFX_EFFECT_BIT(o->raw_kind))) {
        fprintf(stderr, "volfx-game: --dump-raw %s with --no-%s: nothing to dump\n", o->raw_effect, o->raw_effect);
        return false;
    }
    return true;
}

/* One shot's file: STEM-fN[SUFFIX].EXT, STEM being --png without its .png. */
static void shot_path(char *out, size_t cap, const char *png, uint32_t frame, const char *suffix, const char *ext)
{
    size_t n = strlen(png);
    int stem = (int)(n > 4 && !strcmp(png + n - 4, ".png") ? n - 4 : n);
    snprintf(out, cap, "%.*s-f%u%s.%s", stem, png, frame, suffix, ext);
}

/* The shot after frame `frame`: the image as drawn, then (variants, the last frame only: the
 * beams switched off and on restart their growth, the water hidden drops its foam and history)
 * the same instant again (dt 0: no simulation step, the beams at the same time) with the beams
 * off, then with the water hidden, and both; the water's raw distance beside them. The last
 * frame's --png and --dump-raw are written before the variants (*final_done). */
static vfx_result take_shot(game_app *app, game_demo *demo, const game_options *o, const char *png, uint32_t frame,
                            bool last, bool *final_done)
{
    char path[1100];
    shot_path(path, sizeof path, png, frame, "", "png");
    vfx_result r = game_app_screenshot(app, path);
    if (r || !o->shot_variants || !last)
        return r;
    if ((r = game_app_screenshot(app, png)) || (o->raw_effect && (r = game_app_dump_raw(app, o->raw_kind, o->raw_path))))
        return r;
    *final_done = true;
    bool water = !(demo->effects_off & VFX_EFFECT_BIT(VFX_EFFECT_WATER)) && app->water_enabled;
    bool beams = !(demo->effects_off & VFX_EFFECT_BIT(VFX_EFFECT_BEAMS));
    if (water) {
        shot_path(path, sizeof path, png, frame, "-water", "pfm");
        if ((r = game_app_dump_raw(app, VFX_EFFECT_WATER, path)))
            return r;
    }
    /* -again: the shot drawn again with nothing toggled, so that the variants are compared with
     * a frame drawn the same way (dt 0: no diffuse generation, a full anisotropic pass), not with
     * the frame of the running simulation */
    static const struct { bool hide_water, no_beams; const char *suffix; } variants[4] = {
        {false, false, "-again"}, {false, true, "-nobeams"}, {true, false, "-hidewater"}, {true, true, "-nobeams-hidewater"}};
    for (int k = 0; k < 4 && !r; ++k) {
        if (variants[k].hide_water && water) game_demo_toggle(app, demo, VFX_EFFECT_WATER);
        if (variants[k].no_beams && beams) game_demo_toggle(app, demo, VFX_EFFECT_BEAMS);
        game_demo_animate(app, demo, 0.f);
        r = game_app_frame(app, 0.f);
        shot_path(path, sizeof path, png, frame, variants[k].suffix, "png");
        if (!r)
            r = game_app_screenshot(app, path);
        if (variants[k].hide_water && water) game_demo_toggle(app, demo, VFX_EFFECT_WATER);
        if (variants[k].no_beams && beams) game_demo_toggle(app, demo, VFX_EFFECT_BEAMS);
        game_demo_animate(app, demo, 0.f); /* the beams back where they were */
    }
    return r;
}

/* A long run says where it is: frame, elapsed time, the fps of the last 60 frames and, when the
 * frame count is known, the time left at that rate. stderr, so stdout's report stays as it was. */
static void print_progress(const game_app *app, uint32_t frames, double elapsed_ms)
{
    uint32_t done = (uint32_t)app->frame;
    rt_frame_summary s = rt_profiler_summary(app->profiler, done > 60 ? done - 60 : 0);
    if (frames != UINT32_MAX && s.mean_fps > 0)
        fprintf(stderr, "volfx-game: frame %u of %u, %.1f s, %.2f fps (last %u frames), about %.0f s left\n", done,
                frames, elapsed_ms / 1000.0, s.mean_fps, s.frames, (double)(frames - done) / s.mean_fps);
    else
        fprintf(stderr, "volfx-game: frame %u, %.1f s, %.2f fps (last %u frames)\n", done, elapsed_ms / 1000.0,
                s.mean_fps, s.frames);
}

/* Orbit camera and toggles for the window mode. */
static void handle_input(game_app *app, game_demo *demo, bool *paused, bool *step, double dt)
{
    GLFWwindow *w = rt_gl_context_window(app->gl);
    if (!w)
        return;
    if (glfwGetKey(w, GLFW_KEY_ESCAPE) == GLFW_PRESS)
        glfwSetWindowShouldClose(w, 1);
    static const int keys[3] = {GLFW_KEY_1, GLFW_KEY_2, GLFW_KEY_3};
    static const vfx_effect_kind kinds[3] = {VFX_EFFECT_WATER, VFX_EFFECT_BEAMS, VFX_EFFECT_VOLUME};
    for (int k = 0; k < 3; ++k) {
        bool down = glfwGetKey(w, keys[k]) == GLFW_PRESS;
        if (down && !demo->key_latch[k])
            game_demo_toggle(app, demo, kinds[k]);
        demo->key_latch[k] = down;
    }
    bool tab = glfwGetKey(w, GLFW_KEY_TAB) == GLFW_PRESS;
    if (tab && !demo->key_latch[5]) {
        /* TILE (ours, the default) first, then the published method at the paper's sample
         * caps, whose cost and quality the cap sets, then back */
        static const struct { uint32_t method, samples; const char *name; } steps[5] = {
            {VFX_WATER_METHOD_TILE, 0, "tile"}, {VFX_WATER_METHOD_PAPER, 16, "paper, 16 samples"},
            {VFX_WATER_METHOD_PAPER, 32, "paper, 32 samples"}, {VFX_WATER_METHOD_PAPER, 54, "paper, 54 samples"},
            {VFX_WATER_METHOD_PAPER, 64, "paper, 64 samples"}};
        int cur = 0;
        for (int k = 0; k < 5; ++k)
            if (steps[k].method == app->water.method
                && (steps[k].method != VFX_WATER_METHOD_PAPER || steps[k].samples == app->water.max_samples))
                cur = k;
        int next = (cur + 1) % 5;
        app->water.method = steps[next].method;
        app->water.max_samples = steps[next].samples;
        printf("water: %s\n", steps[next].name);
    }
    demo->key_latch[5] = tab;
    bool p = glfwGetKey(w, GLFW_KEY_P) == GLFW_PRESS, n = glfwGetKey(w, GLFW_KEY_N) == GLFW_PRESS;
    if (p && !demo->key_latch[3]) *paused = !*paused;
    if (n && !demo->key_latch[4]) *step = true;
    demo->key_latch[3] = p, demo->key_latch[4] = n;
    double f[3], r[3], u[3];
    rt_camera_basis(&app->camera, f, r, u);
    double speed = 3.0 * dt, move[3] = {0, 0, 0};
    if (glfwGetKey(w, GLFW_KEY_W) == GLFW_PRESS) for (int k = 0; k < 3; ++k) move[k] += f[k] * speed;
    if (glfwGetKey(w, GLFW_KEY_S) == GLFW_PRESS) for (int k = 0; k < 3; ++k) move[k] -= f[k] * speed;
    if (glfwGetKey(w, GLFW_KEY_D) == GLFW_PRESS) for (int k = 0; k < 3; ++k) move[k] += r[k] * speed;
    if (glfwGetKey(w, GLFW_KEY_A) == GLFW_PRESS) for (int k = 0; k < 3; ++k) move[k] -= r[k] * speed;
    if (glfwGetKey(w, GLFW_KEY_E) == GLFW_PRESS) move[1] += speed;
    if (glfwGetKey(w, GLFW_KEY_Q) == GLFW_PRESS) move[1] -= speed;
    rt_camera_translate(&app->camera, move);
    double mx, my;
    glfwGetCursorPos(w, &mx, &my);
    if (glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS && demo->mouse_down) {
        rt_camera_orbit(&app->camera, -(mx - demo->mouse_x) * 0.005, (my - demo->mouse_y) * 0.01);
    }
    demo->mouse_down = glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
    demo->mouse_x = mx, demo->mouse_y = my;
}

int main(int argc, char **argv)
{
    game_options o;
    if (!parse(argc, argv, &o))
        return 2;
    game_app_desc d = {.mode = o.mode, .width = o.width, .height = o.height, .debug_gl = o.debug,
                      .plugin_path = o.plugin, .program_cache = o.program_cache,
                      .gpu_particles = o.gpu_particles, .effects_layer = o.effects_layer};
    game_app *app;
    if (game_app_create(&d, &app)) {
        fprintf(stderr, "volfx-game: could not start (see the messages above)\n");
        return 1;
    }
    game_demo demo;
    if (game_demo_load(app, &demo, o.scene, o.effects_off)) {
        game_app_destroy(app);
        return 1;
    }
    if (o.hide_water && !(demo.effects_off & VFX_EFFECT_BIT(VFX_EFFECT_WATER)))
        game_demo_toggle(app, &demo, VFX_EFFECT_WATER);
    bool headless = !rt_gl_context_has_window(app->gl);
    /* headless default: 30 frames (the default scene runs at ~0.5 fps on llvmpipe) */
    uint32_t frames = o.frames ? o.frames : (headless && o.seconds <= 0 ? 30 : UINT32_MAX);
    printf("volfx-game: %s, %ux%u, %s, %s\n", rt_gl_context_renderer(app->gl), app->camera.width,
           app->camera.height, headless ? "headless" : "window", demo.description);
    const float dt = 1.0f / 60.0f; /* fixed simulation step: runs are repeatable */
    bool paused = false, step = false;
    double start = rt_now_ms(), last_ms = start;
    double next_progress = start + o.progress_s * 1000.0;
    int rc = 0;
    bool final_done = false; /* the last shot wrote --png and --dump-raw before its variants */
    for (uint32_t f = 0; f < frames; ++f) {
        if (o.seconds > 0 && (rt_now_ms() - start) > o.seconds * 1000.0)
            break;
        if (rt_gl_context_should_close(app->gl))
            break;
        /* headless: a fixed dt per frame (repeatable runs); a window: the frame clock (the
         * simulation's accumulator steps by the scene's dt to follow it), at most 0.1 s */
        double now = rt_now_ms();
        float wall_dt = f ? (float)fmin(0.1, (now - last_ms) * 1e-3) : dt;
        last_ms = now;
        float clock_dt = headless ? dt : wall_dt;
        handle_input(app, &demo, &paused, &step, clock_dt);
        float frame_dt = (paused && !step) ? 0.f : clock_dt;
        step = false;
        game_demo_animate(app, &demo, frame_dt);
        if (game_app_frame(app, frame_dt)) {
            fprintf(stderr, "volfx-game: frame %u failed\n", f);
            rc = 1;
            break;
        }
        for (uint32_t k = 0; k < o.shot_count && rc == 0; ++k)
            if (o.shots[k] == f + 1 && take_shot(app, &demo, &o, o.png ? o.png : "volfx-game.png", f + 1, f + 1 == frames,
                                                 &final_done)) {
                fprintf(stderr, "volfx-game: --shots: the shot after frame %u failed\n", f + 1);
                rc = 1;
            }
        if (rc)
            break;
        if (f == 0 && o.raw_effect && frames > 1 && game_app_dump_raw(app, o.raw_kind, o.raw_path) != VFX_OK) {
            /* the effect is absent from this scene: say so now, not after the whole run */
            fprintf(stderr, "volfx-game: cannot dump '%s' to %s\n", o.raw_effect, o.raw_path);
            rc = 1;
            break;
        }
        if (o.progress_s > 0 && rt_now_ms() >= next_progress) {
            print_progress(app, frames, rt_now_ms() - start);
            next_progress = rt_now_ms() + o.progress_s * 1000.0;
        }
        if (o.mem_every && (f % o.mem_every) == 0) {
            rt_gl_object_counts c = rt_gl_count_objects(4096);
            printf("mem frame %u rss_kb %llu gl_objects %u (buffers %u textures %u programs %u queries %u)\n", f,
                   (unsigned long long)(rt_resident_bytes() / 1024), c.total, c.buffers, c.textures,
                   c.programs, c.queries);
            fflush(stdout);
        }
        if (!headless && (f % 30) == 0) {
            rt_frame_summary s = rt_profiler_summary(app->profiler, app->frame > 60 ? (uint32_t)app->frame - 60 : 0);
            char title[128];
            snprintf(title, sizeof title, "volfx  %.1f fps  %.2f ms (p95 %.2f)", s.mean_fps, s.p50_ms, s.p95_ms);
            glfwSetWindowTitle(rt_gl_context_window(app->gl), title);
        }
    }
    uint32_t warm = app->frame > 10 ? 5 : 0;
    rt_frame_summary s = rt_profiler_summary(app->profiler, warm);
    printf("frames %u (after %u warm-up), mean %.2f fps, frame ms p50 %.3f p95 %.3f p99 %.3f max %.3f\n",
           s.frames, warm, s.mean_fps, s.p50_ms, s.p95_ms, s.p99_ms, s.max_ms);
    game_demo_print_profile(app, stdout);
    const char *png = o.png ? o.png : (headless ? "volfx-game.png" : NULL);
    if (png && rc == 0 && !final_done) {
        if (game_app_screenshot(app, png) == VFX_OK)
            printf("screenshot: %s\n", png);
        else
            rc = 1;
    }
    if (o.raw_effect && rc == 0 && !final_done) {
        if (game_app_dump_raw(app, o.raw_kind, o.raw_path) != VFX_OK) {
            fprintf(stderr, "volfx-game: cannot dump '%s' to %s\n", o.raw_effect, o.raw_path);
            rc = 1;
        } else {
            printf("raw %s: %s\n", o.raw_effect, o.raw_path);
        }
    }
    char werr[1200];
    if (o.csv && rt_profiler_write_csv(app->profiler, o.csv, werr, sizeof werr)) {
        fprintf(stderr, "volfx-game: --csv: %s\n", werr);
        rc = 1;
    }
    if (o.trace && rt_profiler_write_trace(app->profiler, o.trace, werr, sizeof werr)) {
        fprintf(stderr, "volfx-game: --trace: %s\n", werr);
        rc = 1;
    }
    game_demo_free(app, &demo);
    game_app_destroy(app);
    return rc;
}
