/* tet_local.c — the single-worker scan engine of the MPI backend (tet_render_internal.h).
 * The set-up mirrors tet_render_workers (same checks, same partitions, same key order) so
 * that P processes partition the cells exactly as P threads would. Partition p's keys live at
 * [bounds[p], bounds[p] + valid[p]) whichever process builds them, so a key index means the
 * same cell on every process; only the own partition is built at creation, the others when
 * keys of theirs arrive by load balancing. */
#include "tet_engine.h"
#include "tet_render_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct tet_local {
    scan_ctx X;
    tf_prep tf;
    shared sh;
    worker w;
    pvert *vp;
    cellkey *keys;
    cellkey *ktmp;    /* radix-sort scratch, as long as the largest partition */
    uint32_t *bounds; /* parts + 1 cell offsets: partition p is cells [bounds[p], bounds[p+1]) */
    uint32_t *valid;  /* keys of partition p (its cells without NaN) once built */
    uint8_t *built;
    int parts;
};

/* Builds partition p's keys sorted front to back; NaN cells are counted when count is set. */
static void local_build(tet_local *L, int p, int count)
{
    uint64_t nan = 0;
    uint32_t c0 = L->bounds[p];
    L->valid[p] = tet_build_keys(L->X.mesh, L->vp, c0, L->bounds[p + 1], L->keys + c0, L->ktmp, &nan);
    if (count)
        L->w.cnt.cells_nan += nan;
    L->built[p] = 1;
}

tet_result tet_local_create(const tet_mesh *mesh, const tet_camera *cam,
                         const tet_tf *tf, const tet_options *opts, int parts,
                         int own, tet_local **out, char *err, size_t errlen)
{
    *out = NULL;
    if (!mesh || !cam || !tf || !opts || parts <= 0 || own < 0 || own >= parts) {
        tet_errf(err, errlen, "tet_render: NULL argument or partition %d of %d", own, parts);
        return TET_ERR_INVALID_ARGUMENT;
    }
    const int W = cam->width, H = cam->height;
    double near_d;
    tet_result rc = tet_check_view(mesh, cam, tf, 1, &near_d, err, errlen);
    if (rc != TET_OK)
        return rc;
    /* every index is checked on every process (cheap), so all report the same bad tet */
    if ((rc = tet_check_indices(mesh, err, errlen)) != TET_OK)
        return rc;
    const float *P = cam->proj, *V = cam->view;
    const uint32_t np = mesh->point_count, nt = mesh->tet_count;
    const int D = opts->tiles_d > 0 ? opts->tiles_d : 1;
    tet_local *L = calloc(1, sizeof *L);
    if (!L) {
        tet_errf(err, errlen, "tet_render: out of memory");
        return TET_ERR_OUT_OF_MEMORY;
    }
    L->parts = parts;
    L->vp = malloc((size_t)np * sizeof *L->vp + 1);
    L->keys = malloc((size_t)(nt ? nt : 1) * sizeof *L->keys);
    L->ktmp = malloc((size_t)(nt ? nt : 1) * sizeof *L->ktmp);
    L->bounds = calloc((size_t)parts + 1, sizeof *L->bounds);
    L->valid = calloc((size_t)parts, sizeof *L->valid);
    L->built = calloc((size_t)parts, sizeof *L->built);
    pthread_mutex_init(&L->w.lock, NULL);
    pthread_mutex_init(&L->sh.lock, NULL);
    if (!L->vp || !L->keys || !L->ktmp || !L->bounds || !L->valid || !L->built ||
        tet_worker_reset(&L->w, W, H, D) != 0) {
        tet_errf(err, errlen, "tet_render: out of memory (%u points, %u tets, %dx%d)", np, nt, W, H);
        tet_local_destroy(L);
        return TET_ERR_OUT_OF_MEMORY;
    }
    if ((rc = tet_tf_prepare(tf, &L->tf, err, errlen)) != TET_OK) {
        tet_local_destroy(L);
        return rc;
    }
    tet_view_vertices(mesh, V, P, W, H, 0, np, L->vp);
    for (int pi = 0; pi <= parts; pi++)
        L->bounds[pi] = (uint32_t)((uint64_t)nt * pi / parts);
    scan_ctx X = {mesh, &L->tf, opts, L->vp, P, near_d, W, H, D};
    L->X = X;
    L->sh.X = &L->X;
    L->sh.keys = L->keys;
    L->sh.w = &L->w;
    L->sh.nw = 1; /* update_table then never touches the shared table */
    L->w.sh = &L->sh;
    local_build(L, own, 1);
    *out = L;
    return TET_OK;
}

void tet_local_destroy(tet_local *L)
{
    if (!L)
        return;
    free(L->vp);
    free(L->keys);
    free(L->ktmp);
    free(L->bounds);
    free(L->valid);
    free(L->built);
    tet_worker_free(&L->w);
    tet_tf_release(&L->tf);
    pthread_mutex_destroy(&L->w.lock);
    pthread_mutex_destroy(&L->sh.lock);
    free(L);
}

void tet_local_part(tet_local *L, int part, uint32_t *k0, uint32_t *k1)
{
    if (!L->built[part])
        local_build(L, part, 0);
    *k0 = L->bounds[part];
    *k1 = L->bounds[part] + L->valid[part];
}

uint32_t tet_local_part_cells(const tet_local *L, int part)
{
    return L->bounds[part + 1] - L->bounds[part];
}

void tet_local_need(tet_local *L, uint32_t k0, uint32_t k1)
{
    for (int p = 0; p < L->parts; p++)
        if (!L->built[p] && k0 < L->bounds[p + 1] && L->bounds[p] < k1)
            local_build(L, p, 0);
}

int tet_local_scan(tet_local *L, uint32_t k)
{
    return tet_scan_cell(&L->X, &L->w, &L->keys[k]);
}

void tet_local_update_table(tet_local *L)
{
    tet_update_table(&L->sh, &L->w);
}

void tet_local_table_get(const tet_local *L, float *enc)
{
    for (int i = 0; i < L->X.D * L->X.D; i++)
        enc[i] = L->w.tiles[i].terminated ? L->w.tiles[i].deepest : INFINITY;
}

void tet_local_table_merge(tet_local *L, const float *enc)
{
    for (int i = 0; i < L->X.D * L->X.D; i++) {
        tile *t = &L->w.tiles[i];
        if (enc[i] < INFINITY && (!t->terminated || enc[i] < t->deepest)) {
            t->terminated = 1;
            t->deepest = enc[i];
        }
    }
}

int tet_local_tiles_d(const tet_local *L)
{
    return L->X.D;
}

size_t tet_local_export(const tet_local *L, size_t p0, size_t p1, uint32_t *offsets,
                            tet_rseg *segs)
{
    size_t n = 0;
    for (size_t p = p0; p < p1; p++) {
        offsets[p - p0] = (uint32_t)n;
        for (int32_t c = L->w.px[p].head; c >= 0; n++) {
            const seg *s = tet_seg_at(&L->w.pool, &L->w.px[p], c);
            if (segs) {
                tet_rseg o = {s->zf, s->zb, s->r, s->g, s->b, s->a};
                segs[n] = o;
            }
            c = s->next;
        }
    }
    offsets[p1 - p0] = (uint32_t)n;
    return n;
}

tet_counters *tet_local_counters(tet_local *L)
{
    return &L->w.cnt;
}
