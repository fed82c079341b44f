/* sph_grid.c — the neighbour grid: particles sorted by cell of H/2 for locality and the
 * cell scans, and the volume fraction read from it. */
#include "sim/sph_wall.h"

#include <string.h>

static void key_chunk(rt_sph *s, uint32_t chunk)
{
    uint32_t b, e;
    sph_chunk_rows(s, chunk, &b, &e);
    const float *lo = s->p.domain_min;
    for (uint32_t i = b; i < e; ++i) {
        int cx = sph_cell_coord(s->x[i], lo[0], s->inv_cell, s->nx);
        int cy = sph_cell_coord(s->y[i], lo[1], s->inv_cell, s->ny);
        int cz = sph_cell_coord(s->z[i], lo[2], s->inv_cell, s->nz);
        s->key[i] = (uint32_t)((cz * s->ny + cy) * s->nx + cx);
    }
}

/* Gathers the own state columns into the (free) integration buffers in sorted order. */
static void permute_chunk(rt_sph *s, uint32_t chunk)
{
    uint32_t b, e;
    sph_chunk_rows(s, chunk, &b, &e);
    const uint32_t *perm = s->perm;
    for (uint32_t i = b; i < e; ++i) {
        uint32_t k = perm[i];
        s->xn[i] = s->x[k], s->yn[i] = s->y[k], s->zn[i] = s->z[k];
        s->vxn[i] = s->vx[k], s->vyn[i] = s->vy[k], s->vzn[i] = s->vz[k];
        s->idtmp[i] = s->id[k];
    }
}

/* The ids alone (the host reorders the bound state columns). */
static void permute_ids_chunk(rt_sph *s, uint32_t chunk)
{
    uint32_t b, e;
    sph_chunk_rows(s, chunk, &b, &e);
    for (uint32_t i = b; i < e; ++i)
        s->idtmp[i] = s->id[s->perm[i]];
}

/* Counting sort of the particles by cell, then every per-particle column permuted so that a
 * cell's particles are contiguous (and a row of x-adjacent cells is one range). Stable, so
 * the order — and every sum over neighbours — does not depend on the thread count. Keys and
 * the permutation run on all threads; the histogram and the scatter are serial (O(n + cells)). */
vfx_result rt_sph_build_grid(rt_sph *s, char *err, size_t errlen)
{
    uint32_t n = s->n;
    rt_sph_parallel(s, key_chunk, false);
    memset(s->cell_start, 0, ((size_t)s->ncells + 1) * sizeof *s->cell_start);
    for (uint32_t i = 0; i < n; ++i)
        s->cell_start[s->key[i] + 1]++;
    for (uint32_t c = 0; c < s->ncells; ++c)
        s->cell_start[c + 1] += s->cell_start[c];
    /* scatter using cell_start as running cursors, then restore it */
    for (uint32_t i = 0; i < n; ++i)
        s->perm[s->cell_start[s->key[i]]++] = i;
    for (uint32_t c = s->ncells; c > 0; --c)
        s->cell_start[c] = s->cell_start[c - 1];
    s->cell_start[0] = 0;
    if (s->bound) {
        /* the host's table reorders every one of its columns (density and whatever else it
         * holds) with the same permutation */
        rt_sph_columns c = {0};
        vfx_result r = s->host.permute(s->host.user, s->perm, &c);
        if (r || c.count != n) {
            s->lists_valid = false;
            return rt_errf(err, errlen, r ? r : VFX_ERR_INVALID_ARGUMENT,
                           "rt_sph_step: the host could not reorder its %u rows by grid cell (%s)", n,
                           r ? vfx_result_name(r) : "wrong row count back");
        }
        rt_sph_take_columns(s, &c);
        rt_sph_parallel(s, permute_ids_chunk, false);
    } else {
        rt_sph_parallel(s, permute_chunk, false);
        rt_sph_swap_state(s);
    }
    uint32_t *t = s->id;
    s->id = s->idtmp;
    s->idtmp = t;
    return VFX_OK;
}

float rt_sph_volume_fraction(const rt_sph *s, const float p[3])
{
    if (!s || !p || !isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
        return NAN;
    /* The grid is that of the last rebuild; with Verlet lists the particles have moved less
     * than skin/2 <= H/2 since, so every particle now within H of p was within 1.5 H = 3 cells
     * of H/2 then: a 7x7x7 stencil over the rows as sorted, distances from the current
     * positions. The 5x5x5 stencil when the grid is rebuilt every substep (it is current). */
    sph_ranges r;
    sph_neighbor_ranges(s, p[0], p[1], p[2], s->verlet ? 3 : 2, &r);
    double sum = 0.0;
    for (int q = 0; q < r.count; ++q)
        for (uint32_t j = r.lo[q]; j < r.hi[q] && j < s->n; ++j) {
            float dx = p[0] - s->x[j], dy = p[1] - s->y[j], dz = p[2] - s->z[j];
            float r2 = dx * dx + dy * dy + dz * dz;
            if (r2 < s->H2) {
                float t = s->H2 - r2;
                sum += (double)t * t * t;
            }
        }
    sph_wall_hit walls[SPH_MAX_WALLS];
    int nw = rt_sph_gather_walls(s, p[0], p[1], p[2], walls, SPH_MAX_WALLS);
    float inside, extra;
    sph_wall_share(s, walls, nw, NULL, &inside, &extra);
    float gam = inside - extra;
    if (!(gam > 0.05f))
        return 0.f; /* inside a solid */
    return (float)(sum * s->mass * s->k_poly6 / s->p.rest_density / gam);
}
