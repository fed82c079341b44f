/* bench_beams_gpu.c — `volfx-bench beams --gpu`: the thesis' Table 4.2 on the GL path through
 * the real host (1 / 5 / 10 beam sets at 256^2 and 512^2; more with --sets and --size), closed
 * form against the ray-marching baseline at 8 / 32 / 120 samples, GPU ms per pass (median of
 * the timestamp-query results) and the error of each method against the float64 closed form. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app.h"
#include "volfx_lab.h"
#include "lab/beam_field_d.h"
#include "beams_ref.h"
#include "camera_ref.h"

int bench_beams_gpu(int argc, char **argv);

static double stat_of(game_app *app, const char *name)
{
    vfx_stats st = {.type = VFX_TYPE_STATS};
    app->api->get_stats(app->ctx, &st);
    for (uint32_t k = 0; k < st.count; ++k)
        if (!strcmp(st.entries[k].name, name))
            return st.entries[k].value;
    return NAN;
}

/* A beam set as in the thesis: beams fired across the view at different depths and angles. Sets
 * above 10 (the 100 / 1,000-beam runs) are spread over the view on a grid of short, thin beams,
 * as a game's many projectiles would be, so a tile sees a few tens of beams rather than all. */
/* The app's beam entities, n of them (respawned when the count changes). */
static vfx_beam *beam_entities(game_app *app, uint32_t n)
{
    uint32_t have;
    game_app_beams(app, &have);
    if (have != n) {
        game_app_clear_beams(app);
        game_app_add_beams(app, NULL, n);
    }
    return game_app_beams(app, &have);
}

static void make_beams(game_app *app, uint32_t n)
{
    vfx_beam *beams = beam_entities(app, n);
    if (n > 10) {
        uint32_t cols = (uint32_t)ceil(sqrt(n * 16.0 / 9.0)), rows = (n + cols - 1) / cols;
        for (uint32_t i = 0; i < n; ++i) {
            double fx = ((i % cols) + 0.5) / cols, fy = ((i / cols) + 0.5) / rows, a = 2.4 * i;
            float L = (float)(4.0 / cols), R = (float)(1.2 / cols);
            beams[i] = (vfx_beam){.type = VFX_TYPE_BEAM,
                                  .head = {(float)(-2.6 + 5.2 * fx), (float)(-1.45 + 2.9 * fy), (float)(-0.5 * sin(a))},
                                  .dir = {(float)cos(a), (float)sin(a), 0.2f}, .length = L,
                                  .radius = R, .a = 0.3f, .b = 0.3f, .eps = 0.0f};
        }
        return;
    }
    for (uint32_t i = 0; i < n; ++i) {
        double a = 2.0 * M_PI * i / (n > 1 ? n : 1);
        beams[i] = (vfx_beam){.type = VFX_TYPE_BEAM,
                              .head = {(float)(-2.0 + 0.3 * cos(a)), (float)(0.8 * sin(a)), (float)(-0.5 * cos(a))},
                              .dir = {1, (float)(0.2 * sin(a)), (float)(0.1 * cos(a))}, .length = 3.0f,
                              .radius = 0.5f, .a = 0.3f, .b = 0.3f, .eps = 0.0f};
    }
}

/* Issue 15's options: the beams go to the plugin with this falloff, the hot ramp and bloom on or
 * off. falloff 0: the thesis's look (the hard support, the thesis ramp, no bloom). */
static int g_falloff, g_bloom;
static void sync_v2(game_app *app)
{
    uint32_t n;
    vfx_beam *beams = game_app_beams(app, &n);
    for (uint32_t i = 0; i < n; ++i) {
        beams[i].falloff = g_falloff ? (uint32_t)g_falloff : VFX_BEAM_FALLOFF_HARD;
        beams[i].ramp = g_falloff ? VFX_BEAM_RAMP_HOT : VFX_BEAM_RAMP_THESIS;
    }
    app->beams_view.bloom = g_falloff && g_bloom ? VFX_BEAMS_BLOOM_ON : VFX_BEAMS_BLOOM_OFF;
}

static vfx_result frame(game_app *app)
{
    sync_v2(app);
    return game_app_frame(app, 0.f);
}

int bench_beams_gpu(int argc, char **argv)
{
    uint32_t sets[8] = {1, 5, 10}, nsets = 3, sizes[4][2] = {{256, 256}, {512, 512}}, nsizes = 2, frames = 8;
    int timing_only = 0;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--timing-only")) {
            timing_only = 1;
            continue;
        }
        if (!strcmp(argv[i], "--sets") && i + 1 < argc) {
            nsets = 0;
            for (char *t = strtok(argv[++i], ","); t && nsets < 8; t = strtok(NULL, ","))
                sets[nsets++] = (uint32_t)strtoul(t, NULL, 10);
        } else if (!strcmp(argv[i], "--size") && i + 1 < argc) {
            if (sscanf(argv[++i], "%ux%u", &sizes[0][0], &sizes[0][1]) != 2) {
                fprintf(stderr, "volfx-bench beams --gpu: --size '%s' is not WxH\n", argv[i]);
                return 2;
            }
            nsizes = 1;
        } else if (!strcmp(argv[i], "--frames") && i + 1 < argc) {
            frames = (uint32_t)strtoul(argv[++i], NULL, 10);
        } else if (!strcmp(argv[i], "--falloff") && i + 1 < argc) {
            const char *f = argv[++i];
            g_falloff = !strcmp(f, "smooth") ? VFX_BEAM_FALLOFF_SMOOTH : !strcmp(f, "hard") ? VFX_BEAM_FALLOFF_HARD : -1;
            if (g_falloff < 0) {
                fprintf(stderr, "volfx-bench beams --gpu: --falloff smooth|hard, got '%s'\n", f);
                return 2;
            }
        } else if (!strcmp(argv[i], "--bloom")) {
            g_bloom = 1;
        } else if (strcmp(argv[i], "--gpu") && strcmp(argv[i], "--json")) {
            fprintf(stderr, "volfx-bench beams --gpu: unknown option '%s' (--sets 1,5,10 --size WxH --frames N "
                            "--timing-only --falloff smooth|hard --bloom)\n", argv[i]);
            return 2;
        }
    }
    for (uint32_t k = 0; k < nsets; ++k)
        if (sets[k] == 0 || sets[k] > GAME_APP_MAX_BEAMS || frames < (timing_only ? 1u : 5u) || frames > 1000) {
            fprintf(stderr, "volfx-bench beams --gpu: sets 1..%d, frames 5..1000 (1..1000 with --timing-only)\n", GAME_APP_MAX_BEAMS);
            return 2;
        }
    for (uint32_t zi = 0; zi < nsizes; ++zi) {
        uint32_t w = sizes[zi][0], h = sizes[zi][1];
        game_app_desc d = {.mode = RT_GL_HEADLESS, .width = w, .height = h};
        game_app *app;
        if (game_app_create(&d, &app))
            return 1;
        if (volfx_lab_attach(app->ctx) != VFX_OK) { /* the march is the lab's */
            game_app_destroy(app);
            return 1;
        }
        vfx_lab_beams lab_beams = {.type = VFX_TYPE_LAB_BEAMS}, *lab = &lab_beams; /* closed form or march */
        app->beams_next = lab;
        /* the host's camera and the float64 reference's: the same numbers */
        rt_camera hc = {{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, M_PI / 3, w, h, 0.05, 50};
        ref_camera cam = {{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, M_PI / 3, w, h, 0.05, 50};
        game_app_set_camera(app, &hc);
        app->beams_view = (vfx_beams_view){.type = VFX_TYPE_BEAMS_VIEW};
        size_t np = (size_t)w * h;
        double *ref = malloc(np * sizeof(double)), *cond = malloc(np * sizeof(double));
        float *img = malloc(np * sizeof(float));
        double *ms = malloc(frames * sizeof(double)), *fr = malloc(frames * sizeof(double));
        for (uint32_t si = 0; si < nsets; ++si) {
            make_beams(app, sets[si]);
            volfx_beam_d bd[GAME_APP_MAX_BEAMS];
            char err[128];
            for (uint32_t i = 0; i < sets[si]; ++i) {
                volfx_beam_validate(&beam_entities(app, sets[si])[i], &bd[i], err, sizeof err);
                bd[i].smooth = g_falloff == VFX_BEAM_FALLOFF_SMOOTH;
            }
            if (timing_only) {
                /* large sets: closed form only, frame wall times (the headless host waits for the
                 * GPU), no reference; the pass timer is reported when its ring has delivered */
                lab->method = VFX_BEAMS_METHOD_CLOSED_FORM;
                double g = NAN;
                for (uint32_t f = 0; f < frames; ++f) {
                    double t0 = rt_now_ms();
                    if (frame(app))
                        return 1;
                    fr[f] = rt_now_ms() - t0;
                    double gf = stat_of(app, "beams.integrate.gpu_ms");
                    if (!isnan(gf))
                        g = gf;
                }
                rt_frame_pcts fp = rt_frame_percentiles(fr, frames);
                char gs[32] = "null"; /* no timer delivered yet (fewer frames than the ring) */
                if (!isnan(g))
                    snprintf(gs, sizeof gs, "%.4f", g);
                printf("{\"effect\":\"beams\",\"path\":\"gpu\",\"beams\":%u,\"width\":%u,\"height\":%u,\"method\":\"closed\","
                       "\"timing_only\":true,\"frames\":%u,\"frame_ms_p50\":%.4f,\"frame_ms\":{\"p50\":%.4f,\"p95\":%.4f,\"p99\":%.4f},"
                       "\"last_gpu_ms\":%s,\"pairs\":%.0f,"
                       "\"pairs_culled\":%.0f,\"gl_renderer\":\"%s\"}\n", sets[si], w, h, frames, fp.p50, fp.p50, fp.p95, fp.p99, gs,
                       stat_of(app, "beams.pairs"), stat_of(app, "beams.pairs_culled"), rt_gl_context_renderer(app->gl));
                fflush(stdout);
                continue;
            }
            double hmax = 0;
            for (uint32_t j = 0; j < h; ++j)
                for (uint32_t i = 0; i < w; ++i) {
                    double v[3], s = 0;
                    ref_pixel_ray(&cam, i, j, v);
                    for (uint32_t b = 0; b < sets[si]; ++b)
                        s += volfx_beam_integral_d(&bd[b], cam.eye, v, 0, cam.far_plane);
                    ref[(size_t)j * w + i] = s;
                    cond[(size_t)j * w + i] = ref_beams_cond_abs(bd, sets[si], cam.eye, v, 0, cam.far_plane, 2.0);
                    hmax = fmax(hmax, s);
                }
            /* Per-frame cost under animation: each animated configuration (a, b, M, D, L changed
             * since the last frame) is drawn, then drawn again unchanged; frame wall times (the
             * headless host waits for the GPU) are compared. Equal medians mean a change costs
             * nothing beyond the drawing the new configuration needs. */
            {
                double *moved = malloc(frames * sizeof(double)), *still = malloc(frames * sizeof(double));
                lab->method = VFX_BEAMS_METHOD_CLOSED_FORM;
                for (uint32_t f = 0; f < frames; ++f) {
                    make_beams(app, sets[si]);
                    for (uint32_t b = 0; b < sets[si]; ++b) {
                        float ph = 0.4f * (float)f + (float)b;
                        vfx_beam *bm = &beam_entities(app, sets[si])[b];
                        bm->a *= 0.5f + 0.5f * sinf(ph), bm->b *= 0.5f + 0.5f * cosf(ph);
                        bm->head[0] += 0.5f * sinf(ph), bm->length *= 0.6f + 0.4f * sinf(ph);
                        bm->dir[1] += 0.3f * cosf(ph), bm->radius *= 0.8f + 0.2f * sinf(ph);
                    }
                    for (int rep = 0; rep < 2; ++rep) {
                        double t0 = rt_now_ms();
                        if (frame(app))
                            return 1;
                        (rep ? still : moved)[f] = rt_now_ms() - t0;
                    }
                }
                double mm = rt_median(moved, frames), ms_still = rt_median(still, frames);
                printf("{\"effect\":\"beams\",\"path\":\"gpu\",\"beams\":%u,\"width\":%u,\"height\":%u,"
                       "\"animation\":{\"frames\":%u,\"changed_frame_ms_p50\":%.4f,\"unchanged_frame_ms_p50\":%.4f,"
                       "\"ratio\":%.3f},\"gl_renderer\":\"%s\"}\n", sets[si], w, h, frames, mm, ms_still,
                       mm / ms_still, rt_gl_context_renderer(app->gl));
                free(moved);
                free(still);
                make_beams(app, sets[si]);
            }
            static const uint32_t samples[4] = {0, 8, 32, 120};
            for (int mi = 0; mi < 4; ++mi) {
                lab->method = samples[mi] ? VFX_BEAMS_METHOD_MARCH : VFX_BEAMS_METHOD_CLOSED_FORM;
                lab->march_samples = samples[mi];
                const char *pass = samples[mi] ? "beams.march.gpu_ms" : "beams.integrate.gpu_ms";
                uint32_t n = 0;
                for (uint32_t f = 0; f < frames + 4; ++f) { /* 4 more: the timer ring's latency */
                    double t0 = rt_now_ms();
                    if (frame(app))
                        return 1;
                    double t = rt_now_ms() - t0, g = stat_of(app, pass);
                    if (f >= 4 && !isnan(g)) {
                        ms[n] = g;
                        fr[n++] = t;
                    }
                }
                app->api->read_raw(app->ctx, VFX_EFFECT_BEAMS, img, np);
                rt_frame_pcts fp = rt_frame_percentiles(fr, n);
                double emax = 0, esum = 0, emax_wc = 0, ratio = 0;
                uint32_t ne = 0, above = 0;
                for (size_t p = 0; p < np; ++p)
                    if (ref[p] > 1e-6 * hmax) {
                        double e = fabs(img[p] - ref[p]) / ref[p];
                        emax = fmax(emax, e);
                        if (cond[p] < 1e-5 * ref[p])
                            emax_wc = fmax(emax_wc, e);
                        /* what float32 inputs allow: 1e-5 plus the 2-ulp conditioning */
                        ratio = fmax(ratio, e * ref[p] / (1e-5 * ref[p] + cond[p]));
                        above += e > 1e-5;
                        esum += e;
                        ne++;
                    }
                printf("{\"effect\":\"beams\",\"path\":\"gpu\",\"beams\":%u,\"width\":%u,\"height\":%u,\"method\":\"%s\","
                       "\"samples\":%u,\"frames\":%u,\"gpu_ms_p50\":%.4f,\"frame_ms_p50\":%.4f,"
                       "\"frame_ms\":{\"p50\":%.4f,\"p95\":%.4f,\"p99\":%.4f},"
                       "\"max_rel_err\":%.4g,\"mean_rel_err\":%.4g,\"above_1e-5\":%u,\"max_rel_where_cond_below_1e-5\":%.4g,"
                       "\"max_err_over_1e-5_plus_cond\":%.4g,\"pixels\":%u,\"falloff\":\"%s\",\"bloom\":%s,"
                       "\"bloom_ms\":%.4f,\"gl_renderer\":\"%s\"}\n",
                       sets[si], w, h, samples[mi] ? "march" : "closed", samples[mi], n, rt_median(ms, n),
                       fp.p50, fp.p50, fp.p95, fp.p99, emax, ne ? esum / ne : 0.0, above, emax_wc, ratio, ne,
                       g_falloff == VFX_BEAM_FALLOFF_SMOOTH ? "smooth" : "hard", g_bloom ? "true" : "false",
                       g_bloom ? stat_of(app, "beams.bloom_down.gpu_ms") + stat_of(app, "beams.bloom_up.gpu_ms") : 0.0,
                       rt_gl_context_renderer(app->gl));
                fflush(stdout);
            }
        }
        free(ref), free(cond), free(img), free(ms), free(fr);
        game_app_destroy(app);
    }
    return 0;
}
