/* tet_engine.h — the pieces of the cell-projection renderer shared by its files (private to
 * tetra/): set-up and projection (tet_setup.c), scan conversion (tet_scan.c), segment lists,
 * ERT tables and the final composite (tet_composite.c), transfer-function integration
 * (tet_tf.c), the persistent worker pool (tet_workers.c) and the MPI scan engine
 * (tet_local.c). Nothing here is part of any public API. */
#ifndef TET_ENGINE_H
#define TET_ENGINE_H

#include <pthread.h>
#include <stddef.h>
#include <stdint.h>
#include "tet_render.h"

/* Segments closer than this (relative to depth) count as touching for partial compositing. */
#define TET_TOUCH_EPS 1e-5f

typedef struct seg {
    float zf, zb;        /* ray distance of entry and exit */
    float r, g, b, a;    /* premultiplied colour and opacity of the (merged) segment */
    int32_t next;
} seg;

typedef struct seg_pool {
    seg *s;
    size_t n, cap;
} seg_pool;

/* A pixel's list: its first segment, its hint (the segment last inserted, a walk start; -1 for
 * none) and the hint's live copy, which is here and not in its pool slot: the pool is written in
 * insertion order, so a cell's neighbouring pixels have their hints on scattered cache lines,
 * while their list entries are neighbours (the insert was the scan's largest cache-miss cost). */
typedef struct pixel_list {
    seg open;
    int32_t head, hint;
} pixel_list;

/* Segment idx of pixel list L (the hint's live copy when idx is the hint). */
static inline const seg *tet_seg_at(const seg_pool *p, const pixel_list *L, int32_t idx)
{
    return idx == L->hint ? &L->open : &p->s[idx];
}

/* front-over-back of two premultiplied segments */
static inline void tet_over(seg *f, const seg *b)
{
    float t = 1.0f - f->a;
    f->r += t * b->r;
    f->g += t * b->g;
    f->b += t * b->b;
    f->a += t * b->a;
}

typedef struct tile {
    int terminated;
    float deepest;
} tile;

typedef struct cellkey {
    float nearest;
    uint32_t id;
} cellkey;

/* A vertex in view space with its scalar and, when in front of the eye, its pixel coordinates:
 * packed so a cell's four vertices cost four cache lines at most (cells are visited in depth
 * order, so vertex accesses are scattered). */
typedef struct pvert {
    double x, y, z, s, px, py;
} pvert;

/* The transfer function prepared for the scan: breakpoints in scalar units (n >= 2, strictly
 * increasing unless the domain is empty), values kept as floats so the two-point case does the
 * same float arithmetic as the linear transfer function always did; for the pre-integrated
 * method the cumulative integrals of extinction and of extinction times colour over a uniform
 * grid of the domain. */
typedef struct tf_prep {
    int n;
    int method;                /* TET_TF_* */
    double span;               /* s[n-1] - s[0]; <= 0: a constant transfer function */
    double eps;                /* breakpoints closer than this to a piece's end are not split at */
    float s[TET_TF_MAX_POINTS];
    float tau[TET_TF_MAX_POINTS];
    float rgb[TET_TF_MAX_POINTS][3];
    double inv_range[TET_TF_MAX_POINTS]; /* 1 / (s[k+1] - s[k]), 0 for an empty piece */
    /* per breakpoint pair k (n - 1 of them), in doubles on one or two cache lines, what the
     * exact integrator's piece reads: no float conversions or differences per piece */
    struct tf_piece {
        double s0, ir;         /* s[k], inv_range[k] */
        double tau0, dtau;     /* tau[k], tau[k+1] - tau[k] */
        double c0[3], dc[3];   /* rgb[k], rgb[k+1] - rgb[k] */
    } pc[TET_TF_MAX_POINTS];
    int pre_n;                 /* grid cells of the pre-integrated tables */
    double pre_ds;             /* grid spacing in scalar units */
    double *pre_T;             /* pre_n + 1: integral of tau ds from s[0] */
    double *pre_K;             /* 3 * (pre_n + 1): integral of tau * rgb ds */
} tf_prep;

typedef struct scan_ctx {
    const tet_mesh *mesh;
    const tf_prep *tf;
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
    pixel_list *px;         /* per pixel */
    tile *tiles;            /* local ERT table */
    size_t pixels;          /* px capacity */
    int tiles_cap;          /* tiles capacity */
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

/* ---- tet_setup.c: checks, projection, keys ---- */

/* The checks every entry point makes once its pointers are known non-NULL, in one order so all
 * report the same first fault: image size, worker count (at most TET_MAX_WORKERS), a scalar field, a
 * perspective projection, a valid transfer function. Sets *near_d to the near-plane distance
 * the projection implies (1e-4 when it implies none). */
tet_result tet_check_view(const tet_mesh *mesh, const tet_camera *cam, const tet_tf *tf, int nw,
                   double *near_d, char *err, size_t errlen);
/* First tet referencing a point out of range: TET_ERR_INVALID_ARGUMENT naming it, or TET_OK. */
tet_result tet_check_indices(const tet_mesh *mesh, char *err, size_t errlen);
/* Transforms points [i0, i1) to view space with their scalar and pixel coordinates (pixel k's
 * centre at k); every engine uses it so all see bit-identical vertices. */
void tet_view_vertices(const tet_mesh *mesh, const float *V, const float *P, int W, int H,
                       uint32_t i0, uint32_t i1, pvert *vp);
/* Keys of cells [c0, c1) sorted front to back by nearest depth into keys (tmp: scratch of as
 * many); cells with a NaN depth or scalar are left out and counted in *nan. Returns the count. */
uint32_t tet_build_keys(const tet_mesh *mesh, const pvert *vp, uint32_t c0, uint32_t c1,
                        cellkey *keys, cellkey *tmp, uint64_t *nan);

/* ---- tet_tf.c: transfer function ---- */

/* Prepares tf for the scan (the pre-integrated tables allocated when its method asks for
 * them). Returns TET_OK, or an error code with a message. */
tet_result tet_tf_prepare(const tet_tf *tf, tf_prep *out, char *err, size_t errlen);
/* Frees what tet_tf_prepare allocated. */
void tet_tf_release(tf_prep *tf);
/* The premultiplied colour and opacity of the ray segment between view depths tin and tout
 * (ray length L per unit depth) along which the scalar is S0 + Sb t. Returns the pieces
 * integrated (1 unless the segment was split at breakpoints). */
int tet_tf_segment(const tf_prep *tf, double S0, double Sb, double tin, double tout, double L,
                   float out[4]);

/* ---- tet_composite.c: ERT tables, final composite (insertion: tet_scan.c) ---- */

/* Rebuilds w's ERT table from its lists; with sharing on, merges it with the shared one. */
void tet_update_table(shared *sh, worker *w);
/* Final composite of rows [y0, y1): the workers' lists merged in depth order per pixel. */
void tet_composite_rows(const shared *sh, float *rgba, int y0, int y1);

/* ---- tet_scan.c ---- */

/* Scan-converts one cell into the worker's lists unless CST proves it hidden.
 * Returns 0, or -1 when out of memory. */
int tet_scan_cell(const scan_ctx *X, worker *w, const cellkey *key);

/* ---- worker state (tet_workers.c) ---- */

/* Sizes w's buffers for W*H pixels and D*D tiles (kept when large enough) and clears its lists,
 * table and counters for a new frame. Returns 0, or -1 when out of memory. */
int tet_worker_reset(worker *w, int W, int H, int D);
/* Frees w's buffers. */
void tet_worker_free(worker *w);

#endif
