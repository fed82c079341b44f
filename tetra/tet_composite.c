/* tet_composite.c — the per-pixel ray-segment lists: insertion in depth order with partial
 * compositing, the ERT tables built from them (seed 002, 3.1.1 and 3.2), and the final
 * front-to-back composite of every worker's lists (fig. 4). */
#if !defined(_POSIX_C_SOURCE) && !defined(_GNU_SOURCE)
#define _POSIX_C_SOURCE 199309L
#endif
#include "tet_engine.h"
#include "tet_clock.h"

#include <math.h>
#include <stdlib.h>

void tet_over(seg *f, const seg *b)
{
    float t = 1.0f - f->a;
    f->r += t * b->r;
    f->g += t * b->g;
    f->b += t * b->b;
    f->a += t * b->a;
}

/* Reserves a pool slot (its contents written later, when it stops being a pixel's hint). */
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

/* Makes idx the pixel's hint: the old hint's live copy goes back to its pool slot and idx's is
 * loaded into open (seg *src: where idx's current contents are, NULL for the pool slot). */
static void set_hint(seg_pool *p, int32_t *hint, seg *open, int32_t idx, const seg *src)
{
    if (idx == *hint)
        return;
    seg cur = src ? *src : p->s[idx];
    if (*hint >= 0)
        p->s[*hint] = *open;
    *open = cur;
    *hint = idx;
}

/* The paper's partial compositing: a merged segment is again a segment. */
int tet_insert_seg(seg_pool *p, int32_t *head, int32_t *hint, seg *open, seg v, int partial,
                   float stop, uint64_t *merged)
{
    const int32_t h = *hint;
    int32_t prev = -1, cur = *head;
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
            set_hint(p, hint, open, prev, ps);
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
            set_hint(p, hint, open, cur, cs);
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
        *head = idx;
#undef SEG
    if (h >= 0)
        p->s[h] = *open;
    *open = v;
    *hint = idx;
    return 0;
}

/* Paper 3.1.1: a pixel is terminated when the opacity of its known segments, composited as if
 * they were contiguous, reaches the threshold; gaps only add opacity, so this is conservative.
 * Returns the ray distance where it terminated, or -1. */
static float pixel_termination(const worker *w, size_t pix, float thr)
{
    float a = 0.0f;
    const int32_t h = w->hints[pix];
    for (int32_t c = w->heads[pix]; c >= 0;) {
        const seg *s = tet_seg_at(&w->pool, &w->open[pix], h, c);
        a += (1.0f - a) * s->a;
        if (a >= thr)
            return s->zb;
        c = s->next;
    }
    return -1.0f;
}

/* Rebuilds the worker's table from its own lists (paper 3.1.1), then, with sharing on, merges
 * it with the shared one entry by entry: the terminated entry with the smallest deepest wins
 * (paper 3.2). Another worker's termination is valid here: our segments only add opacity. */
void tet_update_table(shared *sh, worker *w)
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
                    float z = pixel_termination(w, (size_t)y * W + x,
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

/* Final composition (paper fig. 4): per pixel, the workers' lists are merged in depth order
 * and composited front to back; screen rows are split between threads. */
void tet_composite_rows(const shared *sh, float *rgba, int y0, int y1)
{
    const int W = sh->X->W, nw = sh->nw;
    int32_t cur[TET_MAX_WORKERS];
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < W; x++) {
            size_t pix = (size_t)y * W + x;
            const seg *cs[TET_MAX_WORKERS];
            for (int i = 0; i < nw; i++) {
                cur[i] = sh->w[i].heads[pix];
                cs[i] = cur[i] >= 0 ? tet_seg_at(&sh->w[i].pool, &sh->w[i].open[pix], sh->w[i].hints[pix], cur[i]) : NULL;
            }
            seg acc = {0, 0, 0, 0, 0, 0, -1};
            for (;;) {
                int bi = -1;
                float bz = INFINITY;
                for (int i = 0; i < nw; i++)
                    if (cs[i] && cs[i]->zf < bz) {
                        bz = cs[i]->zf;
                        bi = i;
                    }
                if (bi < 0) break;
                tet_over(&acc, cs[bi]);
                cur[bi] = cs[bi]->next;
                const worker *wb = &sh->w[bi];
                cs[bi] = cur[bi] >= 0 ? tet_seg_at(&wb->pool, &wb->open[pix], wb->hints[pix], cur[bi]) : NULL;
            }
            rgba[4 * pix + 0] = acc.r;
            rgba[4 * pix + 1] = acc.g;
            rgba[4 * pix + 2] = acc.b;
            rgba[4 * pix + 3] = acc.a;
        }
}

