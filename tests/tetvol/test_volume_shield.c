/* test_volume_shield.c — the game's energy-shield terms (sample_game/volume_shield.c) on a
 * generated grid of cubes split into tets, against values worked out by hand: the boundary face
 * count, the rim term from the faces' normals, the hit rings around a beam's strike point. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "scene/scene.h"
#include "volume_shield.h"

enum { N = 2 }; /* cubes per side: points at -0.7, 0, 0.7 */

static float *g_points, *g_scalar;
static uint32_t *g_tets, g_np, g_nt;

/* A box [-0.7, 0.7]^3 of cells^3 cubes split into tets (the scene's generated volume). */
static int box_mesh(int cells, float **P, uint32_t *np, uint32_t **T, uint32_t *nt, float **scalar)
{
    rt_scene_volume sv;
    memset(&sv, 0, sizeof sv);
    sv.generated = true;
    sv.gen_cells = cells;
    for (int k = 0; k < 3; ++k)
        sv.gen_min[k] = -0.7f, sv.gen_max[k] = 0.7f;
    char err[256];
    return rt_scene_volume_generate(&sv, P, np, T, nt, scalar, err, sizeof err) == VFX_OK ? 0 : -1;
}

static int setup(void **state)
{
    (void)state;
    return box_mesh(N, &g_points, &g_np, &g_tets, &g_nt, &g_scalar);
}

static int teardown(void **state)
{
    (void)state;
    free(g_points);
    free(g_tets);
    free(g_scalar);
    return 0;
}

static uint32_t point_at(float x, float y, float z)
{
    for (uint32_t i = 0; i < g_np; ++i)
        if (fabsf(g_points[3 * i] - x) < 1e-6f && fabsf(g_points[3 * i + 1] - y) < 1e-6f &&
            fabsf(g_points[3 * i + 2] - z) < 1e-6f)
            return i;
    fail_msg("no grid point at (%g, %g, %g)", x, y, z);
    return 0;
}

/* Each of the 6 N x N square faces of the box is 2 triangles, so 12 N^2 boundary faces; the
 * floor (y = -0.7) left out leaves 10 N^2. A face miscounted (an interior face seen once, or a
 * boundary one paired) changes the count. */
static void test_boundary_faces(void **state)
{
    (void)state;
    game_shield *s;
    assert_int_equal(game_shield_create(g_points, g_np, g_tets, g_nt, -100.f, &s), VFX_OK);
    assert_int_equal(game_shield_faces(s), 12 * N * N);
    game_shield_destroy(s);
    assert_int_equal(game_shield_create(g_points, g_np, g_tets, g_nt, -0.7f, &s), VFX_OK);
    assert_int_equal(game_shield_faces(s), 10 * N * N);
    game_shield_destroy(s);
    uint32_t bad[4] = {0, 1, 2, g_np}; /* an index out of range is refused */
    assert_int_equal(game_shield_create(g_points, g_np, bad, 1, 0.f, &s), VFX_ERR_INVALID_ARGUMENT);
}

/* Rim: the eye far along +z. The centre of the +z face (normal +z) faces the eye: 0. The
 * centre of the +x face (normal +x) is seen at cos = 0.7 / |(-0.7, 0, 100)|: gain (1 - cos)^p
 * exactly (float accumulation: 1e-5). The box's centre is no boundary vertex: 0. */
static void test_rim(void **state)
{
    (void)state;
    game_shield *s;
    assert_int_equal(game_shield_create(g_points, g_np, g_tets, g_nt, -100.f, &s), VFX_OK);
    rt_scene_volume_animation an = {.rim_gain = 2.0f, .rim_power = 3.0f};
    float *sc = calloc(g_np, sizeof *sc);
    game_shield_frame f = {.points = g_points, .eye = {0, 0, 100}, .radius = 1};
    game_shield_apply(s, &an, &f, sc);
    double c = 0.7 / sqrt(0.7 * 0.7 + 100.0 * 100.0);
    assert_true(fabs(sc[point_at(0, 0, 0.7f)]) < 1e-5);
    assert_true(fabs(sc[point_at(0.7f, 0, 0)] - 2.0 * pow(1 - c, 3)) < 1e-5);
    assert_true(sc[point_at(0, 0, 0)] == 0);
    free(sc);
    game_shield_destroy(s);
}

/* Rim inside the shell: on a 4 x 4 x 4 grid (points at -0.7, -0.35, 0, 0.35, 0.7) with the
 * sphere of radius 0.4 round the origin, the interior point (0, 0, 0.35) is 0.05 inside the
 * sphere: shell weight 1 - 0.05 / (0.15 * 0.4) = 1/6. Its nearest boundary vertices in tet
 * edges all lie on the flat +z face (a neighbour differs by at most 0.35 per axis, and only
 * z can reach 0.7), whose vertex normals are exactly +z. With the eye at (100, 0, 0.35) the
 * view from the point is along +x: cos = 0, rim = gain / 6. The boundary vertex (0, 0, 0.7)
 * keeps its full term (cos = 0.35 / |(100, 0, -0.35)|); the centre, 2 edges in but 0.4 from
 * the sphere, gets nothing. Before the rim reached inside, the interior point got 0 and the
 * rim was a layer one tet thick (beaded along the silhouette). Float accumulation: 1e-5. */
static void test_rim_shell(void **state)
{
    (void)state;
    float *P, *sc0;
    uint32_t *T, np, nt;
    assert_int_equal(box_mesh(4, &P, &np, &T, &nt, &sc0), 0);
    game_shield *s;
    assert_int_equal(game_shield_create(P, np, T, nt, -100.f, &s), VFX_OK);
    rt_scene_volume_animation an = {.rim_gain = 2.0f, .rim_power = 3.0f};
    float *sc = calloc(np, sizeof *sc);
    game_shield_frame f = {.points = P, .eye = {100, 0, 0.35}, .center = {0, 0, 0}, .radius = 0.4f};
    game_shield_apply(s, &an, &f, sc);
    uint32_t inner = UINT32_MAX, outer = UINT32_MAX, centre = UINT32_MAX;
    for (uint32_t i = 0; i < np; ++i) {
        const float *p = &P[3 * i];
        if (fabsf(p[0]) < 1e-6f && fabsf(p[1]) < 1e-6f) {
            if (fabsf(p[2] - 0.35f) < 1e-6f)
                inner = i;
            else if (fabsf(p[2] - 0.7f) < 1e-6f)
                outer = i;
            else if (fabsf(p[2]) < 1e-6f)
                centre = i;
        }
    }
    assert_true(inner != UINT32_MAX && outer != UINT32_MAX && centre != UINT32_MAX);
    assert_true(fabs(sc[inner] - 2.0 / 6.0) < 1e-5);
    double c = 0.35 / sqrt(100.0 * 100.0 + 0.35 * 0.35);
    assert_true(fabs(sc[outer] - 2.0 * pow(1 - c, 3)) < 1e-5);
    assert_true(sc[centre] == 0);
    free(sc);
    game_shield_destroy(s);
    free(P);
    free(T);
    free(sc0);
}

/* Hit rings: a beam from a source at z = 5.5 to a head at z = 0.5 enters the sphere of radius
 * 0.7 round the origin at (0, 0, 0.7), a grid point: there the ring term at time t is
 * gain (1/2 + cos(-k speed t) / 2)^2 (r = 0), and at (0.7, 0, 0.7) (r = 0.7) it fades by
 * exp(-0.7 / reach); interior points far from the sphere get no ring. A beam pointing away from the sphere, far off, adds nothing. */
static void test_hit_ripple(void **state)
{
    (void)state;
    game_shield *s;
    assert_int_equal(game_shield_create(g_points, g_np, g_tets, g_nt, -100.f, &s), VFX_OK);
    rt_scene_volume_animation an = {.hit_gain = 1.5f, .hit_wavelength = 0.5f, .hit_speed = 1.0f, .hit_reach = 0.8f};
    vfx_beam b[2];
    memset(b, 0, sizeof b);
    b[0] = (vfx_beam){.type = VFX_TYPE_BEAM, .head = {0, 0, 0.5f}, .length = 5, .dir = {0, 0, 1}, .radius = 0.2f};
    b[1] = (vfx_beam){.type = VFX_TYPE_BEAM, .head = {9, 9, 9}, .length = 1, .dir = {1, 1, 1}, .radius = 0.2f};
    const double t = 0.3, k = 2 * M_PI / 0.5;
    float *sc = calloc(g_np, sizeof *sc);
    game_shield_frame f = {.points = g_points, .eye = {0, 0, 100}, .beams = b, .beam_count = 2, .time = t,
                           .center = {0, 0, 0}, .radius = 0.7f};
    game_shield_apply(s, &an, &f, sc);
    double ring0 = 0.5 + 0.5 * cos(-k * t), ring1 = 0.5 + 0.5 * cos(k * (0.7 - t));
    assert_true(fabs(sc[point_at(0, 0, 0.7f)] - 1.5 * ring0 * ring0) < 1e-5);
    assert_true(fabs(sc[point_at(0.7f, 0, 0.7f)] - 1.5 * ring1 * ring1 * exp(-0.7 / 0.8)) < 1e-5);
    /* the rings run in the shell: the centre, 0.7 from the strike like the point above (ring
     * 0.65 there) but a radius from the sphere, gets nothing (each ring was a spherical shell
     * through the volume, a haze) */
    assert_true(sc[point_at(0, 0, 0)] == 0);
    /* the far beam alone adds nothing */
    memset(sc, 0, g_np * sizeof *sc);
    f.beams = &b[1], f.beam_count = 1;
    game_shield_apply(s, &an, &f, sc);
    for (uint32_t i = 0; i < g_np; ++i)
        assert_true(sc[i] == 0);
    free(sc);
    game_shield_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_boundary_faces),
        cmocka_unit_test(test_rim),
        cmocka_unit_test(test_rim_shell),
        cmocka_unit_test(test_hit_ripple),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
