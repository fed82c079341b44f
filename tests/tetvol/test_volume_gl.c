/* The volume effect through the real host: its opacity image equals the CPU renderer's called
 * directly with the same camera and transfer function (the effect only wires, clips and
 * composites), the host's depth hides what lies behind a wall, bad views are refused, and an
 * absent volume costs nothing. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app.h"
#include "demo_scene.h"
#include "volfx_lab.h"
#include "tet_testmesh.h"
#include "debug.h"
#include "depth_modes.h"
#include "scene/scene.h"
#include "test_camera.h"
#include "test_util.h"
#include "tet_render.h"

#define W 48
#define H 36

static game_app *g_app;
static rt_entity g_vol; /* the generated grid's volume entity */
/* the camera the host renders with; the references trace its rays in float64 */
static const ref_camera g_cam = {{0.3, 0.4, 3.5}, {0, 0, 0}, {0, 1, 0}, 0.9, W, H, 0.05, 50};
static const char *g_showcase; /* sample_game/scenes/volume-showcase.json (argv[1]) */
static float *g_points, *g_scalar;
static uint32_t *g_tets, g_np, g_nt;

static int setup(void **state)
{
    (void)state;
    g_app = test_app_with_camera(&g_cam, NULL);
    assert_int_equal(volfx_lab_attach(g_app->ctx), VFX_OK); /* the renderer's lab switches */
    rt_scene_volume sv;
    memset(&sv, 0, sizeof sv);
    sv.generated = true;
    sv.gen_cells = 4;
    for (int k = 0; k < 3; ++k)
        sv.gen_min[k] = -0.7f, sv.gen_max[k] = 0.7f;
    char err[256];
    assert_int_equal(rt_scene_volume_generate(&sv, &g_points, &g_np, &g_tets, &g_nt, &g_scalar, err, sizeof err), VFX_OK);
    vfx_volume_view view = {.type = VFX_TYPE_VOLUME_VIEW,
                                    .point_count = g_np, .tet_count = g_nt, .points = g_points, .tets = g_tets,
                                    .scalar = g_scalar, .scalar_min = 0, .scalar_max = 1, .workers = 1,
                                    .revision = 1};
    assert_int_equal(game_app_add_volume(g_app, &view, &g_vol), VFX_OK);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    game_app_destroy(g_app);
    free(g_points), free(g_scalar), free(g_tets);
    return 0;
}

/* A counter of the last frame (NAN when absent). */
static double stat(const char *name)
{
    vfx_stats st = {.type = VFX_TYPE_STATS};
    assert_int_equal(g_app->api->get_stats(g_app->ctx, &st), VFX_OK);
    for (uint32_t i = 0; i < st.count; ++i)
        if (!strcmp(st.entries[i].name, name))
            return st.entries[i].value;
    return NAN;
}

static float *render_alpha(void)
{
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_OK);
    float *a = malloc(W * H * sizeof(float));
    assert_int_equal(g_app->api->read_raw(g_app->ctx, VFX_EFFECT_VOLUME, a, W * H), VFX_OK);
    return a;
}

/* The CPU renderer called directly, same camera, same default transfer function as the effect. */
static float *direct_alpha(void)
{
    tet_mesh m = {.point_count = g_np, .tet_count = g_nt, .points = g_points, .tets = g_tets, .scalar = g_scalar};
    tet_camera cam = {.width = W, .height = H};
    ref_camera_matrices(&g_cam, cam.view, cam.proj);
    tet_tf tf = {.smin = 0, .smax = 1, .tau_lo = 0.2f, .tau_hi = 3.0f, .color_lo = {0.1f, 0.3f, 0.9f},
                     .color_hi = {1.0f, 0.85f, 0.3f}};
    /* the effect's settings as the plugin resolves the host's view (not restated here) */
    vfx_volume_view vv = *game_app_volume(g_app, g_vol);
    assert_int_equal(g_app->api->resolve_defaults(g_app->ctx, &vv), VFX_OK);
    tet_options o;
    tet_options_default(&o);
    o.ert_threshold = vv.ert_threshold, o.tiles_d = (int)vv.tiles, o.update_c = (int)vv.update_c;
    o.workers = 1;
    float *rgba = malloc(W * H * 4 * sizeof(float)), *a = malloc(W * H * sizeof(float));
    char err[256];
    assert_int_equal(tet_render_workers(&m, &cam, &tf, &o, rgba, NULL, NULL, err, sizeof err), TET_OK);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            a[y * W + x] = rgba[4 * ((H - 1 - y) * W + x) + 3];
    free(rgba);
    return a;
}

static void test_matches_renderer(void **state)
{
    (void)state;
    float *gpu = render_alpha(), *cpu = direct_alpha();
    double max_e = 0, max_a = 0;
    for (int p = 0; p < W * H; ++p) {
        max_e = fmax(max_e, fabs(gpu[p] - cpu[p]));
        max_a = fmax(max_a, gpu[p]);
    }
    printf("volume via plugin vs direct renderer: max |d alpha| %.3g (max alpha %.3f)\n", max_e, max_a);
    assert_true(max_a > 0.3);   /* something was drawn */
    assert_true(max_e < 1e-6);  /* same code, same inputs: only float reordering could differ */
    free(gpu), free(cpu);
}

/* The wall clips the volume with the host's depth given in `mode` (tests/common/depth_modes.h). */
static void hidden_by_depth_in(int mode)
{
    depth_mode_set(g_app, mode);
    /* a wall in front of the whole volume, covering everything left of x = 0.1 */
    float *open = render_alpha();
    rt_entity e;
    assert_int_equal(game_app_add_box(g_app, (float[3]){-5, -5, 1.0f}, (float[3]){0.1f, 5, 1.2f},
                                     (float[3]){0.5f, 0.5f, 0.5f}, &e), VFX_OK);
    /* the clip distances are read back one frame late (no wait for the GPU): the first frame
     * with the wall still uses the open frame's distances, the second is clipped */
    float *late = render_alpha();
    assert_true(stat("volume.clip_frames_late") == 1);
    float *a = render_alpha();
    rt_mesh_component *m = rt_world_get(g_app->world, e, g_app->meshes.mesh, 0);
    rt_mesh_gpu_destroy(&m->gpu);
    assert_int_equal(rt_world_despawn(g_app->world, e), VFX_OK);
    /* the wall's edge (x = 0.1, z = 1.2) projected to a pixel column */
    float view[16], proj[16];
    ref_camera_matrices(&g_cam, view, proj);
    double p[4] = {0.1, 0.0, 1.2, 1.0}, v[4] = {0}, c[4] = {0};
    for (int r = 0; r < 4; ++r)
        for (int k = 0; k < 4; ++k)
            v[r] += view[k * 4 + r] * p[k];
    for (int r = 0; r < 4; ++r)
        for (int k = 0; k < 4; ++k)
            c[r] += proj[k * 4 + r] * v[k];
    int edge = (int)((c[0] / c[3] * 0.5 + 0.5) * W);
    double hidden = 0, beside = 0, beside_open = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            if (x < edge - 1)
                hidden += a[y * W + x];
            else if (x > edge + 1) {
                beside += a[y * W + x];
                beside_open += open[y * W + x];
            }
        }
    printf("wall edge at column %d: alpha behind the wall %.3g, beside it %.3g (open %.3g)\n", edge, hidden, beside, beside_open);
    double late_hidden = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < edge - 1; ++x)
            late_hidden += late[y * W + x];
    assert_true(late_hidden > 0.5);                   /* one frame late, as documented */
    assert_true(hidden == 0.0);                       /* clipped by the host's depth */
    assert_true(beside > 0.5 && fabs(beside - beside_open) < 1e-6 * beside_open); /* untouched */
    free(a), free(open), free(late);
    /* the wall is gone: two frames bring the open image back */
    free(render_alpha());
    free(render_alpha());
    depth_mode_set(g_app, DEPTH_STANDARD);
}

static void test_hidden_by_depth(void **state)
{
    (void)state;
    hidden_by_depth_in(DEPTH_STANDARD);
}

/* The same clip, exactly (nothing behind the wall, the rest untouched to 1e-6, one frame late),
 * when the depth comes in a renderbuffer, reversed-Z with an infinite far plane under
 * GL_ZERO_TO_ONE, with flipped rows (the wall spans every row: a lost flip shows in the image's
 * rows, not here), with an infinite far plane, and all at once. */
static void test_hidden_by_depth_modes(void **state)
{
    (void)state;
    for (size_t m = 0; m < DEPTH_MODES_COUNT; ++m) {
        printf("depth mode %s: ", depth_modes_all[m].name);
        hidden_by_depth_in(depth_modes_all[m].mode);
    }
}

static void test_bad_view_and_absence(void **state)
{
    (void)state;
    uint32_t saved = g_tets[5];
    g_tets[5] = g_np + 7;
    game_app_volume(g_app, g_vol)->revision = 2;
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_ERR_INVALID_ARGUMENT);
    assert_true(test_last_error_is(g_app->api, g_app->ctx, VFX_LOG_ID_VOLUME_MESH, "volume[0]: tet 1 uses point"));
    g_tets[5] = saved;
    game_app_volume(g_app, g_vol)->revision = 3;
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_OK);
    vfx_volume_view keep = *game_app_volume(g_app, g_vol);
    assert_int_equal(game_app_remove(g_app, g_vol), VFX_OK);
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_OK);
    assert_null(g_app->ctx->effect_state[VFX_EFFECT_VOLUME]);
    assert_int_equal(game_app_add_volume(g_app, &keep, &g_vol), VFX_OK);
}

/* Nothing changed: the render is skipped (counted) and the image kept; a new transfer function,
 * a new revision or a moved point renders again. */
static void test_skip_when_unchanged(void **state)
{
    (void)state;
    vfx_volume_view *v = game_app_volume(g_app, g_vol);
    float *a = render_alpha();
    float *b = render_alpha();
    assert_true(stat("volume.render_skipped") == 1);
    double skipped = stat("volume.renders_skipped_total");
    assert_memory_equal(a, b, W * H * sizeof *a);
    float table[3 * 4] = {0.1f, 0.3f, 0.9f, 0.2f, 1, 1, 1, 6.0f, 1.0f, 0.85f, 0.3f, 3.0f};
    v->transfer_rgba = table;
    v->transfer_count = 3;
    free(render_alpha());
    assert_true(stat("volume.render_skipped") == 0);
    free(render_alpha());
    assert_true(stat("volume.render_skipped") == 1);
    assert_true(stat("volume.renders_skipped_total") == skipped + 1);
    table[7] = 0.5f; /* same pointer, new values: compared by value */
    free(render_alpha());
    assert_true(stat("volume.render_skipped") == 0);
    v->transfer_rgba = NULL;
    v->transfer_count = 0;
    free(render_alpha());
    /* a deforming mesh: a point moves, the host bumps the revision */
    float keep = g_points[3 * 40];
    g_points[3 * 40] += 0.2f;
    v->revision++;
    float *c = render_alpha();
    assert_true(stat("volume.render_skipped") == 0);
    double d = 0;
    for (int p = 0; p < W * H; ++p)
        d = fmax(d, fabs(c[p] - a[p]));
    assert_true(d > 1e-3);
    g_points[3 * 40] = keep;
    v->revision++;
    free(render_alpha());
    free(a), free(b), free(c);
}

/* A version-2 view with breakpoints at transfer_scalar (in [0,1] of the domain, not spanning
 * all of it): the plugin's opacity equals the renderer given the same table directly. */
static void test_view2_breakpoints(void **state)
{
    (void)state;
    vfx_volume_view *v2 = game_app_volume(g_app, g_vol);
    float rgba[3 * 4] = {0.2f, 0.4f, 1.0f, 0.5f, 1, 1, 1, 9.0f, 1.0f, 0.5f, 0.1f, 2.0f};
    float pos[3] = {0.2f, 0.5f, 0.9f};
    v2->transfer_rgba = rgba;
    v2->transfer_count = 3;
    v2->transfer_scalar = pos;
    float *gpu = render_alpha();
    tet_mesh m = {.point_count = g_np, .tet_count = g_nt, .points = g_points, .tets = g_tets, .scalar = g_scalar};
    tet_camera cam = {.width = W, .height = H};
    ref_camera_matrices(&g_cam, cam.view, cam.proj);
    tet_tf_point pts[3];
    for (int i = 0; i < 3; ++i) /* the view's domain is [0, 1] */
        pts[i] = (tet_tf_point){pos[i], {rgba[4 * i], rgba[4 * i + 1], rgba[4 * i + 2]}, rgba[4 * i + 3]};
    tet_tf tf = {.points = pts, .count = 3};
    tet_options o;
    tet_options_default(&o);
    o.workers = 1;
    float *img = malloc(W * H * 4 * sizeof(float));
    char err[256];
    assert_int_equal(tet_render_workers(&m, &cam, &tf, &o, img, NULL, NULL, err, sizeof err), TET_OK);
    double d = 0, amax = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            d = fmax(d, fabs(gpu[y * W + x] - img[4 * ((H - 1 - y) * W + x) + 3]));
            amax = fmax(amax, gpu[y * W + x]);
        }
    printf("view 2 breakpoints 0.2/0.5/0.9: plugin vs renderer max |d alpha| %.3g (max alpha %.3f)\n", d, amax);
    assert_true(amax > 0.3 && d < 1e-6);
    v2->transfer_rgba = NULL;
    v2->transfer_count = 0;
    v2->transfer_scalar = NULL;
    free(gpu), free(img);
}

/* Writes the ref_testmesh_grid(n) mesh as an ASCII .vtu with the point field "f". */
static void write_grid_vtu(const char *path, int n, tet_mesh *m)
{
    assert_int_equal(ref_testmesh_grid(n, m), 0);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\"><UnstructuredGrid>"
               "<Piece NumberOfPoints=\"%u\" NumberOfCells=\"%u\"><PointData>"
               "<DataArray type=\"Float32\" Name=\"f\" format=\"ascii\">", m->point_count, m->tet_count);
    for (uint32_t i = 0; i < m->point_count; ++i)
        fprintf(f, " %.9g", m->scalar[i]);
    fprintf(f, "</DataArray></PointData><Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">");
    for (uint32_t i = 0; i < 3 * m->point_count; ++i)
        fprintf(f, " %.9g", m->points[i]);
    fprintf(f, "</DataArray></Points><Cells><DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">");
    for (uint32_t i = 0; i < 4 * m->tet_count; ++i)
        fprintf(f, " %u", m->tets[i]);
    fprintf(f, "</DataArray><DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">");
    for (uint32_t i = 1; i <= m->tet_count; ++i)
        fprintf(f, " %u", 4 * i);
    fprintf(f, "</DataArray><DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">");
    for (uint32_t i = 0; i < m->tet_count; ++i)
        fprintf(f, " 10");
    fprintf(f, "</DataArray></Cells></Piece></UnstructuredGrid></VTKFile>\n");
    fclose(f);
}

/* The product and its laboratory: a context as libvolfx makes it (no lab attached) refuses a
 * chained vfx_lab_volume by name and draws on without it; with the lab attached the struct
 * switches the renderer's early ray termination off (a new render, no cell skipped by it), and
 * an unknown bit is refused naming the field. */
static void test_lab_struct_needs_the_lab(void **state)
{
    (void)state;
    vfx_volume_view *v = game_app_volume(g_app, g_vol);
    vfx_lab_volume lab = {.type = VFX_TYPE_LAB_VOLUME, .disable = VFX_VOLUME_NO_ERT};
    const volfx_lab_hooks *hooks = g_app->ctx->lab;
    g_app->ctx->lab = NULL; /* as libvolfx.so, which has no volfx_lab_attach */
    v->next = &lab;
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_ERR_UNSUPPORTED);
    printf("without the lab: %s\n", g_app->api->last_error(g_app->ctx, NULL));
    assert_true(test_last_error_is(g_app->api, g_app->ctx, VFX_LOG_ID_STRUCT_TYPE, "vfx_lab_volume"));
    v->next = NULL; /* nothing chained: the product draws */
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_OK);
    g_app->ctx->lab = hooks;
    v->next = &lab;
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_OK);
    assert_true(stat("volume.render_skipped") == 0 && stat("volume.cells_skipped_ert") == 0);
    assert_true(stat("volume.cells_scanned") > 0);
    lab.disable = 1u << 7;
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_ERR_INVALID_ARGUMENT);
    assert_true(test_last_error_is(g_app->api, g_app->ctx, VFX_LOG_ID_PARAM_RANGE, "vfx_lab_volume.disable 0x80"));
    v->next = NULL;
    assert_int_equal(game_app_frame(g_app, 0.f), VFX_OK);
}

/* A user's .vtu in a scene file with a 64-point transfer function (a smooth map with a narrow
 * spike), loaded by the game's scene code, rendered by the plugin (ERT off: the reference has
 * none, and ERT may drop up to 1 - threshold of light by design), against the float64 ray
 * march. Then a missing file: an error naming it that stops the load. Runs after the tests of
 * the app's own volume: it replaces the camera and the volume. */
static void test_file_volume_in_scene(void **state)
{
    (void)state;
    char dir[] = "/tmp/volfx-test-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char vtu[256], scene[256];
    snprintf(vtu, sizeof vtu, "%s/grid.vtu", dir);
    snprintf(scene, sizeof scene, "%s/scene.json", dir);
    tet_mesh grid;
    write_grid_vtu(vtu, 6, &grid);
    tet_tf_point pts[64];
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    fprintf(f, "{\"version\": 1, \"origin\": [0, 0, 0], \"name\": \"vtu64\", \"camera\": {\"eye\": [0.9, 1.3, 3.4], \"target\": [0, 0, 0],"
               " \"up\": [0, 1, 0], \"fov_y_deg\": 55, \"width\": %d, \"height\": %d, \"near\": 0.1, \"far\": 50},"
               " \"volume\": {\"path\": \"grid.vtu\", \"scalar\": \"f\", \"workers\": 1, \"transfer\": [", W, H);
    for (int i = 0; i < 64; ++i) {
        double u = i < 40 ? 0.58 * i / 39.0 : i < 43 ? 0.595 + 0.005 * (i - 40) : 0.61 + 0.39 * (i - 43) / 20.0;
        tet_tf_point *p = &pts[i];
        p->s = (float)u;
        p->rgb[0] = (float)u, p->rgb[1] = (float)(0.3 + 0.5 * sin(M_PI * u)), p->rgb[2] = (float)(1 - u);
        p->tau = (float)(0.5 + 2.5 * u * u);
        if (i == 41)
            p->rgb[0] = p->rgb[1] = p->rgb[2] = 1.0f, p->tau = 60.0f;
        fprintf(f, "%s{\"scalar\": %.9g, \"rgba\": [%.9g, %.9g, %.9g, %.9g]}", i ? ", " : "", p->s, p->rgb[0],
                p->rgb[1], p->rgb[2], p->tau);
    }
    fprintf(f, "]}}\n");
    fclose(f);
    game_app_remove(g_app, g_vol); /* the scene's volume replaces it (stale after the first) */
    game_demo demo;
    assert_int_equal(game_demo_load(g_app, &demo, scene, 0), VFX_OK);
    /* no early ray termination, as the float64 reference (a lab switch: chained by the test) */
    vfx_lab_volume lab = {.type = VFX_TYPE_LAB_VOLUME, .disable = VFX_VOLUME_NO_ERT};
    game_app_volume(g_app, demo.spawned.volume)->next = &lab;
    float *a = render_alpha();
    free(a);
    a = render_alpha(); /* the second frame clips with this scene's distances */
    tet_camera cam = {.width = W, .height = H};
    const ref_camera scene_cam = {{0.9, 1.3, 3.4}, {0, 0, 0}, {0, 1, 0}, 55 * M_PI / 180.0, W, H, 0.1, 50}; /* the file's */
    ref_camera_matrices(&scene_cam, cam.view, cam.proj);
    tet_tf tf = {.points = pts, .count = 64};
    double *ref = malloc(W * H * 4 * sizeof *ref);
    ref_testmesh_raymarch(6, &grid, &cam, &tf, 3000, ref);
    double mx = 0, se = 0, amax = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            double r = ref[4 * ((size_t)(H - 1 - y) * W + x) + 3], e = fabs(a[y * W + x] - r);
            mx = fmax(mx, e), se += e * e, amax = fmax(amax, r);
        }
    printf(".vtu with a 64-point transfer function in a scene vs float64: alpha max %.3g rmse %.3g (max alpha %.3f)\n",
           mx, sqrt(se / (W * H)), amax);
    assert_true(amax > 0.3);
    /* opacity per piece is exact (1 - exp of the integral of a linear tau), so what remains is
     * the reference's step error where its steps straddle tet faces and breakpoints (~1e-4
     * per ray at h <= 1.2e-3; measured 3.8e-5 max): 1e-3 max, 1e-4 RMSE */
    assert_true(mx < 1e-3 && sqrt(se / (W * H)) < 1e-4);
    game_demo_free(g_app, &demo);
    free(a), free(ref);
    /* a missing file stops the load with its name */
    remove(vtu);
    test_log tl = {0};
    rt_logger saved = g_app->log;
    g_app->log = (rt_logger){test_log_fn, &tl};
    assert_int_equal(game_demo_load(g_app, &demo, scene, 0), VFX_ERR_IO);
    g_app->log = saved;
    printf("missing file: %s\n", tl.last);
    assert_non_null(strstr(tl.last, "grid.vtu"));
    game_demo_free(g_app, &demo);
    remove(scene);
    rmdir(dir);
    free(grid.points), free(grid.scalar), free(grid.tets);
}

/* The showcase scene: its dome loads, and the animation changes points, scalars and the table
 * through the ABI every frame (a new revision each time, no frame skipped, a different image). */
static void test_showcase_animates(void **state)
{
    (void)state;
    if (!g_showcase)
        skip();
    game_app_remove(g_app, g_vol); /* the scene's volume replaces it (stale after the first) */
    game_demo demo;
    assert_int_equal(game_demo_load(g_app, &demo, g_showcase, VFX_EFFECT_BIT(VFX_EFFECT_WATER)), VFX_OK);
    assert_true(demo.vol_animated);
    uint64_t rev = game_app_volume(g_app, demo.spawned.volume)->revision;
    float *prev = NULL;
    for (int f = 0; f < 3; ++f) {
        g_app->time = 2.6 + 0.1 * f; /* the beam crosses the dome */
        game_demo_animate(g_app, &demo, 0.1f);
        float *a = render_alpha();
        assert_true(game_app_volume(g_app, demo.spawned.volume)->revision == rev + 1 + (uint64_t)f);
        if (prev) {
            assert_true(stat("volume.render_skipped") == 0);
            double d = 0;
            for (int p = 0; p < W * H; ++p)
                d = fmax(d, fabs(a[p] - prev[p]));
            assert_true(d > 1e-3);
        }
        free(prev);
        prev = a;
    }
    free(prev);
    /* switched off, an effect's entities leave the world; switched back, they return (the
     * volume as it was, the beams refilled from the keyframes by the next animate) */
    uint32_t nb;
    game_app_beams(g_app, &nb);
    assert_true(nb == demo.beam_base_count && nb > 0);
    uint64_t rev_off = game_app_volume(g_app, demo.spawned.volume)->revision;
    game_demo_toggle(g_app, &demo, VFX_EFFECT_VOLUME);
    game_demo_toggle(g_app, &demo, VFX_EFFECT_BEAMS);
    assert_int_equal(game_app_volume_count(g_app), 0);
    assert_null(game_app_beams(g_app, &nb));
    game_demo_animate(g_app, &demo, 0.1f);
    assert_int_equal(game_app_frame(g_app, 0.1f), VFX_OK);
    assert_null(g_app->ctx->effect_state[VFX_EFFECT_VOLUME]);
    game_demo_toggle(g_app, &demo, VFX_EFFECT_VOLUME);
    game_demo_toggle(g_app, &demo, VFX_EFFECT_BEAMS);
    game_demo_animate(g_app, &demo, 0.1f);
    assert_int_equal(game_app_volume_count(g_app), 1);
    assert_true(game_app_volume(g_app, demo.spawned.volume)->revision == rev_off + 1);
    const vfx_beam *beams = game_app_beams(g_app, &nb);
    assert_true(nb == demo.beam_base_count && beams[0].length > 0);
    assert_int_equal(game_app_frame(g_app, 0.1f), VFX_OK);
    game_demo_free(g_app, &demo);
}

int main(int argc, char **argv)
{
    g_showcase = argc > 1 ? argv[1] : NULL;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matches_renderer),
        cmocka_unit_test(test_hidden_by_depth),
        cmocka_unit_test(test_hidden_by_depth_modes),
        cmocka_unit_test(test_bad_view_and_absence),
        cmocka_unit_test(test_skip_when_unchanged),
        cmocka_unit_test(test_view2_breakpoints),
        cmocka_unit_test(test_lab_struct_needs_the_lab),
        cmocka_unit_test(test_file_volume_in_scene),
        cmocka_unit_test(test_showcase_animates), /* last: it leaves the scene's meshes */
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
