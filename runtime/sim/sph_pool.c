/* sph_pool.c — the solver's worker threads: every pass is split into fixed chunks of
 * SPH_CHUNK particles, so sums do not depend on the thread count. Each participant (the caller
 * is 0, the workers 1..n) runs the same contiguous share of the chunks in every pass: a chunk's
 * neighbour lists and stored pair terms, written by one pass, are read by the next from the same
 * core's cache. (Taken from a shared counter instead, a chunk moved between cores from pass to
 * pass: 2 threads cost 1.35x the CPU of one on the default pool, docs/simulation-wcsph.md.) */
#include "sim/sph_internal.h"

#include <stdlib.h>

static void run_chunks(rt_sph *s, uint32_t who)
{
    const uint64_t parts = (uint64_t)s->nthreads + 1u;
    const uint32_t b = (uint32_t)((uint64_t)s->nchunks * who / parts);
    const uint32_t e = (uint32_t)((uint64_t)s->nchunks * (who + 1u) / parts);
    for (uint32_t c = b; c < e; ++c)
        s->job(s, c);
}

static void *worker_main(void *arg)
{
    sph_worker *w = arg;
    rt_sph *s = w->s;
    const uint32_t who = w->index;
    uint64_t seen = 0;
    for (;;) {
        pthread_mutex_lock(&s->mu);
        while (!s->quit && s->gen == seen)
            pthread_cond_wait(&s->cv_start, &s->mu);
        if (s->quit) {
            pthread_mutex_unlock(&s->mu);
            return NULL;
        }
        seen = s->gen;
        pthread_mutex_unlock(&s->mu);
        run_chunks(s, who);
        pthread_mutex_lock(&s->mu);
        if (--s->busy == 0)
            pthread_cond_signal(&s->cv_done);
        pthread_mutex_unlock(&s->mu);
    }
}

vfx_result rt_sph_pool_start(rt_sph *s)
{
    pthread_mutex_init(&s->mu, NULL);
    pthread_cond_init(&s->cv_start, NULL);
    pthread_cond_init(&s->cv_done, NULL);
    uint32_t workers = s->p.threads - 1;
    if (!workers)
        return VFX_OK;
    s->threads = calloc(workers, sizeof *s->threads);
    s->workers = calloc(workers, sizeof *s->workers);
    if (!s->threads || !s->workers)
        return VFX_ERR_OUT_OF_MEMORY;
    for (uint32_t i = 0; i < workers; ++i) {
        s->workers[i] = (sph_worker){.s = s, .index = i + 1};
        if (pthread_create(&s->threads[i], NULL, worker_main, &s->workers[i]) != 0) {
            s->p.threads = 1 + i; /* run with the ones we have */
            break;
        }
        s->nthreads++;
    }
    return VFX_OK;
}

void rt_sph_pool_stop(rt_sph *s)
{
    pthread_mutex_lock(&s->mu);
    s->quit = true;
    pthread_cond_broadcast(&s->cv_start);
    pthread_mutex_unlock(&s->mu);
    for (uint32_t i = 0; i < s->nthreads; ++i)
        pthread_join(s->threads[i], NULL);
    free(s->threads), free(s->workers);
    s->threads = NULL, s->workers = NULL;
    s->nthreads = 0;
    pthread_mutex_destroy(&s->mu);
    pthread_cond_destroy(&s->cv_start);
    pthread_cond_destroy(&s->cv_done);
}

void rt_sph_parallel(rt_sph *s, sph_chunk_fn fn, bool fresh)
{
    uint32_t nchunks = sph_chunk_count(s);
    for (uint32_t c = 0; c < nchunks; ++c) {
        if (fresh) {
            s->out[c] = (sph_chunk_out){.bad = UINT32_MAX};
        } else {
            s->out[c].bad = UINT32_MAX;
            s->out[c].ke = s->out[c].pe = 0.0;
            s->out[c].disp2_max = 0.f;
        }
    }
    s->job = fn;
    s->nchunks = nchunks;
    if (s->nthreads == 0 || nchunks < 2) {
        for (uint32_t c = 0; c < nchunks; ++c)
            fn(s, c);
        return;
    }
    pthread_mutex_lock(&s->mu);
    s->busy = s->nthreads;
    s->gen++;
    pthread_cond_broadcast(&s->cv_start);
    pthread_mutex_unlock(&s->mu);
    run_chunks(s, 0);
    pthread_mutex_lock(&s->mu);
    while (s->busy > 0)
        pthread_cond_wait(&s->cv_done, &s->mu);
    pthread_mutex_unlock(&s->mu);
}
