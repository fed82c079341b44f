/* tet_scan.c — scan conversion of one tetrahedron into per-pixel ray segments (seed 002, 2.1):
 * load the cell, bound it on screen (and skip it when the ERT table proves it hidden), set up
 * its barycentric coordinates as functions of the ray, then per covered row and pixel find the
 * ray's entry and exit, integrate the transfer function over that piece and insert it. */
#include "tet_engine.h"

#include <math.h>
#include <stdlib.h>

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

/* One cell being scanned: its vertices, screen box and ray set-up. */
typedef struct cell {
    double v[4][3], s[4], spx[4], spy[4];
    int behind;                     /* vertices at or behind the near plane */
    int bx0, by0, bx1, by1;         /* pixel box */
    double inv[3][3];               /* inverse of the edge matrix: barycentrics from positions */
    double a0[4];                   /* barycentrics at the eye */
    double gnorm[4];                /* |grad lambda_j|_1 */
    unsigned on_face, owns;         /* faces whose plane holds the eye; those that take the ray */
    double S0;                      /* scalar at the eye (extrapolated) */
} cell;

/* Step 1: the cell's four view-space vertices; returns how many are behind the near plane. */
static int cell_load(const scan_ctx *X, uint32_t c, cell *C)
{
    const uint32_t *t = &X->mesh->tets[4 * c];
    int behind = 0;
    for (int j = 0; j < 4; j++) {
        const pvert *q = &X->vp[t[j]];
        C->v[j][0] = q->x;
        C->v[j][1] = q->y;
        C->v[j][2] = q->z;
        C->s[j] = q->s;
        C->spx[j] = q->px;
        C->spy[j] = q->py;
        if (-C->v[j][2] <= X->near_d)
            behind++;
    }
    C->behind = behind;
    return behind;
}

/* Step 2: the pixel box (the whole screen for a cell crossing the near plane), and
 * Conservative Subscreen Termination: every tile the box touches is terminated in front of
 * the cell. Returns 1 when the cell covers pixels and is not proven hidden. */
static int cell_bbox(const scan_ctx *X, worker *w, const cellkey *key, cell *C)
{
    const int W = X->W, H = X->H, D = X->D;
    C->bx0 = 0, C->by0 = 0, C->bx1 = W - 1, C->by1 = H - 1;
    if (C->behind) {
        w->cnt.cells_near_crossing++;
        return 1;
    }
    double mnx = INFINITY, mxx = -INFINITY, mny = INFINITY, mxy = -INFINITY;
    for (int j = 0; j < 4; j++) {
        double px = C->spx[j], py = C->spy[j];
        if (px < mnx) mnx = px;
        if (px > mxx) mxx = px;
        if (py < mny) mny = py;
        if (py > mxy) mxy = py;
    }
    if (mxx < 0 || mxy < 0 || mnx > W - 1 || mny > H - 1)
        return 0; /* off screen */
    C->bx0 = mnx < 0 ? 0 : iceil(mnx);
    C->by0 = mny < 0 ? 0 : iceil(mny);
    C->bx1 = mxx > W - 1 ? W - 1 : ifloor(mxx);
    C->by1 = mxy > H - 1 ? H - 1 : ifloor(mxy);
    if (C->bx1 < C->bx0 || C->by1 < C->by0)
        return 0; /* falls between pixel centres */
    if (!X->opts->ert)
        return 1;
    int tx0 = C->bx0 * D / W, tx1 = C->bx1 * D / W, ty0 = C->by0 * D / H, ty1 = C->by1 * D / H;
    for (int ty = ty0; ty <= ty1; ty++)
        for (int tx = tx0; tx <= tx1; tx++) {
            const tile *tl = &w->tiles[ty * D + tx];
            if (!tl->terminated || !(tl->deepest < key->nearest))
                return 1;
        }
    w->cnt.cells_skipped_ert++;
    return 0;
}

/* Step 3: barycentric coordinates as affine functions of position (the inverse edge matrix)
 * and their values at the eye. Returns 0, or -1 for a zero-volume cell. */
static int cell_barycentrics(cell *C)
{
    double (*v)[3] = C->v;
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
            if (fabs(e[r][j]) > scale)
                scale = fabs(e[r][j]);
    if (!(fabs(det) > 1e-12 * scale * scale * scale))
        return -1;
    double (*inv)[3] = C->inv;
    const double idet = 1.0 / det; /* one division, not nine */
    inv[0][0] = (e[1][1] * e[2][2] - e[1][2] * e[2][1]) * idet;
    inv[0][1] = (e[0][2] * e[2][1] - e[0][1] * e[2][2]) * idet;
    inv[0][2] = (e[0][1] * e[1][2] - e[0][2] * e[1][1]) * idet;
    inv[1][0] = (e[1][2] * e[2][0] - e[1][0] * e[2][2]) * idet;
    inv[1][1] = (e[0][0] * e[2][2] - e[0][2] * e[2][0]) * idet;
    inv[1][2] = (e[0][2] * e[1][0] - e[0][0] * e[1][2]) * idet;
    inv[2][0] = (e[1][0] * e[2][1] - e[1][1] * e[2][0]) * idet;
    inv[2][1] = (e[0][1] * e[2][0] - e[0][0] * e[2][1]) * idet;
    inv[2][2] = (e[0][0] * e[1][1] - e[0][1] * e[1][0]) * idet;
    for (int j = 0; j < 3; j++) /* lambda at the eye (t = 0) */
        C->a0[j] = -(inv[j][0] * v[3][0] + inv[j][1] * v[3][1] + inv[j][2] * v[3][2]);
    C->a0[3] = 1 - C->a0[0] - C->a0[1] - C->a0[2];
    return 0;
}

/* Step 4: faces whose plane contains the eye project to a line; a pixel ray on that line runs
 * inside the face, where lambda_j is 0 all along and rounding decides whether the ray is in
 * the tet, so a shared face could be drawn twice or dropped. Tie rule (a symbolic
 * perturbation of the ray): the ray counts as inside exactly when the face's inward normal
 * (grad lambda_j) is lexicographically positive; the two tets sharing the face have opposite
 * normals, so exactly one of them takes the ray. Faces on the eye are rare: flagged here. */
static void cell_face_ties(cell *C)
{
    double g[4][3];
    for (int r = 0; r < 3; r++) {
        g[0][r] = C->inv[0][r];
        g[1][r] = C->inv[1][r];
        g[2][r] = C->inv[2][r];
        g[3][r] = -C->inv[0][r] - C->inv[1][r] - C->inv[2][r];
    }
    C->on_face = C->owns = 0;
    const double *v3 = C->v[3];
    for (int j = 0; j < 4; j++) {
        double ga = fabs(g[j][0]) + fabs(g[j][1]) + fabs(g[j][2]);
        C->gnorm[j] = ga;
        double ea = 1e-10 * (1.0 + fabs(g[j][0] * v3[0]) + fabs(g[j][1] * v3[1]) +
                             fabs(g[j][2] * v3[2]));
        if (fabs(C->a0[j]) > ea)
            continue;
        C->on_face |= 1u << j;
        int sign = 0;
        for (int r = 0; r < 3 && !sign; r++)
            if (fabs(g[j][r]) > 1e-9 * ga)
                sign = g[j][r] > 0 ? 1 : -1;
        if (sign > 0)
            C->owns |= 1u << j;
    }
}

/* Step 5: the footprint on row y is the convex hull of the projected vertices: its span is
 * [min, max] of the row's crossings of the 6 projected edges, widened by a little so a pixel
 * centre on an edge is still tested exactly by the ray. The edges' slopes are set up once per
 * cell (edges_setup), so a row costs no division. Narrows [*x0, *x1]; 0 when empty. */
typedef struct edges {
    double ylo[6], yhi[6];  /* the edge's y extent */
    double xa[6], ya[6];    /* its lower end */
    double slope[6];        /* dx / dy, or NAN for a horizontal edge */
    double xb[6];           /* its other end's x (a horizontal edge covers [xa, xb]) */
} edges;

static void edges_setup(const cell *C, edges *E)
{
    int e = 0;
    for (int j = 0; j < 4; j++)
        for (int k = j + 1; k < 4; k++, e++) {
            int lo = C->spy[j] <= C->spy[k] ? j : k, hi = lo == j ? k : j;
            E->ylo[e] = C->spy[lo];
            E->yhi[e] = C->spy[hi];
            E->xa[e] = C->spx[lo];
            E->ya[e] = C->spy[lo];
            E->xb[e] = C->spx[hi];
            double dy = C->spy[hi] - C->spy[lo];
            E->slope[e] = dy > 0 ? (C->spx[hi] - C->spx[lo]) / dy : NAN;
        }
}

static int row_span(const edges *E, int y, int *x0, int *x1)
{
    double lo = INFINITY, hi = -INFINITY;
    for (int e = 0; e < 6; e++) {
        if (!(E->ylo[e] <= y && y <= E->yhi[e]))
            continue;
        double xa, xb;
        if (E->slope[e] != E->slope[e]) { /* horizontal, on this row */
            xa = E->xa[e];
            xb = E->xb[e];
        } else {
            xa = xb = E->xa[e] + E->slope[e] * (y - E->ya[e]);
        }
        if (xa < lo) lo = xa;
        if (xb < lo) lo = xb;
        if (xa > hi) hi = xa;
        if (xb > hi) hi = xb;
    }
    if (!(hi >= lo))
        return 0;
    double pad = 1e-6 * (1.0 + fabs(lo) + fabs(hi));
    lo -= pad;
    hi += pad;
    if (lo > *x1 || hi < *x0) /* off the box: also keeps iceil/ifloor within int (fuzz_tet_render) */
        return 0;
    if (lo > *x0) *x0 = iceil(lo);
    if (hi < *x1) *x1 = ifloor(hi);
    return *x1 >= *x0;
}

/* Step 6: the ray p(t) = t (dx, dy, -1) enters and leaves the cell where a barycentric
 * coordinate a0 + t b crosses 0. Returns 1 with [*tin, *tout] (view depth, from the near
 * plane on) when the ray crosses the cell. */
static int ray_interval(const cell *C, const double b[4], double dx, double dy, double near_d,
                        double *tin, double *tout)
{
    /* entry max(near_d, -a0_j / b_j over b_j > 0), exit min(-a0_j / b_j over b_j < 0), kept as
     * fractions n / d (d > 0) compared by cross-multiplication: two divisions instead of four */
    double n0 = near_d, d0 = 1.0, n1 = 0, d1 = 0;
    int exit_set = 0;
    for (int j = 0; j < 4; j++) {
        const double bj = b[j], aj = C->a0[j];
        if ((C->on_face >> j & 1u) &&
            fabs(bj) <= 1e-10 * C->gnorm[j] * (fabs(dx) + fabs(dy) + 1.0)) {
            if (!(C->owns >> j & 1u))
                return 0;
            continue; /* inside this face's half-space by the tie rule */
        }
        if (bj > 0) {
            if (-aj * d0 > n0 * bj) {
                n0 = -aj;
                d0 = bj;
            }
        } else if (bj < 0) {
            if (!exit_set || aj * d1 < n1 * -bj) {
                n1 = aj;
                d1 = -bj;
                exit_set = 1;
            }
        } else if (aj < 0) {
            return 0;
        }
    }
    const double t0 = n0 / d0, t1 = exit_set ? n1 / d1 : INFINITY;
    *tin = t0;
    *tout = t1;
    return t1 > t0;
}

/* Reserves a pool slot (written when it stops being its pixel's hint). */
static int32_t pool_reserve(seg_pool *p)
{
    if (p->n == p->cap) {
        size_t nc = p->cap ? p->cap * 2 : 4096;
        seg *ns = realloc(p->s, nc * sizeof *ns);
        if (!ns)
            return -1;
        p->s = ns;
        p->cap = nc;
    }
    return (int32_t)p->n++;
}

/* Makes idx the hint of L: the old hint's live copy goes back to its pool slot and idx's
 * current contents (at src) become the live copy. */
static inline void set_hint(seg_pool *p, pixel_list *L, int32_t idx, const seg *src)
{
    if (idx == L->hint)
        return;
    seg cur = *src;
    if (L->hint >= 0)
        p->s[L->hint] = L->open;
    L->open = cur;
    L->hint = idx;
}

/* Inserts v into pixel list L in order of zf; with partial set, merges it with a touching
 * neighbour (the paper's partial compositing, 2.1: a merged segment is again a segment), never
 * growing a segment past stop. Here, not in tet_composite.c, so that v stays in registers (passed
 * through the stack it was stored as floats and reloaded as vectors, a forwarding stall).
 * Returns 0, or -1 when out of memory. */
static inline int insert_seg(seg_pool *p, pixel_list *L, seg v, int partial, float stop,
                             uint64_t *merged)
{
    const int32_t h = L->hint;
    seg *const open = &L->open;
    int32_t prev = -1, cur = L->head;
#define SEG(i) ((i) == h ? open : &p->s[i])
    /* cells arrive roughly front to back, so the pixel's last inserted segment is usually just
     * in front of the new one: start the walk there. It is always linked: the only unlink (the
     * chain merge below) happens in an insertion, which then makes the survivor the hint. */
    if (h >= 0 && open->zf < v.zf) {
        prev = h;
        cur = open->next;
    }
    while (cur >= 0 && SEG(cur)->zf < v.zf) {
        prev = cur;
        cur = SEG(cur)->next;
    }
    if (partial) {
        float eps = TET_TOUCH_EPS * (1.0f + fabsf(v.zf));
        /* never grow a segment that is already opaque past the ERT threshold: its z_back is
         * where the pixel terminated, and growing it would push the termination depth back */
        if (prev >= 0 && SEG(prev)->a < stop && fabsf(SEG(prev)->zb - v.zf) <= eps) {
            seg *ps = SEG(prev);
            tet_over(ps, &v);
            ps->zb = v.zb;
            (*merged)++;
            /* the grown segment may now touch its successor */
            if (cur >= 0 && ps->a < stop && fabsf(ps->zb - SEG(cur)->zf) <= eps) {
                const seg *cs = SEG(cur);
                tet_over(ps, cs);
                ps->zb = cs->zb;
                ps->next = cs->next;
            }
            set_hint(p, L, prev, ps);
            return 0;
        }
        if (cur >= 0 && v.a < stop && fabsf(v.zb - SEG(cur)->zf) <= eps) {
            seg *cs = SEG(cur);
            seg m = v;
            tet_over(&m, cs);
            m.zb = cs->zb;
            m.next = cs->next;
            *cs = m;
            (*merged)++;
            set_hint(p, L, cur, cs);
            return 0;
        }
    }
    v.next = cur;
    int32_t idx = pool_reserve(p);
    if (idx < 0)
        return -1;
    if (prev >= 0)
        SEG(prev)->next = idx;
    else
        L->head = idx;
#undef SEG
    if (h >= 0)
        p->s[h] = *open;
    *open = v;
    L->hint = idx;
    return 0;
}

/* Step 7: the segment [tin, tout] of pixel pix (ray length per unit depth L, scalar S0 + Sb t
 * along it), clipped by the host's depth, integrated through the transfer function and
 * inserted into the pixel's list. Returns 0, or -1 when out of memory. */
static int emit_segment(const scan_ctx *X, worker *w, size_t pix, double tin, double tout,
                        double L, double S0, double Sb)
{
    const tet_options *opts = X->opts;
    if (opts->max_dist && opts->max_dist[pix] < tout * L) {
        tout = opts->max_dist[pix] / L;
        if (!(tout > tin))
            return 0;
    }
    float c[4];
    w->cnt.tf_pieces += (uint64_t)tet_tf_segment(X->tf, S0, Sb, tin, tout, L, c);
    seg sg = {(float)(tin * L), (float)(tout * L), c[0], c[1], c[2], c[3], -1};
    w->cnt.segments_made++;
    return insert_seg(&w->pool, &w->px[pix], sg, opts->partial_composite,
                          opts->ert_threshold, &w->cnt.segments_merged);
}

int tet_scan_cell(const scan_ctx *X, worker *w, const cellkey *key)
{
    cell C;
    if (cell_load(X, key->id, &C) == 4) {
        w->cnt.cells_behind++;
        return 0;
    }
    if (!cell_bbox(X, w, key, &C))
        return 0;
    if (cell_barycentrics(&C) != 0) {
        w->cnt.cells_degenerate++;
        return 0;
    }
    cell_face_ties(&C);
    w->cnt.cells_scanned++;
    /* Per pixel the ray is p(t) = t * (dx, dy, -1), t = view depth, so each barycentric
     * coordinate is a0 + t * b with b affine in dx along a row: b is stepped, not recomputed.
     * The scalar along the ray is S0 + t * Sb with Sb stepped the same way. */
    const float *P = X->P;
    const int W = X->W, H = X->H;
    const double ix0 = P[8], iy0 = P[9];
    double S0 = 0;
    for (int j = 0; j < 4; j++)
        S0 += C.a0[j] * C.s[j];
    const double ddx = 2.0 / (W * (double)P[0]);
    edges E;
    if (!C.behind)
        edges_setup(&C, &E);
    for (int y = C.by0; y <= C.by1; y++) {
        int x0 = C.bx0, x1 = C.bx1;
        if (!C.behind && !row_span(&E, y, &x0, &x1))
            continue;
        const double dy = (((y + 0.5) / H) * 2 - 1 + iy0) / P[5];
        double dx = (((x0 + 0.5) / W) * 2 - 1 + ix0) / P[0];
        double b[4], bstep[4], Sb = 0, Sbstep = 0;
        for (int j = 0; j < 3; j++) {
            b[j] = C.inv[j][0] * dx + C.inv[j][1] * dy - C.inv[j][2];
            bstep[j] = C.inv[j][0] * ddx;
        }
        b[3] = -b[0] - b[1] - b[2];
        bstep[3] = -bstep[0] - bstep[1] - bstep[2];
        for (int j = 0; j < 4; j++) {
            Sb += b[j] * C.s[j];
            Sbstep += bstep[j] * C.s[j];
        }
        for (int x = x0; x <= x1; x++, dx += ddx, Sb += Sbstep) {
            if (x > x0)
                for (int j = 0; j < 4; j++)
                    b[j] += bstep[j];
            double tin, tout;
            if (!ray_interval(&C, b, dx, dy, X->near_d, &tin, &tout))
                continue;
            /* ray distance = view depth * |(dx, dy, -1)| */
            const double L = sqrt(dx * dx + dy * dy + 1.0);
            if (emit_segment(X, w, (size_t)y * W + x, tin, tout, L, S0, Sb) != 0)
                return -1;
        }
    }
    return 0;
}
