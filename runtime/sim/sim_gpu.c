/* sim_gpu.c — see sim_gpu.h. */
#include "sim/sim_gpu.h"
#include "core/error.h"

#include <stdlib.h>
#include <string.h>

struct rt_sim_gpu {
    rt_sph_gpu *gpu;
    uint64_t revision; /* of the view: one more per step */
};

static vfx_result dev_start(void *user, rt_sph *sph, char *err, size_t errlen)
{
    rt_sim_gpu *g = user;
    if (g->gpu)
        return VFX_OK;
    return rt_sph_gpu_create(sph, NULL, &g->gpu, err, errlen);
}

static vfx_result dev_step(void *user, float dt, rt_sph_report *rep, char *err, size_t errlen)
{
    rt_sim_gpu *g = user;
    g->revision++;
    return rt_sph_gpu_step(g->gpu, dt, rep, err, errlen);
}

static vfx_result dev_settle(void *user, const rt_sph_settle_desc *d, rt_sph_settle_report *rep, char *err,
                             size_t errlen)
{
    rt_sim_gpu *g = user;
    g->revision++;
    return rt_sph_gpu_settle(g->gpu, d, rep, err, errlen);
}

static void dev_impulse(void *user, const float c[3], const float dir[3], float radius, float speed)
{
    rt_sim_gpu *g = user;
    rt_sph_gpu_impulse(g->gpu, c, dir, radius, speed);
}

static void dev_destroy(void *user)
{
    rt_sim_gpu *g = user;
    rt_sph_gpu_destroy(g->gpu);
    free(g);
}

vfx_result rt_sim_gpu_attach(rt_sim_system *sys, rt_sim_gpu **out, char *err, size_t errlen)
{
    if (!sys || !out)
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sim_gpu_attach: sys and out are required");
    rt_sim_gpu *g = calloc(1, sizeof *g);
    if (!g)
        return rt_errf(err, errlen, VFX_ERR_OUT_OF_MEMORY, "rt_sim_gpu_attach: out of memory");
    rt_sim_device d = {.user = g, .id = 1, .start = dev_start, .step = dev_step, .settle = dev_settle,
                       .impulse = dev_impulse, .destroy = dev_destroy};
    vfx_result r = rt_sim_system_set_device(sys, &d);
    if (r) {
        free(g);
        return rt_errf(err, errlen, r, "rt_sim_gpu_attach: the system has run already");
    }
    *out = g;
    return VFX_OK;
}

bool rt_sim_gpu_view(const rt_sim_gpu *g, vfx_particle_view *out)
{
    if (!g || !g->gpu || !out)
        return false;
    memset(out, 0, sizeof *out);
    out->type = VFX_TYPE_PARTICLE_VIEW;
    rt_sph_gpu_columns(g->gpu, &out->gpu_pos, &out->gpu_vel, &out->count);
    out->revision = g->revision + 1;
    return true;
}

