/* tet_composite.c — what is read from the per-pixel ray-segment lists (tet_scan.c inserts
 * into them): the ERT tables (seed 002, 3.1.1 and 3.2) and the final front-to-back composite of
 * every worker's lists (fig. 4). */
#if !defined(_POSIX_C_SOURCE) && !defined(_GNU_SOURCE)
#define _POSIX_C_SOURCE 199309L
#endif
#include "tet_engine.h"
#include "tet_clock.h"

#include <math.h>
#include <stdlib.h>

/* Paper 3.1.1: a pixel is terminated when the opacity of its known segments, composited as if
 * they were contiguous, reaches the threshold; gaps only add opacity, so this is conservative.
 * Returns the ray distance where it terminated, or -1. */
static float pixel_termination(const worker *w, size_t pix, float thr)
{
    float a = 0.0f;
    const pixel_list *L = &w->px[pix];
    for (int32_t c = L->head; c >= 0;) {
        const seg *s = tet_seg_at(&w->pool, L, c);
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
                cur[i] = sh->w[i].px[pix].head;
                cs[i] = cur[i] >= 0 ? tet_seg_at(&sh->w[i].pool, &sh->w[i].px[pix], cur[i]) : NULL;
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
                cs[bi] = cur[bi] >= 0 ? tet_seg_at(&wb->pool, &wb->px[pix], cur[bi]) : NULL;
            }
            rgba[4 * pix + 0] = acc.r;
            rgba[4 * pix + 1] = acc.g;
            rgba[4 * pix + 2] = acc.b;
            rgba[4 * pix + 3] = acc.a;
        }
}

