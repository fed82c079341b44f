/* tet_render.c — cell projection with per-pixel ray-segment lists, partial compositing and
 * Conservative Subscreen Termination (seed 002, sections 2.1, 3.1, 3.2, 4.3.2), on N threads. */
#if !defined(_POSIX_C_SOURCE) && !defined(_GNU_SOURCE)
#define _POSIX_C_SOURCE 199309L
#endif
#include "tet_render.h"
#include "tet_render_internal.h"
#include "tet_clock.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <pthread.h>

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
static int insert_seg(seg_pool *p, int32_t *head, int32_t *hint, seg v, int partial,
                      float stop, uint64_t *merged)
{
    int32_t prev = -1, cur = *head;
    /* cells arrive roughly front to back, so the pixel's last inserted segment is usually just
     * in front of the new one: start the walk there. It is always linked: the only unlink (the
     * chain merge below) happens in an insertion, which then points the hint at the survivor. */
    if (*hint >= 0 && p->s[*hint].zf < v.zf) {
        prev = *hint;
        cur = p->s[prev].next;
    }
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
            *hint = prev;
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
            *hint = cur;
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
    *hint = idx;
    return 0;
}

static void tf_eval(const tet_tf *tf, double s, double *tau, double rgb[3])
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

/* A vertex in view space with its scalar and, when in front of the eye, its pixel coordinates:
 * packed so a cell's four vertices cost four cache lines at most (cells are visited in depth
 * order, so vertex accesses are scattered). */
typedef struct pvert {
    double x, y, z, s, px, py;
} pvert;

/* floor/ceil without the libm call (no SSE4.1 rounding by default); |v| < 2^31 here */
static inline int ifloor(double v)
{
    int i = (int)v;
    return i - (v < i);
}

static inline int iceil(double v)
{
    int i = (int)v;
    return i + (v > i);
}

/* Transforms every point to view space with its scalar and, in front of the eye, its pixel
 * coordinates (pixel k's centre at k). Shared by the threaded path and the MPI engine so both
 * see bit-identical vertices. */
static void view_vertices(const tet_mesh *mesh, const float *V, const float *P, int W, int H,
                          pvert *vp)
{
    for (uint32_t i = 0; i < mesh->point_count; i++) {
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

typedef struct scan_ctx {
    const tet_mesh *mesh;
    const tet_tf *tf;
    const tet_options *opts;
    const pvert *vp;
    const float *P;
    double near_d;
    int W, H, D;
} scan_ctx;

/* Each worker on its own cache lines: its counters are written per segment, and a neighbour
 * sharing the line would read its pool and list pointers through a line bouncing between cores
 * (false sharing). */
typedef struct worker {
    _Alignas(64) seg_pool pool;
    int32_t *heads;
    int32_t *hints;         /* per pixel: the segment last inserted (a walk start), or -1 */
    tile *tiles;            /* local ERT table */
    tet_counters cnt;
    uint32_t next, end;     /* remaining cells: keys[next..end), guarded by lock */
    pthread_mutex_t lock;
    int failed;
    struct shared *sh;
} worker;

typedef struct shared {
    const scan_ctx *X;
    const cellkey *keys;
    worker *w;
    int nw;
    tile *table;            /* the shared ERT table (weak sharing) */
    pthread_mutex_t lock;
} shared;

/* Scan-converts one cell into the worker's lists unless CST proves it hidden.
 * Returns 0, or -1 when out of memory. */
static int scan_cell(const scan_ctx *X, worker *w, const cellkey *key)
{
    const tet_mesh *mesh = X->mesh;
    const tet_tf *tf = X->tf;
    const tet_options *opts = X->opts;
    const pvert *vp = X->vp;
    const float *P = X->P;
    const double near_d = X->near_d, ix0 = P[8], iy0 = P[9];
    const int W = X->W, H = X->H, D = X->D, ert = opts->ert;
    uint32_t c = key->id;
    const uint32_t *t = &mesh->tets[4 * c];
    double v[4][3], s[4], spx[4] = {0}, spy[4] = {0};
    int behind = 0;
    for (int j = 0; j < 4; j++) {
        const pvert *q = &vp[t[j]];
        v[j][0] = q->x;
        v[j][1] = q->y;
        v[j][2] = q->z;
        s[j] = q->s;
        spx[j] = q->px;
        spy[j] = q->py;
        if (-v[j][2] <= near_d)
            behind++;
    }
    if (behind == 4) {
        w->cnt.cells_behind++;
        return 0;
    }
    /* screen bounding box; a cell crossing the near plane may cover anything */
    int bx0 = 0, by0 = 0, bx1 = W - 1, by1 = H - 1;
    if (behind) {
        w->cnt.cells_near_crossing++;
    } else {
        double mnx = INFINITY, mxx = -INFINITY, mny = INFINITY, mxy = -INFINITY;
        for (int j = 0; j < 4; j++) {
            double px = spx[j], py = spy[j];
            if (px < mnx) mnx = px;
            if (px > mxx) mxx = px;
            if (py < mny) mny = py;
            if (py > mxy) mxy = py;
        }
        if (mxx < 0 || mxy < 0 || mnx > W - 1 || mny > H - 1)
            return 0; /* off screen */
        bx0 = mnx < 0 ? 0 : iceil(mnx);
        by0 = mny < 0 ? 0 : iceil(mny);
        bx1 = mxx > W - 1 ? W - 1 : ifloor(mxx);
        by1 = mxy > H - 1 ? H - 1 : ifloor(mxy);
        if (bx1 < bx0 || by1 < by0)
            return 0; /* falls between pixel centres */
        if (ert) {
            /* CST: every tile the bbox touches is terminated in front of the cell */
            int tx0 = bx0 * D / W, tx1 = bx1 * D / W, ty0 = by0 * D / H, ty1 = by1 * D / H;
            int skip = 1;
            for (int ty = ty0; ty <= ty1 && skip; ty++)
                for (int tx = tx0; tx <= tx1; tx++) {
                    const tile *tl = &w->tiles[ty * D + tx];
                    if (!tl->terminated || !(tl->deepest < key->nearest)) {
                        skip = 0;
                        break;
                    }
                }
            if (skip) {
                w->cnt.cells_skipped_ert++;
                return 0;
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
        w->cnt.cells_degenerate++;
        return 0;
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
    /* A face whose plane contains the eye projects to a line; a pixel ray on that line runs
     * inside the face, where lambda_j is 0 all along and rounding decides whether the ray is in
     * the tet, so a shared face could be drawn twice or dropped. Tie rule (a symbolic
     * perturbation of the ray): the ray counts as inside exactly when the face's inward normal
     * (grad lambda_j) is lexicographically positive; the two tets sharing the face have opposite
     * normals, so exactly one of them takes the ray. Faces on the eye are rare: flagged here. */
    double g[4][3];
    for (int r = 0; r < 3; r++) {
        g[0][r] = inv[0][r];
        g[1][r] = inv[1][r];
        g[2][r] = inv[2][r];
        g[3][r] = -inv[0][r] - inv[1][r] - inv[2][r];
    }
    unsigned on_face = 0, owns = 0;
    double gnorm[4];
    for (int j = 0; j < 4; j++) {
        double ga = fabs(g[j][0]) + fabs(g[j][1]) + fabs(g[j][2]);
        gnorm[j] = ga;
        double ea = 1e-10 * (1.0 + fabs(g[j][0] * v[3][0]) + fabs(g[j][1] * v[3][1]) +
                             fabs(g[j][2] * v[3][2]));
        if (fabs(a0[j]) > ea)
            continue;
        on_face |= 1u << j;
        int sign = 0;
        for (int r = 0; r < 3 && !sign; r++)
            if (fabs(g[j][r]) > 1e-9 * ga)
                sign = g[j][r] > 0 ? 1 : -1;
        if (sign > 0)
            owns |= 1u << j;
    }
    w->cnt.cells_scanned++;
    /* Per pixel the ray is p(t) = t * (dx, dy, -1), t = view depth, so each barycentric
     * coordinate is a0 + t * b with b affine in dx along a row: b is stepped, not recomputed.
     * The scalar along the ray is S0 + t * Sb with Sb stepped the same way. */
    double S0 = 0;
    for (int j = 0; j < 4; j++)
        S0 += a0[j] * s[j];
    const double ddx = 2.0 / (W * (double)P[0]);
    for (int y = by0; y <= by1; y++) {
        int x0 = bx0, x1 = bx1;
        if (!behind) {
            /* the footprint is the convex hull of the projected vertices: its span on this
             * row is [min, max] of the row's crossings of the 6 projected edges, widened by a
             * little so a pixel centre on an edge is still tested exactly below */
            double lo = INFINITY, hi = -INFINITY;
            for (int j = 0; j < 4; j++)
                for (int k = j + 1; k < 4; k++) {
                    double yj = spy[j] - y, yk = spy[k] - y;
                    if ((yj > 0 && yk > 0) || (yj < 0 && yk < 0))
                        continue;
                    double xa, xb;
                    if (yj == yk) {
                        xa = spx[j];
                        xb = spx[k];
                    } else {
                        xa = xb = spx[j] + (spx[k] - spx[j]) * (yj / (yj - yk));
                    }
                    if (xa < lo) lo = xa;
                    if (xb < lo) lo = xb;
                    if (xa > hi) hi = xa;
                    if (xb > hi) hi = xb;
                }
            if (!(hi >= lo))
                continue;
            double pad = 1e-6 * (1.0 + fabs(lo) + fabs(hi));
            lo -= pad;
            hi += pad;
            if (lo > x0) x0 = iceil(lo);
            if (hi < x1) x1 = ifloor(hi);
            if (x1 < x0)
                continue;
        }
        const double dy = (((y + 0.5) / H) * 2 - 1 + iy0) / P[5];
        double dx = (((x0 + 0.5) / W) * 2 - 1 + ix0) / P[0];
        double b[4], bstep[4], Sb = 0, Sbstep = 0;
        for (int j = 0; j < 3; j++) {
            b[j] = inv[j][0] * dx + inv[j][1] * dy - inv[j][2];
            bstep[j] = inv[j][0] * ddx;
        }
        b[3] = -b[0] - b[1] - b[2];
        bstep[3] = -bstep[0] - bstep[1] - bstep[2];
        for (int j = 0; j < 4; j++) {
            Sb += b[j] * s[j];
            Sbstep += bstep[j] * s[j];
        }
        for (int x = x0; x <= x1; x++, dx += ddx, Sb += Sbstep) {
            if (x > x0)
                for (int j = 0; j < 4; j++)
                    b[j] += bstep[j];
            double tin = near_d, tout = INFINITY; /* the near plane as view depth */
            int empty = 0;
            for (int j = 0; j < 4; j++) {
                if ((on_face >> j & 1u) &&
                    fabs(b[j]) <= 1e-10 * gnorm[j] * (fabs(dx) + fabs(dy) + 1.0)) {
                    if (!(owns >> j & 1u))
                        empty = 1;
                    continue; /* inside this face's half-space by the tie rule */
                }
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
            if (empty || !(tout > tin))
                continue;
            /* ray distance = view depth * |(dx, dy, -1)| */
            const double L = sqrt(dx * dx + dy * dy + 1.0);
            size_t pix = (size_t)y * W + x;
            if (opts->max_dist && opts->max_dist[pix] < tout * L) {
                tout = opts->max_dist[pix] / L;
                if (!(tout > tin))
                    continue;
            }
            /* colour and extinction at the segment midpoint scalar; the opacity is
             * corrected for the segment's thickness: alpha = 1 - exp(-tau * length) */
            double tau, rgb[3];
            tf_eval(tf, S0 + Sb * 0.5 * (tin + tout), &tau, rgb);
            /* float32 exp: alpha is stored as a float anyway */
            double alpha = 1.0 - (double)expf((float)(-tau * (tout - tin) * L));
            seg sg = {(float)(tin * L), (float)(tout * L), (float)(rgb[0] * alpha),
                      (float)(rgb[1] * alpha), (float)(rgb[2] * alpha), (float)alpha, -1};
            w->cnt.segments_made++;
            if (insert_seg(&w->pool, &w->heads[pix], &w->hints[pix], sg, opts->partial_composite,
                           opts->ert_threshold, &w->cnt.segments_merged) != 0) {
                return -1;
            }
        }
    }
    return 0;
}

/* Rebuilds the worker's table from its own lists (paper 3.1.1), then, with sharing on, merges
 * it with the shared one entry by entry: the terminated entry with the smallest deepest wins
 * (paper 3.2). Another worker's termination is valid here: our segments only add opacity. */
static void update_table(shared *sh, worker *w)
{
    const scan_ctx *X = sh->X;
    const int W = X->W, H = X->H, D = X->D;
    double tu = tet_now_ms();
    for (int ty = 0; ty < D; ty++)
        for (int tx = 0; tx < D; tx++) {
            int x0 = tx * W / D, x1 = (tx + 1) * W / D;
            int y0 = ty * H / D, y1 = (ty + 1) * H / D;
            int term = 1;
            float deep = 0;
            for (int y = y0; y < y1 && term; y++)
                for (int x = x0; x < x1; x++) {
                    float z = pixel_termination(&w->pool, w->heads[(size_t)y * W + x],
                                                X->opts->ert_threshold);
                    if (z < 0) { term = 0; break; }
                    if (z > deep) deep = z;
                }
            w->tiles[ty * D + tx].terminated = term && x1 > x0 && y1 > y0;
            w->tiles[ty * D + tx].deepest = deep;
        }
    if (X->opts->share && sh->nw > 1) {
        pthread_mutex_lock(&sh->lock);
        for (int i = 0; i < D * D; i++) {
            tile *l = &w->tiles[i], *s = &sh->table[i];
            if (s->terminated && (!l->terminated || s->deepest < l->deepest))
                *l = *s;
            else if (l->terminated)
                *s = *l;
        }
        pthread_mutex_unlock(&sh->lock);
    }
    w->cnt.table_updates++;
    w->cnt.t_update_ms += tet_now_ms() - tu;
}

/* Dynamic load balancing (paper 4.3.2): take 1/3 of the remaining cells of the most loaded
 * worker, from the back of its (front-to-back sorted) range. Returns 1 when work was taken. */
static int steal(shared *sh, worker *self)
{
    for (;;) {
        int best = -1;
        uint32_t most = 0;
        for (int i = 0; i < sh->nw; i++) {
            worker *v = &sh->w[i];
            if (v == self) continue;
            pthread_mutex_lock(&v->lock);
            uint32_t rem = v->end - v->next;
            pthread_mutex_unlock(&v->lock);
            if (rem > most) { most = rem; best = i; }
        }
        if (best < 0 || most < 2)
            return 0;
        worker *v = &sh->w[best];
        pthread_mutex_lock(&v->lock);
        uint32_t rem = v->end - v->next;
        uint32_t n = rem / 3 ? rem / 3 : (rem >= 2 ? 1 : 0);
        if (n == 0) { pthread_mutex_unlock(&v->lock); continue; }
        uint32_t e = v->end;
        v->end -= n;
        pthread_mutex_unlock(&v->lock);
        pthread_mutex_lock(&self->lock);
        self->next = e - n;
        self->end = e;
        pthread_mutex_unlock(&self->lock);
        return 1;
    }
}

static void *worker_main(void *arg)
{
    worker *w = arg;
    shared *sh = w->sh;
    const scan_ctx *X = sh->X;
    const int ert = X->opts->ert;
    const uint32_t C = X->opts->update_c > 0 ? (uint32_t)X->opts->update_c : 1;
    double t0 = tet_now_ms(), c0 = tet_thread_cpu_ms();
    pthread_mutex_lock(&w->lock);
    uint32_t rem0 = w->end - w->next;
    pthread_mutex_unlock(&w->lock);
    uint32_t next_update = ert ? (rem0 / C > 0 ? rem0 / C : 1) : UINT32_MAX, since = 0;
    for (;;) {
        pthread_mutex_lock(&w->lock);
        if (w->next >= w->end) {
            pthread_mutex_unlock(&w->lock);
            if (X->opts->dlb && sh->nw > 1 && steal(sh, w))
                continue;
            break;
        }
        uint32_t k = w->next++;
        uint32_t rem = w->end - w->next;
        pthread_mutex_unlock(&w->lock);
        if (ert && since >= next_update) {
            update_table(sh, w);
            next_update = rem / C > 0 ? rem / C : 1;
            since = 0;
        }
        since++;
        if (scan_cell(X, w, &sh->keys[k]) != 0) {
            w->failed = 1;
            break;
        }
    }
    w->cnt.t_sc_ms = tet_now_ms() - t0 - w->cnt.t_update_ms;
    w->cnt.cpu_ms = tet_thread_cpu_ms() - c0;
    return NULL;
}

typedef struct comp_job {
    const shared *sh;
    float *rgba;
    int y0, y1;
} comp_job;

/* Final composition (paper fig. 4): per pixel, the workers' lists are merged in depth order
 * and composited front to back; screen rows are split between threads. */
static void *composite_main(void *arg)
{
    comp_job *j = arg;
    const shared *sh = j->sh;
    const int W = sh->X->W, nw = sh->nw;
    int32_t cur[64];
    for (int y = j->y0; y < j->y1; y++)
        for (int x = 0; x < W; x++) {
            size_t pix = (size_t)y * W + x;
            for (int i = 0; i < nw; i++)
                cur[i] = sh->w[i].heads[pix];
            seg acc = {0, 0, 0, 0, 0, 0, -1};
            for (;;) {
                int bi = -1;
                float bz = INFINITY;
                for (int i = 0; i < nw; i++)
                    if (cur[i] >= 0 && sh->w[i].pool.s[cur[i]].zf < bz) {
                        bz = sh->w[i].pool.s[cur[i]].zf;
                        bi = i;
                    }
                if (bi < 0) break;
                over(&acc, &sh->w[bi].pool.s[cur[bi]]);
                cur[bi] = sh->w[bi].pool.s[cur[bi]].next;
            }
            j->rgba[4 * pix + 0] = acc.r;
            j->rgba[4 * pix + 1] = acc.g;
            j->rgba[4 * pix + 2] = acc.b;
            j->rgba[4 * pix + 3] = acc.a;
        }
    return NULL;
}

int tet_render(const tet_mesh *mesh, const tet_camera *cam, const tet_tf *tf,
                   const tet_options *opts, float *rgba, tet_counters *counters,
                   char err[256])
{
    return tet_render_workers(mesh, cam, tf, opts, rgba, counters, NULL, err);
}

/* The checks both entry points make once their pointers are known non-NULL, in one order so
 * that both report the same first fault: image size, worker count (nw, at most 64), a scalar
 * field, a perspective projection. Sets *near_d to the near-plane distance the projection
 * implies (z_ndc = -1 at z = -near; 1e-4 when it implies none). */
static int check_view(const tet_mesh *mesh, const tet_camera *cam, int nw,
                      double *near_d, char err[256])
{
    const int W = cam->width, H = cam->height;
    if (W <= 0 || H <= 0 || W > 16384 || H > 16384) {
        snprintf(err, 256, "tet_render: image size %dx%d out of range", W, H);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    if (nw > 64) {
        snprintf(err, 256, "tet_render: %d workers requested, at most 64", nw);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    if (!mesh->scalar) {
        snprintf(err, 256, "tet_render: mesh has no scalar field");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    const float *P = cam->proj;
    if (P[11] > -0.5f || !(fabsf(P[0]) > 0) || !(fabsf(P[5]) > 0)) {
        snprintf(err, 256, "tet_render: projection is not a perspective matrix (P[11]=%g)",
                 (double)P[11]);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    *near_d = (double)P[14] / ((double)P[10] - 1.0);
    if (!(*near_d > 0)) *near_d = 1e-4;
    return VFX_OK;
}

int tet_render_workers(const tet_mesh *mesh, const tet_camera *cam,
                           const tet_tf *tf, const tet_options *opts, float *rgba,
                           tet_counters *counters, tet_counters *per_worker,
                           char err[256])
{
    tet_counters cnt;
    memset(&cnt, 0, sizeof cnt);
    if (counters) *counters = cnt;
    if (!mesh || !cam || !tf || !opts || !rgba) {
        snprintf(err, 256, "tet_render: NULL argument");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    const int W = cam->width, H = cam->height;
    const int nw = opts->workers <= 0 ? 1 : opts->workers;
    double near_d;
    int rc = check_view(mesh, cam, nw, &near_d, err);
    if (rc != VFX_OK)
        return rc;
    const float *P = cam->proj, *V = cam->view;

    const uint32_t np = mesh->point_count, nt = mesh->tet_count;
    const int D = opts->tiles_d > 0 ? opts->tiles_d : 1;
    pvert *vp = malloc((size_t)np * sizeof *vp + 1);
    cellkey *keys = malloc((size_t)(nt ? nt : 1) * sizeof *keys);
    cellkey *ktmp = malloc((size_t)(nt ? nt : 1) * sizeof *ktmp);
    worker *ws = aligned_alloc(64, (size_t)nw * sizeof *ws);
    if (ws)
        memset(ws, 0, (size_t)nw * sizeof *ws);
    tile *table = calloc((size_t)D * D, sizeof *table);
    uint32_t *bounds = calloc((size_t)nw + 1, sizeof *bounds);
    int nthreads = 0;
    pthread_t th[64];
    shared sh;
    memset(&sh, 0, sizeof sh);
    pthread_mutex_init(&sh.lock, NULL);
    if (!vp || !keys || !ktmp || !ws || !table || !bounds) {
        snprintf(err, 256, "tet_render: out of memory (%u points, %u tets)", np, nt);
        rc = VFX_ERR_OUT_OF_MEMORY;
        goto done;
    }
    for (int i = 0; i < nw; i++) {
        pthread_mutex_init(&ws[i].lock, NULL);
        ws[i].heads = malloc((size_t)W * H * sizeof *ws[i].heads);
        ws[i].hints = malloc((size_t)W * H * sizeof *ws[i].hints);
        ws[i].tiles = calloc((size_t)D * D, sizeof *ws[i].tiles);
        if (!ws[i].heads || !ws[i].hints || !ws[i].tiles) {
            snprintf(err, 256, "tet_render: out of memory for worker %d (%dx%d)", i, W, H);
            rc = VFX_ERR_OUT_OF_MEMORY;
            goto done;
        }
        for (size_t p = 0; p < (size_t)W * H; p++)
            ws[i].heads[p] = ws[i].hints[p] = -1;
    }
    view_vertices(mesh, V, P, W, H, vp);
    /* Initial assignment: contiguous ranges of the mesh's cell order (the data layout, which
     * keeps neighbouring cells on one worker as in the paper's fig. 8), each sorted front to
     * back by nearest depth (visibility cycles do no harm: pixel lists are depth sorted). */
    uint32_t nk = 0;
    for (int wi = 0; wi < nw; wi++) {
        uint32_t c0 = (uint32_t)((uint64_t)nt * wi / nw), c1 = (uint32_t)((uint64_t)nt * (wi + 1) / nw);
        uint32_t k0 = nk;
        for (uint32_t c = c0; c < c1; c++) {
            const uint32_t *t = &mesh->tets[4 * c];
            int bad = 0;
            float nearest = INFINITY;
            for (int k = 0; k < 4; k++) {
                if (t[k] >= np) {
                    snprintf(err, 256, "tet_render: tet %u references point %u of %u", c, t[k], np);
                    rc = VFX_ERR_INVALID_ARGUMENT;
                    goto done;
                }
                double z = -vp[t[k]].z;
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
        sort_keys(keys + k0, ktmp, nk - k0);
        ws[wi].next = k0;
        ws[wi].end = nk;
    }
    scan_ctx X = {mesh, tf, opts, vp, P, near_d, W, H, D};
    sh.X = &X;
    sh.keys = keys;
    sh.w = ws;
    sh.nw = nw;
    sh.table = table;
    for (int i = 0; i < nw; i++)
        ws[i].sh = &sh;
    if (nw == 1) {
        worker_main(&ws[0]);
    } else {
        for (; nthreads < nw; nthreads++)
            if (pthread_create(&th[nthreads], NULL, worker_main, &ws[nthreads]) != 0)
                break;
        if (nthreads < nw) /* run the ones that did not start here; DLB may already cover them */
            for (int i = nthreads; i < nw; i++)
                worker_main(&ws[i]);
        for (int i = 0; i < nthreads; i++)
            pthread_join(th[i], NULL);
    }
    for (int i = 0; i < nw; i++)
        if (ws[i].failed) {
            snprintf(err, 256, "tet_render: worker %d out of memory at %zu segments", i,
                     ws[i].pool.n);
            rc = VFX_ERR_OUT_OF_MEMORY;
            goto done;
        }
    double tc = tet_now_ms();
    comp_job jobs[64];
    int nj = 0;
    for (int i = 0; i < nw; i++) {
        jobs[i].sh = &sh;
        jobs[i].rgba = rgba;
        jobs[i].y0 = H * i / nw;
        jobs[i].y1 = H * (i + 1) / nw;
    }
    for (; nj < nw - 1; nj++)
        if (pthread_create(&th[nj], NULL, composite_main, &jobs[nj + 1]) != 0)
            break;
    for (int i = nj + 1; i < nw; i++)
        composite_main(&jobs[i]);
    composite_main(&jobs[0]);
    for (int i = 0; i < nj; i++)
        pthread_join(th[i], NULL);
    cnt.t_composite_ms = tet_now_ms() - tc;
done:
    if (ws) {
        for (int i = 0; i < nw; i++) {
            tet_counters *c = &ws[i].cnt;
            cnt.cells_scanned += c->cells_scanned;
            cnt.cells_skipped_ert += c->cells_skipped_ert;
            cnt.cells_behind += c->cells_behind;
            cnt.cells_near_crossing += c->cells_near_crossing;
            cnt.cells_degenerate += c->cells_degenerate;
            cnt.segments_made += c->segments_made;
            cnt.segments_merged += c->segments_merged;
            cnt.table_updates += c->table_updates;
            cnt.cpu_ms += c->cpu_ms;
            if (c->t_sc_ms > cnt.t_sc_ms) cnt.t_sc_ms = c->t_sc_ms;
            if (c->t_update_ms > cnt.t_update_ms) cnt.t_update_ms = c->t_update_ms;
            if (per_worker) per_worker[i] = *c;
            free(ws[i].heads);
            free(ws[i].hints);
            free(ws[i].tiles);
            free(ws[i].pool.s);
            pthread_mutex_destroy(&ws[i].lock);
        }
    }
    if (counters)
        *counters = cnt;
    pthread_mutex_destroy(&sh.lock);
    free(vp);
    free(keys);
    free(ktmp);
    free(ws);
    free(table);
    free(bounds);
    return rc;
}

/* ---- Single-worker scan engine for the MPI backend (tet_render_internal.h) ----
 * The set-up mirrors tet_render_workers (same checks, same partitions, same key order) so
 * that P processes partition the cells exactly as P threads would. Partition p's keys live at
 * [bounds[p], bounds[p] + valid[p]) whichever process builds them, so a key index means the
 * same cell on every process; only the own partition is built at creation, the others when
 * keys of theirs arrive by load balancing. */
struct tet_local {
    scan_ctx X;
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
    const tet_mesh *mesh = L->X.mesh;
    uint32_t c0 = L->bounds[p], c1 = L->bounds[p + 1], n = 0;
    for (uint32_t c = c0; c < c1; c++) {
        const uint32_t *t = &mesh->tets[4 * c];
        int bad = 0;
        float nearest = INFINITY;
        for (int k = 0; k < 4; k++) {
            double z = -L->vp[t[k]].z;
            if (isnan(z) || isnan(mesh->scalar[t[k]]))
                bad = 1;
            if (z < nearest)
                nearest = (float)z;
        }
        if (bad) {
            if (count)
                L->w.cnt.cells_nan++;
            continue;
        }
        L->keys[c0 + n].nearest = nearest;
        L->keys[c0 + n].id = c;
        n++;
    }
    sort_keys(L->keys + c0, L->ktmp, n);
    L->valid[p] = n;
    L->built[p] = 1;
}

int tet_local_create(const tet_mesh *mesh, const tet_camera *cam,
                         const tet_tf *tf, const tet_options *opts, int parts,
                         int own, tet_local **out, char err[256])
{
    *out = NULL;
    if (!mesh || !cam || !tf || !opts || parts <= 0 || own < 0 || own >= parts) {
        snprintf(err, 256, "tet_render: NULL argument or partition %d of %d", own, parts);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    const int W = cam->width, H = cam->height;
    double near_d;
    int rc = check_view(mesh, cam, 1, &near_d, err);
    if (rc != VFX_OK)
        return rc;
    const float *P = cam->proj, *V = cam->view;
    const uint32_t np = mesh->point_count, nt = mesh->tet_count;
    const int D = opts->tiles_d > 0 ? opts->tiles_d : 1;
    tet_local *L = calloc(1, sizeof *L);
    if (!L) {
        snprintf(err, 256, "tet_render: out of memory");
        return VFX_ERR_OUT_OF_MEMORY;
    }
    L->parts = parts;
    L->vp = malloc((size_t)np * sizeof *L->vp + 1);
    L->keys = malloc((size_t)(nt ? nt : 1) * sizeof *L->keys);
    L->ktmp = malloc((size_t)(nt ? nt : 1) * sizeof *L->ktmp);
    L->bounds = calloc((size_t)parts + 1, sizeof *L->bounds);
    L->valid = calloc((size_t)parts, sizeof *L->valid);
    L->built = calloc((size_t)parts, sizeof *L->built);
    L->w.heads = malloc((size_t)W * H * sizeof *L->w.heads);
    L->w.hints = malloc((size_t)W * H * sizeof *L->w.hints);
    L->w.tiles = calloc((size_t)D * D, sizeof *L->w.tiles);
    pthread_mutex_init(&L->w.lock, NULL);
    pthread_mutex_init(&L->sh.lock, NULL);
    if (!L->vp || !L->keys || !L->ktmp || !L->bounds || !L->valid || !L->built ||
        !L->w.heads || !L->w.hints || !L->w.tiles) {
        snprintf(err, 256, "tet_render: out of memory (%u points, %u tets, %dx%d)", np, nt, W, H);
        tet_local_destroy(L);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    for (size_t p = 0; p < (size_t)W * H; p++)
        L->w.heads[p] = L->w.hints[p] = -1;
    /* every index is checked on every process (cheap), so all report the same bad tet */
    for (uint32_t c = 0; c < nt; c++)
        for (int k = 0; k < 4; k++)
            if (mesh->tets[4 * c + k] >= np) {
                snprintf(err, 256, "tet_render: tet %u references point %u of %u", c,
                         mesh->tets[4 * c + k], np);
                tet_local_destroy(L);
                return VFX_ERR_INVALID_ARGUMENT;
            }
    view_vertices(mesh, V, P, W, H, L->vp);
    for (int pi = 0; pi <= parts; pi++)
        L->bounds[pi] = (uint32_t)((uint64_t)nt * pi / parts);
    scan_ctx X = {mesh, tf, opts, L->vp, P, near_d, W, H, D};
    L->X = X;
    L->sh.X = &L->X;
    L->sh.keys = L->keys;
    L->sh.w = &L->w;
    L->sh.nw = 1; /* update_table then never touches the shared table */
    L->w.sh = &L->sh;
    local_build(L, own, 1);
    *out = L;
    return VFX_OK;
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
    free(L->w.heads);
    free(L->w.hints);
    free(L->w.tiles);
    free(L->w.pool.s);
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
    return scan_cell(&L->X, &L->w, &L->keys[k]);
}

void tet_local_update_table(tet_local *L)
{
    update_table(&L->sh, &L->w);
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
        for (int32_t c = L->w.heads[p]; c >= 0; c = L->w.pool.s[c].next, n++)
            if (segs) {
                const seg *s = &L->w.pool.s[c];
                tet_rseg o = {s->zf, s->zb, s->r, s->g, s->b, s->a};
                segs[n] = o;
            }
    }
    offsets[p1 - p0] = (uint32_t)n;
    return n;
}

tet_counters *tet_local_counters(tet_local *L)
{
    return &L->w.cnt;
}
