/* The foam layer (plugin/water/water_foam.c, shaders/water/foam.comp; docs/water.md "Foam
 * layer") against closed forms, through the whole effect on a flat slab of fluid particles:
 *  - fade and spread: a Gaussian blob on water at rest keeps the mass M0 exp(-t / lifetime)
 *    and its variance grows by 2 D t per axis (D = diffusion x h^2), as the heat equation's;
 *  - drift: on water flowing uniformly at v the blob's centre moves by v t (and fades the same);
 *  - thin foam bursts: the fade dd/dt = -(d + FOAM_THIN) / lifetime ends a thin density in
 *    finite time while a thick one lasts (the blobs above are far thicker than FOAM_THIN);
 *  - gathering: the foam particles of one update deposit deposit x dt x h^2 each, centred on
 *    them, and nothing lands a texel away from every one of them.
 * Plus the layer off (the preset low, or vfx_water_foam.layer off) runs no pass, and the ranges. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <epoxy/gl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "debug.h"
#include "test_particle_host.h"
#include "water_test_session.h"
#include "test_util.h"
#include "water/water_effect.h"

#define H 0.1f
#define DT (1.0f / 60.0f)

/* the particles with velocities, one chunk; a test's vfx_water_foam chained as params_next */
typedef test_particle_host host;

typedef water_session session;

/* the camera looks at the slab from above and in front: the draws run too */
static void session_open(session *ss, host *h)
{
    const float eye[3] = {0.8f, 1.5f, 3.0f};
    water_session_open(ss, h, 32, 32, eye);
}

static void session_frame(session *ss) { water_session_frame(ss, DT); }

static double stat_of(session *ss, const char *name) { return water_session_stat(ss, name); }

static void session_close(session *ss) { water_session_close(ss); }

/* A flat slab of n x 3 x n particles at spacing h/2 from the origin, every one moving at
 * (ux, 0, uz). */
static host make_slab(uint32_t n, float ux, float uz)
{
    host s;
    memset(&s, 0, sizeof s);
    s.n = n * 3 * n;
    float **cols[] = {&s.x, &s.y, &s.z, &s.vx, &s.vy, &s.vz};
    for (int k = 0; k < 6; ++k)
        *cols[k] = malloc(s.n * sizeof(float));
    uint32_t i = 0;
    for (uint32_t a = 0; a < n; ++a)
        for (uint32_t b = 0; b < 3; ++b)
            for (uint32_t c = 0; c < n; ++c, ++i) {
                s.x[i] = 0.5f * H * a, s.y[i] = 0.5f * H * b, s.z[i] = 0.5f * H * c;
                s.vx[i] = ux, s.vy[i] = 0, s.vz[i] = uz;
            }
    s.params.type = VFX_TYPE_WATER_PARAMS;
    s.params.h = H;
    return s;
}

static void free_host(host *s) { test_particle_host_free(s); }

/* Mass (sum x cell^2), centre and variance (world x, z) of a density on the grid. */
typedef struct moments {
    double mass, cx, cz, vx, vz;
} moments;

static moments moments_of(const float *d, const volfx_water_foam_grid *g)
{
    double s = 0, sx = 0, sz = 0, sxx = 0, szz = 0;
    for (uint32_t j = 0; j < g->nz; ++j)
        for (uint32_t i = 0; i < g->nx; ++i) {
            double v = d[(size_t)j * g->nx + i], x = g->x0 + (i + 0.5) * g->cell, z = g->z0 + (j + 0.5) * g->cell;
            s += v, sx += v * x, sz += v * z, sxx += v * x * x, szz += v * z * z;
        }
    moments m = {s * g->cell * g->cell, sx / s, sz / s, 0, 0};
    m.vx = sxx / s - m.cx * m.cx;
    m.vz = szz / s - m.cz * m.cz;
    return m;
}

/* The blobs' peak density: far above foam.comp's FOAM_THIN (0.3), the floor below which thin foam
 * bursts, so that the fade of the blob's mass is the exponential's to < 1e-5 relative (the floor
 * takes at most FOAM_THIN (1 - e^-dt/lifetime) a texel an update: 0.3 x 0.63 over the grid's
 * ~6 m^2 in test_fade_and_spread, against a mass of 1e6 x 2 pi sigma^2 = 1.4e5). */
#define BLOB_PEAK 1.0e6
/* foam.comp's FOAM_THIN: the fade is dd/dt = -(d + FOAM_THIN) / lifetime, held at 0 */
#define FOAM_THIN 0.3

/* Runs a frame, wakes the layer, runs another (it makes its grid), then writes a Gaussian blob of standard
 * deviation sigma (world) and peak BLOB_PEAK at (bx, bz); returns the density buffer (the grid in *g). */
static float *start_blob(session *ss, volfx_water_foam_grid *g, float bx, float bz, float sigma)
{
    session_frame(ss); /* the effect exists after its first update */
    assert_int_equal(volfx_water_debug_foam_write(ss->ctx, NULL, 0), VFX_OK);
    session_frame(ss);
    assert_int_equal(volfx_water_debug_foam(ss->ctx, g, NULL, 0), VFX_OK);
    size_t n = (size_t)g->nx * g->nz;
    float *d = calloc(n, sizeof *d);
    for (uint32_t j = 0; j < g->nz; ++j)
        for (uint32_t i = 0; i < g->nx; ++i) {
            double x = g->x0 + (i + 0.5) * g->cell - bx, z = g->z0 + (j + 0.5) * g->cell - bz;
            d[(size_t)j * g->nx + i] = (float)(BLOB_PEAK * exp(-(x * x + z * z) / (2.0 * sigma * sigma)));
        }
    assert_int_equal(volfx_water_debug_foam_write(ss->ctx, d, n), VFX_OK);
    return d;
}

/* Fade and spread: water at rest, lifetime 0.5 s, diffusion 0.5 h^2 / s, 30 updates of 1/60 s. */
static void test_fade_and_spread(void **state)
{
    (void)state;
    host h = make_slab(32, 0, 0);
    vfx_water_foam foam = {.type = VFX_TYPE_WATER_FOAM, .lifetime = 0.5f, .diffusion = 0.5f};
    h.params_next = &foam;
    session ss;
    session_open(&ss, &h);
    volfx_water_foam_grid g;
    float sigma = 1.5f * H;
    float *d = start_blob(&ss, &g, 0.8f, 0.8f, sigma);
    moments m0 = moments_of(d, &g);
    const int N = 30;
    for (int k = 0; k < N; ++k)
        session_frame(&ss);
    assert_true(stat_of(&ss, "water.foam_active") == 1);
    assert_int_equal(volfx_water_debug_foam(ss.ctx, &g, d, (size_t)g.nx * g.nz), VFX_OK);
    moments m = moments_of(d, &g);
    double t = N * (double)DT, want = m0.mass * exp(-t / 0.5);
    double dvar = 2.0 * 0.5 * H * H * t; /* 2 D t, D = 0.5 h^2 / s */
    printf("  grid %u x %u, cell %.4f: mass %.6f -> %.6f (closed form %.6f, rel %.2e); variance x %.6f -> %.6f "
           "(+%.6f, closed form +%.6f), z +%.6f\n", g.nx, g.nz, g.cell, m0.mass, m.mass, want,
           fabs(m.mass / want - 1), m0.vx, m.vx, m.vx - m0.vx, dvar, m.vz - m0.vz);
    /* the decay is exp(-dt / lifetime) each update, exactly, but for the thin-foam floor (below
     * 1e-5 relative at BLOB_PEAK); the 5-point diffusion keeps the mass
     * and adds 2 k cell^2 = 2 D dt to the variance each update, exactly, away from the edges (the
     * blob's tail at the grid's edge is below 1e-12 here). What is left is float32: 1e-4 relative
     * is 30 updates of a few ulps over some thousand texels with a wide margin. */
    assert_true(fabs(m.mass / want - 1) < 1e-4);
    assert_true(fabs((m.vx - m0.vx) / dvar - 1) < 1e-3);
    assert_true(fabs((m.vz - m0.vz) / dvar - 1) < 1e-3);
    /* it stays where it was */
    assert_true(fabs(m.cx - m0.cx) < 1e-4 * g.cell && fabs(m.cz - m0.cz) < 1e-4 * g.cell);
    free(d);
    session_close(&ss);
    free_host(&h);
}

/* Drift: the water flows at (0.6, 0, -0.3) m/s; the blob's centre moves by v t. */
static void test_drift(void **state)
{
    (void)state;
    const float ux = 0.6f, uz = -0.3f;
    host h = make_slab(40, ux, uz);
    /* the slab's leading edges would be wave crests: an energy range far above the flow's keeps
     * every particle from generating (foam there would add to the blob) */
    h.params.energy[0] = 50.0f, h.params.energy[1] = 100.0f;
    vfx_water_foam foam = {.type = VFX_TYPE_WATER_FOAM, .lifetime = 2.0f, .diffusion = 1e-6f};
    h.params_next = &foam;
    session ss;
    session_open(&ss, &h);
    volfx_water_foam_grid g;
    float *d = start_blob(&ss, &g, 0.6f, 1.3f, 1.5f * H);
    moments m0 = moments_of(d, &g);
    const int N = 40;
    for (int k = 0; k < N; ++k)
        session_frame(&ss);
    assert_true(stat_of(&ss, "water.diffuse_generated") == 0); /* a uniform flow: no particle */
    assert_int_equal(volfx_water_debug_foam(ss.ctx, &g, d, (size_t)g.nx * g.nz), VFX_OK);
    moments m = moments_of(d, &g);
    double t = N * (double)DT, want = m0.mass * exp(-t / 2.0);
    printf("  moved (%.5f, %.5f), closed form (%.5f, %.5f); mass rel %.2e\n", m.cx - m0.cx, m.cz - m0.cz, ux * t,
           uz * t, fabs(m.mass / want - 1));
    /* bilinear semi-Lagrangian steps by a constant offset keep the mass and move the centre by
     * exactly v dt each (they only widen the blob). The flow's velocity is the fixed point mean,
     * exact to 0.5 / 4096 v_ref = 1.2e-4 m/s (v_ref = sqrt(9.81 h) ~ 1 m/s): 8e-5 m over 0.67 s;
     * float32 on coordinates ~1 adds ulps of 1e-7 per update: 2e-4 m is both with room. */
    assert_true(fabs(m.cx - m0.cx - ux * t) < 2e-4);
    assert_true(fabs(m.cz - m0.cz - uz * t) < 2e-4);
    assert_true(fabs(m.mass / want - 1) < 1e-4);
    free(d);
    session_close(&ss);
    free_host(&h);
}

/* Thin foam bursts: on water at rest (diffusion at its least), half the grid at density 1 and half
 * at 0.2; after 30 updates of 1/60 s with lifetime 0.5 s, each texel follows the discrete fade
 * d_n + FOAM_THIN = (d_0 + FOAM_THIN) e^(-n dt / lifetime) held at 0: the thick half keeps
 * 1.3 e^-1 - 0.3 = 0.178 (a pure exponential: 0.368), the thin half is gone (0.2 lasts
 * 0.5 ln(1 + 0.2 / 0.3) = 0.26 s; a pure exponential keeps 0.074). */
static void test_thin_foam_bursts(void **state)
{
    (void)state;
    host h = make_slab(32, 0, 0);
    const float life = 0.5f;
    vfx_water_foam foam = {.type = VFX_TYPE_WATER_FOAM, .lifetime = life, .diffusion = 1e-6f};
    h.params_next = &foam;
    session ss;
    session_open(&ss, &h);
    session_frame(&ss);
    assert_int_equal(volfx_water_debug_foam_write(ss.ctx, NULL, 0), VFX_OK);
    session_frame(&ss);
    volfx_water_foam_grid g;
    assert_int_equal(volfx_water_debug_foam(ss.ctx, &g, NULL, 0), VFX_OK);
    size_t n = (size_t)g.nx * g.nz;
    float *d = calloc(n, sizeof *d);
    for (uint32_t j = 0; j < g.nz; ++j)
        for (uint32_t i = 0; i < g.nx; ++i)
            d[(size_t)j * g.nx + i] = i < g.nx / 2 ? 1.0f : 0.2f;
    assert_int_equal(volfx_water_debug_foam_write(ss.ctx, d, n), VFX_OK);
    const int N = 30;
    for (int k = 0; k < N; ++k)
        session_frame(&ss);
    assert_int_equal(volfx_water_debug_foam(ss.ctx, &g, d, n), VFX_OK);
    /* the discrete fade of each update, in float64: (d + thin) e^-dt/life - thin, at 0 or above */
    double thick = 1.0, thin = 0.2, keep = exp(-(double)DT / life);
    for (int k = 0; k < N; ++k) {
        thick = fmax((thick + FOAM_THIN) * keep - FOAM_THIN, 0.0);
        thin = fmax((thin + FOAM_THIN) * keep - FOAM_THIN, 0.0);
    }
    /* texels a quarter of the grid from the step and from the edges: the diffusion's reach over
     * 30 updates (k = 1e-6 h^2 dt / cell^2 an update) is nil there */
    uint32_t j = g.nz / 2, ia = g.nx / 4, ib = 3 * g.nx / 4;
    float a = d[(size_t)j * g.nx + ia], b = d[(size_t)j * g.nx + ib];
    printf("  after %d updates: thick %.6f (closed form %.6f), thin %.6f (closed form %.6f)\n", N, a, thick, b, thin);
    /* float32 over 30 updates of a multiply-add near 1: a few ulps each, 1e-5 with margin */
    assert_true(fabs(a - thick) < 1e-5);
    assert_true(thin == 0.0 && b == 0.0f);
    free(d);
    session_close(&ss);
    free_host(&h);
}

/* A slab whose top layers rise and shear (test_water_diffuse's field): foam particles appear. */
static host make_churn(void)
{
    host s = make_slab(24, 0, 0);
    for (uint32_t i = 0; i < s.n; ++i) {
        float top = s.y[i] / (H);
        s.vx[i] = 2.5f * sinf(9.0f * s.x[i] + 4.0f * s.z[i]);
        s.vy[i] = 3.5f * top * top * (1.0f + 0.5f * sinf(11.0f * s.x[i]));
        s.vz[i] = 0.7f * cosf(5.0f * s.z[i] - 2.0f * s.x[i]);
    }
    s.params.trapped_air[0] = 1.5f, s.params.trapped_air[1] = 6.0f;
    s.params.wave_crest[0] = 0.3f, s.params.wave_crest[1] = 1.5f;
    s.params.energy[0] = 0.5f, s.params.energy[1] = 4.0f;
    s.params.rate_trapped_air = 40.0f, s.params.rate_wave_crest = 60.0f;
    s.params.spray_below = 2, s.params.bubble_above = 60; /* most of them foam */
    return s;
}

/* Gathering: the layer zeroed, one update: its density is the foam particles' deposit alone. */
static void test_gathers_where_deposited(void **state)
{
    (void)state;
    host h = make_churn();
    const float dep = 3.0f;
    vfx_water_foam foam = {.type = VFX_TYPE_WATER_FOAM, .deposit = dep};
    h.params_next = &foam;
    session ss;
    session_open(&ss, &h);
    for (int k = 0; k < 8; ++k)
        session_frame(&ss);
    volfx_water_foam_grid g;
    assert_int_equal(volfx_water_debug_foam(ss.ctx, &g, NULL, 0), VFX_OK);
    size_t n = (size_t)g.nx * g.nz;
    float *d = calloc(n, sizeof *d);
    assert_int_equal(volfx_water_debug_foam_write(ss.ctx, d, n), VFX_OK);
    session_frame(&ss);
    uint32_t alive = 0;
    assert_int_equal(volfx_water_debug_diffuse(ss.ctx, NULL, 0, NULL, 0, &alive), VFX_OK);
    float *pool = calloc((size_t)alive * 8 + 8, sizeof *pool);
    assert_int_equal(volfx_water_debug_diffuse(ss.ctx, NULL, 0, pool, alive, &alive), VFX_OK);
    volfx_water_foam_grid g2;
    assert_int_equal(volfx_water_debug_foam(ss.ctx, &g2, d, n), VFX_OK);
    assert_true(g2.nx == g.nx && g2.nz == g.nz && g2.x0 == g.x0 && g2.z0 == g.z0);
    /* the foam particles' count, centre, and a map of the texels within one texel of one */
    uint32_t nf = 0;
    double sx = 0, sz = 0;
    uint8_t *near = calloc(n, 1);
    for (uint32_t i = 0; i < alive; ++i) {
        const float *q = pool + 8 * (size_t)i;
        if ((uint32_t)q[7] != 1u)
            continue;
        ++nf, sx += q[0], sz += q[2];
        int ci = (int)floor((q[0] - g.x0) / g.cell), cj = (int)floor((q[2] - g.z0) / g.cell);
        for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di)
                if (ci + di >= 0 && cj + dj >= 0 && ci + di < (int)g.nx && cj + dj < (int)g.nz)
                    near[(size_t)(cj + dj) * g.nx + (size_t)(ci + di)] = 1;
    }
    moments m = moments_of(d, &g);
    double want = nf * (double)dep * DT * H * H;
    size_t stray = 0;
    for (size_t k = 0; k < n; ++k)
        stray += d[k] != 0 && !near[k];
    printf("  %u foam particles of %u: mass %.6e (closed form %.6e, rel %.2e), centre (%.5f, %.5f) against "
           "theirs (%.5f, %.5f), %zu texels away from every one\n", nf, alive, m.mass, want, fabs(m.mass / want - 1),
           m.cx, m.cz, nf ? sx / nf : 0, nf ? sz / nf : 0, stray);
    assert_true(nf >= 20);
    /* fixed point: each of a particle's 4 shares is rounded to 1/65536 of a density, against a
     * share of dep dt h^2 / cell^2 = 0.2 here: 4 x 0.5 / 65536 / 0.2 = 1.5e-4 relative at worst */
    assert_true(fabs(m.mass / want - 1) < 1.6e-4);
    /* the bilinear shares put each particle's mass at its own position: the centre is theirs, to
     * the same rounding (1.5e-4 of the spread, ~0.5 m, plus float32) */
    assert_true(fabs(m.cx - sx / nf) < 1e-4 && fabs(m.cz - sz / nf) < 1e-4);
    assert_true(stray == 0);
    free(near);
    free(pool);
    free(d);
    session_close(&ss);
    free_host(&h);
}

/* Off: the preset low and vfx_water_foam.layer off run no foam pass (the foam particles are drawn
 * one by one); an out-of-range field is refused by name. */
static void test_off_and_ranges(void **state)
{
    (void)state;
    for (int v = 0; v < 2; ++v) {
        host h = make_churn();
        vfx_water_foam foam = {.type = VFX_TYPE_WATER_FOAM, .layer = VFX_WATER_FOAM_OFF};
        if (v == 0)
            h.params.preset = VFX_WATER_PRESET_LOW;
        else
            h.params_next = &foam;
        session ss;
        session_open(&ss, &h);
        for (int k = 0; k < 6; ++k)
            session_frame(&ss);
        assert_true(stat_of(&ss, "water.diffuse_foam") > 0);
        assert_true(stat_of(&ss, "water.foam_active") <= 0); /* never set, or 0 */
        assert_int_equal(volfx_water_debug_foam(ss.ctx, &(volfx_water_foam_grid){0}, NULL, 0), VFX_ERR_NOT_FOUND);
        session_close(&ss);
        free_host(&h);
    }
    host h = make_slab(8, 0, 0);
    vfx_water_foam foam = {.type = VFX_TYPE_WATER_FOAM, .lifetime = 0.01f};
    h.params_next = &foam;
    session ss;
    session_open(&ss, &h);
    assert_int_not_equal(ss.api.update(ss.ctx, 0.0, DT), VFX_OK);
    vfx_log_id id = VFX_LOG_ID_NONE;
    const char *msg = ss.api.last_error(ss.ctx, &id);
    print_message("refused: %s\n", msg);
    assert_non_null(strstr(msg, "vfx_water_foam.lifetime"));
    assert_int_equal(id, VFX_LOG_ID_PARAM_RANGE);
    session_close(&ss);
    free_host(&h);
}

int main(void)
{
    rt_gl_context *gl = test_gl_or_skip();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fade_and_spread),
        cmocka_unit_test(test_drift),
        cmocka_unit_test(test_thin_foam_bursts),
        cmocka_unit_test(test_gathers_where_deposited),
        cmocka_unit_test(test_off_and_ranges),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    rt_gl_context_destroy(gl);
    return rc;
}
