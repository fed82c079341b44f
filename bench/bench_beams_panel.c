/* bench_beams_panel.c — `volfx-bench beams --panel DIR`: the docs/beams.md panel and its GPU ms
 * per pass. Loads a scene (default sample_game/scenes/beams-showcase.json) at a time T, renders
 * it as it is and in variants (every beam hard / smooth, bloom off / on, the ray-marching
 * baseline at the sample count whose integrate time is nearest the closed form's: equal time),
 * writes one PNG per variant and one JSON line per variant with the median GPU ms of each beams
 * pass over the frames. Then the per-frame cost under animation: the same frames with the scene
 * animated and frozen. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <epoxy/gl.h>

#include "app.h"
#include "demo_scene.h"
#include "volfx_lab.h"

int bench_beams_panel(int argc, char **argv);

static const char *const k_passes[] = {"beams.integrate", "beams.march", "beams.bloom_down", "beams.bloom_up",
                                       "beams.composite"};
#define NPASS (sizeof k_passes / sizeof k_passes[0])

static double stat_of(game_app *app, const char *name)
{
    vfx_stats st = {.type = VFX_TYPE_STATS};
    if (app->api->get_stats(app->ctx, &st) != VFX_OK)
        return NAN;
    for (uint32_t k = 0; k < st.count && k < VFX_STATS_MAX; ++k)
        if (!strcmp(st.entries[k].name, name))
            return st.entries[k].value;
    return NAN;
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Renders `frames` frames at the app's time (dt 0: the same image each frame) and returns the
 * median GPU ms of every pass (NaN where the pass did not run). Timer results arrive a few
 * frames late, so the first 4 frames warm up. */
static void measure(game_app *app, uint32_t frames, double ms[NPASS])
{
    double v[NPASS][64];
    uint32_t n = 0;
    for (uint32_t f = 0; f < frames + 4 && n < 64; ++f) {
        if (game_app_frame(app, 0.f))
            break;
        if (f < 4)
            continue;
        for (size_t p = 0; p < NPASS; ++p) {
            char name[64];
            snprintf(name, sizeof name, "%s.gpu_ms", k_passes[p]);
            v[p][n] = stat_of(app, name);
        }
        n++;
    }
    for (size_t p = 0; p < NPASS; ++p) {
        qsort(v[p], n, sizeof(double), cmp_d);
        ms[p] = n ? v[p][n / 2] : NAN;
    }
}

static void print_json(const char *variant, const char *png, game_app *app, const double ms[NPASS], FILE *out)
{
    uint32_t beam_count;
    game_app_beams(app, &beam_count);
    fprintf(out, "{\"variant\": \"%s\", \"png\": \"%s\", \"width\": %u, \"height\": %u, \"beams\": %u", variant, png,
            app->camera.width, app->camera.height, beam_count);
    for (size_t p = 0; p < NPASS; ++p)
        if (!isnan(ms[p]))
            fprintf(out, ", \"%s_ms\": %.4f", k_passes[p] + 6, ms[p]);
    fprintf(out, "}\n");
    fflush(out);
}

typedef struct variant {
    const char *name;
    int falloff;       /* 0 as in the scene, else VFX_BEAM_FALLOFF_* for every beam */
    int bloom;         /* 0 as in the scene, else VFX_BEAMS_BLOOM_* */
    uint32_t march;    /* 0 closed form, else ray marching with this many samples */
} variant;

/* One variant: set, render, measure, write the PNG. The scene's beams are re-evaluated first. */
static void run_variant(game_app *app, game_demo *demo, vfx_lab_beams *lab, double t, const variant *v,
                        const char *dir, uint32_t frames, double ms[NPASS])
{
    app->time = t;
    game_demo_animate(app, demo, 0.f);
    uint32_t n;
    vfx_beam *beams = game_app_beams(app, &n);
    for (uint32_t i = 0; i < n; ++i)
        if (v->falloff)
            beams[i].falloff = (uint32_t)v->falloff;
    app->beams_view = demo->scene->beams_view;
    if (v->bloom)
        app->beams_view.bloom = (uint32_t)v->bloom;
    lab->method = v->march ? VFX_BEAMS_METHOD_MARCH : VFX_BEAMS_METHOD_CLOSED_FORM;
    lab->march_samples = v->march;
    measure(app, frames, ms);
    char png[512];
    snprintf(png, sizeof png, "%s/beams-%s.png", dir, v->name);
    game_app_screenshot(app, png);
    print_json(v->name, png, app, ms, stdout);
}

int bench_beams_panel(int argc, char **argv)
{
    const char *dir = NULL, *scene = "sample_game/scenes/beams-showcase.json";
    double t = 2.0;
    uint32_t w = 640, h = 360, frames = 8;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--panel") && i + 1 < argc)
            dir = argv[++i];
        else if (!strcmp(argv[i], "--scene") && i + 1 < argc)
            scene = argv[++i];
        else if (!strcmp(argv[i], "--time") && i + 1 < argc)
            t = atof(argv[++i]);
        else if (!strcmp(argv[i], "--frames") && i + 1 < argc)
            frames = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--size") && i + 1 < argc && sscanf(argv[i + 1], "%ux%u", &w, &h) == 2)
            i++;
        else if (strcmp(argv[i], "beams") && strcmp(argv[i], "--json")) {
            fprintf(stderr, "volfx-bench beams --panel DIR [--scene FILE] [--time T] [--frames N] [--size WxH]: "
                            "unknown option '%s'\n", argv[i]);
            return 2;
        }
    }
    if (!dir || frames < 1 || frames > 60 || !isfinite(t) || w < 16 || h < 16 || w > 4096 || h > 4096) {
        fprintf(stderr, "volfx-bench beams --panel DIR: needs an output folder, 1..60 frames, a finite time, "
                        "16..4096 pixels a side\n");
        return 2;
    }
    game_app *app;
    game_app_desc d = {.mode = RT_GL_HEADLESS, .width = w, .height = h};
    if (game_app_create(&d, &app))
        return 1;
    if (volfx_lab_attach(app->ctx) != VFX_OK) { /* the march is the lab's */
        game_app_destroy(app);
        return 1;
    }
    game_demo demo;
    memset(&demo, 0, sizeof demo);
    if (game_demo_load(app, &demo, scene, VFX_EFFECT_BIT(VFX_EFFECT_WATER) | VFX_EFFECT_BIT(VFX_EFFECT_VOLUME))) {
        game_app_destroy(app);
        return 1;
    }
    vfx_lab_beams lab_beams = {.type = VFX_TYPE_LAB_BEAMS}, *lab = &lab_beams; /* closed form or march */
    app->beams_next = lab;
    fprintf(stdout, "{\"gl_renderer\": \"%s\", \"scene\": \"%s\", \"time\": %g, \"frames\": %u}\n",
            (const char *)glGetString(GL_RENDERER), scene, t, frames);
    static const variant vs[] = {
        {"showcase", 0, 0, 0},
        {"hard", VFX_BEAM_FALLOFF_HARD, VFX_BEAMS_BLOOM_OFF, 0},
        {"smooth", VFX_BEAM_FALLOFF_SMOOTH, VFX_BEAMS_BLOOM_OFF, 0},
        {"smooth-bloom", VFX_BEAM_FALLOFF_SMOOTH, VFX_BEAMS_BLOOM_ON, 0},
    };
    double ms[NPASS], closed_ms = NAN;
    for (size_t i = 0; i < sizeof vs / sizeof vs[0]; ++i) {
        run_variant(app, &demo, lab, t, &vs[i], dir, frames, ms);
        if (!strcmp(vs[i].name, "smooth"))
            closed_ms = ms[0];
    }
    /* equal time: the march sample count whose integrate time is nearest the closed form's */
    uint32_t best = 1;
    double best_gap = INFINITY;
    for (uint32_t n = 1; n <= 1024; n *= 2) {
        variant m = {"march-probe", VFX_BEAM_FALLOFF_SMOOTH, VFX_BEAMS_BLOOM_OFF, n};
        app->time = t;
        game_demo_animate(app, &demo, 0.f);
        uint32_t nb;
        vfx_beam *beams = game_app_beams(app, &nb);
        for (uint32_t i = 0; i < nb; ++i)
            beams[i].falloff = VFX_BEAM_FALLOFF_SMOOTH;
        app->beams_view = demo.scene->beams_view;
        app->beams_view.bloom = VFX_BEAMS_BLOOM_OFF;
        lab->method = VFX_BEAMS_METHOD_MARCH;
        lab->march_samples = n;
        measure(app, frames, ms);
        fprintf(stdout, "{\"variant\": \"%s\", \"samples\": %u, \"march_ms\": %.4f, \"closed_ms\": %.4f}\n", m.name, n,
                ms[1], closed_ms);
        double gap = fabs(log(ms[1] / closed_ms));
        if (gap < best_gap)
            best_gap = gap, best = n;
        if (ms[1] > 2.0 * closed_ms)
            break;
    }
    variant m = {"march-equal-time", VFX_BEAM_FALLOFF_SMOOTH, VFX_BEAMS_BLOOM_OFF, best};
    run_variant(app, &demo, lab, t, &m, dir, frames, ms);
    fprintf(stdout, "{\"variant\": \"equal-time\", \"samples\": %u}\n", best);
    /* cost under animation: frames stepping through the loop against the same frames frozen */
    double anim[2];
    for (int a = 0; a < 2; ++a) {
        lab->method = VFX_BEAMS_METHOD_CLOSED_FORM;
        lab->march_samples = 0;
        app->beams_view = demo.scene->beams_view;
        double v[64];
        uint32_t n = 0;
        for (uint32_t f = 0; f < frames + 4 && n < 64; ++f) {
            app->time = a ? t + 0.1 * f : t;
            game_demo_animate(app, &demo, 0.f);
            if (game_app_frame(app, 0.f))
                break;
            if (f >= 4)
                v[n++] = stat_of(app, "beams.integrate.gpu_ms");
        }
        qsort(v, n, sizeof(double), cmp_d);
        anim[a] = n ? v[n / 2] : NAN;
    }
    fprintf(stdout, "{\"variant\": \"animation\", \"frozen_integrate_ms\": %.4f, \"animated_integrate_ms\": %.4f}\n",
            anim[0], anim[1]);
    game_demo_free(app, &demo);
    game_app_destroy(app);
    return 0;
}
