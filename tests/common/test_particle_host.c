/* test_particle_host.c — the one-chunk particle host of the water tests (test_particle_host.h). */
#include "test_particle_host.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

uint32_t test_particle_host_chunk_count(void *user) { return ((test_particle_host *)user)->n ? 1 : 0; }

vfx_result test_particle_host_chunk(void *user, uint32_t index, vfx_particle_view *out)
{
    test_particle_host *h = user;
    (void)index;
    out->count = h->n;
    out->pos[0] = h->x, out->pos[1] = h->y, out->pos[2] = h->z;
    out->vel[0] = h->vx, out->vel[1] = h->vy, out->vel[2] = h->vz;
    return VFX_OK;
}

vfx_result test_particle_host_water_params(void *user, vfx_water_params *out)
{
    test_particle_host *h = user;
    *out = h->params;
    out->type = VFX_TYPE_WATER_PARAMS;
    out->next = h->params_next;
    return VFX_OK;
}

vfx_context_desc test_particle_host_desc(test_particle_host *host)
{
    return (vfx_context_desc){.type = VFX_TYPE_CONTEXT_DESC, .gl_get_proc_address = test_gl_proc, .user = host,
                              .log = test_vfx_log_fn, .particle_chunk_count = test_particle_host_chunk_count,
                              .particle_chunk = test_particle_host_chunk,
                              .water_params = test_particle_host_water_params};
}

void test_particle_host_lattice(test_particle_host *h, uint32_t nx, uint32_t ny, uint32_t nz, float spacing,
                                const float origin[3], float jitter, uint32_t seed)
{
    h->n = nx * ny * nz;
    float **cols[] = {&h->x, &h->y, &h->z, &h->vx, &h->vy, &h->vz};
    for (int k = 0; k < 6; ++k) {
        *cols[k] = calloc(h->n, sizeof(float));
        assert_non_null(*cols[k]);
    }
    uint32_t i = 0;
    for (uint32_t a = 0; a < nx; ++a)
        for (uint32_t b = 0; b < ny; ++b)
            for (uint32_t c = 0; c < nz; ++c, ++i) {
                float j[3];
                for (int k = 0; k < 3; ++k) {
                    seed = seed * 1664525u + 1013904223u;
                    j[k] = ((float)(seed >> 8) / 16777216.0f - 0.5f) * jitter;
                }
                h->x[i] = spacing * (float)a + j[0] + origin[0];
                h->y[i] = spacing * (float)b + j[1] + origin[1];
                h->z[i] = spacing * (float)c + j[2] + origin[2];
            }
}

void test_particle_host_free(test_particle_host *h)
{
    float *cols[] = {h->x, h->y, h->z, h->vx, h->vy, h->vz};
    for (int k = 0; k < 6; ++k) free(cols[k]);
}

void test_frame_view_look(vfx_frame_view *fv, const float eye[3], float pitch)
{
    const float c = cosf(pitch), s = sinf(pitch);
    const float view[16] = {1, 0, 0, 0, 0, c, s, 0, 0, -s, c, 0,
                            -eye[0], -(c * eye[1] - s * eye[2]), -(s * eye[1] + c * eye[2]), 1};
    const float f = 1.0f / tanf(0.45f), nn = 0.05f, ff = 100.0f, asp = (float)fv->width / (float)fv->height;
    const float proj[16] = {f / asp, 0, 0, 0, 0, f, 0, 0, 0, 0, (ff + nn) / (nn - ff), -1, 0, 0, 2 * ff * nn / (nn - ff), 0};
    fv->fov_y = 0.9f, fv->near_plane = nn, fv->far_plane = ff;
    memcpy(fv->eye, eye, sizeof fv->eye);
    memcpy(fv->view, view, sizeof view);
    memcpy(fv->proj, proj, sizeof proj);
}

double test_stat(const vfx_plugin_api *api, vfx_context *ctx, const char *name)
{
    vfx_stats st = {.type = VFX_TYPE_STATS};
    assert_int_equal(api->get_stats(ctx, &st), VFX_OK);
    for (uint32_t k = 0; k < st.count; ++k)
        if (!strcmp(st.entries[k].name, name))
            return st.entries[k].value;
    return -1;
}
