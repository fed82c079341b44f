/* tet_workers.c — the cell-projection renderer on N workers (seed 002, 4.3): a persistent pool
 * of threads created once, each worker owning a partition of cells with its own lists and ERT
 * table, weak sharing of the tables and dynamic load balancing, then the final composite split
 * by rows on the same threads. */
#if !defined(_POSIX_C_SOURCE) && !defined(_GNU_SOURCE)
#define _POSIX_C_SOURCE 199309L
#endif
#include "tet_engine.h"
#include "tet_clock.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- the pool: threads waiting for a job, the caller doing its share ---- */

typedef void (*pool_fn)(void *arg, int index);

struct tet_pool {
    int n;                    /* workers: the caller (index 0) and threads 1..nthreads */
    int nthreads;
    pthread_t th[TET_MAX_WORKERS - 1];
    pthread_mutex_t m;
    pthread_cond_t go, done;
    uint64_t gen;             /* job generation: a thread runs each one once */
    int pending, quit;
    pool_fn fn;
    void *arg;
    /* per-frame state kept between frames (grown, never shrunk) */
    worker *ws;
    pvert *vp;
    uint32_t vp_cap;
    cellkey *keys, *ktmp;
    uint32_t keys_cap;
    tile *table;
    int table_cap;
    tf_prep tf;
};

typedef struct pool_thread_arg {
    tet_pool *pool;
    int index;
} pool_thread_arg;

static void *pool_thread(void *arg)
{
    tet_pool *p = ((pool_thread_arg *)arg)->pool;
    const int index = ((pool_thread_arg *)arg)->index;
    free(arg);
    uint64_t seen = 0;
    pthread_mutex_lock(&p->m);
    for (;;) {
        while (!p->quit && p->gen == seen)
            pthread_cond_wait(&p->go, &p->m);
        if (p->quit)
            break;
        seen = p->gen;
        pool_fn fn = p->fn;
        void *a = p->arg;
        pthread_mutex_unlock(&p->m);
        fn(a, index);
        pthread_mutex_lock(&p->m);
        if (--p->pending == 0)
            pthread_cond_signal(&p->done);
    }
    pthread_mutex_unlock(&p->m);
    return NULL;
}

/* Runs fn(arg, i) for every worker i and returns when all are done. */
static void pool_run(tet_pool *p, pool_fn fn, void *arg)
{
    if (p->nthreads > 0) {
        pthread_mutex_lock(&p->m);
        p->fn = fn;
        p->arg = arg;
        p->pending = p->nthreads;
        p->gen++;
        pthread_cond_broadcast(&p->go);
        pthread_mutex_unlock(&p->m);
    }
    fn(arg, 0);
    for (int i = p->nthreads + 1; i < p->n; i++) /* threads that never started */
        fn(arg, i);
    if (p->nthreads > 0) {
        pthread_mutex_lock(&p->m);
        while (p->pending > 0)
            pthread_cond_wait(&p->done, &p->m);
        pthread_mutex_unlock(&p->m);
    }
}

tet_result tet_pool_create(int workers, tet_pool **out, char *err, size_t errlen)
{
    *out = NULL;
    const int n = workers <= 0 ? 1 : workers;
    if (n > TET_MAX_WORKERS) {
        tet_errf(err, errlen, "tet_render: %d workers requested, at most %d", n, TET_MAX_WORKERS);
        return TET_ERR_INVALID_ARGUMENT;
    }
    tet_pool *p = calloc(1, sizeof *p);
    worker *ws = aligned_alloc(64, (size_t)n * sizeof *ws);
    if (!p || !ws) {
        free(p);
        free(ws);
        tet_errf(err, errlen, "tet_render: out of memory for a pool of %d workers", n);
        return TET_ERR_OUT_OF_MEMORY;
    }
    memset(ws, 0, (size_t)n * sizeof *ws);
    for (int i = 0; i < n; i++)
        pthread_mutex_init(&ws[i].lock, NULL);
    p->n = n;
    p->ws = ws;
    pthread_mutex_init(&p->m, NULL);
    pthread_cond_init(&p->go, NULL);
    pthread_cond_init(&p->done, NULL);
    for (int i = 1; i < n; i++) {
        pool_thread_arg *a = malloc(sizeof *a);
        if (!a)
            break;
        a->pool = p;
        a->index = i;
        if (pthread_create(&p->th[i - 1], NULL, pool_thread, a) != 0) {
            free(a);
            break;
        }
        p->nthreads++;
    }
    *out = p;
    return TET_OK;
}

void tet_pool_destroy(tet_pool *p)
{
    if (!p)
        return;
    pthread_mutex_lock(&p->m);
    p->quit = 1;
    pthread_cond_broadcast(&p->go);
    pthread_mutex_unlock(&p->m);
    for (int i = 0; i < p->nthreads; i++)
        pthread_join(p->th[i], NULL);
    for (int i = 0; i < p->n; i++) {
        tet_worker_free(&p->ws[i]);
        pthread_mutex_destroy(&p->ws[i].lock);
    }
    pthread_mutex_destroy(&p->m);
    pthread_cond_destroy(&p->go);
    pthread_cond_destroy(&p->done);
    tet_tf_release(&p->tf);
    free(p->ws);
    free(p->vp);
    free(p->keys);
    free(p->ktmp);
    free(p->table);
    free(p);
}

int tet_pool_workers(const tet_pool *p)
{
    return p->n;
}

int tet_pool_threads(const tet_pool *p)
{
    return p->nthreads;
}

/* ---- worker state ---- */

int tet_worker_reset(worker *w, int W, int H, int D)
{
    const size_t np = (size_t)W * H;
    if (w->pixels < np) {
        free(w->px);
        w->px = malloc(np * sizeof *w->px);
        w->pixels = w->px ? np : 0;
        if (!w->pixels)
            return -1;
    }
    if (w->tiles_cap < D * D) {
        free(w->tiles);
        w->tiles = malloc((size_t)D * D * sizeof *w->tiles);
        w->tiles_cap = w->tiles ? D * D : 0;
        if (!w->tiles)
            return -1;
    }
    for (size_t p = 0; p < np; p++)
        w->px[p].head = w->px[p].hint = -1;
    memset(w->tiles, 0, (size_t)D * D * sizeof *w->tiles);
    memset(&w->cnt, 0, sizeof w->cnt);
    w->pool.n = 0;
    w->failed = 0;
    w->next = w->end = 0;
    return 0;
}

void tet_worker_free(worker *w)
{
    free(w->px);
    free(w->tiles);
    free(w->pool.s);
    w->px = NULL;
    w->tiles = NULL;
    w->pool.s = NULL;
    w->pool.n = w->pool.cap = 0;
    w->pixels = 0;
    w->tiles_cap = 0;
}

/* ---- the scan phase ---- */

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

static void scan_worker(worker *w)
{
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
            tet_update_table(sh, w);
            next_update = rem / C > 0 ? rem / C : 1;
            since = 0;
        }
        since++;
        if (tet_scan_cell(X, w, &sh->keys[k]) != 0) {
            w->failed = 1;
            break;
        }
    }
    w->cnt.t_sc_ms = tet_now_ms() - t0 - w->cnt.t_update_ms;
    w->cnt.cpu_ms += tet_thread_cpu_ms() - c0;
}

typedef struct frame_job {
    shared *sh;
    const tet_mesh *mesh;
    const tet_camera *cam;
    pvert *vp;
    cellkey *keys, *ktmp;
    float *rgba;
    double t_scan_end[TET_MAX_WORKERS]; /* wall clock when each worker finished scanning */
} frame_job;

/* Phase 1: worker i projects its share of the points. */
static void project_job(void *arg, int i)
{
    frame_job *j = arg;
    const uint32_t np = j->mesh->point_count, nw = (uint32_t)j->sh->nw;
    double c0 = tet_thread_cpu_ms();
    tet_view_vertices(j->mesh, j->cam->view, j->cam->proj, j->cam->width, j->cam->height,
                      (uint32_t)((uint64_t)np * i / nw), (uint32_t)((uint64_t)np * (i + 1) / nw), j->vp);
    j->sh->w[i].cnt.cpu_ms += tet_thread_cpu_ms() - c0;
}

/* Phase 2: worker i sorts its partition front to back by nearest depth, then scans. The
 * initial assignment is contiguous ranges of the mesh's cell order (the data layout, which
 * keeps neighbouring cells on one worker as in the paper's fig. 8); partition i's keys live at
 * its cells' offset. Visibility cycles do no harm: pixel lists are depth sorted. A worker
 * that runs dry before another has published its keys finds nothing to take there and stops:
 * balance suffers, never correctness. */
static void scan_job(void *arg, int i)
{
    frame_job *j = arg;
    worker *w = &j->sh->w[i];
    const uint32_t nt = j->mesh->tet_count, nw = (uint32_t)j->sh->nw;
    const uint32_t c0 = (uint32_t)((uint64_t)nt * i / nw), c1 = (uint32_t)((uint64_t)nt * (i + 1) / nw);
    double t0 = tet_now_ms(), cpu0 = tet_thread_cpu_ms();
    uint32_t n = tet_build_keys(j->mesh, j->vp, c0, c1, j->keys + c0, j->ktmp + c0, &w->cnt.cells_nan);
    pthread_mutex_lock(&w->lock);
    w->next = c0;
    w->end = c0 + n;
    pthread_mutex_unlock(&w->lock);
    w->cnt.t_setup_ms = tet_now_ms() - t0;
    w->cnt.cpu_ms += tet_thread_cpu_ms() - cpu0;
    scan_worker(w);
    j->t_scan_end[i] = tet_now_ms();
}

static void composite_job(void *arg, int i)
{
    frame_job *j = arg;
    const int H = j->sh->X->H, nw = j->sh->nw;
    double c0 = tet_thread_cpu_ms();
    tet_composite_rows(j->sh, j->rgba, H * i / nw, H * (i + 1) / nw);
    j->sh->w[i].cnt.cpu_ms += tet_thread_cpu_ms() - c0;
}

/* Sizes the pool's frame buffers for np points, nt tets and D*D tiles. */
static int pool_frame_buffers(tet_pool *p, uint32_t np, uint32_t nt, int D)
{
    if (p->vp_cap < np + 1) {
        free(p->vp);
        p->vp = malloc(((size_t)np + 1) * sizeof *p->vp);
        p->vp_cap = p->vp ? np + 1 : 0;
    }
    uint32_t nk = nt ? nt : 1;
    if (p->keys_cap < nk) {
        free(p->keys);
        free(p->ktmp);
        p->keys = malloc((size_t)nk * sizeof *p->keys);
        p->ktmp = malloc((size_t)nk * sizeof *p->ktmp);
        p->keys_cap = p->keys && p->ktmp ? nk : 0;
    }
    if (p->table_cap < D * D) {
        free(p->table);
        p->table = malloc((size_t)D * D * sizeof *p->table);
        p->table_cap = p->table ? D * D : 0;
    }
    if (!p->vp_cap || !p->keys_cap || !p->table_cap)
        return -1;
    memset(p->table, 0, (size_t)D * D * sizeof *p->table);
    return 0;
}

static void sum_counters(tet_counters *cnt, const tet_counters *c)
{
    cnt->cells_scanned += c->cells_scanned;
    cnt->cells_skipped_ert += c->cells_skipped_ert;
    cnt->cells_behind += c->cells_behind;
    cnt->cells_near_crossing += c->cells_near_crossing;
    cnt->cells_degenerate += c->cells_degenerate;
    cnt->segments_made += c->segments_made;
    cnt->segments_merged += c->segments_merged;
    cnt->table_updates += c->table_updates;
    cnt->tf_pieces += c->tf_pieces;
    cnt->cells_nan += c->cells_nan;
    cnt->cpu_ms += c->cpu_ms;
    if (c->t_sc_ms > cnt->t_sc_ms) cnt->t_sc_ms = c->t_sc_ms;
    if (c->t_update_ms > cnt->t_update_ms) cnt->t_update_ms = c->t_update_ms;
    if (c->t_wait_ms > cnt->t_wait_ms) cnt->t_wait_ms = c->t_wait_ms;
}

tet_result tet_render_pool(tet_pool *pool, const tet_mesh *mesh, const tet_camera *cam,
                    const tet_tf *tf, const tet_options *opts, float *rgba,
                    tet_counters *counters, tet_counters *per_worker, char *err, size_t errlen)
{
    tet_counters cnt;
    memset(&cnt, 0, sizeof cnt);
    if (counters) *counters = cnt;
    if (!pool || !mesh || !cam || !tf || !opts || !rgba) {
        tet_errf(err, errlen, "tet_render: NULL argument");
        return TET_ERR_INVALID_ARGUMENT;
    }
    const int W = cam->width, H = cam->height, nw = pool->n;
    double near_d;
    tet_result rc = tet_check_view(mesh, cam, tf, nw, &near_d, err, errlen);
    if (rc == TET_OK)
        rc = tet_check_indices(mesh, err, errlen);
    if (rc == TET_OK)
        rc = tet_tf_prepare(tf, &pool->tf, err, errlen);
    if (rc != TET_OK) {
        tet_tf_release(&pool->tf);
        return rc;
    }
    const uint32_t np = mesh->point_count, nt = mesh->tet_count;
    const int D = opts->tiles_d > 0 ? opts->tiles_d : 1;
    worker *ws = pool->ws;
    shared sh;
    memset(&sh, 0, sizeof sh);
    pthread_mutex_init(&sh.lock, NULL);
    if (pool_frame_buffers(pool, np, nt, D) != 0) {
        tet_errf(err, errlen, "tet_render: out of memory (%u points, %u tets)", np, nt);
        rc = TET_ERR_OUT_OF_MEMORY;
        goto done;
    }
    for (int i = 0; i < nw; i++)
        if (tet_worker_reset(&ws[i], W, H, D) != 0) {
            tet_errf(err, errlen, "tet_render: out of memory for worker %d (%dx%d)", i, W, H);
            rc = TET_ERR_OUT_OF_MEMORY;
            goto done;
        }
    scan_ctx X = {mesh, &pool->tf, opts, pool->vp, cam->proj, near_d, W, H, D};
    sh.X = &X;
    sh.keys = pool->keys;
    sh.w = ws;
    sh.nw = nw;
    sh.table = pool->table;
    for (int i = 0; i < nw; i++)
        ws[i].sh = &sh;
    frame_job job = {.sh = &sh, .mesh = mesh, .cam = cam, .vp = pool->vp, .keys = pool->keys,
                     .ktmp = pool->ktmp, .rgba = rgba};
    const double t_setup = tet_now_ms();
    pool_run(pool, project_job, &job);
    cnt.t_setup_ms = tet_now_ms() - t_setup;
    pool_run(pool, scan_job, &job);
    double t_all = 0, t_keys = 0;
    for (int i = 0; i < nw; i++) {
        t_all = fmax(t_all, job.t_scan_end[i]);
        t_keys = fmax(t_keys, ws[i].cnt.t_setup_ms);
    }
    cnt.t_setup_ms += t_keys;
    for (int i = 0; i < nw; i++)
        ws[i].cnt.t_wait_ms = t_all - job.t_scan_end[i];
    for (int i = 0; i < nw; i++)
        if (ws[i].failed) {
            tet_errf(err, errlen, "tet_render: worker %d out of memory at %zu segments", i,
                     ws[i].pool.n);
            rc = TET_ERR_OUT_OF_MEMORY;
            goto done;
        }
    double tc = tet_now_ms();
    pool_run(pool, composite_job, &job);
    cnt.t_composite_ms = tet_now_ms() - tc;
done:
    for (int i = 0; i < nw; i++) {
        sum_counters(&cnt, &ws[i].cnt);
        if (per_worker) per_worker[i] = ws[i].cnt;
    }
    if (counters)
        *counters = cnt;
    pthread_mutex_destroy(&sh.lock);
    tet_tf_release(&pool->tf);
    return rc;
}

tet_result tet_render_workers(const tet_mesh *mesh, const tet_camera *cam,
                       const tet_tf *tf, const tet_options *opts, float *rgba,
                       tet_counters *counters, tet_counters *per_worker,
                       char *err, size_t errlen)
{
    if (counters) memset(counters, 0, sizeof *counters);
    if (!mesh || !cam || !tf || !opts || !rgba) {
        tet_errf(err, errlen, "tet_render: NULL argument");
        return TET_ERR_INVALID_ARGUMENT;
    }
    double near_d; /* the view's faults first, as the pool would report them */
    tet_result rc = tet_check_view(mesh, cam, tf, opts->workers <= 0 ? 1 : opts->workers, &near_d, err, errlen);
    if (rc != TET_OK)
        return rc;
    tet_pool *pool;
    rc = tet_pool_create(opts->workers, &pool, err, errlen);
    if (rc != TET_OK)
        return rc;
    rc = tet_render_pool(pool, mesh, cam, tf, opts, rgba, counters, per_worker, err, errlen);
    tet_pool_destroy(pool);
    return rc;
}

tet_result tet_render(const tet_mesh *mesh, const tet_camera *cam, const tet_tf *tf,
               const tet_options *opts, float *rgba, tet_counters *counters, char *err, size_t errlen)
{
    return tet_render_workers(mesh, cam, tf, opts, rgba, counters, NULL, err, errlen);
}
