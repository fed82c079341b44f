/* pbf_cases.c — see pbf_cases.h. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>

#include "pbf_cases.h"

rt_sph *pbf_make(rt_sph_desc d)
{
    rt_sph *s = NULL;
    char err[256];
    d.solver = RT_SPH_SOLVER_PBF;
    vfx_result r = rt_sph_create(&d, &s, err, sizeof err);
    if (r)
        fprintf(stderr, "create: %s\n", err);
    assert_int_equal(r, VFX_OK);
    return s;
}

rt_sph_desc pbf_small_box(uint32_t threads)
{
    rt_sph_desc d = {.spacing = 0.01f, .domain_min = {0, 0, 0}, .domain_max = {0.1f, 0.2f, 0.06f}, .threads = threads};
    return d;
}

rt_sph *pbf_case_one_point(uint32_t threads)
{
    rt_sph *s = pbf_make(pbf_small_box(threads));
    enum { N = 300 };
    float x[N], y[N], z[N];
    for (int i = 0; i < N; ++i)
        x[i] = 0.05f, y[i] = 0.1f, z[i] = 0.03f;
    assert_int_equal(rt_sph_add_particles(s, N, x, y, z, NULL, NULL, NULL, NULL, 0), VFX_OK);
    return s;
}

rt_sph *pbf_case_speed_cap(uint32_t threads)
{
    rt_sph_desc d = pbf_small_box(threads);
    d.velocity_limit = 1.f;
    rt_sph *s = pbf_make(d);
    float x[3] = {0.02f, 0.05f, 0.08f}, y[3] = {0.1f, 0.1f, 0.1f}, z[3] = {0.03f, 0.03f, 0.03f};
    float vy[3] = {0.f, 0.f, -50.f};
    assert_int_equal(rt_sph_add_particles(s, 3, x, y, z, NULL, vy, NULL, NULL, 0), VFX_OK);
    return s;
}

rt_sph *pbf_case_thin_wall(uint32_t threads)
{
    rt_sph_desc d = {.spacing = 0.01f, .domain_min = {0, 0, 0}, .domain_max = {0.2f, 0.3f, 0.04f}, .threads = threads};
    rt_sph *s = pbf_make(d);
    rt_sph_collider wall = {.kind = RT_SPH_BOX, .center = {0.1f, 0.08f, 0.02f}, .half = {0.3f, 0.005f, 0.3f}};
    /* wider than the domain: its nearest face is always the top or the bottom */
    assert_int_equal(rt_sph_add_collider(s, &wall, NULL, NULL, 0), VFX_OK);
    float lo[3] = {0.06f, 0.15f, 0}, hi[3] = {0.14f, 0.28f, 0.04f};
    assert_int_equal(rt_sph_add_block(s, lo, hi, NULL, NULL, 0), VFX_OK);
    return s;
}

rt_sph *pbf_case_pool(uint32_t threads)
{
    rt_sph_desc d = {.spacing = 0.02f, .domain_min = {0, 0, 0}, .domain_max = {0.6f, 0.4f, 0.3f}, .threads = threads};
    rt_sph *s = pbf_make(d);
    float lo[3] = {0, 0, 0}, hi[3] = {0.6f, 0.12f, 0.3f};
    assert_int_equal(rt_sph_add_block(s, lo, hi, NULL, NULL, 0), VFX_OK);
    return s;
}
