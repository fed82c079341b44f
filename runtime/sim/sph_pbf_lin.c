/* sph_pbf_lin.c — PBF's pair terms computed once per iteration (the default; RT_SPH_PBF_RECOMPUTE
 * runs the original passes, which compute them in both).
 *
 * Both passes of a Jacobi iteration evaluate the pairs at the same iterate. The lambda pass
 * (sph_pbf.c) now also stores, for the pairs its four-wide loop takes, q_ij d_ij (the kernel
 * gradient over Vks, d_ij = x_i - x_j, q_ij = (H - r)^2 / r, 0 for coincident pairs, which it
 * counts), and the position pass computes sum_j (l_i + l_j) (q_ij d_ij) from them with the same
 * operations in the same order:
 * a gather of the neighbours' multipliers over stored floats, no position gather, square root
 * or division, and bitwise the original result (the scalar remainder of each list, < 4 pairs,
 * is recomputed as before). The clamp to the walls is skipped when a particle is nearer to its
 * predicted position than a lower bound of its distance to every wall less the clamp margin
 * (computed once a step): the clamp is the identity there, so this too is bitwise.
 *
 * Tried first and measured unstable (scratch runs, closed tank at rest, 6 iterations): the
 * gradients frozen at the predicted positions for the whole step (IISPH/DFSPH's
 * linearisation), with the constraint linearised too (with poly6's gradient: each iteration's
 * decompression overestimated by ~5%, the tank at 6% compression and 4 m/s within 5 frames) or
 * evaluated exactly (one frozen position pass already diverged: at a wall grad_i C_i is a small
 * difference of the neighbours' and the wall's gradients, and its direction turns with moves of
 * 1e-4 m).
 *
 * Storage: three float arrays per work item parallel to the exact neighbour list cnb[chunk]
 * (same offsets nb_start[i]), and per particle the count of coincident stored pairs and the
 * room; grown as needed, valid within a step. */
#include "sim/sph_collide.h"
#include "core/error.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

/* per-pair arrays of pbf_pe[chunk], each pbf_pe_cap[chunk] floats: G_ij / Vks = q_ij d_ij (3) */
enum { PE_N = 3 };
/* per-particle columns of pbf_lin, each pbf_lin_cap floats */
enum { LIN_ROOM, LIN_COINCIDENT, LIN_NCOLS };

static inline float *lin_col(const rt_sph *s, int c) { return s->pbf_lin + (size_t)c * s->pbf_lin_cap; }

vfx_result rt_sph_pbf_lin_reserve(rt_sph *s, char *err, size_t errlen)
{
    if (s->pbf_lin_cap < s->n) {
        float *nl = realloc(s->pbf_lin, (size_t)s->cap * LIN_NCOLS * sizeof *nl);
        if (!nl)
            return rt_errf(err, errlen, VFX_ERR_OUT_OF_MEMORY, "rt_sph_step: out of memory for PBF's %u x %d "
                           "per-particle terms", s->cap, (int)LIN_NCOLS);
        s->pbf_lin = nl, s->pbf_lin_cap = s->cap;
    }
    uint32_t nch = sph_chunk_count(s);
    if (nch > s->pbf_pe_chunks) {
        float **np = realloc(s->pbf_pe, (size_t)nch * sizeof *np);
        if (!np)
            goto oom;
        s->pbf_pe = np;
        uint32_t *nc = realloc(s->pbf_pe_cap, (size_t)nch * sizeof *nc);
        if (!nc)
            goto oom;
        s->pbf_pe_cap = nc;
        for (uint32_t c = s->pbf_pe_chunks; c < nch; ++c)
            s->pbf_pe[c] = NULL, s->pbf_pe_cap[c] = 0;
        s->pbf_pe_chunks = nch;
    }
    for (uint32_t c = 0; c < nch; ++c) {
        uint32_t last = (c + 1) * SPH_CHUNK < s->n ? (c + 1) * SPH_CHUNK - 1 : s->n - 1;
        uint32_t want = s->nb_start[last] + s->nb_count[last];
        if (want <= s->pbf_pe_cap[c])
            continue;
        /* 1/8 slack as the lists (their sizes change little from step to step) */
        uint64_t cap = (uint64_t)want + want / 8 + 256;
        float *nb = cap > UINT32_MAX || cap * PE_N > SIZE_MAX / sizeof(float)
                        ? NULL
                        : realloc(s->pbf_pe[c], (size_t)cap * PE_N * sizeof(float));
        if (!nb)
            goto oom;
        s->pbf_pe[c] = nb, s->pbf_pe_cap[c] = (uint32_t)cap;
    }
    return VFX_OK;
oom:
    return rt_errf(err, errlen, VFX_ERR_OUT_OF_MEMORY, "rt_sph_step: out of memory for PBF's per-pair terms "
                   "of %u particles", s->n);
}

void rt_sph_pbf_lin_free(rt_sph *s)
{
    for (uint32_t c = 0; c < s->pbf_pe_chunks; ++c)
        free(s->pbf_pe[c]);
    free(s->pbf_pe), free(s->pbf_pe_cap), free(s->pbf_lin);
    s->pbf_pe = NULL, s->pbf_pe_cap = NULL, s->pbf_pe_chunks = 0;
    s->pbf_lin = NULL, s->pbf_lin_cap = 0;
}

size_t rt_sph_pbf_lin_bytes(const rt_sph *s)
{
    size_t b = (size_t)s->pbf_lin_cap * LIN_NCOLS * sizeof(float);
    for (uint32_t c = 0; c < s->pbf_pe_chunks; ++c)
        b += (size_t)s->pbf_pe_cap[c] * PE_N * sizeof(float) + sizeof(float *) + sizeof(uint32_t);
    return b;
}

void rt_sph_pbf_pair_arrays(const rt_sph *s, uint32_t chunk, float *pe[3])
{
    size_t cap = s->pbf_pe_cap[chunk];
    for (int k = 0; k < PE_N; ++k)
        pe[k] = s->pbf_pe[chunk] + (size_t)k * cap;
}

/* A lower bound of the distance from p to every collider's surface and every face of the
 * domain box, less the clamp margin (so a move shorter than it leaves rt_sph_pbf_clamp the
 * identity), with a slack of 1e-4 relative and 4 ulps of the coordinates against rounding (as
 * sph_collider_beyond). Box colliders: max over the axes of |d_a| - half_a; spheres: of
 * |d_a| - radius; planes and meshes give -1 (always clamp). */
static float lin_room(const rt_sph *s, const float p[3], float margin)
{
    const float *lo = s->p.domain_min, *hi = s->p.domain_max;
    float room = INFINITY, big = 1.f;
    for (int a = 0; a < 3; ++a) {
        float u = p[a] - (lo[a] + margin), v = (hi[a] - margin) - p[a];
        room = u < room ? u : room;
        room = v < room ? v : room;
        big = fabsf(p[a]) > big ? fabsf(p[a]) : big;
    }
    for (uint32_t c = 0; c < s->ncol; ++c) {
        const sph_collider_state *st = &s->col[c];
        if (st->sdf || st->c.kind == RT_SPH_PLANE)
            return -1.f;
        float q = -INFINITY;
        for (int a = 0; a < 3; ++a) {
            float e = fabsf(p[a] - st->pos[a]) - (st->c.kind == RT_SPH_BOX ? st->c.half[a] : st->c.radius);
            q = e > q ? e : q;
        }
        q -= 1.0001f * margin;
        room = q < room ? q : room;
    }
    return room * 0.9999f - 4.f * FLT_EPSILON * big;
}

void rt_sph_pbf_store_particle(rt_sph *s, uint32_t i, uint32_t coincident)
{
    lin_col(s, LIN_COINCIDENT)[i] = (float)coincident;
    if (s->pbf_iter == 0) { /* at the predicted position (s->x..), once a step */
        float p[3] = {s->x[i], s->y[i], s->z[i]};
        lin_col(s, LIN_ROOM)[i] = lin_room(s, p, 0.25f * s->p.spacing);
    }
}

uint32_t rt_sph_pbf_stored_coincident(const rt_sph *s, uint32_t i)
{
    return (uint32_t)lin_col(s, LIN_COINCIDENT)[i];
}

bool rt_sph_pbf_may_reach_wall(const rt_sph *s, uint32_t i, const float p[3])
{
    float room = lin_col(s, LIN_ROOM)[i];
    float mx = p[0] - s->x[i], my = p[1] - s->y[i], mz = p[2] - s->z[i];
    return !(room > 0.f && mx * mx + my * my + mz * mz < room * room);
}
