/* tet_mpi.h — the seed-002 cell-projection renderer across MPI processes (Open MPI): each rank
 * holds the whole mesh, owns a partition of cells and a local ERT table, shares ERT tables
 * weakly through non-blocking reductions, balances load by moving key ranges, and composites
 * the per-pixel depth-tagged ray-segment lists by binary swap. Built only with -Dmpi. */
#ifndef TET_MPI_H
#define TET_MPI_H

#include <mpi.h>
#include <stddef.h>
#include <stdint.h>
#include "tet_render.h"
#include "tet_render_internal.h"

/* Per-pixel ray-segment lists of the pixel range [p0, p1), depth ordered per pixel, in CSR
 * form: pixel p's segments are segs[off[p - p0] .. off[p - p0 + 1]). Heap arrays. */
typedef struct tet_seglists {
    size_t p0, p1;
    uint32_t *off;
    tet_rseg *segs;
} tet_seglists;

typedef struct tet_mpi_stats {
    tet_counters cnt;     /* this rank's scan counters (t_sc_ms: scan time alone) */
    uint64_t cells_assigned;  /* keys of the initial partition */
    uint64_t keys_done;       /* keys this rank took through the scan loop (any outcome) */
    uint64_t cells_taken;     /* keys received by load balancing */
    uint64_t cells_given;     /* keys handed to other ranks */
    uint64_t steal_requests;  /* requests this rank sent */
    uint64_t share_rounds;    /* exchanges with the shared ERT table */
    uint64_t reductions;      /* completed load-balancing / termination reductions */
    uint64_t segments_local;  /* segments in this rank's lists after the scan */
    uint64_t segments_final;  /* segments in the rank's screen part after binary swap */
    uint64_t bytes_sent;      /* binary swap (and fold) payload sent by this rank */
    uint64_t pixels_final;    /* pixels this rank composited */
    double t_phase1_ms;       /* scan loop wall time, communication included */
    double t_phase1_cpu_ms;   /* CPU time of this rank's thread in the scan loop (with more
                               * ranks than cores the wall times include other ranks' turns) */
    double t_comm_ms;         /* of which polling and sharing while the rank had keys */
    double t_idle_ms;         /* of which waiting out of keys (asking for work, last rounds) */
    uint64_t polls;           /* progress calls while scanning */
    double t_setup_ms;        /* transform, keys of every partition, sort (replicated per rank) */
    double t_export_ms;       /* copying the lists out of the scan state */
    double t_swap_ms, t_gather_ms, t_total_ms;
} tet_mpi_stats;

/* A communicator and what is kept between renders on it (the shared ERT table's window). */
typedef struct tet_mpi tet_mpi;

/* Creates a context on comm (which must outlive it). Collective; TET_OK or an error code on
 * every rank with a message in err. */
tet_result tet_mpi_create(MPI_Comm comm, tet_mpi **out, char *err, size_t errlen);
/* Frees a context; NULL allowed. Collective when not NULL. */
void tet_mpi_destroy(tet_mpi *ctx);

/* Renders mesh on all ranks of ctx's comm (every rank passes the same mesh, camera, tf and opts;
 * opts->workers is ignored: one scan per rank). rgba (width*height*4, premultiplied) is filled
 * on rank 0 and may be NULL elsewhere; mine (may be NULL) gets this rank's statistics, all
 * (rank 0, NULL or comm-size entries) every rank's. Collective; returns TET_OK or the same
 * error code on every rank, with a message in err. */
tet_result tet_mpi_render(tet_mpi *ctx, const tet_mesh *mesh, const tet_camera *cam,
                       const tet_tf *tf, const tet_options *opts, float *rgba,
                       tet_mpi_stats *mine, tet_mpi_stats *all, char *err, size_t errlen);

/* Binary-swap composition of every rank's full-screen lists (range [0, width*height)): ranks
 * beyond the largest power of two first fold theirs into a partner, then log2 stages swap
 * half the current range with a partner and merge the received lists by depth (touching
 * segments partially composited when partial is set); each rank composites its 1/P front to
 * back and rank 0 gathers rgba. lists is consumed (its arrays freed). st may be NULL.
 * Collective; returns TET_OK or an error code on every rank with a message in err. */
tet_result tet_mpi_composite(MPI_Comm comm, int width, int height, tet_seglists *lists,
                          int partial, float *rgba, tet_mpi_stats *st, char *err, size_t errlen);

/* Merges two depth-ordered lists over the same pixel range into out (allocated here);
 * touching segments are partially composited when partial is set. Returns 0 or -1 (memory). */
int tet_seglists_merge(const tet_seglists *a, const tet_seglists *b, int partial,
                           tet_seglists *out);

/* Frees the arrays of lists and zeroes it; NULL allowed. */
void tet_seglists_free(tet_seglists *lists);

#endif
