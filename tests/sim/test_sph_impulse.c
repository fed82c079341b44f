/* A beam striking the water (docs/simulation.md "Impacts"): rt_sph_impulse on a settled pool.
 * The particles near the hit gain velocity away from it, water is thrown up above the surface
 * within a few frames (what the water effect's diffuse particles turn into spray), and the
 * largest speed stays bounded while the impulse repeats every frame (a beam held on the water). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim/sph.h"

#define DX 0.02f
#define TOP 0.14f /* the pool's surface before settling */

static rt_sph *pool(void)
{
    rt_sph_desc d = {.spacing = DX, .domain_min = {0, 0, 0}, .domain_max = {0.4f, 0.4f, 0.4f}, .threads = 2,
                     .solver = RT_SPH_SOLVER_PBF};
    rt_sph *s = NULL;
    char err[256];
    assert_int_equal(rt_sph_create(&d, &s, err, sizeof err), VFX_OK);
    float lo[3] = {0.01f, 0.01f, 0.01f}, hi[3] = {0.39f, TOP, 0.39f};
    assert_int_equal(rt_sph_add_block(s, lo, hi, NULL, err, sizeof err), VFX_OK);
    assert_int_equal(rt_sph_settle(s, NULL, NULL, err, sizeof err), VFX_OK);
    return s;
}

static float surface_y(rt_sph *s)
{
    rt_sph_columns c = rt_sph_get_columns(s);
    float top = 0;
    for (uint32_t i = 0; i < c.count; ++i)
        top = fmaxf(top, c.y[i]);
    return top;
}

static float max_speed(rt_sph *s)
{
    rt_sph_columns c = rt_sph_get_columns(s);
    float m = 0;
    for (uint32_t i = 0; i < c.count; ++i) {
        float v = sqrtf(c.vx[i] * c.vx[i] + c.vy[i] * c.vy[i] + c.vz[i] * c.vz[i]);
        assert_true(isfinite(v));
        m = fmaxf(m, v);
    }
    return m;
}

static void test_impulse_pushes_away_and_splashes(void **state)
{
    (void)state;
    rt_sph *s = pool();
    const float speed = 4.0f, radius = 0.08f, dir[3] = {0.3f, -1, 0};
    float top = surface_y(s), hit[3] = {0.2f, top, 0.2f};
    rt_sph_columns c = rt_sph_get_columns(s);
    /* the particles near the hit, by id (steps reorder the rows) */
    uint32_t n = c.count, *near = calloc(n, sizeof *near), nn = 0;
    for (uint32_t i = 0; i < n; ++i) {
        float o[3] = {c.x[i] - hit[0], c.y[i] - hit[1], c.z[i] - hit[2]};
        if (sqrtf(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]) < 0.5f * radius)
            near[c.id[i]] = 1, nn++;
    }
    assert_true(nn >= 5);
    float before = max_speed(s);
    uint32_t pushed = rt_sph_impulse(s, hit, dir, radius, speed);
    printf("settled pool of %u, surface at %.3f m, max speed %.3f m/s; impulse pushed %u (%u within radius/2)\n", n,
           top, before, pushed, nn);
    assert_true(pushed >= nn);
    assert_true(max_speed(s) <= before + speed); /* the stated bound of one impulse */
    /* bad input changes nothing */
    assert_int_equal(rt_sph_impulse(s, hit, dir, -1.f, speed), 0);
    assert_int_equal(rt_sph_impulse(s, hit, dir, radius, NAN), 0);
    assert_int_equal(rt_sph_impulse(s, (float[3]){NAN, 0, 0}, dir, radius, speed), 0);

    rt_sph_report rep;
    char err[256];
    assert_int_equal(rt_sph_step(s, 1.f / 60, &rep, err, sizeof err), VFX_OK);
    c = rt_sph_get_columns(s);
    /* after a frame: the particles that were near the hit move away from it */
    double out_sum = 0;
    uint32_t out_pos = 0;
    for (uint32_t i = 0; i < c.count; ++i) {
        if (!near[c.id[i]])
            continue;
        float o[3] = {c.x[i] - hit[0], c.y[i] - hit[1], c.z[i] - hit[2]};
        float r = sqrtf(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
        float vr = r > 0 ? (c.vx[i] * o[0] + c.vy[i] * o[1] + c.vz[i] * o[2]) / r : 0;
        out_sum += vr;
        out_pos += vr > 0;
    }
    printf("after one frame: mean speed away from the hit %.3f m/s, %u of %u moving away\n", out_sum / nn, out_pos, nn);
    assert_true(out_sum / nn > 0.2 * speed);
    assert_true(out_pos >= 3 * nn / 4);
    /* a beam held on the water: the impulse every frame; water is thrown above the surface within
     * a few frames, and the largest speed stays bounded */
    float vmax = 0;
    int thrown_at = -1;
    for (int f = 0; f < 30; ++f) {
        rt_sph_impulse(s, hit, dir, radius, speed);
        assert_int_equal(rt_sph_step(s, 1.f / 60, &rep, err, sizeof err), VFX_OK);
        vmax = fmaxf(vmax, max_speed(s));
        if (getenv("IMPULSE_TRACE")) printf("frame %d top %.3f vmax %.3f\n", f, surface_y(s), max_speed(s));
        if (thrown_at < 0 && surface_y(s) > top + 3 * DX)
            thrown_at = f + 2;
    }
    printf("held 30 frames: water thrown 3 spacings above the surface at frame %d, largest speed %.3f m/s\n",
           thrown_at, vmax);
    assert_true(thrown_at > 0 && thrown_at <= 6);
    /* bound: the impulse keeps each particle's component along its push at most speed; gravity and
     * the fluid's pressure add what a fall through the pool's height gives, sqrt(2 g 0.4) = 2.8 */
    assert_true(vmax <= speed + 2.8f);
    free(near);
    rt_sph_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_impulse_pushes_away_and_splashes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
