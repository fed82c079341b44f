/* sph_internal.h — the solver's state and the functions its files share (not installed; the
 * API is sph.h). One file per concern: sph_pool.c (worker threads), sph_params.c (defaults,
 * lattice calibration, create/destroy), sph_storage.c (columns, adding particles),
 * sph_collide.c (colliders, mesh distance fields), sph_grid.c (cell sort, volume fraction),
 * sph_wall.c (wall integrals, wall law, wall terms of the passes), sph_kernels.c (the
 * per-chunk passes and their SSE2 pair loops), sph_emit.c (emitters), sph_step.c (substeps),
 * sph_pbf.c (Position Based Fluids), sph_pbf_lin.c (its pair terms, computed once per iteration).
 * The colliders' and the walls' shared functions have their own headers, sph_collide.h and
 * sph_wall.h (the walls use the colliders, never the other way): this header calls no file. */
#ifndef RT_SIM_SPH_INTERNAL_H
#define RT_SIM_SPH_INTERNAL_H

#include "core/error.h"
#include "sim/sph.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>

#define SPH_CHUNK 1024u          /* particles per work item: fixed, so sums do not depend on threads */
#define SPH_MAX_COLLIDERS 64u
#define SPH_MAX_EMITTERS 16u
#define SPH_MAX_MESH_TRIANGLES 20000u
#define SPH_MESH_GRID 64
#define SPH_MAX_CELLS (1u << 26)
#define SPH_PI 3.14159265358979323846

typedef struct sph_chunk_out {
    float v2_max, a2_max, c2_max;
    float rho_err_max;
    double rho_err_sum, ke, pe, ie;
    uint64_t pairs, skin_pairs;
    float disp2_max;   /* max squared displacement since the last rebuild (integration pass) */
    uint32_t bad;      /* first failing row in the chunk, UINT32_MAX when none */
    int bad_kind;      /* 1 non-finite, 2 speed, 3 density change */
    float bad_value;
    uint32_t clamped;  /* PBF: speeds held at the limit */
} sph_chunk_out;

typedef struct sph_collider_state {
    rt_sph_collider c;
    float pos[3], vel[3]; /* at the current substep */
    /* triangle mesh: signed distance sampled on a grid (positive outside), trilinear */
    float *sdf;
    int sdf_n[3];
    float sdf_lo[3], sdf_h[3];
} sph_collider_state;

typedef struct sph_emitter_state {
    rt_sph_emitter e;
    float u[3], w[3];     /* basis of the nozzle plane */
    double travelled;     /* distance moved by the last layer */
    uint32_t emitted;
    bool started;
} sph_emitter_state;

typedef void (*sph_chunk_fn)(rt_sph *s, uint32_t chunk);

/* A worker thread's share: participant `index` (the caller is 0) of every pass. */
typedef struct sph_worker {
    rt_sph *s;
    uint32_t index;
} sph_worker;

struct rt_sph {
    rt_sph_desc p;
    float mass, H, H2, h, inv_cell;
    float k_poly6, k_spiky;          /* W = k_poly6 (H^2-r^2)^3, |grad W| = k_spiky (H-r)^2 */
    float wall_scale;                /* lattice calibration of the wall density fraction */
    float fric_scale;                /* lattice calibration of the wall-law shear (see create) */
    bool friction;                   /* some face or collider is no-slip */
    float B, c0;
    double time;
    uint32_t n, cap, next_id, clamped_on_add;
    /* columns: the state (x..vz, rho) is the host's while bound, the rest is always ours */
    bool bound;
    rt_sph_host host;
    uint32_t state_cap; /* rows of our own state columns (0 while bound) */
    float *x, *y, *z, *vx, *vy, *vz, *rho, *pr, *ax, *ay, *az, *drho;
    float *xn, *yn, *zn, *vxn, *vyn, *vzn, *tmp;
    uint32_t *id, *idtmp, *key, *perm;
    /* grid */
    int nx, ny, nz;
    uint32_t ncells;
    uint32_t *cell_start; /* ncells + 1 */
    /* boundaries */
    sph_collider_state col[SPH_MAX_COLLIDERS];
    uint32_t ncol;
    sph_emitter_state em[SPH_MAX_EMITTERS];
    uint32_t nem;
    /* per-chunk reductions */
    sph_chunk_out *out;
    uint32_t out_cap;
    float dt_try;
    bool want_energy; /* the closing density pass also sums the EOS internal energy */
    /* neighbour lists found by the density pass and reused by the force pass: one growing
     * buffer per chunk (a chunk is only ever run by one thread), offsets per particle */
    uint32_t **cnb, *cnb_cap, *nb_start, *nb_count;
    uint32_t cnb_chunks;
    atomic_bool nb_oom;
    /* Verlet lists: every pair within H + skin at the last rebuild, per chunk like cnb (rows
     * are only re-sorted at a rebuild, so a row's chunk is stable between rebuilds), and the
     * positions at that rebuild. Valid while 2 max|x - x0| < skin. */
    bool verlet;                 /* false with RT_SPH_REBUILD_EVERY_SUBSTEP */
    bool lists_valid;
    int dens_mode;               /* density pass: 0 cell scan, 1 cell scan recording the Verlet
                                  * lists, 2 walk the Verlet lists */
    float skin, S2;              /* skin [m], (H + skin)^2 */
    float disp2_max;             /* of the last integration, over all particles */
    float *x0, *y0, *z0;
    uint32_t **snb, *snb_cap, *snb_used, *sk_start, *sk_count;
    /* thread pool */
    pthread_t *threads;
    sph_worker *workers;
    uint32_t nthreads; /* workers besides the caller */
    pthread_mutex_t mu;
    pthread_cond_t cv_start, cv_done;
    uint64_t gen;
    uint32_t busy;
    bool quit;
    sph_chunk_fn job;
    uint32_t nchunks;
    /* Position Based Fluids (sph_pbf.c): pr holds each particle's pressure [Pa] (the multiplier
     * lambda = -p dt^2 / rho0) and follows the rows through sorts */
    uint32_t pbf_valid;          /* rows [0, pbf_valid) have a pressure; later rows are new */
    float pbf_D0;                /* sum_j |grad_j C_i|^2 of a lattice particle [1/m^2] (0: not yet) */
    float pbf_eps, pbf_wdq;      /* constraint-force mixing; (H^2 - dq^2)^3 of s_corr */
    float pbf_eps_step;          /* the mixing of the current step's dt (pbf_step_eps) */
    float pbf_vmax;              /* largest speed after the last step */
    float pbf_dt;                /* the step being taken */
    uint32_t pbf_iter;           /* the Jacobi iteration being run (0: the walls are evaluated) */
    float cheb_omega;            /* this iteration's Chebyshev weight (1: a plain Jacobi update) */
    float *cheb_prev[3];         /* the iterate before the current one (its extrapolation base) */
    float *pc[3], *pn[3];        /* positions of the current and the next Jacobi iterate */
    bool pbf_store;              /* this step's lambda passes store the pair terms (sph_pbf_lin.c) */
    /* sph_pbf_lin.c: the iteration's pair terms, three arrays per work item parallel to cnb
     * (pbf_pe_cap[c] entries each), and per-particle terms (columns of pbf_lin_cap) */
    float **pbf_pe;
    uint32_t *pbf_pe_cap, pbf_pe_chunks;
    float *pbf_lin;
    uint32_t pbf_lin_cap;
};

/* Rows [*b, *e) of a work item. */
static inline void sph_chunk_rows(const rt_sph *s, uint32_t chunk, uint32_t *b, uint32_t *e)
{
    *b = chunk * SPH_CHUNK;
    *e = *b + SPH_CHUNK < s->n ? *b + SPH_CHUNK : s->n;
}

static inline uint32_t sph_chunk_count(const rt_sph *s) { return (s->n + SPH_CHUNK - 1) / SPH_CHUNK; }

static inline float sph_clampf(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }
static inline bool sph_finite3(const float *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

static inline int sph_cell_coord(float v, float lo, float inv, int n)
{
    int c = (int)((v - lo) * inv);
    return c < 0 ? 0 : (c >= n ? n - 1 : c);
}

typedef struct sph_ranges {
    uint32_t lo[49], hi[49]; /* up to 7x7 rows of cells */
    int count;
} sph_ranges;

/* The particle index ranges of the (2R+1)^3 cells of H/2 around p (R <= 3): one range per row
 * of x-adjacent cells, rows with no particle left out. */
static inline void sph_neighbor_ranges(const rt_sph *s, float px, float py, float pz, int R, sph_ranges *r)
{
    const float *lo = s->p.domain_min;
    int cx = sph_cell_coord(px, lo[0], s->inv_cell, s->nx);
    int cy = sph_cell_coord(py, lo[1], s->inv_cell, s->ny);
    int cz = sph_cell_coord(pz, lo[2], s->inv_cell, s->nz);
    int x0 = cx >= R ? cx - R : 0, x1 = cx + R < s->nx ? cx + R : s->nx - 1;
    r->count = 0;
    for (int z = cz - R; z <= cz + R; ++z) {
        if (z < 0 || z >= s->nz)
            continue;
        for (int y = cy - R; y <= cy + R; ++y) {
            if (y < 0 || y >= s->ny)
                continue;
            uint32_t row = (uint32_t)((z * s->ny + y) * s->nx);
            uint32_t a = s->cell_start[row + (uint32_t)x0], b = s->cell_start[row + (uint32_t)x1 + 1];
            if (b > a) {
                r->lo[r->count] = a;
                r->hi[r->count] = b;
                r->count++;
            }
        }
    }
}

/* sph_pool.c: starts the workers (fewer when a thread cannot be made: p.threads then says how
 * many run; out of memory for their handles is an error); stops and joins them */
vfx_result rt_sph_pool_start(rt_sph *s);
void rt_sph_pool_stop(rt_sph *s);
/* Runs fn over every chunk on all threads. The density pass starts the chunk reductions
 * afresh (fresh); later passes of the same substep add to them and only reset the failure slot. */
void rt_sph_parallel(rt_sph *s, sph_chunk_fn fn, bool fresh);

/* sph_storage.c */
/* Grows every per-particle and per-chunk buffer to hold `want` particles. */
vfx_result rt_sph_reserve(rt_sph *s, uint64_t want, char *err, size_t errlen);
void rt_sph_free_columns(rt_sph *s);
/* Exchanges the state columns with the integration buffers (xn ...); own state only. */
void rt_sph_swap_state(rt_sph *s);
/* Makes the integration buffers the state: a swap, or a copy into the host's columns. */
void rt_sph_commit_state(rt_sph *s);
/* Takes the host's column pointers. */
void rt_sph_take_columns(rt_sph *s, const rt_sph_columns *c);

/* sph_grid.c: sorts the particles by cell (all columns follow, through the host when bound),
 * cell_start is rebuilt; an error when the host could not reorder (nothing changed then) */
vfx_result rt_sph_build_grid(rt_sph *s, char *err, size_t errlen);

/* sph_kernels.c: the passes run by rt_sph_parallel */
void rt_sph_density_chunk(rt_sph *s, uint32_t chunk);
/* The density pass's neighbour lists alone (exact and, by dens_mode, Verlet), no density,
 * pressure or wall terms: what PBF's linearised iterations need of it */
void rt_sph_lists_chunk(rt_sph *s, uint32_t chunk);
void rt_sph_force_chunk(rt_sph *s, uint32_t chunk);
void rt_sph_integrate_chunk(rt_sph *s, uint32_t chunk);
void rt_sph_disp_chunk(rt_sph *s, uint32_t chunk);

/* sph_kernels.c: deterministic, antisymmetric unit direction for two exactly coincident
 * particles (ids a, b) */
void rt_sph_coincident_dir(uint32_t a, uint32_t b, float out[3]);

/* sph_pbf.c: a frame of Position Based Fluids (the WCSPH frame is in sph_step.c) */
vfx_result rt_sph_pbf_step(rt_sph *s, float frame_dt, rt_sph_report *rep, char *err, size_t errlen);
/* sph_pbf.c: the calibrated constants PBF steps with (calibrated on first use, as the first
 * step does): the lattice's sum |grad C|^2, the mixing eps of a call of frame_dt, (H^2 - dq^2)^3
 * (the GPU solver's, sph_gpu.c) */
void rt_sph_pbf_constants(rt_sph *s, float frame_dt, float *D0, float *eps, float *wdq);
/* sph_pbf.c: moves p out of every collider and the domain box to the clamp margin (dx/4) */
void rt_sph_pbf_clamp(const rt_sph *s, float p[3]);

/* sph_pbf_lin.c: the pair terms PBF's lambda pass stores for its position pass.
 * Grows the storage for the current lists (after the neighbour pass); an error when out of memory. */
vfx_result rt_sph_pbf_lin_reserve(rt_sph *s, char *err, size_t errlen);
void rt_sph_pbf_lin_free(rt_sph *s);
size_t rt_sph_pbf_lin_bytes(const rt_sph *s);
/* The work item's arrays of the stored gradients q_ij d_ij (x, y, z), indexed as cnb[chunk]. */
void rt_sph_pbf_pair_arrays(const rt_sph *s, uint32_t chunk, float *pe[3]);
/* Row i's count of coincident stored pairs; in the first iteration also its wall room. */
void rt_sph_pbf_store_particle(rt_sph *s, uint32_t i, uint32_t coincident);
uint32_t rt_sph_pbf_stored_coincident(const rt_sph *s, uint32_t i);
/* False when row i at p is surely farther than the clamp margin from every wall (the clamp is
 * then the identity). */
bool rt_sph_pbf_may_reach_wall(const rt_sph *s, uint32_t i, const float p[3]);

/* sph_emit.c: runs the emitters for dt (0 on the first substep); count added to *emitted */
vfx_result rt_sph_emit(rt_sph *s, double dt, uint32_t *emitted, char *err, size_t errlen);
/* sph_settle.c: one settle over either solver (rt_sph_settle, rt_sph_gpu_settle). step advances the
 * solver by dt, then damp scales its velocities by factor (given the step's report); count is its
 * particle count. */
typedef struct rt_sph_settle_ops {
    vfx_result (*step)(void *solver, float dt, rt_sph_report *rep, char *err, size_t errlen);
    void (*damp)(void *solver, float factor, const rt_sph_report *rep);
    void *solver;
    const uint32_t *count;
} rt_sph_settle_ops;
/* rt_sph_settle's steps through ops: desc checked (refused naming `who`) and defaulted, s's clock
 * held at its start time and its colliders put back there after; *rep written at the end. */
vfx_result rt_sph_settle_run(rt_sph *s, const char *who, const rt_sph_settle_desc *desc, const rt_sph_settle_ops *ops,
                             rt_sph_settle_report *rep, char *err, size_t errlen);

#endif
