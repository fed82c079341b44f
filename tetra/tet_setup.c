/* tet_setup.c — what every engine of the cell-projection renderer does before scanning: check
 * the view, transform the points once, and sort each partition's cells front to back. */
#include "tet_engine.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

void tet_options_default(tet_options *o)
{
    memset(o, 0, sizeof *o);
    o->ert = 1;
    o->ert_threshold = 0.9f;
    o->tiles_d = 20;
    o->update_c = 100;
    o->partial_composite = 1;
    o->workers = 1;
    o->share = 1;
    o->dlb = 1;
}

tet_result tet_check_view(const tet_mesh *mesh, const tet_camera *cam, const tet_tf *tf, int nw,
                   double *near_d, char *err, size_t errlen)
{
    const int W = cam->width, H = cam->height;
    if (W <= 0 || H <= 0 || W > 16384 || H > 16384) {
        tet_errf(err, errlen, "tet_render: image size %dx%d out of range", W, H);
        return TET_ERR_INVALID_ARGUMENT;
    }
    if (nw > TET_MAX_WORKERS) {
        tet_errf(err, errlen, "tet_render: %d workers requested, at most %d", nw, TET_MAX_WORKERS);
        return TET_ERR_INVALID_ARGUMENT;
    }
    if (!mesh->scalar) {
        tet_errf(err, errlen, "tet_render: mesh has no scalar field");
        return TET_ERR_INVALID_ARGUMENT;
    }
    const float *P = cam->proj;
    if (P[11] > -0.5f || !(fabsf(P[0]) > 0) || !(fabsf(P[5]) > 0)) {
        tet_errf(err, errlen, "tet_render: projection is not a perspective matrix (P[11]=%g)",
                 (double)P[11]);
        return TET_ERR_INVALID_ARGUMENT;
    }
    if (tf->count != 0 && (tf->count < 2 || tf->count > TET_TF_MAX_POINTS || !tf->points)) {
        tet_errf(err, errlen, "tet_render: transfer function of %d points (need 0 or 2..%d with a table)",
                 tf->count, TET_TF_MAX_POINTS);
        return TET_ERR_INVALID_ARGUMENT;
    }
    if (tf->method < TET_TF_EXACT || tf->method > TET_TF_MIDPOINT) {
        tet_errf(err, errlen, "tet_render: unknown transfer-function method %d", tf->method);
        return TET_ERR_INVALID_ARGUMENT;
    }
    if (tf->pre_size < 0 || tf->pre_size > (1 << 20)) {
        tet_errf(err, errlen, "tet_render: pre-integrated table of %d cells (0..%d)", tf->pre_size, 1 << 20);
        return TET_ERR_INVALID_ARGUMENT;
    }
    *near_d = (double)P[14] / ((double)P[10] - 1.0);
    if (!(*near_d > 0)) *near_d = 1e-4;
    return TET_OK;
}

tet_result tet_check_indices(const tet_mesh *mesh, char *err, size_t errlen)
{
    const uint32_t np = mesh->point_count;
    for (uint32_t c = 0; c < mesh->tet_count; c++)
        for (int k = 0; k < 4; k++)
            if (mesh->tets[4 * c + k] >= np) {
                tet_errf(err, errlen, "tet_render: tet %u references point %u of %u", c,
                         mesh->tets[4 * c + k], np);
                return TET_ERR_INVALID_ARGUMENT;
            }
    return TET_OK;
}

void tet_view_vertices(const tet_mesh *mesh, const float *V, const float *P, int W, int H,
                       uint32_t i0, uint32_t i1, pvert *vp)
{
    for (uint32_t i = i0; i < i1; i++) {
        const float *x = &mesh->points[3 * i];
        double e[3];
        for (int r = 0; r < 3; r++)
            e[r] = (double)V[r] * x[0] + (double)V[4 + r] * x[1] + (double)V[8 + r] * x[2] + V[12 + r];
        vp[i].x = e[0];
        vp[i].y = e[1];
        vp[i].z = e[2];
        vp[i].s = mesh->scalar[i];
        vp[i].px = vp[i].py = 0;
        double wz = -vp[i].z;
        if (wz > 0) {
            double nx = (P[0] * vp[i].x + P[8] * vp[i].z) / wz;
            double ny = (P[5] * vp[i].y + P[9] * vp[i].z) / wz;
            vp[i].px = (nx + 1) * 0.5 * W - 0.5;
            vp[i].py = (ny + 1) * 0.5 * H - 0.5;
        }
    }
}

/* float -> unsigned with the same order (sign bit flipped for positives, all bits for negatives) */
static inline uint32_t fkey(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return (u & 0x80000000u) ? ~u : u | 0x80000000u;
}

/* Stable LSD radix sort of keys by nearest (4 passes of 8 bits through tmp); keys arrive in
 * ascending id, so ties stay in id order. qsort cost ~8% of a frame on the pipe mesh. */
static void sort_keys(cellkey *keys, cellkey *tmp, uint32_t n)
{
    cellkey *src = keys, *dst = tmp;
    for (int pass = 0; pass < 4; pass++) {
        uint32_t cnt[257] = {0};
        const int sh = 8 * pass;
        for (uint32_t i = 0; i < n; i++)
            cnt[((fkey(src[i].nearest) >> sh) & 255u) + 1]++;
        for (int b = 0; b < 256; b++)
            cnt[b + 1] += cnt[b];
        for (uint32_t i = 0; i < n; i++)
            dst[cnt[(fkey(src[i].nearest) >> sh) & 255u]++] = src[i];
        cellkey *t = src;
        src = dst;
        dst = t;
    }
    /* an even number of passes leaves the result in keys */
}

uint32_t tet_build_keys(const tet_mesh *mesh, const pvert *vp, uint32_t c0, uint32_t c1,
                        cellkey *keys, cellkey *tmp, uint64_t *nan)
{
    uint32_t n = 0;
    for (uint32_t c = c0; c < c1; c++) {
        const uint32_t *t = &mesh->tets[4 * c];
        int bad = 0;
        float nearest = INFINITY;
        for (int k = 0; k < 4; k++) {
            double z = -vp[t[k]].z;
            /* !isfinite, not isnan: an Inf scalar or depth made NaN pixels (fuzz_tet_render) */
            if (!isfinite(z) || !isfinite(mesh->scalar[t[k]]))
                bad = 1;
            if (z < nearest)
                nearest = (float)z;
        }
        if (bad) {
            (*nan)++;
            continue;
        }
        keys[n].nearest = nearest;
        keys[n].id = c;
        n++;
    }
    sort_keys(keys, tmp, n);
    return n;
}
