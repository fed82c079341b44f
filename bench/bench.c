/* bench.c — volfx-bench: one headless benchmark program; each effect adds its subcommand
 * (bench/bench_<system>.c). Prints one JSON object per configuration. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app.h"
#include "core/args.h"
#include "demo_scene.h"

/* Weak: an effect left out of the build (or not written yet) leaves its entry NULL. */
int bench_sim(int argc, char **argv) __attribute__((weak));
int bench_metaballs(int argc, char **argv) __attribute__((weak));
int bench_beams(int argc, char **argv) __attribute__((weak));
int bench_tetvol(int argc, char **argv) __attribute__((weak));
int bench_ecs(int argc, char **argv);

/* `frame`: a scene (the built-in default unless --scene), headless, N frames; optionally the
 * raw quantity of one effect of the last frame as a PFM (--dump-raw water|beams|volume FILE). */
static int bench_frame(int argc, char **argv)
{
    uint32_t frames = 60, w = 0, h = 0;
    const char *scene = NULL, *raw_effect = NULL, *raw_path = NULL;
    char e[200];
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--frames") && i + 1 < argc) {
            if (!rt_arg_u32("--frames", argv[++i], 1, 10000000, &frames, e, sizeof e)) {
                fprintf(stderr, "volfx-bench frame: %s\n", e);
                return 2;
            }
        } else if (!strcmp(argv[i], "--size") && i + 1 < argc) {
            if (!rt_arg_size("--size", argv[++i], 16384, &w, &h, e, sizeof e)) {
                fprintf(stderr, "volfx-bench frame: %s\n", e);
                return 2;
            }
        } else if (!strcmp(argv[i], "--scene") && i + 1 < argc) {
            scene = argv[++i];
        } else if (!strcmp(argv[i], "--dump-raw") && i + 2 < argc) {
            raw_effect = argv[++i];
            raw_path = argv[++i];
        } else if (!strcmp(argv[i], "--json")) {
        } else {
            fprintf(stderr, "volfx-bench frame: unknown option '%s' (--frames N --size WxH --scene FILE "
                            "--dump-raw water|beams|volume FILE.pfm --json)\n", argv[i]);
            return 2;
        }
    }
    vfx_effect_kind raw_kind = VFX_EFFECT_COUNT;
    if (raw_effect) {
        raw_kind = !strcmp(raw_effect, "water") ? VFX_EFFECT_WATER : !strcmp(raw_effect, "beams") ? VFX_EFFECT_BEAMS
                   : !strcmp(raw_effect, "volume") ? VFX_EFFECT_VOLUME : VFX_EFFECT_COUNT;
        if (raw_kind == VFX_EFFECT_COUNT) {
            fprintf(stderr, "volfx-bench frame: --dump-raw wants water, beams or volume, got '%s'\n", raw_effect);
            return 2;
        }
        if (!rt_arg_writable("--dump-raw", raw_path, e, sizeof e)) {
            fprintf(stderr, "volfx-bench frame: %s\n", e);
            return 2;
        }
    }
    game_app_desc d = {.mode = RT_GL_HEADLESS, .width = w, .height = h};
    game_app *app;
    if (game_app_create(&d, &app))
        return 1;
    game_demo demo;
    if (game_demo_load(app, &demo, scene, 0)) {
        game_app_destroy(app);
        return 1;
    }
    int rc = 0;
    for (uint32_t f = 0; f < frames && rc == 0; ++f) {
        game_demo_animate(app, &demo, 1.f / 60.f);
        rc = game_app_frame(app, 1.f / 60.f) ? 1 : 0;
    }
    rt_frame_summary s = rt_profiler_summary(app->profiler, frames > 10 ? 5 : 0);
    if (rc == 0 && raw_path && game_app_dump_raw(app, raw_kind, raw_path) != VFX_OK)
        rc = 1;
    printf("{\"effect\":\"frame\",\"scene\":\"%s\",\"width\":%u,\"height\":%u,\"frames\":%u,\"gl_renderer\":\"%s\","
           "\"frame_ms\":{\"p50\":%.4f,\"p95\":%.4f,\"p99\":%.4f},\"mean_fps\":%.3f,\"stats\":{",
           scene ? scene : "(default)", app->camera.width, app->camera.height, s.frames,
           rt_gl_context_renderer(app->gl), s.p50_ms, s.p95_ms, s.p99_ms, s.mean_fps);
    vfx_stats st = {.type = VFX_TYPE_STATS};
    app->api->get_stats(app->ctx, &st);
    for (uint32_t i = 0; i < st.count; ++i)
        printf("%s\"%s\":%.6g", i ? "," : "", st.entries[i].name, st.entries[i].value);
    printf("}");
    if (demo.spawned.sim) { /* the simulation's last frame (docs/stats.md sim.*) and its median CPU ms */
        const rt_sim_stats *ss = rt_sim_system_stats(demo.spawned.sim);
        printf(",\"sim\":{\"device\":%u,\"particles\":%u,\"steps\":%u,\"iterations\":%u,\"max_speed\":%.4g,"
               "\"density_error\":%.4g,\"cpu_ms_p50\":%.4f}", ss->device, demo.spawned.particle_count, ss->steps, ss->iterations,
               ss->max_speed, ss->density_error, rt_profiler_series_median(app->profiler, "vfx.sim.sph"));
    }
    printf("}\n");
    game_demo_free(app, &demo);
    game_app_destroy(app);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "--help")) {
        puts("usage: volfx-bench <sim|metaballs|beams|tetvol|ecs|frame> [options] [--json]\n"
             "each subcommand prints one JSON object per configuration; --help after it lists its options");
        return argc < 2 ? 2 : 0;
    }
    const char *sub = argv[1];
    struct { const char *name; int (*fn)(int, char **); } subs[] = {
        {"sim", bench_sim}, {"metaballs", bench_metaballs}, {"beams", bench_beams},
        {"tetvol", bench_tetvol}, {"ecs", bench_ecs}, {"frame", bench_frame}};
    for (size_t i = 0; i < sizeof subs / sizeof subs[0]; ++i) {
        if (strcmp(sub, subs[i].name) != 0)
            continue;
        if (!subs[i].fn) {
            fprintf(stderr, "volfx-bench: '%s' is not built into this binary\n", sub);
            return 2;
        }
        return subs[i].fn(argc - 1, argv + 1);
    }
    fprintf(stderr, "volfx-bench: unknown subcommand '%s'\n", sub);
    return 2;
}
