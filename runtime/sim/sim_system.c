/* sim_system.c — see sim_system.h. */
#include "sim/sim_system.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct rt_sim_system {
    rt_sph *sph;
    rt_particle_components pc;
    rt_sph_report report;
    /* import buffers (world order) */
    float *x, *y, *z, *vx, *vy, *vz;
    uint32_t cap;
    /* first global (query order) index of each visited table, to write back by id */
    uint32_t *table_base, *table_rows, *table_index;
    uint32_t table_cap;
    char err[512];
};

static vfx_result grow(rt_sim_system *s, uint32_t n)
{
    if (n <= s->cap)
        return VFX_OK;
    uint32_t cap = s->cap ? s->cap : 1024;
    while (cap < n)
        cap *= 2;
    float **b[] = {&s->x, &s->y, &s->z, &s->vx, &s->vy, &s->vz};
    for (int i = 0; i < 6; ++i) {
        float *p = realloc(*b[i], (size_t)cap * sizeof(float));
        if (!p) {
            snprintf(s->err, sizeof s->err, "vfx.sim.sph: out of memory importing %u particles", n);
            return VFX_ERR_OUT_OF_MEMORY;
        }
        *b[i] = p;
    }
    s->cap = cap;
    return VFX_OK;
}

static vfx_result grow_tables(rt_sim_system *s, uint32_t n)
{
    if (n <= s->table_cap)
        return VFX_OK;
    uint32_t cap = s->table_cap ? s->table_cap * 2 : 16;
    while (cap < n)
        cap *= 2;
    uint32_t **b[] = {&s->table_base, &s->table_rows, &s->table_index};
    for (int i = 0; i < 3; ++i) {
        uint32_t *p = realloc(*b[i], (size_t)cap * sizeof(uint32_t));
        if (!p)
            return VFX_ERR_OUT_OF_MEMORY;
        *b[i] = p;
    }
    s->table_cap = cap;
    return VFX_OK;
}

static vfx_result sim_run(rt_world *w, const rt_system_ctx *ctx)
{
    rt_sim_system *s = ctx->user;
    s->err[0] = 0;
    rt_component terms[3] = {s->pc.position, s->pc.velocity, s->pc.density};
    uint32_t n = rt_query_count(w, terms, 3);
    vfx_result r = grow(s, n);
    if (r)
        return r;
    /* import, remembering where each table starts in the global order */
    uint32_t k = 0, nt = 0;
    rt_query_iter it = rt_query_begin(w, terms, 3);
    while (rt_query_next(&it)) {
        if (grow_tables(s, nt + 1)) {
            snprintf(s->err, sizeof s->err, "vfx.sim.sph: out of memory");
            return VFX_ERR_OUT_OF_MEMORY;
        }
        s->table_base[nt] = k;
        s->table_rows[nt] = it.rows;
        s->table_index[nt] = it.table;
        nt++;
        const float *c[6] = {rt_query_column(&it, s->pc.position, 0), rt_query_column(&it, s->pc.position, 1),
                             rt_query_column(&it, s->pc.position, 2), rt_query_column(&it, s->pc.velocity, 0),
                             rt_query_column(&it, s->pc.velocity, 1), rt_query_column(&it, s->pc.velocity, 2)};
        float *d[6] = {s->x + k, s->y + k, s->z + k, s->vx + k, s->vy + k, s->vz + k};
        for (int f = 0; f < 6; ++f)
            memcpy(d[f], c[f], (size_t)it.rows * sizeof(float));
        k += it.rows;
    }
    /* Nothing changed since the last write-back (same count, every imported value the solver's
     * own, by id): keep the solver's state, and with it its Verlet lists and grid order (a
     * clear and add would force a rebuild every frame). Any edit, spawn or despawn re-imports. */
    rt_sph_columns c0 = rt_sph_get_columns(s->sph);
    bool same = k > 0 && c0.count == k;
    for (uint32_t i = 0; same && i < c0.count; ++i) {
        uint32_t id = c0.id[i];
        same = id < k && s->x[id] == c0.x[i] && s->y[id] == c0.y[i] && s->z[id] == c0.z[i] &&
               s->vx[id] == c0.vx[i] && s->vy[id] == c0.vy[i] && s->vz[id] == c0.vz[i];
    }
    if (!same) {
        rt_sph_clear(s->sph);
        r = rt_sph_add_particles(s->sph, k, s->x, s->y, s->z, s->vx, s->vy, s->vz);
        if (r) {
            snprintf(s->err, sizeof s->err, "vfx.sim.sph: %s", rt_sph_last_error(s->sph));
            return r;
        }
    }
    r = rt_sph_step(s->sph, ctx->dt, &s->report);
    if (r)
        snprintf(s->err, sizeof s->err, "vfx.sim.sph: %s", rt_sph_last_error(s->sph));
    /* write back (even after a numeric failure: the solver then holds the last good state,
     * which is finite). Solver rows are sorted by grid cell; id is the import index. */
    rt_sph_columns c = rt_sph_get_columns(s->sph);
    uint32_t t = 0;
    it = rt_query_begin(w, terms, 3);
    while (rt_query_next(&it) && t < nt) {
        /* same tables in the same order as the import (nothing structural happened between) */
        float *o[7] = {rt_query_column(&it, s->pc.position, 0), rt_query_column(&it, s->pc.position, 1),
                       rt_query_column(&it, s->pc.position, 2), rt_query_column(&it, s->pc.velocity, 0),
                       rt_query_column(&it, s->pc.velocity, 1), rt_query_column(&it, s->pc.velocity, 2),
                       rt_query_column(&it, s->pc.density, 0)};
        uint32_t base = s->table_base[t], rows = s->table_rows[t];
        const float *src[7] = {c.x, c.y, c.z, c.vx, c.vy, c.vz, c.density};
        for (uint32_t i = 0; i < c.count; ++i) {
            uint32_t id = c.id[i];
            if (id < base || id >= base + rows)
                continue;
            for (int f = 0; f < 7; ++f)
                o[f][id - base] = src[f][i];
        }
        t++;
    }
    /* particles the emitters made: new entities */
    uint32_t extra = c.count > k ? c.count - k : 0;
    if (extra && r == VFX_OK) {
        rt_entity *ids = malloc((size_t)extra * sizeof *ids);
        if (!ids)
            return VFX_ERR_OUT_OF_MEMORY;
        r = rt_world_spawn(w, extra, terms, 3, ids);
        if (!r) {
            for (uint32_t i = 0; i < c.count; ++i) {
                if (c.id[i] < k)
                    continue;
                rt_entity e = ids[c.id[i] - k];
                float vals[7] = {c.x[i], c.y[i], c.z[i], c.vx[i], c.vy[i], c.vz[i], c.density[i]};
                for (int f = 0; f < 7; ++f) {
                    float *p = rt_world_get(w, e, f < 3 ? s->pc.position : f < 6 ? s->pc.velocity : s->pc.density,
                                             (uint32_t)(f < 6 ? f % 3 : 0));
                    if (p)
                        *p = vals[f];
                }
            }
        } else {
            snprintf(s->err, sizeof s->err, "vfx.sim.sph: spawning %u emitted particles: %s", extra,
                     rt_world_last_error(w));
        }
        free(ids);
    }
    return r;
}

vfx_result rt_sim_system_create(rt_world *world, const rt_sph_desc *desc, rt_sim_system **out,
                                 char *err, size_t err_len)
{
    char dummy[8];
    if (!err || err_len == 0)
        err = dummy, err_len = sizeof dummy;
    err[0] = 0;
    if (!world || !out) {
        snprintf(err, err_len, "rt_sim_system_create: world and out are required");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    *out = NULL;
    rt_sim_system *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, err_len, "rt_sim_system_create: out of memory");
        return VFX_ERR_OUT_OF_MEMORY;
    }
    vfx_result r = rt_particles_register(world, &s->pc);
    if (r) {
        snprintf(err, err_len, "rt_sim_system_create: %s", rt_world_last_error(world));
        free(s);
        return r;
    }
    r = rt_sph_create(desc, &s->sph, err, err_len);
    if (r) {
        free(s);
        return r;
    }
    rt_component rw[3] = {s->pc.position, s->pc.velocity, s->pc.density};
    rt_system_desc sd = {.name = "vfx.sim.sph", .phase = RT_PHASE_SIMULATE, .reads = rw, .read_count = 3,
                          .writes = rw, .write_count = 3, .fn = sim_run, .user = s};
    r = rt_world_add_system(world, &sd);
    if (r) {
        snprintf(err, err_len, "rt_sim_system_create: %s", rt_world_last_error(world));
        rt_sim_system_destroy(s);
        return r;
    }
    *out = s;
    return VFX_OK;
}

void rt_sim_system_destroy(rt_sim_system *s)
{
    if (!s)
        return;
    rt_sph_destroy(s->sph);
    free(s->x), free(s->y), free(s->z), free(s->vx), free(s->vy), free(s->vz);
    free(s->table_base), free(s->table_rows), free(s->table_index);
    free(s);
}

rt_sph *rt_sim_system_solver(rt_sim_system *s) { return s ? s->sph : NULL; }
const rt_sph_report *rt_sim_system_report(const rt_sim_system *s) { return s ? &s->report : NULL; }
const char *rt_sim_system_last_error(const rt_sim_system *s) { return s ? s->err : "rt_sim_system is NULL"; }
