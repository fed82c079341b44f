/* sph.c — weakly compressible SPH: see sph.h and docs/simulation.md. */
#include "sim/sph.h"

#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#if defined(__SSE2__) && (defined(__GNUC__) || defined(__clang__))
#include <emmintrin.h>
/* SSE2 (every x86-64): the density walk and the force pair loop take four pairs at a time;
 * elsewhere the scalar loops below do the same sums */
#define SPH_SSE 1
static inline float sph_hsum(__m128 v)
{
    float l[4];
    _mm_storeu_ps(l, v);
    return (l[0] + l[1]) + (l[2] + l[3]);
}
#else
#define SPH_SSE 0
#endif

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
    /* columns */
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
    uint32_t nthreads; /* workers besides the caller */
    pthread_mutex_t mu;
    pthread_cond_t cv_start, cv_done;
    uint64_t gen;
    uint32_t busy;
    bool quit;
    sph_chunk_fn job;
    atomic_uint next_chunk;
    uint32_t nchunks;
    char err[512];
};

static void set_err(rt_sph *s, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void set_err(rt_sph *s, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(s->err, sizeof s->err, fmt, ap);
    va_end(ap);
}

/* ---- closed-form wall integrals ------------------------------------------------------------ */

double rt_sph_wall_density_fraction(double d, double H)
{
    if (d >= H)
        return 0.0;
    if (d < 0.0)
        d = 0.0; /* inside the wall: the clamp puts it back; use the half-space value */
    /* int_{z>d} int_plane W_poly6 = (pi k/4) int_d^H (H^2-z^2)^4 dz, k = 315/(64 pi H^9);
     * with u = d/H: (315/256) [P(1) - P(u)], P(u) = u - 4u^3/3 + 6u^5/5 - 4u^7/7 + u^9/9
     * (Horner form: this runs per particle and wall in every pass) */
    double u = d / H, u2 = u * u;
    double Pu = u * (1.0 + u2 * (-4.0 / 3.0 + u2 * (6.0 / 5.0 + u2 * (-4.0 / 7.0 + u2 / 9.0))));
    double v = 315.0 / 256.0 * (128.0 / 315.0 - Pu);
    return v;
}

double rt_sph_wall_density_gradient(double d, double H)
{
    if (d >= H)
        return 0.0;
    if (d < 0.0)
        d = 0.0;
    /* -d/dd of rt_sph_wall_density_fraction = (pi k/4) (H^2-d^2)^4 = (315/256)(1-u^2)^4/H */
    double u = d / H, q = 1.0 - u * u;
    return 315.0 / 256.0 * q * q * q * q / H;
}

double rt_sph_wall_friction_velocity(double ut, double y, double nu)
{
    if (!(ut > 0.0) || !(y > 0.0) || !(nu > 0.0) || !isfinite(ut) || !isfinite(y) || !isfinite(nu))
        return 0.0;
    /* smooth wall, kappa = 0.41, B = 5.2; the two laws meet at y+ = 11.06 */
    const double kappa = 0.41, Bl = 5.2, yc = 11.06;
    double us = sqrt(nu * ut / y); /* linear sublayer: u+ = y+ */
    if (y * us / nu <= yc)
        return us;
    /* log law, F(u*) = u* (ln(y u* / nu)/kappa + B) - u_t: increasing and convex, and the
     * sublayer value lies left of its root (there u+_log < y+), so Newton overshoots once to
     * the right and then descends monotonically */
    for (int it = 0; it < 40; ++it) {
        double lg = log(y * us / nu) / kappa + Bl;
        double F = us * lg - ut, dF = lg + 1.0 / kappa;
        double next = us - F / dF;
        if (!(next > 0.0))
            next = 0.5 * us;
        if (fabs(next - us) <= 1e-12 * us) {
            us = next;
            break;
        }
        us = next;
    }
    return us;
}

/* ---- thread pool --------------------------------------------------------------------------- */

static void run_chunks(rt_sph *s)
{
    for (;;) {
        uint32_t c = atomic_fetch_add(&s->next_chunk, 1u);
        if (c >= s->nchunks)
            break;
        s->job(s, c);
    }
}

static void *worker_main(void *arg)
{
    rt_sph *s = arg;
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
        run_chunks(s);
        pthread_mutex_lock(&s->mu);
        if (--s->busy == 0)
            pthread_cond_signal(&s->cv_done);
        pthread_mutex_unlock(&s->mu);
    }
}

/* Runs fn over every chunk on all threads. The density pass starts the chunk reductions
 * afresh; later passes of the same substep add to them and only reset the failure slot. */
static void parallel(rt_sph *s, sph_chunk_fn fn, bool fresh)
{
    uint32_t nchunks = (s->n + SPH_CHUNK - 1) / SPH_CHUNK;
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
    atomic_store(&s->next_chunk, 0u);
    if (s->nthreads == 0 || nchunks < 2) {
        run_chunks(s);
        return;
    }
    pthread_mutex_lock(&s->mu);
    s->busy = s->nthreads;
    s->gen++;
    pthread_cond_broadcast(&s->cv_start);
    pthread_mutex_unlock(&s->mu);
    run_chunks(s);
    pthread_mutex_lock(&s->mu);
    while (s->busy > 0)
        pthread_cond_wait(&s->cv_done, &s->mu);
    pthread_mutex_unlock(&s->mu);
}

/* ---- creation ------------------------------------------------------------------------------ */

static float def(float v, float d) { return v != 0.f ? v : d; }

static vfx_result fill_params(rt_sph_desc *p, char *err, size_t err_len)
{
    p->spacing = def(p->spacing, 0.02f);
    p->support_ratio = def(p->support_ratio, 2.0f);
    p->rest_density = def(p->rest_density, 1000.f);
    p->gamma = def(p->gamma, 7.f);
    p->cfl = def(p->cfl, 0.4f);
    if (p->flags & RT_SPH_NO_VISCOSITY)
        p->viscosity = 0.f;
    else
        p->viscosity = def(p->viscosity, 0.05f);
    if (p->flags & RT_SPH_NO_GRAVITY) {
        p->gravity[0] = p->gravity[1] = p->gravity[2] = 0.f;
    } else if (p->gravity[0] == 0.f && p->gravity[1] == 0.f && p->gravity[2] == 0.f) {
        p->gravity[1] = -9.81f;
    }
    bool dom_set = false;
    for (int a = 0; a < 3; ++a)
        dom_set |= p->domain_min[a] != p->domain_max[a];
    if (!dom_set)
        for (int a = 0; a < 3; ++a)
            p->domain_min[a] = 0.f, p->domain_max[a] = 1.f;
    if (!p->max_substeps) p->max_substeps = 256;
    if (!p->max_redo) p->max_redo = 10;
    if (!p->max_particles) p->max_particles = 1u << 27;
    if (!p->threads) {
        long nc = sysconf(_SC_NPROCESSORS_ONLN);
        p->threads = nc > 0 ? (uint32_t)nc : 1u;
    }
    p->density_change_limit = def(p->density_change_limit, 0.05f);
    p->kinematic_viscosity = def(p->kinematic_viscosity, 1.0e-6f);
    if (p->no_slip_faces & ~0x3fu) {
        snprintf(err, err_len, "rt_sph_create: desc.no_slip_faces 0x%x has bits beyond the six "
                 "RT_SPH_FACE_* faces", p->no_slip_faces);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    p->neighbor_skin = def(p->neighbor_skin, 0.3f); /* measured: docs/simulation.md */

    const float *fields[] = {&p->spacing, &p->support_ratio, &p->rest_density, &p->sound_speed,
                             &p->stiffness, &p->gamma, &p->viscosity, &p->cfl, &p->velocity_limit,
                             &p->density_change_limit, &p->kinematic_viscosity,
                             &p->gravity[0], &p->gravity[1], &p->gravity[2],
                             &p->domain_min[0], &p->domain_min[1], &p->domain_min[2],
                             &p->domain_max[0], &p->domain_max[1], &p->domain_max[2],
                             &p->neighbor_skin};
    static const char *names[] = {"spacing", "support_ratio", "rest_density", "sound_speed",
                                  "stiffness", "gamma", "viscosity", "cfl", "velocity_limit",
                                  "density_change_limit", "kinematic_viscosity", "gravity[0]", "gravity[1]", "gravity[2]",
                                  "domain_min[0]", "domain_min[1]", "domain_min[2]",
                                  "domain_max[0]", "domain_max[1]", "domain_max[2]",
                                  "neighbor_skin"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; ++i) {
        if (!isfinite(*fields[i])) {
            snprintf(err, err_len, "rt_sph_create: desc.%s is not finite", names[i]);
            return VFX_ERR_INVALID_ARGUMENT;
        }
    }
    if (p->spacing < 0.f || p->support_ratio < 1.f || p->rest_density < 0.f || p->gamma < 1.f ||
        p->viscosity < 0.f || p->cfl <= 0.f || p->cfl > 1.f || p->sound_speed < 0.f ||
        p->stiffness < 0.f || p->velocity_limit < 0.f || p->density_change_limit < 0.f ||
        p->kinematic_viscosity < 0.f) {
        snprintf(err, err_len, "rt_sph_create: a parameter is out of range (spacing>0, "
                 "support_ratio>=1, rest_density>0, gamma>=1, 0<cfl<=1, others >= 0)");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    if (!(p->neighbor_skin > 0.f && p->neighbor_skin <= 1.f)) {
        /* <= 1: rt_sph_volume_fraction's 7x7x7 stencil of H/2 cells reaches H + skin/2 */
        snprintf(err, err_len, "rt_sph_create: desc.neighbor_skin %g must be in (0, 1] (a "
                 "fraction of H)", (double)p->neighbor_skin);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    for (int a = 0; a < 3; ++a) {
        if (!(p->domain_max[a] - p->domain_min[a] >= 2.f * p->spacing)) {
            snprintf(err, err_len, "rt_sph_create: domain axis %d is thinner than 2 spacings "
                     "(%g..%g)", a, p->domain_min[a], p->domain_max[a]);
            return VFX_ERR_INVALID_ARGUMENT;
        }
    }
    if (p->threads > 256)
        p->threads = 256;
    return VFX_OK;
}

vfx_result rt_sph_create(const rt_sph_desc *desc, rt_sph **out, char *err, size_t err_len)
{
    char dummy[8];
    if (!err || err_len == 0)
        err = dummy, err_len = sizeof dummy;
    err[0] = 0;
    if (!out) {
        snprintf(err, err_len, "rt_sph_create: out is NULL");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    *out = NULL;
    rt_sph_desc p = desc ? *desc : (rt_sph_desc){0};
    vfx_result r = fill_params(&p, err, err_len);
    if (r)
        return r;
    rt_sph *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, err_len, "rt_sph_create: out of memory");
        return VFX_ERR_OUT_OF_MEMORY;
    }
    s->H = p.spacing * p.support_ratio;
    s->H2 = s->H * s->H;
    s->h = 0.5f * s->H;
    s->k_poly6 = (float)(315.0 / (64.0 * SPH_PI * pow(s->H, 9)));
    s->k_spiky = (float)(45.0 / (SPH_PI * pow(s->H, 6)));
    /* Mass calibrated on the lattice the solver fills blocks with, so a block starts at rho0
     * exactly instead of at the kernel's lattice bias (a few % for poly6 at H = 2 dx). */
    double sum = 0.0;
    int R = (int)ceil(p.support_ratio) + 1;
    for (int i = -R; i <= R; ++i)
        for (int j = -R; j <= R; ++j)
            for (int k = -R; k <= R; ++k) {
                double r2 = ((double)i * i + (double)j * j + (double)k * k) * p.spacing * p.spacing;
                double q = (double)s->H2 - r2;
                if (q > 0)
                    sum += (double)s->k_poly6 * q * q * q;
            }
    s->mass = (float)(p.rest_density / sum);
    /* Same lattice: the discrete gradient of a linear field, sum_j V_j (x_j - x_i) dW/dx, is
     * -1 for a consistent kernel; the spiky gradient at H = 2 dx misses by ~10-20%, which would
     * make every pressure gradient (and the hydrostatic pressure) wrong by as much. Scale it. */
    double gsum = 0.0, V = s->mass / p.rest_density;
    for (int i = -R; i <= R; ++i)
        for (int j = -R; j <= R; ++j)
            for (int k = -R; k <= R; ++k) {
                double r2 = ((double)i * i + (double)j * j + (double)k * k) * p.spacing * p.spacing;
                if (r2 <= 0.0 || r2 >= (double)s->H2)
                    continue;
                double rl = sqrt(r2), hr = s->H - rl, xk = i * p.spacing;
                gsum += V * xk * (-s->k_spiky * hr * hr) * (xk / rl);
            }
    s->k_spiky = (float)(s->k_spiky / -gsum);
    /* The wall term is the continuum integral; a lattice particle half a spacing from a wall
     * misses the lattice layers beyond it, which is not quite the same number. Scale the wall
     * fraction so that the first lattice layer sits exactly at rho0. */
    double beyond = 0.0;
    for (int i = -R; i <= R; ++i)
        for (int j = -R; j <= R; ++j)
            for (int k = -R; k <= -1; ++k) {
                double r2 = ((double)i * i + (double)j * j + (double)k * k) * p.spacing * p.spacing;
                double q = (double)s->H2 - r2;
                if (q > 0)
                    beyond += (double)s->k_poly6 * q * q * q;
            }
    s->wall_scale = (float)(beyond / sum / rt_sph_wall_density_fraction(0.5 * p.spacing, s->H));
    /* Wall-law friction: a wall shear stress tau = rho0 u*^2 is a force per wall area; it is
     * spread over the particles within H of the wall with the weight of the wall-density
     * gradient g(d), a = u*^2 g(d) fric_scale. On the lattice (layers at d = dx/2 + k dx, mass
     * m per dx^2 of wall each) the summed force is tau exactly when
     * fric_scale = rho0 dx^3 / (m sum_k dx g(d_k)). */
    double gl = 0.0;
    for (int k = 0; (k + 0.5) * p.spacing < s->H; ++k)
        gl += p.spacing * rt_sph_wall_density_gradient((k + 0.5) * p.spacing, s->H);
    s->fric_scale = (float)(p.rest_density * pow(p.spacing, 3) / (s->mass * gl));
    s->friction = p.no_slip_faces != 0;
    float height = 0.f, g = sqrtf(p.gravity[0] * p.gravity[0] + p.gravity[1] * p.gravity[1] +
                                  p.gravity[2] * p.gravity[2]);
    for (int a = 0; a < 3; ++a)
        if (fabsf(p.domain_max[a] - p.domain_min[a]) > height)
            height = p.domain_max[a] - p.domain_min[a];
    if (p.stiffness > 0.f) {
        p.sound_speed = sqrtf(p.gamma * p.stiffness / p.rest_density);
    } else {
        if (p.sound_speed == 0.f)
            p.sound_speed = g > 0.f ? 10.f * sqrtf(2.f * g * height) : 10.f;
        p.stiffness = p.rest_density * p.sound_speed * p.sound_speed / p.gamma;
    }
    p.velocity_limit = def(p.velocity_limit, 20.f * p.sound_speed);
    s->B = p.stiffness;
    s->c0 = p.sound_speed;
    s->p = p;
    s->verlet = !(p.flags & RT_SPH_REBUILD_EVERY_SUBSTEP);
    s->skin = p.neighbor_skin * s->H;
    s->S2 = (s->H + s->skin) * (s->H + s->skin);
    /* cells of H/2 and a 5x5x5 stencil: 42% fewer candidate pairs than H cells and 3x3x3 */
    s->inv_cell = 2.f / s->H;
    double dims[3];
    for (int a = 0; a < 3; ++a)
        dims[a] = ceil((p.domain_max[a] - p.domain_min[a]) * s->inv_cell);
    if (dims[0] * dims[1] * dims[2] > SPH_MAX_CELLS) {
        snprintf(err, err_len, "rt_sph_create: domain/support gives %.0f grid cells (max %u): "
                 "shrink the domain or grow the spacing", dims[0] * dims[1] * dims[2], SPH_MAX_CELLS);
        free(s);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    s->nx = (int)dims[0], s->ny = (int)dims[1], s->nz = (int)dims[2];
    s->ncells = (uint32_t)(s->nx * s->ny * s->nz);
    s->cell_start = calloc((size_t)s->ncells + 1, sizeof *s->cell_start);
    if (!s->cell_start) {
        snprintf(err, err_len, "rt_sph_create: out of memory for %u grid cells", s->ncells);
        free(s);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    pthread_mutex_init(&s->mu, NULL);
    pthread_cond_init(&s->cv_start, NULL);
    pthread_cond_init(&s->cv_done, NULL);
    atomic_init(&s->next_chunk, 0u);
    atomic_init(&s->nb_oom, false);
    uint32_t workers = p.threads - 1;
    if (workers) {
        s->threads = calloc(workers, sizeof *s->threads);
        if (!s->threads) {
            rt_sph_destroy(s);
            snprintf(err, err_len, "rt_sph_create: out of memory");
            return VFX_ERR_OUT_OF_MEMORY;
        }
        for (uint32_t i = 0; i < workers; ++i) {
            if (pthread_create(&s->threads[i], NULL, worker_main, s) != 0) {
                s->p.threads = 1 + i; /* run with the ones we have */
                break;
            }
            s->nthreads++;
        }
    }
    *out = s;
    return VFX_OK;
}

static void free_columns(rt_sph *s)
{
    float **f[] = {&s->x, &s->y, &s->z, &s->vx, &s->vy, &s->vz, &s->rho, &s->pr, &s->ax, &s->ay,
                   &s->az, &s->drho, &s->xn, &s->yn, &s->zn, &s->vxn, &s->vyn, &s->vzn, &s->tmp,
                   &s->x0, &s->y0, &s->z0};
    for (size_t i = 0; i < sizeof f / sizeof f[0]; ++i) {
        free(*f[i]);
        *f[i] = NULL;
    }
    free(s->id), free(s->idtmp), free(s->key), free(s->perm), free(s->nb_start), free(s->nb_count);
    free(s->sk_start), free(s->sk_count);
    s->id = s->idtmp = s->key = s->perm = s->nb_start = s->nb_count = NULL;
    s->sk_start = s->sk_count = NULL;
    for (uint32_t c = 0; c < s->cnb_chunks; ++c) {
        free(s->cnb[c]);
        if (s->snb)
            free(s->snb[c]);
    }
    free(s->cnb), free(s->cnb_cap), free(s->snb), free(s->snb_cap), free(s->snb_used);
    s->cnb = NULL, s->cnb_cap = NULL, s->cnb_chunks = 0;
    s->snb = NULL, s->snb_cap = NULL, s->snb_used = NULL;
    s->lists_valid = false;
}

void rt_sph_destroy(rt_sph *s)
{
    if (!s)
        return;
    pthread_mutex_lock(&s->mu);
    s->quit = true;
    pthread_cond_broadcast(&s->cv_start);
    pthread_mutex_unlock(&s->mu);
    for (uint32_t i = 0; i < s->nthreads; ++i)
        pthread_join(s->threads[i], NULL);
    free(s->threads);
    pthread_mutex_destroy(&s->mu);
    pthread_cond_destroy(&s->cv_start);
    pthread_cond_destroy(&s->cv_done);
    free_columns(s);
    free(s->cell_start);
    free(s->out);
    for (uint32_t c = 0; c < s->ncol; ++c)
        free(s->col[c].sdf);
    free(s);
}

const char *rt_sph_last_error(const rt_sph *s) { return s ? s->err : "rt_sph is NULL"; }
const rt_sph_desc *rt_sph_params(const rt_sph *s) { return s ? &s->p : NULL; }
float rt_sph_particle_mass(const rt_sph *s) { return s ? s->mass : 0.f; }
float rt_sph_support(const rt_sph *s) { return s ? s->H : 0.f; }
uint32_t rt_sph_clamped_on_add(const rt_sph *s) { return s ? s->clamped_on_add : 0; }
double rt_sph_time(const rt_sph *s) { return s ? s->time : 0.0; }
uint32_t rt_sph_thread_count(const rt_sph *s) { return s ? s->nthreads + 1 : 0; }

size_t rt_sph_memory_bytes(const rt_sph *s)
{
    if (!s)
        return 0;
    size_t lists = 0;
    for (uint32_t c = 0; c < s->cnb_chunks; ++c)
        lists += ((size_t)s->cnb_cap[c] + s->snb_cap[c]) * sizeof(uint32_t) + 3 * sizeof(uint32_t) +
                 2 * sizeof(uint32_t *);
    return sizeof *s + lists + (size_t)s->cap * (22 * sizeof(float) + 8 * sizeof(uint32_t)) +
           ((size_t)s->ncells + 1) * sizeof(uint32_t) + (size_t)s->out_cap * sizeof(sph_chunk_out);
}

float rt_sph_pressure(const rt_sph *s, uint32_t i)
{
    if (!s || i >= s->n)
        return 0.f;
    return s->pr[i] * s->rho[i] * s->rho[i];
}

rt_sph_columns rt_sph_get_columns(rt_sph *s)
{
    if (!s)
        return (rt_sph_columns){0};
    return (rt_sph_columns){s->n, s->x, s->y, s->z, s->vx, s->vy, s->vz, s->rho, s->id};
}

static vfx_result reserve(rt_sph *s, uint64_t want)
{
    if (want > s->p.max_particles) {
        set_err(s, "rt_sph: %llu particles requested, capacity bound is %u (desc.max_particles)",
                (unsigned long long)want, s->p.max_particles);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    if (want <= s->cap)
        return VFX_OK;
    uint64_t cap = s->cap ? s->cap : 1024;
    while (cap < want)
        cap *= 2;
    if (cap > s->p.max_particles)
        cap = s->p.max_particles;
    float **f[] = {&s->x, &s->y, &s->z, &s->vx, &s->vy, &s->vz, &s->rho, &s->pr, &s->ax, &s->ay,
                   &s->az, &s->drho, &s->xn, &s->yn, &s->zn, &s->vxn, &s->vyn, &s->vzn, &s->tmp,
                   &s->x0, &s->y0, &s->z0};
    for (size_t i = 0; i < sizeof f / sizeof f[0]; ++i) {
        float *np = realloc(*f[i], (size_t)cap * sizeof(float));
        if (!np)
            goto oom;
        *f[i] = np;
    }
    uint32_t **u[] = {&s->id, &s->idtmp, &s->key, &s->perm, &s->nb_start, &s->nb_count,
                      &s->sk_start, &s->sk_count};
    for (size_t i = 0; i < sizeof u / sizeof u[0]; ++i) {
        uint32_t *np = realloc(*u[i], (size_t)cap * sizeof(uint32_t));
        if (!np)
            goto oom;
        *u[i] = np;
    }
    uint32_t chunks = (uint32_t)((cap + SPH_CHUNK - 1) / SPH_CHUNK);
    sph_chunk_out *no = realloc(s->out, (size_t)chunks * sizeof *no);
    if (!no)
        goto oom;
    s->out = no;
    s->out_cap = chunks;
    if (chunks > s->cnb_chunks) {
        uint32_t **nl = realloc(s->cnb, (size_t)chunks * sizeof *nl);
        if (!nl)
            goto oom;
        s->cnb = nl;
        uint32_t *nc = realloc(s->cnb_cap, (size_t)chunks * sizeof *nc);
        if (!nc)
            goto oom;
        s->cnb_cap = nc;
        uint32_t **sl = realloc(s->snb, (size_t)chunks * sizeof *sl);
        if (!sl)
            goto oom;
        s->snb = sl;
        uint32_t *sc = realloc(s->snb_cap, (size_t)chunks * sizeof *sc);
        if (!sc)
            goto oom;
        s->snb_cap = sc;
        uint32_t *su = realloc(s->snb_used, (size_t)chunks * sizeof *su);
        if (!su)
            goto oom;
        s->snb_used = su;
        for (uint32_t c = s->cnb_chunks; c < chunks; ++c)
            s->cnb[c] = NULL, s->cnb_cap[c] = 0, s->snb[c] = NULL, s->snb_cap[c] = 0, s->snb_used[c] = 0;
        s->cnb_chunks = chunks;
    }
    s->cap = (uint32_t)cap;
    return VFX_OK;
oom:
    set_err(s, "rt_sph: out of memory growing to %llu particles", (unsigned long long)cap);
    return VFX_ERR_OUT_OF_MEMORY;
}

static float clampf(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }

vfx_result rt_sph_add_particles(rt_sph *s, uint32_t n, const float *x, const float *y,
                                 const float *z, const float *vx, const float *vy, const float *vz)
{
    if (!s)
        return VFX_ERR_INVALID_ARGUMENT;
    s->err[0] = 0;
    if (n == 0)
        return VFX_OK;
    if (!x || !y || !z) {
        set_err(s, "rt_sph_add_particles: position array is NULL for %u particles", n);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    if ((uint64_t)s->n + n > s->p.max_particles) {
        set_err(s, "rt_sph_add_particles: %u + %u particles exceed the capacity bound %u "
                "(desc.max_particles)", s->n, n, s->p.max_particles);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    const float *arr[6] = {x, y, z, vx, vy, vz};
    static const char *nm[6] = {"x", "y", "z", "vx", "vy", "vz"};
    for (uint32_t i = 0; i < n; ++i)
        for (int a = 0; a < 6; ++a)
            if (arr[a] && !isfinite(arr[a][i])) {
                set_err(s, "rt_sph_add_particles: particle %u (of %u in this batch) has a "
                        "non-finite %s (%g); batch refused", i, n, nm[a], (double)arr[a][i]);
                return VFX_ERR_INVALID_ARGUMENT;
            }
    vfx_result r = reserve(s, (uint64_t)s->n + n);
    if (r)
        return r;
    /* keep fresh particles a quarter spacing inside the walls, where the clamp would put them */
    float m = 0.25f * s->p.spacing;
    for (uint32_t i = 0; i < n; ++i) {
        uint32_t k = s->n + i;
        float px = clampf(x[i], s->p.domain_min[0] + m, s->p.domain_max[0] - m);
        float py = clampf(y[i], s->p.domain_min[1] + m, s->p.domain_max[1] - m);
        float pz = clampf(z[i], s->p.domain_min[2] + m, s->p.domain_max[2] - m);
        if (px != x[i] || py != y[i] || pz != z[i])
            s->clamped_on_add++;
        s->x[k] = px, s->y[k] = py, s->z[k] = pz;
        s->vx[k] = vx ? vx[i] : 0.f;
        s->vy[k] = vy ? vy[i] : 0.f;
        s->vz[k] = vz ? vz[i] : 0.f;
        s->rho[k] = s->p.rest_density;
        s->pr[k] = 0.f;
        s->id[k] = s->next_id++;
    }
    s->n += n;
    s->lists_valid = false; /* new rows are in no list */
    return VFX_OK;
}

void rt_sph_clear(rt_sph *s)
{
    if (!s)
        return;
    s->n = 0;
    s->next_id = 0;
    s->lists_valid = false;
}

vfx_result rt_sph_add_block(rt_sph *s, const float lo[3], const float hi[3], uint32_t *added)
{
    if (added)
        *added = 0;
    if (!s || !lo || !hi)
        return VFX_ERR_INVALID_ARGUMENT;
    float dx = s->p.spacing;
    uint64_t c[3];
    for (int a = 0; a < 3; ++a) {
        if (!isfinite(lo[a]) || !isfinite(hi[a]) || hi[a] < lo[a]) {
            set_err(s, "rt_sph_add_block: bad bounds on axis %d (%g..%g)", a, (double)lo[a], (double)hi[a]);
            return VFX_ERR_INVALID_ARGUMENT;
        }
        c[a] = (uint64_t)floor((hi[a] - lo[a]) / dx + 1e-4);
    }
    uint64_t total = c[0] * c[1] * c[2];
    if (total == 0)
        return VFX_OK;
    vfx_result r = reserve(s, s->n + total);
    if (r)
        return r;
    uint32_t base = s->n;
    for (uint64_t k = 0; k < c[2]; ++k)
        for (uint64_t j = 0; j < c[1]; ++j)
            for (uint64_t i = 0; i < c[0]; ++i) {
                uint32_t q = s->n++;
                s->x[q] = lo[0] + ((float)i + 0.5f) * dx;
                s->y[q] = lo[1] + ((float)j + 0.5f) * dx;
                s->z[q] = lo[2] + ((float)k + 0.5f) * dx;
                s->vx[q] = s->vy[q] = s->vz[q] = 0.f;
                s->rho[q] = s->p.rest_density;
                s->pr[q] = 0.f;
                s->id[q] = s->next_id++;
            }
    /* out-of-domain lattice points are clamped like any other input */
    float m = 0.25f * dx;
    for (uint32_t q = base; q < s->n; ++q) {
        float px = clampf(s->x[q], s->p.domain_min[0] + m, s->p.domain_max[0] - m);
        float py = clampf(s->y[q], s->p.domain_min[1] + m, s->p.domain_max[1] - m);
        float pz = clampf(s->z[q], s->p.domain_min[2] + m, s->p.domain_max[2] - m);
        if (px != s->x[q] || py != s->y[q] || pz != s->z[q])
            s->clamped_on_add++;
        s->x[q] = px, s->y[q] = py, s->z[q] = pz;
    }
    s->lists_valid = false;
    if (added)
        *added = (uint32_t)total;
    return VFX_OK;
}

static bool finite3(const float *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

vfx_result rt_sph_add_collider(rt_sph *s, const rt_sph_collider *c, uint32_t *index)
{
    if (!s || !c)
        return VFX_ERR_INVALID_ARGUMENT;
    if (s->ncol >= SPH_MAX_COLLIDERS) {
        set_err(s, "rt_sph_add_collider: at most %u colliders", SPH_MAX_COLLIDERS);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    rt_sph_collider k = *c;
    if (!finite3(k.center) || !finite3(k.normal) || !finite3(k.half) || !finite3(k.motion_axis) ||
        !isfinite(k.radius) || !isfinite(k.motion_amplitude) || !isfinite(k.motion_frequency)) {
        set_err(s, "rt_sph_add_collider: collider %u has a non-finite field", s->ncol);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    if (k.kind == RT_SPH_PLANE) {
        float l = sqrtf(k.normal[0] * k.normal[0] + k.normal[1] * k.normal[1] + k.normal[2] * k.normal[2]);
        if (!(l > 1e-6f)) {
            set_err(s, "rt_sph_add_collider: plane %u has a zero normal", s->ncol);
            return VFX_ERR_INVALID_ARGUMENT;
        }
        for (int a = 0; a < 3; ++a)
            k.normal[a] /= l;
    } else if (k.kind == RT_SPH_SPHERE) {
        if (!(k.radius > 0.f)) {
            set_err(s, "rt_sph_add_collider: sphere %u needs radius > 0 (got %g)", s->ncol, (double)k.radius);
            return VFX_ERR_INVALID_ARGUMENT;
        }
    } else if (k.kind == RT_SPH_BOX) {
        if (!(k.half[0] > 0.f && k.half[1] > 0.f && k.half[2] > 0.f)) {
            set_err(s, "rt_sph_add_collider: box %u needs half extents > 0", s->ncol);
            return VFX_ERR_INVALID_ARGUMENT;
        }
    } else {
        set_err(s, "rt_sph_add_collider: unknown kind %d", (int)k.kind);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    float al = sqrtf(k.motion_axis[0] * k.motion_axis[0] + k.motion_axis[1] * k.motion_axis[1] +
                     k.motion_axis[2] * k.motion_axis[2]);
    if (al > 0.f)
        for (int a = 0; a < 3; ++a)
            k.motion_axis[a] /= al;
    else
        k.motion_amplitude = 0.f;
    sph_collider_state *st = &s->col[s->ncol];
    st->c = k;
    s->friction |= k.no_slip != 0;
    memcpy(st->pos, k.center, sizeof st->pos);
    memset(st->vel, 0, sizeof st->vel);
    if (index)
        *index = s->ncol;
    s->ncol++;
    return VFX_OK;
}

vfx_result rt_sph_add_emitter(rt_sph *s, const rt_sph_emitter *e)
{
    if (!s || !e)
        return VFX_ERR_INVALID_ARGUMENT;
    if (s->nem >= SPH_MAX_EMITTERS) {
        set_err(s, "rt_sph_add_emitter: at most %u emitters", SPH_MAX_EMITTERS);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    rt_sph_emitter k = *e;
    float l = sqrtf(k.direction[0] * k.direction[0] + k.direction[1] * k.direction[1] +
                    k.direction[2] * k.direction[2]);
    if (!finite3(k.center) || !(l > 1e-6f) || !isfinite(l) || !(k.speed > 0.f) || !isfinite(k.speed) ||
        !(k.radius >= 0.5f * s->p.spacing) || !isfinite(k.radius)) {
        set_err(s, "rt_sph_add_emitter: emitter %u needs finite centre, non-zero direction, "
                "speed > 0 and radius >= spacing/2", s->nem);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    sph_emitter_state *st = &s->em[s->nem++];
    memset(st, 0, sizeof *st);
    for (int a = 0; a < 3; ++a)
        k.direction[a] /= l;
    st->e = k;
    /* nozzle plane basis: any vector not parallel to the direction, orthogonalised */
    const float *d = k.direction;
    float t[3] = {1.f, 0.f, 0.f};
    if (fabsf(d[0]) > 0.9f)
        t[0] = 0.f, t[1] = 1.f;
    float u[3] = {d[1] * t[2] - d[2] * t[1], d[2] * t[0] - d[0] * t[2], d[0] * t[1] - d[1] * t[0]};
    float ul = sqrtf(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int a = 0; a < 3; ++a)
        u[a] /= ul;
    float w[3] = {d[1] * u[2] - d[2] * u[1], d[2] * u[0] - d[0] * u[2], d[0] * u[1] - d[1] * u[0]};
    memcpy(st->u, u, sizeof u);
    memcpy(st->w, w, sizeof w);
    return VFX_OK;
}

/* Closest distance from p to triangle abc (Ericson, Real-Time Collision Detection 5.1.5). */
static double tri_distance(const double p[3], const double a[3], const double b[3], const double c[3])
{
#define SUB(o, x, y) (o[0] = x[0] - y[0], o[1] = x[1] - y[1], o[2] = x[2] - y[2])
#define DOT(x, y) (x[0] * y[0] + x[1] * y[1] + x[2] * y[2])
    double ab[3], ac[3], ap[3], bp[3], cp[3], q[3];
    SUB(ab, b, a);
    SUB(ac, c, a);
    SUB(ap, p, a);
    double d1 = DOT(ab, ap), d2 = DOT(ac, ap);
    if (d1 <= 0 && d2 <= 0)
        return sqrt(DOT(ap, ap));
    SUB(bp, p, b);
    double d3 = DOT(ab, bp), d4 = DOT(ac, bp);
    if (d3 >= 0 && d4 <= d3)
        return sqrt(DOT(bp, bp));
    double vc = d1 * d4 - d3 * d2, v, w;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        v = d1 / (d1 - d3);
        for (int k = 0; k < 3; ++k)
            q[k] = a[k] + v * ab[k] - p[k];
        return sqrt(DOT(q, q));
    }
    SUB(cp, p, c);
    double d5 = DOT(ab, cp), d6 = DOT(ac, cp);
    if (d6 >= 0 && d5 <= d6)
        return sqrt(DOT(cp, cp));
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        w = d2 / (d2 - d6);
        for (int k = 0; k < 3; ++k)
            q[k] = a[k] + w * ac[k] - p[k];
        return sqrt(DOT(q, q));
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int k = 0; k < 3; ++k)
            q[k] = b[k] + w * (c[k] - b[k]) - p[k];
        return sqrt(DOT(q, q));
    }
    double den = 1.0 / (va + vb + vc);
    v = vb * den, w = vc * den;
    for (int k = 0; k < 3; ++k)
        q[k] = a[k] + ab[k] * v + ac[k] * w - p[k];
    return sqrt(DOT(q, q));
#undef SUB
#undef DOT
}

/* Solid angle of triangle abc seen from p (Van Oosterom & Strackee 1983), signed. */
static double tri_solid_angle(const double p[3], const double a0[3], const double b0[3], const double c0[3])
{
    double a[3], b[3], c[3];
    for (int k = 0; k < 3; ++k)
        a[k] = a0[k] - p[k], b[k] = b0[k] - p[k], c[k] = c0[k] - p[k];
    double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    double lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    double lc = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                 a[2] * (b[0] * c[1] - b[1] * c[0]);
    double den = la * lb * lc + (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) * lc +
                 (a[0] * c[0] + a[1] * c[1] + a[2] * c[2]) * lb + (b[0] * c[0] + b[1] * c[1] + b[2] * c[2]) * la;
    return 2.0 * atan2(det, den);
}

vfx_result rt_sph_add_mesh_collider(rt_sph *s, const float *positions, uint32_t vertex_count,
                                     const uint32_t *indices, uint32_t index_count,
                                     const rt_sph_collider *motion, uint32_t *index)
{
    if (!s)
        return VFX_ERR_INVALID_ARGUMENT;
    s->err[0] = 0;
    if (s->ncol >= SPH_MAX_COLLIDERS) {
        set_err(s, "rt_sph_add_mesh_collider: at most %u colliders", SPH_MAX_COLLIDERS);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    if (!positions || !indices || vertex_count == 0 || index_count < 3 || index_count % 3 != 0) {
        set_err(s, "rt_sph_add_mesh_collider: need vertices and a multiple of 3 indices (got %u "
                "vertices, %u indices)", vertex_count, index_count);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    if (index_count / 3 > SPH_MAX_MESH_TRIANGLES) {
        set_err(s, "rt_sph_add_mesh_collider: %u triangles, at most %u (the distance field is "
                "built by brute force)", index_count / 3, SPH_MAX_MESH_TRIANGLES);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t v = 0; v < vertex_count; ++v)
        for (int a = 0; a < 3; ++a) {
            float x = positions[3 * v + a];
            if (!isfinite(x)) {
                set_err(s, "rt_sph_add_mesh_collider: vertex %u is not finite", v);
                return VFX_ERR_INVALID_ARGUMENT;
            }
            lo[a] = x < lo[a] ? x : lo[a];
            hi[a] = x > hi[a] ? x : hi[a];
        }
    for (uint32_t i = 0; i < index_count; ++i)
        if (indices[i] >= vertex_count) {
            set_err(s, "rt_sph_add_mesh_collider: triangle %u uses vertex %u of %u", i / 3,
                    indices[i], vertex_count);
            return VFX_ERR_INVALID_ARGUMENT;
        }
    sph_collider_state st = {0};
    if (motion) {
        st.c = *motion;
        if (!finite3(st.c.center) || !finite3(st.c.motion_axis) || !isfinite(st.c.motion_amplitude) ||
            !isfinite(st.c.motion_frequency)) {
            set_err(s, "rt_sph_add_mesh_collider: motion has a non-finite field");
            return VFX_ERR_INVALID_ARGUMENT;
        }
    }
    st.c.kind = RT_SPH_BOX; /* unused for meshes: the sdf decides */
    float al = sqrtf(st.c.motion_axis[0] * st.c.motion_axis[0] + st.c.motion_axis[1] * st.c.motion_axis[1] +
                     st.c.motion_axis[2] * st.c.motion_axis[2]);
    if (al > 0.f)
        for (int a = 0; a < 3; ++a)
            st.c.motion_axis[a] /= al;
    else
        st.c.motion_amplitude = 0.f;
    /* grid: mesh bounds padded by H (beyond that the wall terms vanish), node spacing ~H/2,
     * at most SPH_MESH_GRID nodes per axis */
    size_t total = 1;
    for (int a = 0; a < 3; ++a) {
        st.sdf_lo[a] = lo[a] - s->H;
        float ext = hi[a] - lo[a] + 2.f * s->H;
        int n = (int)ceilf(ext / (0.5f * s->H)) + 1;
        n = n < 2 ? 2 : (n > SPH_MESH_GRID ? SPH_MESH_GRID : n);
        st.sdf_n[a] = n;
        st.sdf_h[a] = ext / (float)(n - 1);
        total *= (size_t)n;
    }
    st.sdf = malloc(total * sizeof(float));
    if (!st.sdf) {
        set_err(s, "rt_sph_add_mesh_collider: out of memory for a %zu-node distance field", total);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    uint32_t ntri = index_count / 3;
    for (int k = 0; k < st.sdf_n[2]; ++k)
        for (int j = 0; j < st.sdf_n[1]; ++j)
            for (int i = 0; i < st.sdf_n[0]; ++i) {
                double p[3] = {st.sdf_lo[0] + i * st.sdf_h[0], st.sdf_lo[1] + j * st.sdf_h[1],
                               st.sdf_lo[2] + k * st.sdf_h[2]};
                double dmin = INFINITY, omega = 0.0;
                for (uint32_t t = 0; t < ntri; ++t) {
                    double v[3][3];
                    for (int c = 0; c < 3; ++c)
                        for (int a = 0; a < 3; ++a)
                            v[c][a] = positions[3 * indices[3 * t + c] + a];
                    double d = tri_distance(p, v[0], v[1], v[2]);
                    dmin = d < dmin ? d : dmin;
                    omega += tri_solid_angle(p, v[0], v[1], v[2]);
                }
                /* generalised winding number: ~1 inside a closed outward-wound mesh, ~0 out */
                bool inside = fabs(omega) / (4.0 * SPH_PI) > 0.5;
                st.sdf[i + (size_t)st.sdf_n[0] * (j + (size_t)st.sdf_n[1] * k)] = (float)(inside ? -dmin : dmin);
            }
    memcpy(st.pos, st.c.center, sizeof st.pos);
    s->friction |= st.c.no_slip != 0;
    s->col[s->ncol] = st;
    if (index)
        *index = s->ncol;
    s->ncol++;
    return VFX_OK;
}

/* ---- boundaries ---------------------------------------------------------------------------- */

/* Signed distance of p to collider surface (positive on the fluid side) and outward normal. */
static float sdf_sample(const sph_collider_state *st, const float q[3])
{
    float f[3];
    int i[3];
    for (int a = 0; a < 3; ++a) {
        float u = (q[a] - st->sdf_lo[a]) / st->sdf_h[a];
        int k = (int)floorf(u);
        k = k < 0 ? 0 : (k > st->sdf_n[a] - 2 ? st->sdf_n[a] - 2 : k);
        i[a] = k;
        f[a] = u - (float)k;
    }
    const int nx = st->sdf_n[0], nxy = st->sdf_n[0] * st->sdf_n[1];
    const float *g = st->sdf + i[0] + i[1] * nx + i[2] * nxy;
    float c00 = g[0] + f[0] * (g[1] - g[0]), c10 = g[nx] + f[0] * (g[nx + 1] - g[nx]);
    float c01 = g[nxy] + f[0] * (g[nxy + 1] - g[nxy]);
    float c11 = g[nxy + nx] + f[0] * (g[nxy + nx + 1] - g[nxy + nx]);
    float c0 = c00 + f[1] * (c10 - c00), c1 = c01 + f[1] * (c11 - c01);
    return c0 + f[2] * (c1 - c0);
}

static float mesh_distance(const sph_collider_state *st, float px, float py, float pz, float n[3])
{
    /* the mesh moves rigidly with the collider's motion offset */
    float q[3] = {px - (st->pos[0] - st->c.center[0]), py - (st->pos[1] - st->c.center[1]),
                  pz - (st->pos[2] - st->c.center[2])};
    n[0] = 0.f, n[1] = 1.f, n[2] = 0.f;
    for (int a = 0; a < 3; ++a) {
        float hi = st->sdf_lo[a] + st->sdf_h[a] * (float)(st->sdf_n[a] - 1);
        if (q[a] < st->sdf_lo[a] || q[a] > hi)
            return INFINITY; /* the grid is padded by H: outside it the mesh is out of reach */
    }
    float d = sdf_sample(st, q), gl = 0.f;
    for (int a = 0; a < 3; ++a) {
        float e = 0.5f * st->sdf_h[a], qp[3] = {q[0], q[1], q[2]}, qm[3] = {q[0], q[1], q[2]};
        qp[a] += e, qm[a] -= e;
        n[a] = sdf_sample(st, qp) - sdf_sample(st, qm);
        gl += n[a] * n[a];
    }
    gl = sqrtf(gl);
    if (gl > 0.f)
        for (int a = 0; a < 3; ++a)
            n[a] /= gl;
    else
        n[0] = 0.f, n[1] = 1.f, n[2] = 0.f;
    return d;
}

static float collider_distance(const sph_collider_state *st, float px, float py, float pz, float n[3])
{
    const rt_sph_collider *c = &st->c;
    if (st->sdf)
        return mesh_distance(st, px, py, pz, n);
    float dx = px - st->pos[0], dy = py - st->pos[1], dz = pz - st->pos[2];
    if (c->kind == RT_SPH_PLANE) {
        n[0] = c->normal[0], n[1] = c->normal[1], n[2] = c->normal[2];
        return dx * n[0] + dy * n[1] + dz * n[2];
    }
    if (c->kind == RT_SPH_SPHERE) {
        float l = sqrtf(dx * dx + dy * dy + dz * dz);
        if (l < 1e-12f) {
            n[0] = 0.f, n[1] = 1.f, n[2] = 0.f;
        } else {
            n[0] = dx / l, n[1] = dy / l, n[2] = dz / l;
        }
        return l - c->radius;
    }
    float d[3] = {dx, dy, dz}, q[3], o[3], ol2 = 0.f, qmax = -INFINITY;
    int amax = 0;
    for (int a = 0; a < 3; ++a) {
        q[a] = fabsf(d[a]) - c->half[a];
        o[a] = q[a] > 0.f ? q[a] : 0.f;
        ol2 += o[a] * o[a];
        if (q[a] > qmax)
            qmax = q[a], amax = a;
    }
    if (ol2 > 0.f) {
        float ol = sqrtf(ol2);
        for (int a = 0; a < 3; ++a)
            n[a] = (d[a] < 0.f ? -o[a] : o[a]) / ol;
        return ol;
    }
    n[0] = n[1] = n[2] = 0.f;
    n[amax] = d[amax] < 0.f ? -1.f : 1.f;
    return qmax;
}

float rt_sph_collider_distance(const rt_sph *s, uint32_t index, const float p[3])
{
    if (!s || index >= s->ncol || !p)
        return NAN;
    float n[3];
    return collider_distance(&s->col[index], p[0], p[1], p[2], n);
}

static void update_colliders(rt_sph *s, double t)
{
    for (uint32_t i = 0; i < s->ncol; ++i) {
        sph_collider_state *st = &s->col[i];
        const rt_sph_collider *c = &st->c;
        double w = 2.0 * SPH_PI * c->motion_frequency;
        double off = c->motion_amplitude * sin(w * t), vel = c->motion_amplitude * w * cos(w * t);
        for (int a = 0; a < 3; ++a) {
            st->pos[a] = c->center[a] + (float)(off * c->motion_axis[a]);
            st->vel[a] = (float)(vel * c->motion_axis[a]);
        }
    }
}

/* ---- neighbour grid ------------------------------------------------------------------------ */

static inline int cell_coord(float v, float lo, float inv, int n)
{
    int c = (int)((v - lo) * inv);
    return c < 0 ? 0 : (c >= n ? n - 1 : c);
}

static void key_chunk(rt_sph *s, uint32_t chunk)
{
    uint32_t b = chunk * SPH_CHUNK, e = b + SPH_CHUNK < s->n ? b + SPH_CHUNK : s->n;
    const float *lo = s->p.domain_min;
    for (uint32_t i = b; i < e; ++i) {
        int cx = cell_coord(s->x[i], lo[0], s->inv_cell, s->nx);
        int cy = cell_coord(s->y[i], lo[1], s->inv_cell, s->ny);
        int cz = cell_coord(s->z[i], lo[2], s->inv_cell, s->nz);
        s->key[i] = (uint32_t)((cz * s->ny + cy) * s->nx + cx);
    }
}

/* Gathers the state columns into the (free) integration buffers in sorted order. */
static void permute_chunk(rt_sph *s, uint32_t chunk)
{
    uint32_t b = chunk * SPH_CHUNK, e = b + SPH_CHUNK < s->n ? b + SPH_CHUNK : s->n;
    const uint32_t *perm = s->perm;
    for (uint32_t i = b; i < e; ++i) {
        uint32_t k = perm[i];
        s->xn[i] = s->x[k], s->yn[i] = s->y[k], s->zn[i] = s->z[k];
        s->vxn[i] = s->vx[k], s->vyn[i] = s->vy[k], s->vzn[i] = s->vz[k];
        s->idtmp[i] = s->id[k];
    }
}

static void swap_state(rt_sph *s);
static void parallel(rt_sph *s, sph_chunk_fn fn, bool fresh);

/* Counting sort of the particles by cell, then every per-particle column permuted so that a
 * cell's particles are contiguous (and a row of x-adjacent cells is one range). Stable, so
 * the order — and every sum over neighbours — does not depend on the thread count. Keys and
 * the permutation run on all threads; the histogram and the scatter are serial (O(n + cells)). */
static void build_grid(rt_sph *s)
{
    uint32_t n = s->n;
    parallel(s, key_chunk, false);
    memset(s->cell_start, 0, ((size_t)s->ncells + 1) * sizeof *s->cell_start);
    for (uint32_t i = 0; i < n; ++i)
        s->cell_start[s->key[i] + 1]++;
    for (uint32_t c = 0; c < s->ncells; ++c)
        s->cell_start[c + 1] += s->cell_start[c];
    /* scatter using cell_start as running cursors, then restore it */
    for (uint32_t i = 0; i < n; ++i)
        s->perm[s->cell_start[s->key[i]]++] = i;
    for (uint32_t c = s->ncells; c > 0; --c)
        s->cell_start[c] = s->cell_start[c - 1];
    s->cell_start[0] = 0;
    parallel(s, permute_chunk, false);
    swap_state(s);
    uint32_t *t = s->id;
    s->id = s->idtmp;
    s->idtmp = t;
}

typedef struct sph_ranges {
    uint32_t lo[49], hi[49]; /* up to 7x7 rows of cells */
    int count;
} sph_ranges;

/* The particle index ranges of the (2R+1)^3 cells of H/2 around p (R <= 3): one range per row
 * of x-adjacent cells, rows with no particle left out. */
static inline void neighbor_ranges(const rt_sph *s, float px, float py, float pz, int R, sph_ranges *r)
{
    const float *lo = s->p.domain_min;
    int cx = cell_coord(px, lo[0], s->inv_cell, s->nx);
    int cy = cell_coord(py, lo[1], s->inv_cell, s->ny);
    int cz = cell_coord(pz, lo[2], s->inv_cell, s->nz);
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

/* Walls of the domain box and every collider: density fraction and force integral. */
typedef struct sph_wall_hit {
    float n[3], d, vel[3];
    bool is_box, no_slip;
} sph_wall_hit;

static int gather_walls(const rt_sph *s, float px, float py, float pz, sph_wall_hit *w, int max)
{
    int k = 0;
    const float *lo = s->p.domain_min, *hi = s->p.domain_max;
    float pp[3] = {px, py, pz};
    for (int a = 0; a < 3; ++a) {
        float d0 = pp[a] - lo[a], d1 = hi[a] - pp[a];
        if (d0 < s->H && k < max) {
            w[k] = (sph_wall_hit){{0}, d0, {0}, true, (s->p.no_slip_faces >> (2 * a)) & 1u};
            w[k].n[a] = 1.f;
            k++;
        }
        if (d1 < s->H && k < max) {
            w[k] = (sph_wall_hit){{0}, d1, {0}, true, (s->p.no_slip_faces >> (2 * a + 1)) & 1u};
            w[k].n[a] = -1.f;
            k++;
        }
    }
    for (uint32_t c = 0; c < s->ncol && k < max; ++c) {
        float n[3];
        float d = collider_distance(&s->col[c], px, py, pz, n);
        if (d < s->H) {
            w[k] = (sph_wall_hit){{n[0], n[1], n[2]}, d, {s->col[c].vel[0], s->col[c].vel[1], s->col[c].vel[2]},
                                  false, s->col[c].c.no_slip != 0};
            k++;
        }
    }
    return k;
}

#define SPH_MAX_WALLS (6 + SPH_MAX_COLLIDERS)

/* Number of leading box walls in a gather_walls list (they come before the colliders). */
static inline int walls_box(const sph_wall_hit *w, int nw)
{
    int k = 0;
    while (k < nw && w[k].is_box)
        k++;
    return k;
}

float rt_sph_volume_fraction(const rt_sph *s, const float p[3])
{
    if (!s || !p || !isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
        return NAN;
    /* The grid is that of the last rebuild; with Verlet lists the particles have moved less
     * than skin/2 <= H/2 since, so every particle now within H of p was within 1.5 H = 3 cells
     * of H/2 then: a 7x7x7 stencil over the rows as sorted, distances from the current
     * positions. The 5x5x5 stencil when the grid is rebuilt every substep (it is current). */
    sph_ranges r;
    neighbor_ranges(s, p[0], p[1], p[2], s->verlet ? 3 : 2, &r);
    double sum = 0.0;
    for (int q = 0; q < r.count; ++q)
        for (uint32_t j = r.lo[q]; j < r.hi[q] && j < s->n; ++j) {
            float dx = p[0] - s->x[j], dy = p[1] - s->y[j], dz = p[2] - s->z[j];
            float r2 = dx * dx + dy * dy + dz * dz;
            if (r2 < s->H2) {
                float t = s->H2 - r2;
                sum += (double)t * t * t;
            }
        }
    sph_wall_hit walls[SPH_MAX_WALLS];
    int nw = gather_walls(s, p[0], p[1], p[2], walls, SPH_MAX_WALLS), nb = walls_box(walls, nw);
    float inside = 1.f, extra = 0.f;
    for (int w = 0; w < nw; ++w) {
        float f = s->wall_scale * (float)rt_sph_wall_density_fraction(walls[w].d, s->H);
        if (w < nb)
            inside *= 1.f - f;
        else
            extra += f;
    }
    float gam = inside - extra;
    if (!(gam > 0.05f))
        return 0.f; /* inside a solid */
    return (float)(sum * s->mass * s->k_poly6 / s->p.rest_density / gam);
}

/* ---- passes -------------------------------------------------------------------------------- */

/* Grows a per-chunk list buffer to hold `want` entries; false (and nb_oom set) when it cannot. */
static bool grow_list(rt_sph *s, uint32_t **buf, uint32_t *cap, uint32_t want)
{
    if (want <= *cap)
        return true;
    /* 1/8 slack rather than doubling: at 1 M particles the lists are most of the memory, and
     * after the first rebuild their sizes change little */
    uint64_t c64 = (uint64_t)want + want / 8 + 1024;
    uint32_t c = c64 > UINT32_MAX ? UINT32_MAX : (uint32_t)c64;
    uint32_t *nl = realloc(*buf, (size_t)c * sizeof *nl);
    if (!nl) {
        atomic_store(&s->nb_oom, true);
        return false;
    }
    *buf = nl;
    *cap = c;
    return true;
}

/* Everything of the density pass after the neighbour sum: walls, EOS, reductions. */
static inline __attribute__((always_inline)) void
density_tail(rt_sph *s, uint32_t i, float sum, uint32_t nn, float px, float py, float pz,
             sph_chunk_out *o, sph_wall_hit *walls)
{
    const float kp = s->k_poly6, m = s->mass, rho0 = s->p.rest_density;
    const double H = s->H;
    const float gam = s->p.gamma, B = s->B, c2_0 = s->c0 * s->c0;
    float rho = m * kp * sum;
    int nw = gather_walls(s, px, py, pz, walls, SPH_MAX_WALLS);
    /* The box walls are perpendicular: the region beyond them is a union of half-spaces,
     * counted as 1 - prod(1 - f) (exact for a separable kernel, close for poly6) so the
     * edges and corners are not compressed by double counting. Colliders just add. */
    float inside = 1.f, extra = 0.f;
    for (int w = 0; w < nw; ++w) {
        float f = s->wall_scale * (float)rt_sph_wall_density_fraction(walls[w].d, H);
        if (w < walls_box(walls, nw))
            inside *= 1.f - f;
        else
            extra += f;
    }
    rho += rho0 * (1.f - inside + extra);
    s->rho[i] = rho;
    /* EOS on the clamped ratio: p >= 0 (no tensile attraction at the free surface) and
     * ratio <= 2 (p <= 127 B) so a collapsed input cannot produce an unbounded force. */
    float ratio = clampf(rho / rho0, 1.f, 2.f);
    float rg1;
    if (gam == 7.f) {
        float q2 = ratio * ratio; /* the default exponent: ratio^6 without a powf call */
        rg1 = q2 * q2 * q2;
    } else {
        rg1 = powf(ratio, gam - 1.f);
    }
    float p = B * (rg1 * ratio - 1.f);
    s->pr[i] = p / (rho * rho);
    float c2 = c2_0 * rg1;
    if (c2 > o->c2_max)
        o->c2_max = c2;
    /* internal (EOS) energy m e(rho), e = int p/rho^2 drho from rho0, with the clamps:
     * what a compressed fluid can turn into motion (tests bound total energy with it) */
    double rr = rho / rho0, rc = rr > 2.0 ? 2.0 : rr;
    if (s->want_energy && rr > 1.0) {
        double e = B / rho0 * ((pow(rc, gam - 1.0) - 1.0) / (gam - 1.0) + 1.0 / rc - 1.0);
        if (rr > 2.0)
            e += B * (pow(2.0, gam) - 1.0) / rho0 * (0.5 - 1.0 / rr);
        o->ie += (double)m * e;
    }
    float err = (rho - rho0) / rho0;
    if (err > o->rho_err_max)
        o->rho_err_max = err;
    if (err > 0.f)
        o->rho_err_sum += err;
    o->pairs += nn;
    if (!isfinite(rho) && o->bad == UINT32_MAX)
        o->bad = i, o->bad_kind = 1, o->bad_value = rho;
}

/* Density by a scan of the 5x5x5 cells, recording the exact list (r < H) for the force pass
 * and, when `record`, the Verlet list (r < H + skin) and the positions it was built at. */
static inline __attribute__((always_inline)) void density_scan(rt_sph *s, uint32_t chunk, const bool record)
{
    uint32_t b = chunk * SPH_CHUNK, e = b + SPH_CHUNK < s->n ? b + SPH_CHUNK : s->n;
    const float H2 = s->H2, S2 = s->S2;
    /* reductions in a local copy, stored once per chunk: neighbouring chunks' slots share a
     * cache line and run on different threads (false sharing on every particle otherwise) */
    sph_chunk_out acc = s->out[chunk], *o = &acc;
    const float *X = s->x, *Y = s->y, *Z = s->z;
    sph_wall_hit walls[SPH_MAX_WALLS];
    uint32_t used = 0, sused = 0;
    for (uint32_t i = b; i < e; ++i) {
        float px = X[i], py = Y[i], pz = Z[i];
        sph_ranges r;
        neighbor_ranges(s, px, py, pz, 2, &r);
        uint32_t cand = 0;
        for (int q = 0; q < r.count; ++q)
            cand += r.hi[q] - r.lo[q];
        if (!grow_list(s, &s->cnb[chunk], &s->cnb_cap[chunk], used + cand) ||
            (record && !grow_list(s, &s->snb[chunk], &s->snb_cap[chunk], sused + cand))) {
            s->out[chunk] = acc;
            return;
        }
        uint32_t *L = s->cnb[chunk] + used, *SL = record ? s->snb[chunk] + sused : NULL;
        float sum = 0.f;
        uint32_t nn = 0, ns = 0;
        for (int q = 0; q < r.count; ++q) {
            for (uint32_t j = r.lo[q]; j < r.hi[q]; ++j) {
                float dx = px - X[j], dy = py - Y[j], dz = pz - Z[j];
                float r2 = dx * dx + dy * dy + dz * dz;
                if (record && r2 < S2) {
                    SL[ns] = j;
                    ns += j != i;
                }
                if (r2 < H2) {
                    float t = H2 - r2;
                    sum += t * t * t;
                    L[nn] = j;
                    nn += j != i;
                }
            }
        }
        s->nb_start[i] = used;
        s->nb_count[i] = nn;
        used += nn;
        if (record) {
            s->sk_start[i] = sused;
            s->sk_count[i] = ns;
            sused += ns;
            o->skin_pairs += ns;
            s->x0[i] = px, s->y0[i] = py, s->z0[i] = pz;
        }
        density_tail(s, i, sum, nn, px, py, pz, o, walls);
    }
    if (record)
        s->snb_used[chunk] = sused;
    s->out[chunk] = acc;
}

/* Density by a walk of the Verlet lists (r < H test), writing the exact list for the force
 * pass. Branch-free: ~40% of a list is within H at the default skin of 0.3 H, a coin flip for
 * the predictor (the cell scan's 27% hit rate is why its branch measured cheaper there). */
static void density_walk(rt_sph *s, uint32_t chunk)
{
    uint32_t b = chunk * SPH_CHUNK, e = b + SPH_CHUNK < s->n ? b + SPH_CHUNK : s->n;
    const float H2 = s->H2, self = H2 * H2 * H2;
    sph_chunk_out acc = s->out[chunk], *o = &acc;
    const float *X = s->x, *Y = s->y, *Z = s->z;
    sph_wall_hit walls[SPH_MAX_WALLS];
    const uint32_t *SLc = s->snb[chunk];
    uint32_t used = 0;
    for (uint32_t i = b; i < e; ++i) {
        float px = X[i], py = Y[i], pz = Z[i];
        const uint32_t *SL = SLc + s->sk_start[i];
        const uint32_t ns = s->sk_count[i];
        /* the exact list of i is a subset of its Verlet list */
        if (used + ns > s->cnb_cap[chunk] && !grow_list(s, &s->cnb[chunk], &s->cnb_cap[chunk], used + ns)) {
            s->out[chunk] = acc;
            return;
        }
        uint32_t *L = s->cnb[chunk] + used;
        float sum = self;
        uint32_t nn = 0, k = 0;
#if SPH_SSE
        {
            const __m128 vpx = _mm_set1_ps(px), vpy = _mm_set1_ps(py), vpz = _mm_set1_ps(pz);
            const __m128 vH2 = _mm_set1_ps(H2), zero = _mm_setzero_ps();
            __m128 acc = zero;
            for (; k + 4 <= ns; k += 4) {
                uint32_t j0 = SL[k], j1 = SL[k + 1], j2 = SL[k + 2], j3 = SL[k + 3];
                __m128 dx = vpx - _mm_setr_ps(X[j0], X[j1], X[j2], X[j3]);
                __m128 dy = vpy - _mm_setr_ps(Y[j0], Y[j1], Y[j2], Y[j3]);
                __m128 dz = vpz - _mm_setr_ps(Z[j0], Z[j1], Z[j2], Z[j3]);
                __m128 r2 = dx * dx + dy * dy + dz * dz;
                __m128 t = _mm_max_ps(vH2 - r2, zero);
                acc += t * t * t;
                int in = _mm_movemask_ps(_mm_cmplt_ps(r2, vH2));
                L[nn] = j0, nn += (uint32_t)in & 1u;
                L[nn] = j1, nn += ((uint32_t)in >> 1) & 1u;
                L[nn] = j2, nn += ((uint32_t)in >> 2) & 1u;
                L[nn] = j3, nn += ((uint32_t)in >> 3) & 1u;
            }
            sum += sph_hsum(acc);
        }
#endif
        for (; k < ns; ++k) {
            uint32_t j = SL[k];
            float dx = px - X[j], dy = py - Y[j], dz = pz - Z[j];
            float r2 = dx * dx + dy * dy + dz * dz;
            float t = H2 - r2;
            t = t > 0.f ? t : 0.f;
            sum += t * t * t;
            L[nn] = j;
            nn += r2 < H2;
        }
        s->nb_start[i] = used;
        s->nb_count[i] = nn;
        used += nn;
        o->skin_pairs += ns;
        density_tail(s, i, sum, nn, px, py, pz, o, walls);
    }
    s->out[chunk] = acc;
}

static void density_chunk(rt_sph *s, uint32_t chunk)
{
    if (s->dens_mode == 2)
        density_walk(s, chunk);
    else if (s->dens_mode == 1)
        density_scan(s, chunk, true);
    else
        density_scan(s, chunk, false);
}

/* Squared displacement of every particle since the last rebuild (columns edited by hand). */
static void disp_chunk(rt_sph *s, uint32_t chunk)
{
    uint32_t b = chunk * SPH_CHUNK, e = b + SPH_CHUNK < s->n ? b + SPH_CHUNK : s->n;
    float d2 = 0.f;
    for (uint32_t i = b; i < e; ++i) {
        float dx = s->x[i] - s->x0[i], dy = s->y[i] - s->y0[i], dz = s->z[i] - s->z0[i];
        float q = dx * dx + dy * dy + dz * dz;
        if (!(q <= d2))
            d2 = isnan(q) ? INFINITY : q; /* a NaN edit forces a rebuild too */
    }
    s->out[chunk].disp2_max = d2;
}

/* Deterministic, antisymmetric unit direction for exactly coincident particles. */
static void coincident_dir(uint32_t a, uint32_t b, float out[3])
{
    uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
    uint64_t h = ((uint64_t)lo * 0x9E3779B97F4A7C15ull) ^ ((uint64_t)hi * 0xC2B2AE3D27D4EB4Full);
    h ^= h >> 29;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 32;
    float th = (float)((h & 0xFFFF) / 65536.0 * 2.0 * SPH_PI);
    float cz = (float)(((h >> 16) & 0xFFFF) / 65536.0 * 2.0 - 1.0);
    float sz = sqrtf(1.f - cz * cz), sg = a < b ? 1.f : -1.f;
    out[0] = sg * sz * cosf(th), out[1] = sg * sz * sinf(th), out[2] = sg * cz;
}

static void force_chunk(rt_sph *s, uint32_t chunk)
{
    uint32_t b = chunk * SPH_CHUNK, e = b + SPH_CHUNK < s->n ? b + SPH_CHUNK : s->n;
    const float H = s->H, H2 = s->H2, ks = s->k_spiky, m = s->mass, h = s->h;
    const float alpha = s->p.viscosity, c0 = s->c0, rho0 = s->p.rest_density;
    const float eps2 = 1e-12f * H2;
    const float hh = 0.01f * h * h, visc = 2.f * alpha * c0, mks = m * ks;
    const float *g = s->p.gravity;
    const float *X = s->x, *Y = s->y, *Z = s->z, *VX = s->vx, *VY = s->vy, *VZ = s->vz;
    const float *R = s->rho, *P = s->pr;
    /* reductions in a local copy, stored once per chunk: neighbouring chunks' slots share a
     * cache line and run on different threads (false sharing on every particle otherwise) */
    sph_chunk_out acc = s->out[chunk], *o = &acc;
    sph_wall_hit walls[SPH_MAX_WALLS];
    for (uint32_t i = b; i < e; ++i) {
        float px = X[i], py = Y[i], pz = Z[i], vxi = VX[i], vyi = VY[i], vzi = VZ[i];
        float pri = P[i], rhoi = R[i];
        float ax = 0.f, ay = 0.f, az = 0.f, dr = 0.f;
        const uint32_t *L = s->cnb[chunk] + s->nb_start[i];
        const uint32_t nn = s->nb_count[i];
        {
            /* Per pair, with d = x_i - x_j, r = |d|: grad_i W = -ks (H - r)^2 d / r, so the
             * constant -ks and the mass leave the loop (applied to the sums after it) and the
             * unit vector is never formed; v.u r = v.d in the viscosity term. Fewer live values
             * per pair: the loop had spilled to the stack on every iteration. */
            float sx = 0.f, sy = 0.f, sz = 0.f, sd = 0.f;
            uint32_t coincident = 0, k = 0;
#if SPH_SSE
            /* four pairs at a time: the same operations lane by lane (IEEE, so each pair's
             * terms are the scalar ones), summed per lane and then across */
            {
                const __m128 vpx = _mm_set1_ps(px), vpy = _mm_set1_ps(py), vpz = _mm_set1_ps(pz);
                const __m128 vvx = _mm_set1_ps(vxi), vvy = _mm_set1_ps(vyi), vvz = _mm_set1_ps(vzi);
                const __m128 veps = _mm_set1_ps(eps2), vH = _mm_set1_ps(H), vh = _mm_set1_ps(h);
                const __m128 vhh = _mm_set1_ps(hh), vrho = _mm_set1_ps(rhoi), vpri = _mm_set1_ps(pri);
                const __m128 vvisc = _mm_set1_ps(visc), zero = _mm_setzero_ps();
                __m128 ax4 = zero, ay4 = zero, az4 = zero, ad4 = zero;
                for (; k + 4 <= nn; k += 4) {
                    uint32_t j0 = L[k], j1 = L[k + 1], j2 = L[k + 2], j3 = L[k + 3];
#define SPH_G4(A) _mm_setr_ps(A[j0], A[j1], A[j2], A[j3])
                    __m128 dx = vpx - SPH_G4(X), dy = vpy - SPH_G4(Y), dz = vpz - SPH_G4(Z);
                    __m128 dvx = vvx - SPH_G4(VX), dvy = vvy - SPH_G4(VY), dvz = vvz - SPH_G4(VZ);
                    __m128 rj = SPH_G4(R), pj = SPH_G4(P);
#undef SPH_G4
                    __m128 r2 = dx * dx + dy * dy + dz * dz;
                    __m128 valid = _mm_cmpgt_ps(r2, veps);
                    /* lanes with r^2 <= eps2, counted by a nibble table: __builtin_popcount
                     * is a libgcc call without -mpopcnt (4% of all instructions) */
                    coincident += (0x4332322132212110ull >> (4 * (~_mm_movemask_ps(valid) & 15))) & 15u;
                    __m128 rl = _mm_sqrt_ps(r2), hr = vH - rl;
                    /* one division for w = (H - r)^2 / r and the viscosity's denominator (the
                     * divider is as busy as everything else in this loop); r = 0 lanes get
                     * inv = 0, so w = mu = 0 there, not inf or NaN */
                    __m128 den = (r2 + vhh) * (vrho + rj);
                    __m128 inv = _mm_and_ps(valid, _mm_set1_ps(1.f) / (rl * den));
                    __m128 w = hr * hr * den * inv;
                    __m128 vdotd = dvx * dx + dvy * dy + dvz * dz;
                    __m128 vneg = _mm_min_ps(vdotd, zero);
                    __m128 mu = vh * vneg * rl * inv;
                    __m128 coef = (vpri + pj - vvisc * mu) * w;
                    ax4 += coef * dx, ay4 += coef * dy, az4 += coef * dz;
                    ad4 += vdotd * w;
                }
                sx = sph_hsum(ax4), sy = sph_hsum(ay4), sz = sph_hsum(az4), sd = sph_hsum(ad4);
            }
#endif
            for (; k < nn; ++k) {
                uint32_t j = L[k];
                float dx = px - X[j], dy = py - Y[j], dz = pz - Z[j];
                float r2 = dx * dx + dy * dy + dz * dz;
                float dvx = vxi - VX[j], dvy = vyi - VY[j], dvz = vzi - VZ[j];
                if (r2 > eps2) {
                    float rl = sqrtf(r2);
                    float hr = H - rl;
                    float w = hr * hr / rl; /* |grad W| / (ks r) */
                    float vdotd = dvx * dx + dvy * dy + dvz * dz;
                    /* Monaghan (1992) artificial viscosity, mu = h v.r/(r^2 + 0.01 h^2),
                     * approaching pairs only; branch-free (the sign is a coin flip) */
                    float vneg = vdotd < 0.f ? vdotd : 0.f;
                    float mu = h * vneg / ((r2 + hh) * (rhoi + R[j]));
                    float coef = (pri + P[j] - visc * mu) * w;
                    sx += coef * dx, sy += coef * dy, sz += coef * dz;
                    sd += vdotd * w;
                } else {
                    coincident++;
                }
            }
            /* exactly coincident pairs (r = 0): the deterministic direction u, (H - r)^2 = H^2.
             * In a loop of their own: a call inside the main loop made the compiler keep its
             * array pointers on the stack */
            for (uint32_t k = 0; coincident && k < nn; ++k) {
                uint32_t j = L[k];
                float dx = px - X[j], dy = py - Y[j], dz = pz - Z[j];
                if (!(dx * dx + dy * dy + dz * dz <= eps2))
                    continue;
                float u[3];
                coincident_dir(s->id[i], s->id[j], u);
                float coef = (pri + P[j]) * H * H;
                sx += coef * u[0], sy += coef * u[1], sz += coef * u[2];
                sd += ((vxi - VX[j]) * u[0] + (vyi - VY[j]) * u[1] + (vzi - VZ[j]) * u[2]) * H * H;
                coincident--;
            }
            /* a_i = -sum m coef grad W = m ks sum coef w d; d rho_i/dt = sum m v.grad W */
            ax = mks * sx, ay = mks * sy, az = mks * sz;
            dr = -mks * sd;
        }
        /* Walls, after the unified semi-analytical walls of Ferrand et al. (2013): the fluid
         * beyond a wall is missing from the sums above, so
         * (1) the missing volume acts as a mirror image of particle i: its pressure term
         *     2 (p_i/rho_i^2) and its artificial viscosity (image at 2d approaching at twice
         *     the normal speed, the pair formula above) times the gradient of the same wall
         *     density the density pass added (box walls through the product). A uniform
         *     pressure then has no net force at a wall, and a particle bouncing on it loses
         *     energy as it would on a fluid neighbour;
         * (2) the particle-plus-wall sum is divided by gamma_i, the kernel fraction inside the
         *     fluid, so a pressure gradient along a wall is not under-estimated by the
         *     truncated kernel (it would be by the fraction f missing: a wall layer half a
         *     spacing from a side wall needed a 1/(1 - f) = 1.28x steeper pressure to hold
         *     its weight).
         * Measured in a resting column (docs/simulation.md): the earlier single-sided form
         * p_i/rho_i^2 read +58% in the wall layer and +26% overall; (1) without the image
         * viscosity pumped energy into a resting tank; (2) alone compressed the wall layer. */
        int nw = gather_walls(s, px, py, pz, walls, SPH_MAX_WALLS);
        int nb = walls_box(walls, nw);
        float fr[SPH_MAX_WALLS], gr[SPH_MAX_WALLS]; /* density fraction, its gradient */
        float inside = 1.f, extra = 0.f;
        for (int w = 0; w < nw; ++w) {
            fr[w] = s->wall_scale * (float)rt_sph_wall_density_fraction(walls[w].d, H);
            if (w < nb)
                inside *= 1.f - fr[w];
            else
                extra += fr[w];
        }
        for (int w = 0; w < nw; ++w) {
            float others = 1.f;
            if (w < nb)
                for (int v = 0; v < nb; ++v)
                    if (v != w)
                        others *= 1.f - fr[v];
            const float *wv = walls[w].vel, *wn = walls[w].n;
            float vn = (vxi - wv[0]) * wn[0] + (vyi - wv[1]) * wn[1] + (vzi - wv[2]) * wn[2];
            float dd = walls[w].d > 0.f ? walls[w].d : 0.f;
            float vneg = vn < 0.f ? vn : 0.f;
            float mu = h * (2.f * vneg) * (2.f * dd) / ((4.f * dd * dd + 0.01f * h * h) * rhoi);
            float coef = 2.f * pri - alpha * c0 * mu;
            gr[w] = (float)rt_sph_wall_density_gradient(walls[w].d, H);
            float f = coef * rho0 * s->wall_scale * others * gr[w];
            ax += f * wn[0], ay += f * wn[1], az += f * wn[2];
        }
        /* a particle in a box corner at the clamp margin keeps 0.28 of its kernel; below 0.2
         * (only inside a collider, which the clamp then pushes it out of) the factor is held */
        float gam = inside - extra, inv_gam = gam > 0.2f ? 1.f / gam : 5.f;
        ax *= inv_gam, ay *= inv_gam, az *= inv_gam;
        /* No-slip walls: the shear stress of the smooth-wall law at the particle's own
         * tangential speed and distance, spread over the wall's kernel layer (see create).
         * Free-slip walls (the default) take no tangential force. The law, not a resolved
         * boundary layer: at the spacings of a game the viscous layer is far thinner than dx. */
        if (s->friction)
            for (int w = 0; w < nw; ++w) {
                if (!walls[w].no_slip)
                    continue;
                const float *wv = walls[w].vel, *wn = walls[w].n;
                float rx = vxi - wv[0], ry = vyi - wv[1], rz = vzi - wv[2];
                float vn = rx * wn[0] + ry * wn[1] + rz * wn[2];
                float tx = rx - vn * wn[0], ty = ry - vn * wn[1], tz = rz - vn * wn[2];
                float ut = sqrtf(tx * tx + ty * ty + tz * tz);
                if (!(ut > 0.f))
                    continue;
                float y = walls[w].d > 0.25f * s->p.spacing ? walls[w].d : 0.25f * s->p.spacing;
                float us = (float)rt_sph_wall_friction_velocity(ut, y, s->p.kinematic_viscosity);
                float am = us * us * s->fric_scale * gr[w] / ut;
                ax -= am * tx, ay -= am * ty, az -= am * tz;
            }
        ax += g[0], ay += g[1], az += g[2];
        s->ax[i] = ax, s->ay[i] = ay, s->az[i] = az;
        s->drho[i] = dr; /* continuity: d rho_i/dt = sum_j m v_ij . grad_i W_ij */
        float a2 = ax * ax + ay * ay + az * az, v2 = vxi * vxi + vyi * vyi + vzi * vzi;
        if (a2 > o->a2_max)
            o->a2_max = a2;
        if (v2 > o->v2_max)
            o->v2_max = v2;
        if (!isfinite(a2) && o->bad == UINT32_MAX)
            o->bad = i, o->bad_kind = 1, o->bad_value = a2;
    }
    s->out[chunk] = acc;
}

static void integrate_chunk(rt_sph *s, uint32_t chunk)
{
    uint32_t b = chunk * SPH_CHUNK, e = b + SPH_CHUNK < s->n ? b + SPH_CHUNK : s->n;
    const float dt = s->dt_try, margin = 0.25f * s->p.spacing;
    const float vlim2 = s->p.velocity_limit * s->p.velocity_limit, dlim = s->p.density_change_limit;
    const float *lo = s->p.domain_min, *hi = s->p.domain_max;
    const float m = s->mass;
    const float *g = s->p.gravity;
    /* reductions in a local copy, stored once per chunk: neighbouring chunks' slots share a
     * cache line and run on different threads (false sharing on every particle otherwise) */
    sph_chunk_out acc = s->out[chunk], *o = &acc;
    const bool track = s->verlet;
    float disp2 = 0.f;
    for (uint32_t i = b; i < e; ++i) {
        float v[3] = {s->vx[i] + dt * s->ax[i], s->vy[i] + dt * s->ay[i], s->vz[i] + dt * s->az[i]};
        float p[3] = {s->x[i] + dt * v[0], s->y[i] + dt * v[1], s->z[i] + dt * v[2]};
        /* colliders: push back to the margin, remove the velocity into the solid (relative) */
        for (uint32_t c = 0; c < s->ncol; ++c) {
            float n[3];
            float d = collider_distance(&s->col[c], p[0], p[1], p[2], n);
            if (d < margin) {
                for (int a = 0; a < 3; ++a)
                    p[a] += (margin - d) * n[a];
                const float *cv = s->col[c].vel;
                float vn = (v[0] - cv[0]) * n[0] + (v[1] - cv[1]) * n[1] + (v[2] - cv[2]) * n[2];
                if (vn < 0.f)
                    for (int a = 0; a < 3; ++a)
                        v[a] -= vn * n[a];
            }
        }
        /* domain box last: nothing leaves it whatever the colliders did */
        for (int a = 0; a < 3; ++a) {
            if (p[a] < lo[a] + margin) {
                p[a] = lo[a] + margin;
                if (v[a] < 0.f)
                    v[a] = 0.f;
            } else if (p[a] > hi[a] - margin) {
                p[a] = hi[a] - margin;
                if (v[a] > 0.f)
                    v[a] = 0.f;
            }
        }
        float v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        float drel = fabsf(dt * s->drho[i] / s->rho[i]);
        if (o->bad == UINT32_MAX) {
            if (!isfinite(v2) || !finite3(p))
                o->bad = i, o->bad_kind = 1, o->bad_value = v2;
            else if (v2 > vlim2)
                o->bad = i, o->bad_kind = 2, o->bad_value = sqrtf(v2);
            else if (!(drel <= dlim))
                o->bad = i, o->bad_kind = 3, o->bad_value = drel;
        }
        s->xn[i] = p[0], s->yn[i] = p[1], s->zn[i] = p[2];
        s->vxn[i] = v[0], s->vyn[i] = v[1], s->vzn[i] = v[2];
        if (track) {
            /* exact per-particle displacement since the rebuild: the rebuild decision is a max
             * over particles, the same whatever the thread count */
            float ex = p[0] - s->x0[i], ey = p[1] - s->y0[i], ez = p[2] - s->z0[i];
            float d2 = ex * ex + ey * ey + ez * ez;
            disp2 = d2 > disp2 ? d2 : disp2;
        }
        o->ke += 0.5 * (double)m * v2;
        o->pe -= (double)m * (g[0] * (p[0] - lo[0]) + g[1] * (p[1] - lo[1]) + g[2] * (p[2] - lo[2]));
    }
    acc.disp2_max = disp2;
    s->out[chunk] = acc;
}

/* ---- emitters ------------------------------------------------------------------------------ */

static vfx_result emit(rt_sph *s, double dt, uint32_t *emitted)
{
    float dx = s->p.spacing;
    for (uint32_t k = 0; k < s->nem; ++k) {
        sph_emitter_state *st = &s->em[k];
        const rt_sph_emitter *e = &st->e;
        if (!st->started) {
            st->started = true;
            st->travelled = dx; /* first layer at once */
        } else {
            st->travelled += e->speed * dt;
        }
        while (st->travelled >= dx) {
            st->travelled -= dx;
            int R = (int)floorf(e->radius / dx);
            float off = (float)st->travelled; /* the layer has already moved this far */
            for (int a = -R; a <= R; ++a)
                for (int b = -R; b <= R; ++b) {
                    if (((float)(a * a + b * b)) * dx * dx > e->radius * e->radius)
                        continue;
                    if (e->max_emit && st->emitted >= e->max_emit)
                        return VFX_OK;
                    if (s->n >= s->p.max_particles)
                        return VFX_OK; /* capacity reached: the emitter just stops */
                    float p[3], v[3];
                    for (int c = 0; c < 3; ++c) {
                        p[c] = e->center[c] + (float)a * dx * st->u[c] + (float)b * dx * st->w[c] +
                               off * e->direction[c];
                        v[c] = e->speed * e->direction[c];
                    }
                    vfx_result r = rt_sph_add_particles(s, 1, &p[0], &p[1], &p[2], &v[0], &v[1], &v[2]);
                    if (r)
                        return r;
                    st->emitted++;
                    (*emitted)++;
                }
        }
    }
    return VFX_OK;
}

/* ---- step ---------------------------------------------------------------------------------- */

static void swap_state(rt_sph *s)
{
    float *t;
#define SW(a, b) (t = s->a, s->a = s->b, s->b = t)
    SW(x, xn);
    SW(y, yn);
    SW(z, zn);
    SW(vx, vxn);
    SW(vy, vyn);
    SW(vz, vzn);
#undef SW
}

static uint32_t first_bad(const rt_sph *s, uint32_t nchunks, const sph_chunk_out **which)
{
    for (uint32_t c = 0; c < nchunks; ++c)
        if (s->out[c].bad != UINT32_MAX) {
            *which = &s->out[c];
            return s->out[c].bad;
        }
    return UINT32_MAX;
}

/* The density pass of a substep (or the closing one): with Verlet lists, a walk of them while
 * every particle has moved less than skin/2 since the rebuild (then no pair can have come
 * within H unlisted: each side moved < skin/2), otherwise a rebuild: sort by cell, scan the
 * cells, record the lists. Returns true when it rebuilt. */
static bool density_pass(rt_sph *s)
{
    bool rebuild = !s->verlet || !s->lists_valid || !(4.f * s->disp2_max < s->skin * s->skin);
    if (rebuild) {
        build_grid(s);
        s->dens_mode = s->verlet ? 1 : 0;
    } else {
        s->dens_mode = 2;
    }
    parallel(s, density_chunk, true);
    if (s->verlet && rebuild) {
        s->lists_valid = !atomic_load(&s->nb_oom);
        s->disp2_max = 0.f;
    }
    return rebuild;
}

static void reduce_disp(rt_sph *s)
{
    uint32_t nchunks = (s->n + SPH_CHUNK - 1) / SPH_CHUNK;
    float d2 = 0.f;
    for (uint32_t c = 0; c < nchunks; ++c)
        d2 = s->out[c].disp2_max > d2 ? s->out[c].disp2_max : d2;
    s->disp2_max = d2;
}

static void finish_report(rt_sph *s, rt_sph_report *rep)
{
    uint32_t nchunks = (s->n + SPH_CHUNK - 1) / SPH_CHUNK;
    float emax = 0.f, v2 = 0.f;
    double esum = 0.0, ke = 0.0, pe = 0.0, ie = 0.0;
    const float m = s->mass;
    const float *g = s->p.gravity, *lo = s->p.domain_min;
    if (s->n) {
        s->want_energy = true;
        if (density_pass(s))
            rep->neighbor_rebuilds++;
        s->want_energy = false;
        if (atomic_exchange(&s->nb_oom, false))
            s->lists_valid = false; /* the sums below are partial; the next substep says why */
        for (uint32_t c = 0; c < nchunks; ++c) {
            if (s->out[c].rho_err_max > emax)
                emax = s->out[c].rho_err_max;
            esum += s->out[c].rho_err_sum;
            ie += s->out[c].ie;
        }
    }
    for (uint32_t i = 0; i < s->n; ++i) {
        float w = s->vx[i] * s->vx[i] + s->vy[i] * s->vy[i] + s->vz[i] * s->vz[i];
        if (w > v2)
            v2 = w;
        ke += 0.5 * m * w;
        pe -= (double)m * (g[0] * (s->x[i] - lo[0]) + g[1] * (s->y[i] - lo[1]) + g[2] * (s->z[i] - lo[2]));
    }
    rep->max_density_error = emax;
    rep->mean_density_error = s->n ? (float)(esum / s->n) : 0.f;
    rep->max_speed = sqrtf(v2);
    rep->kinetic_energy = ke;
    rep->potential_energy = pe;
    rep->internal_energy = ie;
}

vfx_result rt_sph_step(rt_sph *s, float frame_dt, rt_sph_report *report)
{
    rt_sph_report rep = {0};
    if (report)
        *report = rep;
    if (!s)
        return VFX_ERR_INVALID_ARGUMENT;
    s->err[0] = 0;
    if (!isfinite(frame_dt) || frame_dt < 0.f) {
        set_err(s, "rt_sph_step: frame_dt %g must be finite and >= 0", (double)frame_dt);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    const double h = s->h, lam = s->p.cfl;
    double t = 0.0;
    rep.dt_min = INFINITY;
    vfx_result res = VFX_OK;
    if (s->verlet && s->lists_valid && s->n) {
        /* the columns are writable between steps: measure how far they were moved */
        parallel(s, disp_chunk, false);
        reduce_disp(s);
    }
    while (t < (double)frame_dt * (1.0 - 1e-9)) {
        if (rep.substeps >= s->p.max_substeps) {
            rep.cap_hit = true;
            break;
        }
        if (s->nem) {
            res = emit(s, rep.substeps ? rep.dt_last : 0.0, &rep.emitted);
            if (res)
                break;
        }
        update_colliders(s, s->time);
        double remaining = (double)frame_dt - t;
        double dt = remaining;
        rt_sph_dt_limit lim = RT_SPH_DT_FRAME;
        uint32_t nchunks = (s->n + SPH_CHUNK - 1) / SPH_CHUNK;
        if (s->n) {
            if (density_pass(s))
                rep.neighbor_rebuilds++;
            if (atomic_exchange(&s->nb_oom, false)) {
                s->lists_valid = false;
                set_err(s, "rt_sph_step: out of memory for the neighbour lists of %u particles", s->n);
                res = VFX_ERR_OUT_OF_MEMORY;
                break;
            }
            parallel(s, force_chunk, false);
            float v2 = 0.f, a2 = 0.f, c2 = 0.f;
            const sph_chunk_out *bo = NULL;
            uint32_t bad = first_bad(s, nchunks, &bo);
            if (bad != UINT32_MAX) {
                set_err(s, "rt_sph_step: particle %u (row %u) has a non-finite density or "
                        "force (%g) at t=%.6g s; state left at the last good substep",
                        s->id[bad], bad, (double)bo->bad_value, s->time);
                res = VFX_ERR_NUMERIC;
                break;
            }
            for (uint32_t c = 0; c < nchunks; ++c) {
                const sph_chunk_out *o = &s->out[c];
                v2 = o->v2_max > v2 ? o->v2_max : v2;
                a2 = o->a2_max > a2 ? o->a2_max : a2;
                c2 = o->c2_max > c2 ? o->c2_max : c2;
                rep.neighbor_pairs += o->pairs;
                rep.skin_pairs += o->skin_pairs;
            }
            double vmax = sqrt(v2), amax = sqrt(a2), cmax = sqrt(c2);
            double nu = s->p.viscosity * h * s->c0 / 10.0; /* artificial viscosity as nu, 3D */
            if (s->friction && s->p.kinematic_viscosity > nu)
                nu = s->p.kinematic_viscosity; /* keeps the explicit wall shear from overshooting */
            if (vmax > 0 && lam * h / vmax < dt)
                dt = lam * h / vmax, lim = RT_SPH_DT_CFL;
            if (cmax > 0 && lam * h / cmax < dt)
                dt = lam * h / cmax, lim = RT_SPH_DT_ACOUSTIC;
            if (amax > 0 && 0.25 * sqrt(h / amax) < dt)
                dt = 0.25 * sqrt(h / amax), lim = RT_SPH_DT_FORCE;
            if (nu > 0 && 0.125 * h * h / nu < dt)
                dt = 0.125 * h * h / nu, lim = RT_SPH_DT_VISCOUS;
            /* avoid a sliver substep at the end of the frame */
            if (lim != RT_SPH_DT_FRAME && remaining < 1.5 * dt && remaining > dt)
                dt = 0.5 * remaining;
            uint32_t tries = 0;
            for (;;) {
                s->dt_try = (float)dt;
                parallel(s, integrate_chunk, false);
                bad = first_bad(s, nchunks, &bo);
                if (bad == UINT32_MAX)
                    break;
                if (bo->bad_kind == 1 || tries >= s->p.max_redo) {
                    static const char *what[] = {"", "non-finite state", "speed", "density change"};
                    set_err(s, "rt_sph_step: particle %u (row %u) blew up: %s %g (limit %g) "
                            "after %u dt halvings (dt %.3g s) at t=%.6g s; state left at the "
                            "last good substep", s->id[bad], bad, what[bo->bad_kind],
                            (double)bo->bad_value,
                            bo->bad_kind == 2 ? (double)s->p.velocity_limit
                                              : (double)s->p.density_change_limit,
                            tries, dt, s->time);
                    res = VFX_ERR_NUMERIC;
                    break;
                }
                dt *= 0.5;
                tries++;
                rep.redo_count++;
            }
            if (res)
                break;
            swap_state(s);
            if (s->verlet)
                reduce_disp(s);
        }
        t += dt;
        s->time += dt;
        rep.substeps++;
        rep.dt_last = dt;
        rep.dt_limit = lim;
        if (dt < rep.dt_min)
            rep.dt_min = dt;
        if (dt > rep.dt_max)
            rep.dt_max = dt;
    }
    if (rep.substeps == 0)
        rep.dt_min = 0.0;
    rep.simulated_time = t;
    finish_report(s, &rep);
    if (report)
        *report = rep;
    return res;
}
