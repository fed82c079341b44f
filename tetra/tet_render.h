/* tet_render.h — CPU cell-projection renderer for tetrahedral meshes (seed 002): each tet is
 * scan-converted into per-pixel ray segments kept in depth-ordered per-pixel lists with partial
 * compositing on insert, with Conservative Subscreen Termination (DxD ERT table). */
#ifndef TET_RENDER_H
#define TET_RENDER_H

#include <stdint.h>
#include "tet_mesh.h"

/* Perspective camera: column-major view and projection matrices (OpenGL/cglm convention). */
typedef struct tet_camera {
    float view[16];
    float proj[16];
    int width, height;
} tet_camera;

/* Most render workers (threads) of one frame: the plugin's volume.workers goes to 256. */
#define TET_MAX_WORKERS 256

/* Most breakpoints a transfer function table may have. */
#define TET_TF_MAX_POINTS 1024

/* How a ray segment's colour and opacity come from the transfer function. */
enum {
    TET_TF_EXACT = 0,        /* the segment is split at the table's breakpoints (the scalar is
                              * linear along it, so tau and colour are linear along each piece)
                              * and each piece's emission-absorption integral is evaluated
                              * (opacity exactly, colour to ~1e-6) */
    TET_TF_PREINTEGRATED,    /* pre-integrated lookup (Engel et al. 2001): cumulative integrals
                              * of tau and tau*colour over a grid, no self-attenuation */
    TET_TF_MIDPOINT,         /* one evaluation at the segment's midpoint scalar, colour times
                              * the segment's opacity (the renderer's rule before tables) */
};

/* One breakpoint of a piecewise-linear transfer function. */
typedef struct tet_tf_point {
    float s;        /* scalar (data units), strictly increasing along the table */
    float rgb[3];
    float tau;      /* extinction per world unit */
} tet_tf_point;

/* Transfer function of the scalar. With count == 0 it is linear over the normalised scalar
 * u = (s - smin) / (smax - smin) clamped to [0,1]: extinction tau = tau_lo + (tau_hi - tau_lo) u
 * per world unit, colour lerped. With count >= 2, points[0..count) is piecewise linear in s,
 * clamped to its end values outside [points[0].s, points[count-1].s] (smin..colour_hi unused). */
typedef struct tet_tf {
    float smin, smax;
    float tau_lo, tau_hi;
    float color_lo[3], color_hi[3];
    const tet_tf_point *points;
    int count;              /* 0 or 2..TET_TF_MAX_POINTS */
    int method;             /* TET_TF_*; 0 = exact */
    int pre_size;           /* TET_TF_PREINTEGRATED: grid cells, 0 -> 1024 */
} tet_tf;

typedef struct tet_options {
    int ert;               /* 1: Conservative Subscreen Termination on */
    float ert_threshold;   /* accumulated opacity at which a pixel counts as terminated */
    int tiles_d;           /* D: the ERT table is D x D tiles */
    int update_c;          /* C: table updated every (remaining cells)/C cells */
    int partial_composite; /* 1: merge adjacent segments on insert */
    const float *max_dist; /* optional width*height host depth as ray distance; NULL = none */
    int workers;           /* threads, each owning a partition of cells (<= 0 means 1, max TET_MAX_WORKERS) */
    int share;             /* 1: weak sharing of the ERT tables at each table update */
    int dlb;               /* 1: dynamic load balancing (idle worker takes 1/3 of the most loaded) */
} tet_options;

typedef struct tet_counters {
    uint64_t cells_scanned;      /* cells scan-converted */
    uint64_t cells_skipped_ert;  /* N: cells skipped by subscreen termination */
    uint64_t cells_behind;       /* cells wholly behind the near plane (skipped) */
    uint64_t cells_near_crossing;/* cells crossing the near plane (ray-clipped at near) */
    uint64_t cells_degenerate;   /* zero-volume cells (skipped) */
    uint64_t cells_nan;          /* cells with a NaN or Inf scalar or coordinate (skipped) */
    uint64_t segments_made;      /* ray segments produced by scan conversion */
    uint64_t segments_merged;    /* of those, merged by partial compositing on insert */
    uint64_t table_updates;
    double t_sc_ms, t_update_ms, t_composite_ms;
    uint64_t tf_pieces;          /* ray pieces integrated (segments split at TF breakpoints) */
    double cpu_ms;               /* CPU time of the worker thread in the frame (its share of the
                                  * projection, its sort, scan, table updates and its rows of
                                  * the composite); totals: sum */
    double t_wait_ms;            /* waiting for other workers at the end of the scan phase */
    double t_setup_ms;           /* projection and front-to-back sort before the scan */
} tet_counters;

/* Fills opts with the paper's defaults (ERT on, threshold 0.9, D = 20, C = 100, partial on,
 * one worker, sharing and load balancing on). */
void tet_options_default(tet_options *opts);

/* Renders mesh (with its scalar) into rgba (width*height*4 floats, premultiplied, row 0 = bottom).
 * Returns TET_OK or an error code with a message in err; counters may be NULL. */
tet_result tet_render(const tet_mesh *mesh, const tet_camera *cam, const tet_tf *tf,
                   const tet_options *opts, float *rgba, tet_counters *counters,
                   char *err, size_t errlen);

/* As tet_render with opts->workers threads; per_worker (NULL or opts->workers entries)
 * receives each worker's counters. counters totals the cells and keeps the maximum times. */
tet_result tet_render_workers(const tet_mesh *mesh, const tet_camera *cam,
                           const tet_tf *tf, const tet_options *opts, float *rgba,
                           tet_counters *counters, tet_counters *per_worker,
                           char *err, size_t errlen);

/* A persistent pool of render workers: workers - 1 threads created once that wait for frames,
 * plus the calling thread, with their segment lists and tables kept between frames. */
typedef struct tet_pool tet_pool;

/* Creates a pool of workers (<= 0 means 1, at most TET_MAX_WORKERS). Returns TET_OK or an error
 * code with a message in err. A thread that cannot be started is not fatal: its share runs on
 * the caller. */
tet_result tet_pool_create(int workers, tet_pool **out, char *err, size_t errlen);
/* Stops the threads and frees the pool; NULL allowed. */
void tet_pool_destroy(tet_pool *pool);
/* Workers of the pool (threads started + the caller). */
int tet_pool_workers(const tet_pool *pool);
/* Threads started since creation (workers - 1 when all started; never grows with frames). */
int tet_pool_threads(const tet_pool *pool);

/* As tet_render_workers on the pool's workers (opts->workers is ignored). */
tet_result tet_render_pool(tet_pool *pool, const tet_mesh *mesh, const tet_camera *cam,
                    const tet_tf *tf, const tet_options *opts, float *rgba,
                    tet_counters *counters, tet_counters *per_worker, char *err, size_t errlen);

#endif
