/* sph_params.c — parameters: defaults and checks, the lattice calibration of mass, kernel
 * gradient and wall terms, and the solver's creation and destruction. */
#include "sim/sph_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

static float def(float v, float d) { return v != 0.f ? v : d; }

/* The defaults of every zero field (and the two enum checks that come with them). */
static vfx_result default_params(rt_sph_desc *p, char *err, size_t err_len)
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
    p->neighbor_skin = def(p->neighbor_skin, 0.3f); /* measured: docs/simulation-wcsph.md */
    if (p->solver > RT_SPH_SOLVER_PBF) {
        snprintf(err, err_len, "rt_sph_create: desc.solver %u is not a solver (0 WCSPH, 1 PBF)", p->solver);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    /* PBF defaults: 6 plain iterations at eps = 0.2 D0 brought the default pool's mean compression
     * from 2.7% (4 at 1.0) to 0.8% (the cost/accuracy table in docs/simulation.md's git history);
     * the accelerated iterations below: docs/simulation-pbf.md, "Chebyshev acceleration" */
    if (!p->pbf_iterations) p->pbf_iterations = 5;
    p->pbf_max_step = def(p->pbf_max_step, 1.f / 60.f);
    p->pbf_cfl = def(p->pbf_cfl, 0.5f);
    /* 0.5 with the Chebyshev acceleration (rho 0.8): the default pool as compressed as with 0.2 and
     * rho 0.7 (0.53% against 0.48%), but a third of the kinetic energy left at rest after 300
     * frames (0.26 J against 0.72 J): the larger mixing damps the iteration's highest-frequency
     * mode, which the extrapolation otherwise amplifies (docs/simulation-pbf.md, "Chebyshev") */
    p->pbf_relaxation = def(p->pbf_relaxation, 0.5f);
    /* s_corr off by default: in zero gravity a free block with 0.5 cm/s of noise gained 9x its
     * kinetic energy in 2 s with k = 0.001 and lost 78% without (the artificial pressure pushes
     * at rest), and the projection lambda <= 0 already keeps the surface from clumping */
    p->pbf_scorr_k = def(p->pbf_scorr_k, 0.f);
    p->pbf_scorr_dq = def(p->pbf_scorr_dq, 0.2f);
    p->pbf_xsph = def(p->pbf_xsph, 0.01f);
    /* 0.8 with 5 iterations (and eps 0.5 D0): the default pool at 0.53% mean compression against
     * 0.76% with the old 6 plain ones, and the dam break within 10% at all 9 points (worst 9.6%);
     * 0.9 stirred the pool up (66 J of kinetic energy against 53.5 J at frame 120), and 2
     * iterations at 0.8 more (240 J) (docs/simulation-pbf.md, "Chebyshev acceleration") */
    p->pbf_chebyshev_rho = def(p->pbf_chebyshev_rho, 0.8f);
    return VFX_OK;
}

/* Every float of the completed desc finite and in its range, the domain at least two spacings
 * thick; the thread count capped at 256. */
static vfx_result check_params(rt_sph_desc *p, char *err, size_t err_len)
{
    const float *fields[] = {&p->spacing, &p->support_ratio, &p->rest_density, &p->sound_speed,
                             &p->stiffness, &p->gamma, &p->viscosity, &p->cfl, &p->velocity_limit,
                             &p->density_change_limit, &p->kinematic_viscosity,
                             &p->gravity[0], &p->gravity[1], &p->gravity[2],
                             &p->domain_min[0], &p->domain_min[1], &p->domain_min[2],
                             &p->domain_max[0], &p->domain_max[1], &p->domain_max[2],
                             &p->neighbor_skin, &p->pbf_max_step, &p->pbf_cfl, &p->pbf_relaxation,
                             &p->pbf_scorr_k, &p->pbf_scorr_dq, &p->pbf_xsph, &p->pbf_vorticity,
                             &p->pbf_chebyshev_rho};
    static const char *names[] = {"spacing", "support_ratio", "rest_density", "sound_speed",
                                  "stiffness", "gamma", "viscosity", "cfl", "velocity_limit",
                                  "density_change_limit", "kinematic_viscosity", "gravity[0]", "gravity[1]", "gravity[2]",
                                  "domain_min[0]", "domain_min[1]", "domain_min[2]",
                                  "domain_max[0]", "domain_max[1]", "domain_max[2]",
                                  "neighbor_skin", "pbf_max_step", "pbf_cfl", "pbf_relaxation",
                                  "pbf_scorr_k", "pbf_scorr_dq", "pbf_xsph", "pbf_vorticity",
                                  "pbf_chebyshev_rho"};
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
    if (!(p->pbf_max_step > 0.f) || !(p->pbf_cfl > 0.f) || !(p->pbf_relaxation > 0.f) ||
        p->pbf_scorr_k < 0.f || !(p->pbf_scorr_dq > 0.f && p->pbf_scorr_dq < 1.f) || p->pbf_xsph < 0.f ||
        p->pbf_xsph > 1.f || p->pbf_vorticity < 0.f || p->pbf_iterations > 1000 ||
        !(p->pbf_chebyshev_rho >= 0.f && p->pbf_chebyshev_rho < 1.f)) {
        snprintf(err, err_len, "rt_sph_create: a PBF parameter is out of range (pbf_max_step, pbf_cfl, "
                 "pbf_relaxation > 0; 0 < pbf_scorr_dq < 1; 0 <= pbf_xsph <= 1; pbf_scorr_k, "
                 "pbf_vorticity >= 0; pbf_iterations <= 1000; 0 <= pbf_chebyshev_rho < 1)");
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

/* The desc completed with its defaults, then checked. */
static vfx_result fill_params(rt_sph_desc *p, char *err, size_t err_len)
{
    vfx_result r = default_params(p, err, err_len);
    return r ? r : check_params(p, err, err_len);
}

/* Kernel constants, particle mass and the wall scales, each calibrated on the lattice the
 * solver fills blocks with; then the sound speed and stiffness made consistent (completes p). */
static void calibrate(rt_sph *s, rt_sph_desc *pp)
{
    rt_sph_desc p = *pp;
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
    *pp = p;
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
    calibrate(s, &p);
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
    atomic_init(&s->nb_oom, false);
    if (rt_sph_pool_start(s)) {
        rt_sph_destroy(s);
        snprintf(err, err_len, "rt_sph_create: out of memory");
        return VFX_ERR_OUT_OF_MEMORY;
    }
    *out = s;
    return VFX_OK;
}

void rt_sph_destroy(rt_sph *s)
{
    if (!s)
        return;
    rt_sph_pool_stop(s);
    rt_sph_free_columns(s);
    free(s->cell_start);
    free(s->out);
    for (uint32_t c = 0; c < s->ncol; ++c)
        free(s->col[c].sdf);
    free(s);
}

const rt_sph_desc *rt_sph_params(const rt_sph *s) { return s ? &s->p : NULL; }
float rt_sph_particle_mass(const rt_sph *s) { return s ? s->mass : 0.f; }
float rt_sph_support(const rt_sph *s) { return s ? s->H : 0.f; }
uint32_t rt_sph_clamped_on_add(const rt_sph *s) { return s ? s->clamped_on_add : 0; }
double rt_sph_time(const rt_sph *s) { return s ? s->time : 0.0; }
uint32_t rt_sph_thread_count(const rt_sph *s) { return s ? s->nthreads + 1 : 0; }

