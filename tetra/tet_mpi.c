/* tet_mpi.c — the seed-002 renderer across MPI processes: phase 1 (cell-parallel scan with
 * local ERT tables, weak sharing, dynamic load balancing), phase 2 (binary-swap composition of
 * depth-tagged ray-segment lists). See docs/tetvol-mpi.md for the protocol and its choices. */
#if !defined(_POSIX_C_SOURCE) && !defined(_GNU_SOURCE)
#define _POSIX_C_SOURCE 199309L
#endif
#include "tet_mpi.h"
#include "tet_clock.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { TAG_REQ = 7101, TAG_GIVE = 7102, TAG_SWAP_N = 7103, TAG_SWAP_S = 7104 };

/* as in tet_render.c: segments this close (relative to depth) count as touching */
#define TOUCH_EPS 1e-5f

/* An idle rank sleeps between polls instead of spinning in MPI_Wait: with more ranks than
 * cores (the test and bench machines) a spinning rank would take CPU from working ones. */
static void idle_pause(void)
{
    struct timespec ts = {0, 100000};
    nanosleep(&ts, NULL);
}

/* Waits for requests by testing and sleeping: blocking MPI waits spin (or, with
 * mpi_yield_when_idle, give the core away at every test), which with more ranks than cores
 * takes CPU from the ranks still working. */
static void wait_polite(int n, MPI_Request *rq)
{
    int flag = 0;
    MPI_Testall(n, rq, &flag, MPI_STATUSES_IGNORE);
    while (!flag) {
        idle_pause();
        MPI_Testall(n, rq, &flag, MPI_STATUSES_IGNORE);
    }
}

void tet_seglists_free(tet_seglists *l)
{
    if (!l)
        return;
    free(l->off);
    free(l->segs);
    memset(l, 0, sizeof *l);
}

static void over(tet_rseg *f, const tet_rseg *b)
{
    float t = 1.0f - f->a;
    f->r += t * b->r;
    f->g += t * b->g;
    f->b += t * b->b;
    f->a += t * b->a;
}

int tet_seglists_merge(const tet_seglists *a, const tet_seglists *b, int partial,
                       tet_seglists *out)
{
    size_t np = a->p1 - a->p0;
    size_t na = a->off[np], nb = b->off[np];
    memset(out, 0, sizeof *out);
    if (na + nb > INT_MAX) /* offsets are uint32 and MPI counts int */
        return -1;
    out->p0 = a->p0;
    out->p1 = a->p1;
    out->off = malloc((np + 1) * sizeof *out->off);
    out->segs = malloc((na + nb + 1) * sizeof *out->segs);
    if (!out->off || !out->segs) {
        tet_seglists_free(out);
        return -1;
    }
    size_t n = 0;
    for (size_t p = 0; p < np; p++) {
        out->off[p] = (uint32_t)n;
        size_t i = a->off[p], ie = a->off[p + 1], j = b->off[p], je = b->off[p + 1];
        size_t first = n;
        while (i < ie || j < je) {
            const tet_rseg *s;
            if (j >= je || (i < ie && a->segs[i].zf <= b->segs[j].zf))
                s = &a->segs[i++];
            else
                s = &b->segs[j++];
            /* partial compositing across ranks: a segment that touches the previous one
             * (adjacent cells of two partitions) joins it, which shrinks the next stage's
             * message without changing the image beyond float association */
            if (partial && n > first) {
                tet_rseg *last = &out->segs[n - 1];
                if (fabsf(last->zb - s->zf) <= TOUCH_EPS * (1.0f + fabsf(s->zf))) {
                    over(last, s);
                    last->zb = s->zb;
                    continue;
                }
            }
            out->segs[n++] = *s;
        }
    }
    out->off[np] = (uint32_t)n;
    return 0;
}

/* The lists of pixels [q0, q1) (inside l's range) as their own lists (copied). */
static int slice_lists(const tet_seglists *l, size_t q0, size_t q1, tet_seglists *out)
{
    size_t a = q0 - l->p0, np = q1 - q0, base = l->off[a], ns = l->off[a + np] - base;
    memset(out, 0, sizeof *out);
    out->p0 = q0;
    out->p1 = q1;
    out->off = malloc((np + 1) * sizeof *out->off);
    out->segs = malloc((ns + 1) * sizeof *out->segs);
    if (!out->off || !out->segs) {
        tet_seglists_free(out);
        return -1;
    }
    for (size_t p = 0; p <= np; p++)
        out->off[p] = l->off[a + p] - (uint32_t)base;
    memcpy(out->segs, l->segs + base, ns * sizeof *out->segs);
    return 0;
}

/* All ranks agree on failure: the worst code wins, and its message is the local one if any. */
static tet_result agree(MPI_Comm comm, tet_result rc, char *err, size_t errlen, const char *what)
{
    int mine = (int)rc, worst = mine; /* an enum's size is the compiler's: MPI sees ints */
    MPI_Request rq;
    MPI_Iallreduce(&mine, &worst, 1, MPI_INT, MPI_MAX, comm, &rq);
    wait_polite(1, &rq);
    if (worst != TET_OK && rc == TET_OK)
        tet_errf(err, errlen, "tet_mpi: another rank failed during %s (code %d)", what, worst);
    return (tet_result)worst;
}

/* One exchange step, called by every rank of comm: sends the lists of [s0, s1) of cur to dst
 * (dst < 0: none) and receives those of [k0, k1) from src (src < 0: none) into in. The segment
 * counts travel first and every rank agrees that the receive buffers exist before any payload
 * moves, so a failed allocation returns an error everywhere instead of leaving a send hanging. */
static tet_result exchange(MPI_Comm comm, MPI_Datatype segt, const tet_seglists *cur, int dst,
                    size_t s0, size_t s1, int src, size_t k0, size_t k1, uint32_t *counts,
                    tet_seglists *in, uint64_t *bytes, char *err, size_t errlen)
{
    tet_result rc = TET_OK;
    uint64_t ns = 0, nr = 0;
    MPI_Request rq[3];
    int nrq = 0;
    memset(in, 0, sizeof *in);
    if (dst >= 0) {
        size_t a = s0 - cur->p0, b = s1 - cur->p0;
        for (size_t p = a; p < b; p++)
            counts[p - a] = cur->off[p + 1] - cur->off[p];
        ns = cur->off[b] - cur->off[a];
        MPI_Isend(&ns, 1, MPI_UINT64_T, dst, TAG_SWAP_N, comm, &rq[nrq++]);
    }
    if (src >= 0) {
        MPI_Request r1;
        MPI_Irecv(&nr, 1, MPI_UINT64_T, src, TAG_SWAP_N, comm, &r1);
        wait_polite(1, &r1);
        in->p0 = k0;
        in->p1 = k1;
        in->off = malloc((k1 - k0 + 1) * sizeof *in->off);
        in->segs = nr <= INT_MAX ? malloc((size_t)(nr + 1) * sizeof *in->segs) : NULL;
        if (!in->off || !in->segs) {
            tet_errf(err, errlen, "tet_mpi: out of memory receiving %llu segments from rank %d",
                     (unsigned long long)nr, src);
            rc = TET_ERR_OUT_OF_MEMORY;
        }
    }
    rc = agree(comm, rc, err, errlen, "list exchange");
    if (rc == TET_OK && dst >= 0) {
        size_t a = s0 - cur->p0;
        MPI_Isend(counts, (int)(s1 - s0), MPI_UINT32_T, dst, TAG_SWAP_N, comm, &rq[nrq++]);
        MPI_Isend(cur->segs + cur->off[a], (int)ns, segt, dst, TAG_SWAP_S, comm, &rq[nrq++]);
        *bytes += sizeof ns + (uint64_t)(s1 - s0) * sizeof(uint32_t) + ns * sizeof(tet_rseg);
    }
    if (rc == TET_OK && src >= 0) {
        size_t np = k1 - k0;
        MPI_Request r2[2];
        MPI_Irecv(in->off, (int)np, MPI_UINT32_T, src, TAG_SWAP_N, comm, &r2[0]);
        MPI_Irecv(in->segs, (int)nr, segt, src, TAG_SWAP_S, comm, &r2[1]);
        wait_polite(2, r2);
        uint32_t acc = 0; /* counts -> offsets */
        for (size_t p = 0; p < np; p++) {
            uint32_t c = in->off[p];
            in->off[p] = acc;
            acc += c;
        }
        in->off[np] = acc;
    }
    wait_polite(nrq, rq);
    if (rc != TET_OK)
        tet_seglists_free(in);
    return rc;
}

/* What the stages of one composite share: the communicator, the segment type, this rank, the
 * ranks, the power of two that swaps, the screen, the count scratch and the bytes sent. */
typedef struct composite_run {
    MPI_Comm comm;
    MPI_Datatype segt;
    int rank, P, G, partial;
    size_t npix;
    uint32_t *counts;
    uint64_t bytes;
    char *err;
    size_t errlen;
} composite_run;

/* Fold: ranks G..P-1 hand their whole screen to rank - G, so the swap runs on 2^k ranks; *cur
 * is this rank's lists before and after. */
static tet_result composite_fold(composite_run *c, tet_seglists *cur)
{
    tet_seglists in, merged;
    memset(&merged, 0, sizeof merged);
    int rank = c->rank, G = c->G, P = c->P;
    int dst = rank >= G ? rank - G : -1, src = rank + G < P ? rank + G : -1;
    tet_result rc = exchange(c->comm, c->segt, cur, dst, 0, c->npix, src, 0, c->npix, c->counts, &in, &c->bytes,
                             c->err, c->errlen);
    tet_result r2 = TET_OK;
    if (rc == TET_OK && src >= 0) {
        if (tet_seglists_merge(cur, &in, c->partial, &merged) != 0) {
            tet_errf(c->err, c->errlen, "tet_mpi: out of memory folding rank %d's lists", src);
            r2 = TET_ERR_OUT_OF_MEMORY;
        } else {
            tet_seglists_free(cur);
            *cur = merged;
        }
    }
    if (rc == TET_OK && dst >= 0)
        tet_seglists_free(cur);
    tet_seglists_free(&in);
    if (rc == TET_OK)
        rc = agree(c->comm, r2, c->err, c->errlen, "fold");
    return rc;
}

/* Binary swap: at stage s the pair (rank, rank ^ 2^s) splits its common range in halves;
 * the lower rank keeps the first. Lists are merged by depth, so the result is exact
 * however the two ranks' cells interleave along the rays. Ranks >= G only take part in
 * the agreements. *cur ends as this rank's lists of pixels [*p0, *p1). */
static tet_result composite_swap(composite_run *c, tet_seglists *cur, size_t *p0_out, size_t *p1_out)
{
    tet_seglists in, keep, merged;
    memset(&merged, 0, sizeof merged);
    int rank = c->rank;
    tet_result rc = TET_OK;
    size_t p0 = 0, p1 = c->npix;
    for (int bit = 1; rc == TET_OK && bit < c->G; bit <<= 1) {
        int partner = rank < c->G ? rank ^ bit : -1;
        size_t mid = p0 + (p1 - p0) / 2;
        size_t k0 = (rank & bit) ? mid : p0, k1 = (rank & bit) ? p1 : mid;
        size_t s0 = (rank & bit) ? p0 : mid, s1 = (rank & bit) ? mid : p1;
        rc = exchange(c->comm, c->segt, cur, partner, s0, s1, partner, k0, k1, c->counts, &in, &c->bytes,
                      c->err, c->errlen);
        if (rc != TET_OK)
            break;
        tet_result r2 = TET_OK;
        if (partner >= 0) {
            if (slice_lists(cur, k0, k1, &keep) != 0 ||
                tet_seglists_merge(&keep, &in, c->partial, &merged) != 0) {
                tet_errf(c->err, c->errlen, "tet_mpi: out of memory in binary swap stage %d", bit);
                r2 = TET_ERR_OUT_OF_MEMORY;
            }
            tet_seglists_free(&keep);
            tet_seglists_free(&in);
            tet_seglists_free(cur);
            *cur = merged;
            memset(&merged, 0, sizeof merged);
            p0 = k0;
            p1 = k1;
        }
        rc = agree(c->comm, r2, c->err, c->errlen, "binary swap");
    }
    *p0_out = p0;
    *p1_out = p1;
    return rc;
}

tet_result tet_mpi_composite(MPI_Comm comm, int W, int H, tet_seglists *lists, int partial,
                          float *rgba, tet_mpi_stats *st, char *err, size_t errlen)
{
    int rank, P, rc = TET_OK;
    MPI_Comm_rank(comm, &rank);
    MPI_Comm_size(comm, &P);
    double t0 = tet_now_ms();
    MPI_Datatype segt;
    MPI_Type_contiguous(6, MPI_FLOAT, &segt);
    MPI_Type_commit(&segt);
    const size_t npix = (size_t)W * H;
    uint32_t *counts = malloc((npix + 1) * sizeof *counts);
    if (!counts) {
        tet_errf(err, errlen, "tet_mpi: out of memory for %zu pixel counts", npix);
        rc = TET_ERR_OUT_OF_MEMORY;
    } else if (lists->p0 != 0 || lists->p1 != npix || !lists->off) {
        tet_errf(err, errlen, "tet_mpi: composite needs full-screen lists (got pixels %zu..%zu of %zu)",
                 lists->p0, lists->p1, npix);
        rc = TET_ERR_INVALID_ARGUMENT;
    }
    rc = agree(comm, rc, err, errlen, "composite set-up");
    int G = 1;
    while (G * 2 <= P)
        G *= 2;
    composite_run run = {comm, segt, rank, P, G, partial, npix, counts, 0, err, errlen};
    tet_seglists cur = *lists;
    memset(lists, 0, sizeof *lists);
    if (rc == TET_OK && P > G)
        rc = composite_fold(&run, &cur);
    size_t p0 = 0, p1 = npix;
    if (rc == TET_OK)
        rc = composite_swap(&run, &cur, &p0, &p1);
    uint64_t bytes = run.bytes;
    double t1 = tet_now_ms();
    /* Final composition of this rank's part, then gather to rank 0. */
    size_t mine = rank < G ? p1 - p0 : 0;
    float *part = malloc((mine + 1) * 4 * sizeof *part);
    long long *ranges = rank == 0 ? malloc((size_t)P * 2 * sizeof *ranges) : NULL;
    int *cnts = rank == 0 ? malloc((size_t)P * 2 * sizeof *cnts) : NULL;
    if (rc == TET_OK && (!part || (rank == 0 && (!ranges || !cnts)))) {
        tet_errf(err, errlen, "tet_mpi: out of memory for %zu final pixels", mine);
        rc = TET_ERR_OUT_OF_MEMORY;
    }
    if (rc == TET_OK && rank == 0 && !rgba) {
        tet_errf(err, errlen, "tet_mpi: rank 0 needs an output image");
        rc = TET_ERR_INVALID_ARGUMENT;
    }
    rc = agree(comm, rc, err, errlen, "final composition");
    if (rc == TET_OK) {
        for (size_t p = 0; p < mine; p++) {
            tet_rseg acc = {0, 0, 0, 0, 0, 0};
            for (uint32_t i = cur.off[p]; i < cur.off[p + 1]; i++)
                over(&acc, &cur.segs[i]);
            part[4 * p + 0] = acc.r;
            part[4 * p + 1] = acc.g;
            part[4 * p + 2] = acc.b;
            part[4 * p + 3] = acc.a;
        }
        long long range[2] = {(long long)(rank < G ? p0 : 0), (long long)mine};
        MPI_Request rq;
        MPI_Igather(range, 2, MPI_LONG_LONG, ranges, 2, MPI_LONG_LONG, 0, comm, &rq);
        wait_polite(1, &rq);
        if (rank == 0)
            for (int r = 0; r < P; r++) {
                cnts[r] = (int)(ranges[2 * r + 1] * 4);
                cnts[P + r] = (int)(ranges[2 * r] * 4);
            }
        MPI_Igatherv(part, (int)(mine * 4), MPI_FLOAT, rgba, cnts, rank == 0 ? cnts + P : NULL,
                     MPI_FLOAT, 0, comm, &rq);
        wait_polite(1, &rq);
        if (st) {
            st->pixels_final = mine;
            st->segments_final = rank < G ? cur.off[mine] : 0;
        }
    }
    free(ranges);
    free(cnts);
    if (st) {
        st->bytes_sent += bytes;
        st->t_swap_ms += t1 - t0;
        st->t_gather_ms += tet_now_ms() - t1;
    }
    free(part);
    free(counts);
    tet_seglists_free(&cur);
    MPI_Type_free(&segt);
    return rc;
}

struct tet_mpi {
    MPI_Comm comm;
    MPI_Win win;   /* the shared ERT table on rank 0, kept between renders */
    float *win_mem;
    int win_dd;    /* its entries; 0 = no window yet */
};

tet_result tet_mpi_create(MPI_Comm comm, tet_mpi **out, char *err, size_t errlen)
{
    tet_mpi *m = calloc(1, sizeof *m);
    tet_result rc = m ? TET_OK : TET_ERR_OUT_OF_MEMORY;
    if (!m)
        tet_errf(err, errlen, "tet_mpi: out of memory for the context");
    rc = agree(comm, rc, err, errlen, "context creation");
    if (rc != TET_OK) {
        free(m);
        *out = NULL;
        return rc;
    }
    m->comm = comm;
    *out = m;
    return TET_OK;
}

void tet_mpi_destroy(tet_mpi *m)
{
    if (!m)
        return;
    if (m->win_dd)
        MPI_Win_free(&m->win);
    free(m);
}

/* Phase-1 state of one rank. */
typedef struct rank_scan {
    MPI_Comm comm;
    int rank, P, DD;
    tet_local *L;
    const tet_options *opts;
    uint32_t next, end;   /* remaining keys [next, end) of this rank */
    int share, dlb;
    /* weak sharing: the shared table lives in a window on rank 0 (the paper's manager node,
     * without a manager process), D*D floats: deepest where terminated, +inf elsewhere */
    MPI_Win win;
    float *enc, *known;
    /* the current reduction (load balancing and termination): one "done" flag (MIN: 1 only
     * when every rank is done) and one remaining-key count per rank (each rank writes its own
     * slot, +inf elsewhere) */
    float *sendbuf, *recvbuf, *remaining;
    MPI_Request round;
    int round_active, all_done, done;
    /* load balancing: the outstanding request, if any */
    MPI_Request give_rq, ask_rq;
    uint32_t give[2];
    int ask_msg;
    int asked;            /* rank asked, -1 when none */
    tet_mpi_stats *st;
    /* the scan: coop when reductions run (sharing or load balancing with P > 1), the ERT
     * table updated C times per stretch, failed once a scan ran out of memory */
    int coop, ert, failed;
    uint32_t C;
} rank_scan;

static void start_round(rank_scan *R)
{
    R->sendbuf[0] = R->done ? 1.0f : 0.0f;
    for (int i = 0; i < R->P; i++)
        R->sendbuf[1 + i] = i == R->rank ? (float)(R->end - R->next) : INFINITY;
    MPI_Iallreduce(R->sendbuf, R->recvbuf, 1 + R->P, MPI_FLOAT, MPI_MIN, R->comm, &R->round);
    R->round_active = 1;
}

/* Weak sharing (paper 3.2): one atomic exchange with the shared table, element-wise
 * minimum in, previous value out (MPI_Get_accumulate under a shared lock: concurrent
 * accumulates with one op are atomic per element). It involves no other rank's progress, so
 * a rank shares at its own pace as with the paper's manager node. The result is merged into
 * the monotone known table (terminations only move forward) and into the local table:
 * another rank's termination is valid here since our segments only add opacity in front. */
static void share_table(rank_scan *R)
{
    tet_local_table_get(R->L, R->enc);
    MPI_Win_lock(MPI_LOCK_SHARED, 0, 0, R->win);
    MPI_Get_accumulate(R->enc, R->DD, MPI_FLOAT, R->sendbuf + 1 + R->P, R->DD, MPI_FLOAT, 0, 0,
                       R->DD, MPI_FLOAT, MPI_MIN, R->win);
    MPI_Win_unlock(0, R->win);
    const float *got = R->sendbuf + 1 + R->P;
    for (int i = 0; i < R->DD; i++) {
        float v = got[i] < R->enc[i] ? got[i] : R->enc[i];
        if (v < R->known[i])
            R->known[i] = v;
    }
    tet_local_table_merge(R->L, R->known);
    R->st->share_rounds++;
}

/* Progress: completes the reduction in flight, answers load-balancing requests with 1/3 of
 * our remaining keys from the deep end, and starts a new reduction when start is set and none
 * is in flight. */
static void poll_rank(rank_scan *R, int start)
{
    if (R->round_active) {
        int flag = 0;
        MPI_Test(&R->round, &flag, MPI_STATUS_IGNORE);
        if (flag) {
            R->round_active = 0;
            R->st->reductions++;
            R->all_done = R->recvbuf[0] >= 1.0f;
            for (int i = 0; i < R->P; i++)
                R->remaining[i] = R->recvbuf[1 + i];
        }
    }
    for (;;) {
        int flag = 0;
        MPI_Status s;
        MPI_Iprobe(MPI_ANY_SOURCE, TAG_REQ, R->comm, &flag, &s);
        if (!flag)
            break;
        int dummy;
        MPI_Recv(&dummy, 1, MPI_INT, s.MPI_SOURCE, TAG_REQ, R->comm, MPI_STATUS_IGNORE);
        uint32_t rem = R->end - R->next, n = rem / 3 ? rem / 3 : (rem >= 2 ? 1 : 0);
        uint32_t reply[2] = {R->end - n, R->end};
        R->end -= n;
        R->st->cells_given += n;
        /* the thief posted its receive before asking, so this send is matched at once */
        MPI_Send(reply, 2, MPI_UINT32_T, s.MPI_SOURCE, TAG_GIVE, R->comm);
    }
    if (start && !R->round_active && !R->all_done)
        start_round(R);
}

/* Out of keys: ask the rank with the most remaining keys (as of the last reduction) for some.
 * Returns 1 when a request went out. */
static int ask_for_work(rank_scan *R)
{
    int best = -1;
    float most = 1.5f; /* a rank with fewer than 2 keys gives none */
    for (int i = 0; i < R->P; i++)
        if (i != R->rank && R->remaining[i] > most && R->remaining[i] < INFINITY) {
            most = R->remaining[i];
            best = i;
        }
    if (best < 0)
        return 0;
    R->ask_msg = 0;
    MPI_Irecv(R->give, 2, MPI_UINT32_T, best, TAG_GIVE, R->comm, &R->give_rq);
    MPI_Isend(&R->ask_msg, 1, MPI_INT, best, TAG_REQ, R->comm, &R->ask_rq);
    R->asked = best;
    R->st->steal_requests++;
    return 1;
}

/* 64-bit hash of n 32-bit words (multiply-xorshift per word: fast enough to run every frame). */
static uint64_t hash_words(uint64_t h, const void *data, size_t n)
{
    const unsigned char *b = data;
    for (size_t i = 0; i < n; i++) {
        uint32_t w;
        memcpy(&w, b + 4 * i, sizeof w);
        h = (h ^ w) * 0x9e3779b97f4a7c15ull;
        h ^= h >> 29;
    }
    return h;
}

/* What every rank must agree on before a render: the mesh (counts and checksums of points,
 * tets and scalars) and the image and table sizes that shape the collectives. */
enum { FP_POINTS, FP_TETS, FP_SCALAR, FP_H_POINTS, FP_H_TETS, FP_H_SCALAR, FP_W, FP_H, FP_D, FP_N };

static void fingerprint(const tet_mesh *mesh, const tet_camera *cam, const tet_options *opts,
                        uint64_t fp[FP_N])
{
    memset(fp, 0, FP_N * sizeof *fp);
    if (mesh) {
        fp[FP_POINTS] = mesh->point_count;
        fp[FP_TETS] = mesh->tet_count;
        fp[FP_SCALAR] = mesh->scalar != NULL;
        if (mesh->points)
            fp[FP_H_POINTS] = hash_words(1, mesh->points, (size_t)mesh->point_count * 3);
        if (mesh->tets)
            fp[FP_H_TETS] = hash_words(2, mesh->tets, (size_t)mesh->tet_count * 4);
        if (mesh->scalar)
            fp[FP_H_SCALAR] = hash_words(3, mesh->scalar, mesh->point_count);
    }
    if (cam)
        fp[FP_W] = (uint64_t)(int64_t)cam->width, fp[FP_H] = (uint64_t)(int64_t)cam->height;
    if (opts)
        fp[FP_D] = (uint64_t)(int64_t)opts->tiles_d;
}

/* Collective: TET_OK when every rank holds the same mesh, image size and table size as rank 0,
 * else TET_ERR_INVALID_ARGUMENT on every rank with the differing ranks named in err. Ranks
 * with a stale copy of a mesh would otherwise scan cells the others never sorted (a crash in
 * the scan) or composite different data into one image. */
static tet_result check_same_input(MPI_Comm comm, int P, const tet_mesh *mesh, const tet_camera *cam,
                            const tet_options *opts, char *err, size_t errlen)
{
    uint64_t mine[FP_N];
    fingerprint(mesh, cam, opts, mine);
    uint64_t *all = malloc((size_t)P * FP_N * sizeof *all);
    int have = all != NULL, every = 0;
    MPI_Request rq;
    MPI_Iallreduce(&have, &every, 1, MPI_INT, MPI_MIN, comm, &rq);
    wait_polite(1, &rq);
    if (!every) {
        free(all);
        tet_errf(err, errlen, "tet_mpi: out of memory for %d ranks' mesh checksums", P);
        return TET_ERR_OUT_OF_MEMORY;
    }
    MPI_Iallgather(mine, FP_N, MPI_UINT64_T, all, FP_N, MPI_UINT64_T, comm, &rq);
    wait_polite(1, &rq);
    char list[128] = "";
    size_t len = 0;
    int bad = 0, first = -1;
    for (int r = 1; r < P; r++) {
        if (memcmp(all + (size_t)r * FP_N, all, FP_N * sizeof *all) == 0)
            continue;
        if (first < 0)
            first = r;
        if (bad++ < 8 && len < sizeof list - 16)
            len += (size_t)snprintf(list + len, sizeof list - len, "%s%d", bad > 1 ? ", " : "", r);
    }
    if (bad) {
        const uint64_t *f = all + (size_t)first * FP_N;
        const char *what = f[FP_POINTS] != all[FP_POINTS] || f[FP_TETS] != all[FP_TETS] ? "counts"
                           : f[FP_H_POINTS] != all[FP_H_POINTS] ? "points"
                           : f[FP_H_TETS] != all[FP_H_TETS] ? "tets"
                           : f[FP_H_SCALAR] != all[FP_H_SCALAR] || f[FP_SCALAR] != all[FP_SCALAR] ? "scalars"
                           : "image or table size";
        tet_errf(err, errlen, "tet_mpi: rank%s %s%s hold%s a different mesh from rank 0 (%s differ; "
                 "rank %d: %llu points, %llu tets; rank 0: %llu points, %llu tets)",
                 bad > 1 ? "s" : "", list, bad > 8 ? ", ..." : "", bad > 1 ? "" : "s", what, first,
                 (unsigned long long)f[FP_POINTS], (unsigned long long)f[FP_TETS],
                 (unsigned long long)all[FP_POINTS], (unsigned long long)all[FP_TETS]);
    }
    free(all);
    return bad ? TET_ERR_INVALID_ARGUMENT : TET_OK;
}

/* Set-up after the local engine: the reduction buffers and the tables' scratch. */
static tet_result alloc_exchange(rank_scan *R, char *err, size_t errlen)
{
    R->DD = tet_local_tiles_d(R->L) * tet_local_tiles_d(R->L);
    size_t n = (size_t)R->DD + 1 + (size_t)R->P; /* the reduction, then a table's scratch */
    R->sendbuf = malloc(n * sizeof(float));
    R->recvbuf = malloc(n * sizeof(float));
    R->known = malloc((size_t)R->DD * sizeof(float));
    R->enc = malloc((size_t)R->DD * sizeof(float));
    R->remaining = malloc((size_t)R->P * sizeof(float));
    if (!R->sendbuf || !R->recvbuf || !R->known || !R->enc || !R->remaining) {
        tet_errf(err, errlen, "tet_mpi: out of memory for the ERT exchange (D*D = %d)", R->DD);
        return TET_ERR_OUT_OF_MEMORY;
    }
    return TET_OK;
}

/* The shared ERT table's window on rank 0, reset to +inf (collective; only when sharing).
 * Same decision and D on every rank (same opts), so the collectives match. The window is
 * kept in the context: creating one is a collective that spins inside Open MPI, which with
 * more ranks than cores cost seconds per frame. */
static void share_window(tet_mpi *ctx, rank_scan *R, char *err, size_t errlen)
{
    if (ctx->win_dd != R->DD) {
        if (ctx->win_dd)
            MPI_Win_free(&ctx->win);
        MPI_Aint bytes = R->rank == 0 ? (MPI_Aint)R->DD * (MPI_Aint)sizeof(float) : 0;
        MPI_Win_allocate(bytes, sizeof(float), MPI_INFO_NULL, R->comm, &ctx->win_mem, &ctx->win);
        ctx->win_dd = R->DD;
    }
    R->win = ctx->win;
    if (R->rank == 0) {
        MPI_Win_lock(MPI_LOCK_EXCLUSIVE, 0, 0, R->win);
        for (int i = 0; i < R->DD; i++)
            ctx->win_mem[i] = INFINITY;
        MPI_Win_unlock(0, R->win);
    }
    /* nobody reads it before it is reset; the agreement after the scan keeps the next
     * frame's reset after every access of this one */
    agree(R->comm, TET_OK, err, errlen, "window set-up");
}

/* Scan: the keys [next, end) in order, the ERT table updated C times per stretch and, when
 * cooperating, shared and the reductions and requests moved along (cheap MPI_Test /
 * MPI_Iprobe every POLL keys, so a rank scanning a long stretch still answers). Sets failed
 * when a scan runs out of memory. */
static void scan_keys(rank_scan *R, char *err, size_t errlen)
{
    const uint32_t POLL = 256;
    tet_mpi_stats *st = R->st;
    tet_counters *cnt = tet_local_counters(R->L);
    uint32_t rem = R->end - R->next;
    uint32_t interval = rem / R->C > 0 ? rem / R->C : 1, since = 0;
    double ts = tet_now_ms(), tin = 0, tu0 = cnt->t_update_ms;
    while (R->next < R->end && !R->failed) {
        if (since >= interval) {
            if (R->ert)
                tet_local_update_table(R->L);
            if (R->coop) {
                double tp = tet_now_ms();
                if (R->share)
                    share_table(R);
                poll_rank(R, 1);
                st->polls++;
                tin += tet_now_ms() - tp;
            }
            interval = (R->end - R->next) / R->C > 0 ? (R->end - R->next) / R->C : 1;
            since = 0;
        } else if (R->coop && since % POLL == POLL - 1) {
            double tp = tet_now_ms();
            poll_rank(R, 0);
            st->polls++;
            tin += tet_now_ms() - tp;
        }
        if (R->next >= R->end)
            break; /* everything left was handed away */
        since++;
        st->keys_done++;
        if (tet_local_scan(R->L, R->next++) != 0) {
            R->failed = 1;
            R->end = R->next; /* nothing to hand out either */
            tet_errf(err, errlen, "tet_mpi: rank %d out of memory at %llu segments", R->rank,
                     (unsigned long long)cnt->segments_made);
        }
    }
    cnt->t_sc_ms += tet_now_ms() - ts - tin - (cnt->t_update_ms - tu0);
    st->t_comm_ms += tin;
}

/* Steal: out of keys, ask for more until a request is answered with some (returns 1, the
 * keys in [next, end)) or nobody has any to give (0). The rank keeps answering other
 * requests meanwhile (with nothing). */
static int steal_keys(rank_scan *R)
{
    while (ask_for_work(R)) {
        double tw = tet_now_ms();
        for (;;) {
            int flag = 0;
            MPI_Test(&R->give_rq, &flag, MPI_STATUS_IGNORE);
            if (flag)
                break;
            poll_rank(R, 1);
            idle_pause();
        }
        wait_polite(1, &R->ask_rq); /* it was answered, so it was received */
        R->st->t_idle_ms += tet_now_ms() - tw;
        uint32_t n = R->give[1] - R->give[0];
        int asked = R->asked;
        R->asked = -1;
        if (n > 0) {
            tet_local_need(R->L, R->give[0], R->give[1]); /* sorts the victim's keys */
            R->next = R->give[0];
            R->end = R->give[1];
            R->st->cells_taken += n;
            return 1;
        }
        R->remaining[asked] = 0; /* stale: do not ask it again before new counts */
    }
    return 0;
}

/* Termination: keep taking part in reductions (answering requests with nothing) until one
 * shows every rank done. Every rank sees the same result of the same reduction, so all
 * leave after the same one and no message is left in flight (a rank waiting for an answer
 * is not done, so that reduction cannot say all done). */
static void wait_all_done(rank_scan *R)
{
    double tw = tet_now_ms();
    R->done = 1;
    while (!R->all_done) {
        poll_rank(R, 1);
        if (!R->all_done)
            idle_pause();
    }
    R->st->t_idle_ms += tet_now_ms() - tw;
}

/* Phase 1 on this rank: scan, steal when out of keys (load balancing), then termination. */
static void scan_phase(rank_scan *R, char *err, size_t errlen)
{
    for (;;) {
        scan_keys(R, err, errlen);
        if (!R->coop || R->failed || !R->dlb || !steal_keys(R))
            break;
    }
    if (R->coop)
        wait_all_done(R);
}

/* Phase 2: this rank's full-screen segment lists exported (the local engine is destroyed
 * after: the lists are all phase 2 needs), then composited by binary swap. */
static tet_result binary_swap_phase(rank_scan *R, const tet_camera *cam, const tet_options *opts,
                                    float *rgba, char *err, size_t errlen)
{
    tet_mpi_stats *st = R->st;
    double te = tet_now_ms();
    tet_seglists lists;
    memset(&lists, 0, sizeof lists);
    size_t npix = (size_t)cam->width * cam->height;
    lists.p0 = 0;
    lists.p1 = npix;
    lists.off = malloc((npix + 1) * sizeof *lists.off);
    size_t nseg = lists.off ? tet_local_export(R->L, 0, npix, lists.off, NULL) : 0;
    lists.segs = lists.off && nseg <= INT_MAX ? malloc((nseg + 1) * sizeof *lists.segs) : NULL;
    tet_result r2 = TET_OK;
    if (!lists.segs) {
        tet_errf(err, errlen, "tet_mpi: rank %d out of memory exporting %zu segments", R->rank, nseg);
        r2 = TET_ERR_OUT_OF_MEMORY;
        tet_seglists_free(&lists);
    } else {
        tet_local_export(R->L, 0, npix, lists.off, lists.segs);
    }
    st->segments_local = nseg;
    st->cnt = *tet_local_counters(R->L);
    tet_local_destroy(R->L);
    R->L = NULL;
    tet_result rc = agree(R->comm, r2, err, errlen, "export");
    st->t_export_ms = tet_now_ms() - te;
    if (rc == TET_OK)
        rc = tet_mpi_composite(R->comm, cam->width, cam->height, &lists, opts->partial_composite,
                               rgba, st, err, errlen);
    tet_seglists_free(&lists);
    return rc;
}

tet_result tet_mpi_render(tet_mpi *ctx, const tet_mesh *mesh, const tet_camera *cam,
                       const tet_tf *tf, const tet_options *opts, float *rgba,
                       tet_mpi_stats *mine, tet_mpi_stats *all, char *err, size_t errlen)
{
    double t_start = tet_now_ms();
    MPI_Comm comm = ctx->comm;
    int rank, P;
    MPI_Comm_rank(comm, &rank);
    MPI_Comm_size(comm, &P);
    tet_mpi_stats st;
    memset(&st, 0, sizeof st);
    rank_scan R;
    memset(&R, 0, sizeof R);
    R.comm = comm;
    R.rank = rank;
    R.P = P;
    R.opts = opts;
    R.asked = -1;
    R.st = &st;
    /* rank 0 gathers the statistics even when the caller wants none */
    tet_mpi_stats *gather_tmp = rank == 0 && !all ? malloc((size_t)P * sizeof *gather_tmp) : NULL;
    tet_result rc = check_same_input(comm, P, mesh, cam, opts, err, errlen);
    if (rc != TET_OK)
        goto done;
    rc = tet_local_create(mesh, cam, tf, opts, P, rank, &R.L, err, errlen);
    if (rc == TET_OK && rank == 0 && !all && !gather_tmp) {
        tet_errf(err, errlen, "tet_mpi: out of memory for %d ranks' statistics", P);
        rc = TET_ERR_OUT_OF_MEMORY;
    }
    if (rc == TET_OK)
        rc = alloc_exchange(&R, err, errlen);
    rc = agree(comm, rc, err, errlen, "set-up");
    if (rc != TET_OK)
        goto done;
    R.share = opts->share && opts->ert && P > 1;
    if (R.share)
        share_window(ctx, &R, err, errlen);
    tet_local_part(R.L, rank, &R.next, &R.end);
    st.cells_assigned = R.end - R.next;
    for (int i = 0; i < R.DD; i++)
        R.known[i] = INFINITY;
    for (int i = 0; i < P; i++) /* until the first reduction: cells, NaN ones included */
        R.remaining[i] = (float)tet_local_part_cells(R.L, i);
    R.dlb = opts->dlb;
    /* reductions are needed for sharing, and for the remaining counts and the termination
     * agreement of load balancing; without either the ranks scan independently */
    R.coop = P > 1 && (R.share || R.dlb);
    R.ert = opts->ert;
    R.C = opts->update_c > 0 ? (uint32_t)opts->update_c : 1;
    double t1 = tet_now_ms(), c1 = tet_thread_cpu_ms();
    st.t_setup_ms = t1 - t_start;
    scan_phase(&R, err, errlen);
    st.t_phase1_ms = tet_now_ms() - t1;
    st.t_phase1_cpu_ms = tet_thread_cpu_ms() - c1;
    rc = agree(comm, R.failed ? TET_ERR_OUT_OF_MEMORY : TET_OK, err, errlen, "the scan");
    if (rc == TET_OK)
        rc = binary_swap_phase(&R, cam, opts, rgba, err, errlen);
done:
    if (R.L)
        st.cnt = *tet_local_counters(R.L);
    st.t_total_ms = tet_now_ms() - t_start;
    if (mine)
        *mine = st;
    if (rc == TET_OK) {
        MPI_Request rq;
        MPI_Igather(&st, (int)sizeof st, MPI_BYTE, all ? all : gather_tmp, (int)sizeof st,
                    MPI_BYTE, 0, comm, &rq);
        wait_polite(1, &rq);
    }
    free(gather_tmp);
    tet_local_destroy(R.L);
    free(R.sendbuf);
    free(R.recvbuf);
    free(R.known);
    free(R.enc);
    free(R.remaining);
    return rc;
}
