/* test_particle_host.h — the water tests' one-chunk particle host: n particles as x, y, z columns
 * (and velocity columns when vx is set) handed to the plugin as a single chunk, read in place, and
 * the water parameters it hands as they are. A test with more to hand (beams, a volume, GPU
 * columns) puts a test_particle_host first in its own host struct and adds its callbacks. */
#ifndef TEST_PARTICLE_HOST_H
#define TEST_PARTICLE_HOST_H

#include <stdint.h>

#include "test_util.h"
#include "volfx/volfx.h"

typedef struct test_particle_host {
    test_log log;               /* first: test_vfx_log_fn takes the user pointer for a test_log */
    uint32_t n;                 /* 0: no chunk */
    float *x, *y, *z;           /* the positions */
    float *vx, *vy, *vz;        /* the velocities, or NULL: no velocity columns */
    vfx_water_params params;    /* handed as they are (their next is params_next) */
    const void *params_next;    /* chained to the parameters (vfx_water_foam, vfx_lab_water) or NULL */
} test_particle_host;

/* vfx_context_desc.particle_chunk_count: 1 while the host has particles, else 0. */
uint32_t test_particle_host_chunk_count(void *user);
/* vfx_context_desc.particle_chunk: the one chunk, its position and velocity columns. */
vfx_result test_particle_host_chunk(void *user, uint32_t index, vfx_particle_view *out);
/* vfx_context_desc.water_params: the host's parameters with params_next chained. */
vfx_result test_particle_host_water_params(void *user, vfx_water_params *out);
/* The context description of a particle host (user = the host, its log, the headless GL
 * context's loader, the three callbacks above); a test adds its own callbacks to it. */
vfx_context_desc test_particle_host_desc(test_particle_host *host);
/* nx x ny x nz particles on a lattice of `spacing` from `origin`, particle (a, b, c) at index
 * (a * ny + b) * nz + c, each coordinate moved by (u - 0.5) x jitter with u uniform in [0, 1)
 * from a linear congruential sequence started at `seed`; the six columns allocated, the
 * velocities zeroed. */
void test_particle_host_lattice(test_particle_host *h, uint32_t nx, uint32_t ny, uint32_t nz, float spacing,
                                const float origin[3], float jitter, uint32_t seed);
/* Frees the six columns. */
void test_particle_host_free(test_particle_host *h);
/* A camera for fv (its width and height set): at `eye`, looking down -z tilted down by `pitch`
 * radians, a vertical field of view of 0.9 rad, near 0.05, far 100; fills fov_y, the planes,
 * eye, view and proj. */
void test_frame_view_look(vfx_frame_view *fv, const float eye[3], float pitch);
/* The value of the stat `name` from get_stats, or -1 when the plugin reports none. */
double test_stat(const vfx_plugin_api *api, vfx_context *ctx, const char *name);

#endif
