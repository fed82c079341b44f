/* sph_storage.c — the particle columns: growth, adding particles, the views the API hands out. */
#include "sim/sph_internal.h"

#include <stdlib.h>
#include <string.h>

/* The state columns (the host's while bound) and the solver's scratch columns. */
#define SPH_STATE_COLUMNS(s) {&s->x, &s->y, &s->z, &s->vx, &s->vy, &s->vz, &s->rho}
#define SPH_SCRATCH_COLUMNS(s)                                                                     \
    {&s->pr, &s->ax, &s->ay, &s->az, &s->drho, &s->xn, &s->yn, &s->zn, &s->vxn, &s->vyn, &s->vzn, \
     &s->tmp, &s->x0, &s->y0, &s->z0}

/* Frees the own state columns (none while bound: those are the host's) and forgets them. */
static void drop_state(rt_sph *s)
{
    float **f[] = SPH_STATE_COLUMNS(s);
    for (size_t i = 0; i < sizeof f / sizeof f[0]; ++i) {
        if (!s->bound)
            free(*f[i]);
        *f[i] = NULL;
    }
    s->state_cap = 0;
}

void rt_sph_free_columns(rt_sph *s)
{
    drop_state(s);
    float **f[] = SPH_SCRATCH_COLUMNS(s);
    for (size_t i = 0; i < sizeof f / sizeof f[0]; ++i) {
        free(*f[i]);
        *f[i] = NULL;
    }
    free(s->id), free(s->idtmp), free(s->key), free(s->perm), free(s->nb_start), free(s->nb_count);
    free(s->sk_start), free(s->sk_count);
    s->id = s->idtmp = s->key = s->perm = s->nb_start = s->nb_count = NULL;
    s->sk_start = s->sk_count = NULL;
    for (uint32_t c = 0; c < s->cnb_chunks; ++c) {
        free(s->cnb[c]);
        if (s->snb)
            free(s->snb[c]);
    }
    free(s->cnb), free(s->cnb_cap), free(s->snb), free(s->snb_cap), free(s->snb_used);
    s->cnb = NULL, s->cnb_cap = NULL, s->cnb_chunks = 0;
    s->snb = NULL, s->snb_cap = NULL, s->snb_used = NULL;
    s->lists_valid = false;
    rt_sph_pbf_lin_free(s);
}

size_t rt_sph_memory_bytes(const rt_sph *s)
{
    if (!s)
        return 0;
    size_t lists = 0;
    for (uint32_t c = 0; c < s->cnb_chunks; ++c)
        lists += ((size_t)s->cnb_cap[c] + s->snb_cap[c]) * sizeof(uint32_t) + 3 * sizeof(uint32_t) +
                 2 * sizeof(uint32_t *);
    size_t scratch = (size_t)s->cap * (15 * sizeof(float) + 8 * sizeof(uint32_t));
    return sizeof *s + lists + scratch + rt_sph_pbf_lin_bytes(s) + (size_t)s->state_cap * 7 * sizeof(float) +
           ((size_t)s->ncells + 1) * sizeof(uint32_t) + (size_t)s->out_cap * sizeof(sph_chunk_out);
}

float rt_sph_pressure(const rt_sph *s, uint32_t i)
{
    if (!s || i >= s->n)
        return 0.f;
    if (s->p.solver == RT_SPH_SOLVER_PBF)
        return s->pr[i]; /* PBF keeps the pressure itself */
    return s->pr[i] * s->rho[i] * s->rho[i];
}

rt_sph_columns rt_sph_get_columns(rt_sph *s)
{
    if (!s)
        return (rt_sph_columns){0};
    return (rt_sph_columns){s->n, s->x, s->y, s->z, s->vx, s->vy, s->vz, s->rho, s->id};
}

vfx_result rt_sph_reserve(rt_sph *s, uint64_t want, char *err, size_t errlen)
{
    if (want > s->p.max_particles) {
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph: %llu particles requested, capacity bound is %u (desc.max_particles)",
                (unsigned long long)want, s->p.max_particles);
    }
    if (want <= s->cap && (s->bound || want <= s->state_cap))
        return VFX_OK;
    uint64_t cap = s->cap ? s->cap : 1024;
    while (cap < want)
        cap *= 2;
    if (cap > s->p.max_particles)
        cap = s->p.max_particles;
    if (!s->bound && s->state_cap < cap) {
        float **f[] = SPH_STATE_COLUMNS(s);
        for (size_t i = 0; i < sizeof f / sizeof f[0]; ++i) {
            float *np = realloc(*f[i], (size_t)cap * sizeof(float));
            if (!np)
                goto oom;
            *f[i] = np;
        }
        s->state_cap = (uint32_t)cap;
    }
    if (cap == s->cap)
        return VFX_OK;
    float **f[] = SPH_SCRATCH_COLUMNS(s);
    for (size_t i = 0; i < sizeof f / sizeof f[0]; ++i) {
        float *np = realloc(*f[i], (size_t)cap * sizeof(float));
        if (!np)
            goto oom;
        *f[i] = np;
    }
    uint32_t **u[] = {&s->id, &s->idtmp, &s->key, &s->perm, &s->nb_start, &s->nb_count,
                      &s->sk_start, &s->sk_count};
    for (size_t i = 0; i < sizeof u / sizeof u[0]; ++i) {
        uint32_t *np = realloc(*u[i], (size_t)cap * sizeof(uint32_t));
        if (!np)
            goto oom;
        *u[i] = np;
    }
    uint32_t chunks = (uint32_t)((cap + SPH_CHUNK - 1) / SPH_CHUNK);
    sph_chunk_out *no = realloc(s->out, (size_t)chunks * sizeof *no);
    if (!no)
        goto oom;
    s->out = no;
    s->out_cap = chunks;
    if (chunks > s->cnb_chunks) {
        uint32_t **nl = realloc(s->cnb, (size_t)chunks * sizeof *nl);
        if (!nl)
            goto oom;
        s->cnb = nl;
        uint32_t *nc = realloc(s->cnb_cap, (size_t)chunks * sizeof *nc);
        if (!nc)
            goto oom;
        s->cnb_cap = nc;
        uint32_t **sl = realloc(s->snb, (size_t)chunks * sizeof *sl);
        if (!sl)
            goto oom;
        s->snb = sl;
        uint32_t *sc = realloc(s->snb_cap, (size_t)chunks * sizeof *sc);
        if (!sc)
            goto oom;
        s->snb_cap = sc;
        uint32_t *su = realloc(s->snb_used, (size_t)chunks * sizeof *su);
        if (!su)
            goto oom;
        s->snb_used = su;
        for (uint32_t c = s->cnb_chunks; c < chunks; ++c)
            s->cnb[c] = NULL, s->cnb_cap[c] = 0, s->snb[c] = NULL, s->snb_cap[c] = 0, s->snb_used[c] = 0;
        s->cnb_chunks = chunks;
    }
    s->cap = (uint32_t)cap;
    return VFX_OK;
oom:
    return rt_errf(err, errlen, VFX_ERR_OUT_OF_MEMORY, "rt_sph: out of memory growing to %llu particles", (unsigned long long)cap);
}

/* Refuses n rows when any of the arrays (NULL ones skipped) holds a NaN/Inf, naming the row. */
static vfx_result check_finite(const char *who, const char *of, const char *what,
                               uint32_t n, const float *const arr[6], char *err, size_t errlen)
{
    static const char *nm[6] = {"x", "y", "z", "vx", "vy", "vz"};
    for (uint32_t i = 0; i < n; ++i)
        for (int a = 0; a < 6; ++a)
            if (arr[a] && !isfinite(arr[a][i])) {
                return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "%s: particle %u (of %u %s) has a non-finite %s (%g); %s refused", who,
                            i, n, of, nm[a], (double)arr[a][i], what);
            }
    return VFX_OK;
}

void rt_sph_take_columns(rt_sph *s, const rt_sph_columns *c)
{
    s->x = c->x, s->y = c->y, s->z = c->z;
    s->vx = c->vx, s->vy = c->vy, s->vz = c->vz;
    s->rho = c->density;
}

/* Room for `add` more rows (n is not changed): our buffers, and the host's rows when bound. */
static vfx_result grow_rows(rt_sph *s, uint32_t add, char *err, size_t errlen)
{
    vfx_result r = rt_sph_reserve(s, (uint64_t)s->n + add, err, errlen);
    if (r || !s->bound)
        return r;
    rt_sph_columns c = {0};
    r = s->host.append(s->host.user, add, &c);
    if (r || c.count != s->n + add) {
        return rt_errf(err, errlen, r ? r : VFX_ERR_INVALID_ARGUMENT,
                       "rt_sph: the host could not append %u rows to its %u (%s)", add, s->n,
                       r ? vfx_result_name(r) : "wrong row count back");
    }
    rt_sph_take_columns(s, &c);
    return VFX_OK;
}

/* Rows base..end-1 (room made by grow_rows, positions and velocities written) become particles:
 * moved a quarter spacing inside the walls, where the clamp would put them, at rest density,
 * with the next ids. */
static void fresh_rows(rt_sph *s, uint32_t base, uint32_t end)
{
    float m = 0.25f * s->p.spacing;
    const float *lo = s->p.domain_min, *hi = s->p.domain_max;
    for (uint32_t q = base; q < end; ++q) {
        float px = sph_clampf(s->x[q], lo[0] + m, hi[0] - m);
        float py = sph_clampf(s->y[q], lo[1] + m, hi[1] - m);
        float pz = sph_clampf(s->z[q], lo[2] + m, hi[2] - m);
        if (px != s->x[q] || py != s->y[q] || pz != s->z[q])
            s->clamped_on_add++;
        s->x[q] = px, s->y[q] = py, s->z[q] = pz;
        s->rho[q] = s->p.rest_density;
        s->pr[q] = 0.f;
        s->id[q] = s->next_id++;
    }
    s->n = end;
    s->lists_valid = false; /* new rows are in no list */
}

vfx_result rt_sph_add_particles(rt_sph *s, uint32_t n, const float *x, const float *y,
                                 const float *z, const float *vx, const float *vy, const float *vz,
                                 char *err, size_t errlen)
{
    if (!s)
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_particles: NULL solver");
    if (n == 0)
        return VFX_OK;
    if (!x || !y || !z) {
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_particles: position array is NULL for %u particles", n);
    }
    if ((uint64_t)s->n + n > s->p.max_particles) {
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_particles: %u + %u particles exceed the capacity bound %u "
                "(desc.max_particles)", s->n, n, s->p.max_particles);
    }
    const float *arr[6] = {x, y, z, vx, vy, vz};
    vfx_result r = check_finite("rt_sph_add_particles", "in this batch", "batch", n, arr, err, errlen);
    if (r)
        return r;
    uint32_t base = s->n;
    if ((r = grow_rows(s, n, err, errlen)))
        return r;
    for (uint32_t i = 0; i < n; ++i) {
        uint32_t k = base + i;
        s->x[k] = x[i], s->y[k] = y[i], s->z[k] = z[i];
        s->vx[k] = vx ? vx[i] : 0.f;
        s->vy[k] = vy ? vy[i] : 0.f;
        s->vz[k] = vz ? vz[i] : 0.f;
    }
    fresh_rows(s, base, base + n);
    return VFX_OK;
}

void rt_sph_clear(rt_sph *s)
{
    if (!s)
        return;
    if (s->bound) {
        drop_state(s); /* the host's columns are not ours to keep */
        s->bound = false;
    }
    s->n = 0;
    s->next_id = 0;
    s->lists_valid = false;
    s->pbf_valid = 0;
}

vfx_result rt_sph_add_block(rt_sph *s, const float lo[3], const float hi[3], uint32_t *added,
                            char *err, size_t errlen)
{
    if (added)
        *added = 0;
    if (!s || !lo || !hi)
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_block: NULL solver or bounds");
    float dx = s->p.spacing;
    uint64_t c[3];
    for (int a = 0; a < 3; ++a) {
        if (!isfinite(lo[a]) || !isfinite(hi[a]) || hi[a] < lo[a]) {
            return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_block: bad bounds on axis %d (%g..%g)", a, (double)lo[a], (double)hi[a]);
        }
        c[a] = (uint64_t)floor((hi[a] - lo[a]) / dx + 1e-4);
    }
    uint64_t total = c[0] * c[1] * c[2];
    if (total == 0)
        return VFX_OK;
    if (total > s->p.max_particles - s->n)
        return rt_sph_reserve(s, s->n + total, err, errlen); /* names the capacity bound */
    uint32_t base = s->n;
    vfx_result r = grow_rows(s, (uint32_t)total, err, errlen);
    if (r)
        return r;
    uint32_t q = base;
    for (uint64_t k = 0; k < c[2]; ++k)
        for (uint64_t j = 0; j < c[1]; ++j)
            for (uint64_t i = 0; i < c[0]; ++i, ++q) {
                s->x[q] = lo[0] + ((float)i + 0.5f) * dx;
                s->y[q] = lo[1] + ((float)j + 0.5f) * dx;
                s->z[q] = lo[2] + ((float)k + 0.5f) * dx;
                s->vx[q] = s->vy[q] = s->vz[q] = 0.f;
            }
    fresh_rows(s, base, base + (uint32_t)total); /* out-of-domain lattice points are clamped like any other input */
    if (added)
        *added = (uint32_t)total;
    return VFX_OK;
}

void rt_sph_swap_state(rt_sph *s)
{
    float *t;
#define SW(a, b) (t = s->a, s->a = s->b, s->b = t)
    SW(x, xn);
    SW(y, yn);
    SW(z, zn);
    SW(vx, vxn);
    SW(vy, vyn);
    SW(vz, vzn);
#undef SW
}

void rt_sph_commit_state(rt_sph *s)
{
    if (!s->bound) {
        rt_sph_swap_state(s);
        return;
    }
    /* the host's columns stay where they are: the integrated state is copied into them */
    const size_t bytes = (size_t)s->n * sizeof(float);
    memcpy(s->x, s->xn, bytes), memcpy(s->y, s->yn, bytes), memcpy(s->z, s->zn, bytes);
    memcpy(s->vx, s->vxn, bytes), memcpy(s->vy, s->vyn, bytes), memcpy(s->vz, s->vzn, bytes);
}

vfx_result rt_sph_bind(rt_sph *s, const rt_sph_host *host, const rt_sph_columns *c, char *err,
                       size_t errlen)
{
    if (!s)
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_bind: NULL solver");
    if (!host || !host->permute || !host->append || !c ||
        (c->count && (!c->x || !c->y || !c->z || !c->vx || !c->vy || !c->vz || !c->density))) {
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_bind: need a host with permute and append, and every column of "
                    "its %u rows", c ? c->count : 0);
    }
    const float *arr[6] = {c->x, c->y, c->z, c->vx, c->vy, c->vz};
    vfx_result r = check_finite("rt_sph_bind", "bound rows", "binding", c->count, arr, err, errlen);
    if (r)
        return r;
    drop_state(s); /* our own particles, or the previous binding's pointers */
    s->bound = true;
    s->host = *host;
    s->n = 0;
    s->next_id = 0;
    s->pbf_valid = 0; /* PBF: hydrostatic pressures again for the bound rows */
    if ((r = rt_sph_reserve(s, c->count, err, errlen))) {
        rt_sph_clear(s);
        return r;
    }
    rt_sph_take_columns(s, c);
    fresh_rows(s, 0, c->count);
    return VFX_OK;
}
