/* tet_render.c — cell projection with per-pixel ray-segment lists, partial compositing and
 * Conservative Subscreen Termination (seed 002, sections 2.1 and 3.1). Single worker. */
#if !defined(_POSIX_C_SOURCE) && !defined(_GNU_SOURCE)
#define _POSIX_C_SOURCE 199309L
#endif
#include "tet_render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct seg {
    float zf, zb;        /* ray distance of entry and exit */
    float r, g, b, a;    /* premultiplied colour and opacity of the (merged) segment */
    int32_t next;
} seg;

typedef struct seg_pool {
    seg *s;
    size_t n, cap;
} seg_pool;

typedef struct tile {
    int terminated;
    float deepest;
} tile;

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

void vfx_tet_options_default(vfx_tet_options *o)
{
    memset(o, 0, sizeof *o);
    o->ert = 1;
    o->ert_threshold = 0.9f;
    o->tiles_d = 20;
    o->update_c = 100;
    o->partial_composite = 1;
}

/* Segments closer than this (relative to depth) count as touching for partial compositing. */
#define TOUCH_EPS 1e-5f

static int pool_push(seg_pool *p, seg v)
{
    if (p->n == p->cap) {
        size_t nc = p->cap ? p->cap * 2 : 4096;
        seg *ns = realloc(p->s, nc * sizeof *ns);
        if (!ns)
            return -1;
        p->s = ns;
        p->cap = nc;
    }
    p->s[p->n] = v;
    return (int)p->n++;
}

/* front-over-back of two premultiplied segments */
static void over(seg *f, const seg *b)
{
    float t = 1.0f - f->a;
    f->r += t * b->r;
    f->g += t * b->g;
    f->b += t * b->b;
    f->a += t * b->a;
}

/* Inserts v into the pixel list at *head in order of zf; merges with the neighbours it touches
 * (the paper's partial compositing: a merged segment is again a segment). */
static int insert_seg(seg_pool *p, int32_t *head, seg v, int partial, float stop,
                      uint64_t *merged)
{
    int32_t prev = -1, cur = *head;
    while (cur >= 0 && p->s[cur].zf < v.zf) {
        prev = cur;
        cur = p->s[cur].next;
    }
    if (partial) {
        float eps = TOUCH_EPS * (1.0f + fabsf(v.zf));
        /* never grow a segment that is already opaque past the ERT threshold: its z_back is
         * where the pixel terminated, and growing it would push the termination depth back */
        if (prev >= 0 && p->s[prev].a < stop && fabsf(p->s[prev].zb - v.zf) <= eps) {
            seg *ps = &p->s[prev];
            over(ps, &v);
            ps->zb = v.zb;
            (*merged)++;
            /* the grown segment may now touch its successor */
            if (cur >= 0 && ps->a < stop && fabsf(ps->zb - p->s[cur].zf) <= eps) {
                over(ps, &p->s[cur]);
                ps->zb = p->s[cur].zb;
                ps->next = p->s[cur].next;
            }
            return 0;
        }
        if (cur >= 0 && v.a < stop && fabsf(v.zb - p->s[cur].zf) <= eps) {
            seg *cs = &p->s[cur];
            seg m = v;
            over(&m, cs);
            m.zb = cs->zb;
            m.next = cs->next;
            *cs = m;
            (*merged)++;
            return 0;
        }
    }
    v.next = cur;
    int idx = pool_push(p, v);
    if (idx < 0)
        return -1;
    if (prev >= 0)
        p->s[prev].next = idx;
    else
        *head = idx;
    return 0;
}

static void tf_eval(const vfx_tet_tf *tf, double s, double *tau, double rgb[3])
{
    double range = (double)tf->smax - tf->smin;
    double u = range > 0 ? (s - tf->smin) / range : 0.0;
    if (u < 0) u = 0;
    if (u > 1) u = 1;
    *tau = tf->tau_lo + (tf->tau_hi - tf->tau_lo) * u;
    for (int k = 0; k < 3; k++)
        rgb[k] = tf->color_lo[k] + (tf->color_hi[k] - tf->color_lo[k]) * u;
}

/* Paper 3.1.1: a pixel is terminated when the opacity of its known segments, composited as if
 * they were contiguous, reaches the threshold; gaps only add opacity, so this is conservative.
 * Returns the ray distance where it terminated, or -1. */
static float pixel_termination(const seg_pool *p, int32_t head, float thr)
{
    float a = 0.0f;
    for (int32_t c = head; c >= 0; c = p->s[c].next) {
        a += (1.0f - a) * p->s[c].a;
        if (a >= thr)
            return p->s[c].zb;
    }
    return -1.0f;
}

typedef struct cellkey {
    float nearest;
    uint32_t id;
} cellkey;

static int cmp_key(const void *a, const void *b)
{
    const cellkey *x = a, *y = b;
    if (x->nearest < y->nearest) return -1;
    if (x->nearest > y->nearest) return 1;
    return (x->id > y->id) - (x->id < y->id);
}

int vfx_tet_render(const vfx_tet_mesh *mesh, const vfx_tet_camera *cam, const vfx_tet_tf *tf,
                   const vfx_tet_options *opts, float *rgba, vfx_tet_counters *counters,
                   char err[256])
{
    vfx_tet_counters cnt;
    memset(&cnt, 0, sizeof cnt);
    if (!mesh || !cam || !tf || !opts || !rgba) {
        snprintf(err, 256, "tet_render: NULL argument");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    const int W = cam->width, H = cam->height;
    if (W <= 0 || H <= 0 || W > 16384 || H > 16384) {
        snprintf(err, 256, "tet_render: image size %dx%d out of range", W, H);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    if (!mesh->scalar) {
        snprintf(err, 256, "tet_render: mesh has no scalar field");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    const float *P = cam->proj, *V = cam->view;
    if (P[11] > -0.5f || !(fabsf(P[0]) > 0) || !(fabsf(P[5]) > 0)) {
        snprintf(err, 256, "tet_render: projection is not a perspective matrix (P[11]=%g)",
                 (double)P[11]);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    /* near plane distance from the projection: z_ndc = -1 at z = -near */
    double near_d = (double)P[14] / ((double)P[10] - 1.0);
    if (!(near_d > 0)) near_d = 1e-4;

    const uint32_t np = mesh->point_count, nt = mesh->tet_count;
    double *vp = malloc((size_t)np * 3 * sizeof *vp);
    int32_t *heads = malloc((size_t)W * H * sizeof *heads);
    cellkey *keys = malloc((size_t)(nt ? nt : 1) * sizeof *keys);
    int D = opts->tiles_d > 0 ? opts->tiles_d : 1;
    tile *tiles = calloc((size_t)D * D, sizeof *tiles);
    seg_pool pool = {0};
    int rc = VFX_OK;
    if (!vp || !heads || !keys || !tiles) {
        snprintf(err, 256, "tet_render: out of memory (%u points, %u tets)", np, nt);
        rc = VFX_ERR_OUT_OF_MEMORY;
        goto done;
    }
    for (size_t i = 0; i < (size_t)W * H; i++)
        heads[i] = -1;
    for (uint32_t i = 0; i < np; i++) {
        const float *x = &mesh->points[3 * i];
        for (int r = 0; r < 3; r++)
            vp[3 * i + r] = (double)V[r] * x[0] + (double)V[4 + r] * x[1] +
                            (double)V[8 + r] * x[2] + V[12 + r];
    }
    /* front-to-back order by the nearest view depth of each cell (visibility cycles do no harm:
     * the per-pixel lists are sorted by depth anyway; the order only feeds ERT) */
    uint32_t nk = 0;
    for (uint32_t c = 0; c < nt; c++) {
        const uint32_t *t = &mesh->tets[4 * c];
        int bad = 0;
        float nearest = INFINITY;
        for (int k = 0; k < 4; k++) {
            if (t[k] >= np) {
                snprintf(err, 256, "tet_render: tet %u references point %u of %u", c, t[k], np);
                rc = VFX_ERR_INVALID_ARGUMENT;
                goto done;
            }
            double z = -vp[3 * t[k] + 2];
            if (isnan(z) || isnan(mesh->scalar[t[k]]))
                bad = 1;
            if (z < nearest)
                nearest = (float)z;
        }
        if (bad) {
            cnt.cells_nan++;
            continue;
        }
        keys[nk].nearest = nearest;
        keys[nk].id = c;
        nk++;
    }
    qsort(keys, nk, sizeof *keys, cmp_key);

    const double ix0 = P[8], iy0 = P[9];
    const int ert = opts->ert;
    const int C = opts->update_c > 0 ? opts->update_c : 1;
    uint32_t next_update = ert ? (nk / C > 0 ? nk / C : 1) : UINT32_MAX;
    uint32_t since = 0;
    double t0 = now_ms();
    for (uint32_t k = 0; k < nk; k++) {
        if (ert && since >= next_update) {
            double tu = now_ms();
            for (int ty = 0; ty < D; ty++)
                for (int tx = 0; tx < D; tx++) {
                    int x0 = tx * W / D, x1 = (tx + 1) * W / D;
                    int y0 = ty * H / D, y1 = (ty + 1) * H / D;
                    int term = 1;
                    float deep = 0;
                    for (int y = y0; y < y1 && term; y++)
                        for (int x = x0; x < x1; x++) {
                            float z = pixel_termination(&pool, heads[(size_t)y * W + x],
                                                        opts->ert_threshold);
                            if (z < 0) { term = 0; break; }
                            if (z > deep) deep = z;
                        }
                    tiles[ty * D + tx].terminated = term && x1 > x0 && y1 > y0;
                    tiles[ty * D + tx].deepest = deep;
                }
            cnt.table_updates++;
            cnt.t_update_ms += now_ms() - tu;
            uint32_t rem = nk - k;
            next_update = rem / C > 0 ? rem / C : 1;
            since = 0;
        }
        since++;
        uint32_t c = keys[k].id;
        const uint32_t *t = &mesh->tets[4 * c];
        double v[4][3], s[4];
        int behind = 0;
        for (int j = 0; j < 4; j++) {
            memcpy(v[j], &vp[3 * t[j]], sizeof v[j]);
            s[j] = mesh->scalar[t[j]];
            if (-v[j][2] <= near_d)
                behind++;
        }
        if (behind == 4) {
            cnt.cells_behind++;
            continue;
        }
        /* screen bounding box; a cell crossing the near plane may cover anything */
        int bx0 = 0, by0 = 0, bx1 = W - 1, by1 = H - 1;
        if (behind) {
            cnt.cells_near_crossing++;
        } else {
            double mnx = INFINITY, mxx = -INFINITY, mny = INFINITY, mxy = -INFINITY;
            for (int j = 0; j < 4; j++) {
                double w = -v[j][2];
                double nx = (P[0] * v[j][0] + P[8] * v[j][2]) / w;
                double ny = (P[5] * v[j][1] + P[9] * v[j][2]) / w;
                double px = (nx + 1) * 0.5 * W - 0.5, py = (ny + 1) * 0.5 * H - 0.5;
                if (px < mnx) mnx = px;
                if (px > mxx) mxx = px;
                if (py < mny) mny = py;
                if (py > mxy) mxy = py;
            }
            if (mxx < 0 || mxy < 0 || mnx > W - 1 || mny > H - 1)
                continue; /* off screen */
            bx0 = mnx < 0 ? 0 : (int)ceil(mnx);
            by0 = mny < 0 ? 0 : (int)ceil(mny);
            bx1 = mxx > W - 1 ? W - 1 : (int)floor(mxx);
            by1 = mxy > H - 1 ? H - 1 : (int)floor(mxy);
            if (bx1 < bx0 || by1 < by0)
                continue; /* falls between pixel centres */
            if (ert) {
                /* CST: every tile the bbox touches is terminated in front of the cell */
                int tx0 = bx0 * D / W, tx1 = bx1 * D / W, ty0 = by0 * D / H, ty1 = by1 * D / H;
                int skip = 1;
                for (int ty = ty0; ty <= ty1 && skip; ty++)
                    for (int tx = tx0; tx <= tx1; tx++) {
                        const tile *tl = &tiles[ty * D + tx];
                        if (!tl->terminated || !(tl->deepest < keys[k].nearest)) {
                            skip = 0;
                            break;
                        }
                    }
                if (skip) {
                    cnt.cells_skipped_ert++;
                    continue;
                }
            }
        }
        /* barycentric coordinates as affine functions of the ray parameter */
        double e[3][3];
        for (int j = 0; j < 3; j++)
            for (int r = 0; r < 3; r++)
                e[r][j] = v[j][r] - v[3][r];
        double det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                     e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                     e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
        double scale = 0;
        for (int r = 0; r < 3; r++)
            for (int j = 0; j < 3; j++)
                scale = fmax(scale, fabs(e[r][j]));
        if (!(fabs(det) > 1e-12 * scale * scale * scale)) {
            cnt.cells_degenerate++;
            continue;
        }
        double inv[3][3];
        inv[0][0] = (e[1][1] * e[2][2] - e[1][2] * e[2][1]) / det;
        inv[0][1] = (e[0][2] * e[2][1] - e[0][1] * e[2][2]) / det;
        inv[0][2] = (e[0][1] * e[1][2] - e[0][2] * e[1][1]) / det;
        inv[1][0] = (e[1][2] * e[2][0] - e[1][0] * e[2][2]) / det;
        inv[1][1] = (e[0][0] * e[2][2] - e[0][2] * e[2][0]) / det;
        inv[1][2] = (e[0][2] * e[1][0] - e[0][0] * e[1][2]) / det;
        inv[2][0] = (e[1][0] * e[2][1] - e[1][1] * e[2][0]) / det;
        inv[2][1] = (e[0][1] * e[2][0] - e[0][0] * e[2][1]) / det;
        inv[2][2] = (e[0][0] * e[1][1] - e[0][1] * e[1][0]) / det;
        double a0[4]; /* lambda at the eye (t = 0) */
        for (int j = 0; j < 3; j++)
            a0[j] = -(inv[j][0] * v[3][0] + inv[j][1] * v[3][1] + inv[j][2] * v[3][2]);
        a0[3] = 1 - a0[0] - a0[1] - a0[2];
        cnt.cells_scanned++;
        for (int y = by0; y <= by1; y++) {
            double dy = (((y + 0.5) / H) * 2 - 1 + iy0) / P[5];
            for (int x = bx0; x <= bx1; x++) {
                double dx = (((x + 0.5) / W) * 2 - 1 + ix0) / P[0];
                double inl = 1.0 / sqrt(dx * dx + dy * dy + 1.0);
                double d[3] = {dx * inl, dy * inl, -inl};
                double b[4];
                for (int j = 0; j < 3; j++)
                    b[j] = inv[j][0] * d[0] + inv[j][1] * d[1] + inv[j][2] * d[2];
                b[3] = -b[0] - b[1] - b[2];
                double tin = near_d / inl, tout = INFINITY; /* near plane as ray distance */
                int empty = 0;
                for (int j = 0; j < 4 && !empty; j++) {
                    if (b[j] > 0) {
                        double tt = -a0[j] / b[j];
                        if (tt > tin) tin = tt;
                    } else if (b[j] < 0) {
                        double tt = -a0[j] / b[j];
                        if (tt < tout) tout = tt;
                    } else if (a0[j] < 0) {
                        empty = 1;
                    }
                }
                size_t pix = (size_t)y * W + x;
                if (opts->max_dist && opts->max_dist[pix] < tout)
                    tout = opts->max_dist[pix];
                if (empty || !(tout > tin))
                    continue;
                double sf = 0, sb = 0;
                for (int j = 0; j < 4; j++) {
                    sf += (a0[j] + b[j] * tin) * s[j];
                    sb += (a0[j] + b[j] * tout) * s[j];
                }
                /* colour and extinction at the segment midpoint scalar; the opacity is
                 * corrected for the segment's thickness: alpha = 1 - exp(-tau * length) */
                double tau, rgb[3];
                tf_eval(tf, 0.5 * (sf + sb), &tau, rgb);
                double alpha = 1.0 - exp(-tau * (tout - tin));
                seg sg = {(float)tin, (float)tout, (float)(rgb[0] * alpha),
                          (float)(rgb[1] * alpha), (float)(rgb[2] * alpha), (float)alpha, -1};
                cnt.segments_made++;
                if (insert_seg(&pool, &heads[pix], sg, opts->partial_composite,
                               opts->ert_threshold, &cnt.segments_merged) != 0) {
                    snprintf(err, 256, "tet_render: out of memory at %zu segments", pool.n);
                    rc = VFX_ERR_OUT_OF_MEMORY;
                    goto done;
                }
            }
        }
    }
    cnt.t_sc_ms = now_ms() - t0 - cnt.t_update_ms;
    double tc = now_ms();
    for (size_t i = 0; i < (size_t)W * H; i++) {
        seg acc = {0, 0, 0, 0, 0, 0, -1};
        for (int32_t c = heads[i]; c >= 0; c = pool.s[c].next)
            over(&acc, &pool.s[c]);
        rgba[4 * i + 0] = acc.r;
        rgba[4 * i + 1] = acc.g;
        rgba[4 * i + 2] = acc.b;
        rgba[4 * i + 3] = acc.a;
    }
    cnt.t_composite_ms = now_ms() - tc;
done:
    if (counters)
        *counters = cnt;
    free(vp);
    free(heads);
    free(keys);
    free(tiles);
    free(pool.s);
    return rc;
}
