/* sph.h — weakly compressible SPH fluid (Tait EOS, Becker & Teschner 2007) on SoA float
 * columns, independent of the ECS (runtime/sim/sim_system.h adapts it).
 *
 * Kernels (support radius H = support_ratio * spacing): Mueller et al. 2003 poly6 for density,
 * spiky gradient for pressure and viscosity forces (its gradient does not vanish at r = 0, so
 * coincident particles are pushed apart). Walls (domain box, planes, sphere and box colliders,
 * moving paddles) are semi-analytic: the density of the missing fluid beyond a wall is
 * integrated in closed form over the half-space; it acts as a mirror image (pressure and
 * artificial viscosity) and the particle's force sum is divided by the kernel fraction inside
 * the fluid (Ferrand et al. 2013); plus a hard non-penetration clamp. Walls are free-slip unless
 * marked no-slip, which adds the shear stress of a smooth wall's law of the wall.
 * Time step: min of CFL, acoustic, force and viscosity conditions, substeps per frame with a
 * cap; a substep whose result blows up (NaN/Inf, speed or density change beyond bounds) is
 * redone with half the dt, and fails with a message naming the particle if that keeps failing.
 * The columns never hold NaN: a failed substep leaves the previous state in place.
 *
 * Neighbours: Verlet lists with a skin (every pair within H + skin, found by a sort by grid cell
 * and a cell scan), rebuilt when a particle has moved half the skin since the last rebuild, when
 * particles are added or cleared, or when the columns were edited by hand beyond that (checked
 * at the start of every rt_sph_step).
 * Column pointers returned by rt_sph_columns stay valid until the next add or step (particles
 * are reordered by grid cell at every rebuild for locality; `id` says which input particle a row
 * is). The state columns (x..vz, density) are the solver's own, or a host's bound with
 * rt_sph_bind (an ECS table: the solver then steps them in place and reorders and appends rows
 * through the host). No global state; one rt_sph is not thread-safe, it uses its own worker
 * threads. */
#ifndef RT_SIM_SPH_H
#define RT_SIM_SPH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <volfx/volfx.h>

enum {
    RT_SPH_NO_GRAVITY = 1u << 0,   /* gravity = 0 (a zero gravity field otherwise means default) */
    RT_SPH_NO_VISCOSITY = 1u << 1, /* artificial viscosity alpha = 0 */
    /* the grid sort and 5x5x5 cell scan on every substep instead of Verlet lists (the
     * baseline the benchmark compares against) */
    RT_SPH_REBUILD_EVERY_SUBSTEP = 1u << 2,
    /* PBF: turn off a part of the solver (each measured in docs/simulation-pbf.md) */
    RT_SPH_PBF_WARM_START = 1u << 3,    /* experiment: pressures carried between steps (unstable) */
    RT_SPH_PBF_NO_SCORR = 1u << 4,      /* no artificial pressure s_corr */
    RT_SPH_PBF_NO_XSPH = 1u << 5,       /* no XSPH viscosity */
    /* the original passes, each pair's kernel gradient computed in both passes of an iteration
     * (the default computes it once, sph_pbf_lin.c; bitwise the same result: for benchmarks) */
    RT_SPH_PBF_RECOMPUTE = 1u << 6,
    /* PBF: plain Jacobi iterations, without the Chebyshev acceleration (the pre-round-3 method;
     * give it 6 iterations for the old default) */
    RT_SPH_PBF_NO_CHEBYSHEV = 1u << 7,
};

/* The solver (rt_sph_desc.solver). */
typedef enum rt_sph_solver {
    RT_SPH_SOLVER_WCSPH = 0, /* weakly compressible, explicit, adaptive substeps (the default) */
    RT_SPH_SOLVER_PBF = 1,   /* Position Based Fluids (Macklin & Mueller 2013), sph_pbf.c */
} rt_sph_solver;

/* Faces of the domain box, for rt_sph_desc.no_slip_faces. */
enum {
    RT_SPH_FACE_X_MIN = 1u << 0, RT_SPH_FACE_X_MAX = 1u << 1,
    RT_SPH_FACE_Y_MIN = 1u << 2, RT_SPH_FACE_Y_MAX = 1u << 3, /* y min: the floor */
    RT_SPH_FACE_Z_MIN = 1u << 4, RT_SPH_FACE_Z_MAX = 1u << 5,
};

/* Zero in any field means its default (listed). */
typedef struct rt_sph_desc {
    float spacing;              /* particle spacing dx [m]; 0.02 */
    float support_ratio;        /* kernel support H / dx; 2.0 */
    float rest_density;         /* rho0 [kg/m^3]; 1000 */
    float sound_speed;          /* c0 [m/s]; 10*sqrt(2*|g|*domain height) (~1% compression) */
    float stiffness;            /* Tait B [Pa]; rho0*c0^2/gamma. Setting it sets c0 from it */
    float gamma;                /* Tait exponent; 7 */
    float viscosity;            /* Monaghan artificial viscosity alpha; 0.05 */
    float gravity[3];           /* [m/s^2]; (0,-9.81,0) */
    float domain_min[3];        /* solid box walls; [0,1]^3 when min == max */
    float domain_max[3];
    float cfl;                  /* lambda of the CFL and acoustic conditions; 0.4 */
    uint32_t max_substeps;      /* per rt_sph_step; 256 */
    uint32_t max_redo;          /* dt halvings per substep before giving up; 10 */
    float velocity_limit;       /* blow-up bound on |v| [m/s]; 20*c0 */
    float density_change_limit; /* blow-up bound on |d rho|/rho per substep; 0.05 */
    uint32_t max_particles;     /* capacity bound (adds and emitters); 1<<27 */
    uint32_t threads;           /* worker threads; all online cores */
    float neighbor_skin;        /* Verlet skin as a fraction of H, 0 < skin <= 1; 0.3 */
    uint32_t flags;             /* RT_SPH_* */
    /* Wall friction (smooth-wall law of the wall, docs/simulation-wcsph.md): box faces that are
     * no-slip (RT_SPH_FACE_* bits; 0 = every face free-slip) and the fluid's molecular
     * kinematic viscosity that sets their shear stress [m^2/s]; 1.0e-6 (water at 20 C). */
    uint32_t no_slip_faces;
    float kinematic_viscosity;
    /* Position Based Fluids (solver = RT_SPH_SOLVER_PBF; docs/simulation-pbf.md): a call of
     * rt_sph_step takes ceil(frame_dt / pbf_max_step) steps, more when a particle would move
     * more than pbf_cfl * H in one (up to max_substeps; the frame is always covered). */
    uint32_t solver;            /* rt_sph_solver; WCSPH */
    uint32_t pbf_iterations;    /* Jacobi iterations per step; 5 */
    float pbf_max_step;         /* longest step [s]; 1/60 */
    float pbf_cfl;              /* largest move per step as a fraction of H; 0.5 */
    float pbf_relaxation;       /* constraint-force mixing eps, a fraction of the lattice's
                                 * sum |grad C|^2; 0.5 */
    float pbf_scorr_k;          /* artificial pressure k of s_corr = -k (W(r)/W(dq))^4; 0 (off) */
    float pbf_scorr_dq;         /* its dq as a fraction of H; 0.2 */
    float pbf_xsph;             /* XSPH viscosity c; 0.01 */
    float pbf_vorticity;        /* vorticity confinement epsilon [m/s]; 0 (off) */
    /* Chebyshev semi-iterative acceleration of the Jacobi iterations (Wang 2015): the estimate
     * of the iteration's spectral radius rho, 0 <= rho < 1; 0.8. Off with RT_SPH_PBF_NO_CHEBYSHEV */
    float pbf_chebyshev_rho;
} rt_sph_desc;

typedef enum rt_sph_dt_limit {
    RT_SPH_DT_FRAME = 0,    /* the rest of the frame was shorter than every condition */
    RT_SPH_DT_CFL = 1,      /* lambda*h/v_max */
    RT_SPH_DT_ACOUSTIC = 2, /* lambda*h/c_max */
    RT_SPH_DT_FORCE = 3,    /* 0.25*sqrt(h/a_max) */
    RT_SPH_DT_VISCOUS = 4,  /* 0.125*h^2/nu */
} rt_sph_dt_limit;

typedef struct rt_sph_report {
    uint32_t substeps;
    uint32_t redo_count;        /* substeps redone with a halved dt */
    bool cap_hit;               /* max_substeps reached before the frame time was covered */
    double simulated_time;      /* <= frame_dt; less when cap_hit */
    double dt_min, dt_max, dt_last;
    rt_sph_dt_limit dt_limit;  /* what bounded the last dt */
    float max_density_error;    /* max (rho - rho0)/rho0 over particles (compression), end state */
    float mean_density_error;   /* mean of max(0, rho - rho0)/rho0, end state */
    float max_speed;            /* end state [m/s] */
    double kinetic_energy;      /* [J], end state */
    double potential_energy;    /* [J], -sum m g.(x - domain_min), end state */
    double internal_energy;     /* [J], sum m e(rho) of the clamped Tait EOS, end state */
    uint64_t neighbor_pairs;    /* ordered pairs (i != j) within H, summed over substeps (one pass) */
    uint32_t neighbor_rebuilds; /* grid sorts + cell scans, the closing density pass included
                                 * (substeps + 1 with RT_SPH_REBUILD_EVERY_SUBSTEP) */
    uint64_t skin_pairs;        /* entries of the Verlet lists walked, summed over substeps */
    uint32_t emitted;           /* particles emitted during this step */
    uint32_t iterations;        /* PBF: Jacobi iterations over all steps (0 for WCSPH) */
    uint32_t speed_clamped;     /* PBF: particles whose speed was held at velocity_limit */
} rt_sph_report;

typedef struct rt_sph_columns {
    uint32_t count;
    float *x, *y, *z, *vx, *vy, *vz, *density;
    const uint32_t *id; /* input index (order of addition/emission) of each row */
} rt_sph_columns;

typedef enum rt_sph_collider_kind {
    RT_SPH_PLANE = 0,  /* fluid on the side `normal` points to */
    RT_SPH_SPHERE = 1, /* solid ball */
    RT_SPH_BOX = 2,    /* solid axis-aligned box */
} rt_sph_collider_kind;

typedef struct rt_sph_collider {
    rt_sph_collider_kind kind;
    float center[3];          /* plane: a point on it; sphere/box: centre at t = 0 */
    float normal[3];          /* plane only, normalised on add */
    float radius;             /* sphere */
    float half[3];            /* box half extents */
    /* Paddle motion: centre(t) = centre + axis*amplitude*r(t)*sin(2*pi*frequency*t) (r = 1, or
     * the ramp below); 0 = static. */
    float motion_axis[3];
    float motion_amplitude;   /* [m] */
    float motion_frequency;   /* [Hz] */
    uint32_t no_slip;         /* nonzero: wall-law friction on its surface (default free-slip) */
    /* The amplitude ramps in over this many seconds from t = 0 (a smoothstep: the paddle
     * starts at rest and without a jerk); 0 = full amplitude from the start. */
    float motion_ramp_s;
} rt_sph_collider;

typedef struct rt_sph_emitter {
    float center[3];
    float direction[3];       /* normalised on add */
    float speed;              /* [m/s], > 0 */
    float radius;             /* nozzle disc radius [m], >= spacing/2 */
    uint32_t max_emit;        /* stop after this many particles; 0 = until capacity */
} rt_sph_emitter;

typedef struct rt_sph rt_sph;

/* Errors: every function that can fail returns a vfx_result and takes `char *err, size_t errlen`
 * last (NULL allowed) for a message naming what failed (the particle, collider or bound);
 * the solver keeps no message of its own (runtime/core/error.h). */

/* Creates a solver; NULL desc = defaults. */
vfx_result rt_sph_create(const rt_sph_desc *desc, rt_sph **out, char *err, size_t errlen);
/* Stops the workers and frees everything. NULL allowed. */
void rt_sph_destroy(rt_sph *sim);
/* The resolved parameters (defaults filled in, c0 and B consistent). */
const rt_sph_desc *rt_sph_params(const rt_sph *sim);
/* Particle mass [kg] (calibrated so a lattice of `spacing` has the rest density). */
float rt_sph_particle_mass(const rt_sph *sim);
/* Kernel support radius H [m]. */
float rt_sph_support(const rt_sph *sim);

/* Adds n particles (x,y,z required, v* NULL = 0). Refuses the whole batch, naming the first
 * particle, when any value is NaN/Inf; positions outside the domain are moved inside (counted
 * in rt_sph_clamped_on_add). n = 0 is a no-op. */
vfx_result rt_sph_add_particles(rt_sph *sim, uint32_t n, const float *x, const float *y,
                                 const float *z, const float *vx, const float *vy, const float *vz,
                                 char *err, size_t errlen);
/* Host-owned state columns (rt_sph_bind). Each call leaves the columns as they are afterwards in
 * *cols (pointers may move; id is ignored). */
typedef struct rt_sph_host {
    void *user;
    /* Reorders the rows: new row i = old row perm[i] (a permutation of 0..count-1). */
    vfx_result (*permute)(void *user, const uint32_t *perm, rt_sph_columns *cols);
    /* Appends `add` rows at the end (the solver then writes their values). */
    vfx_result (*append)(void *user, uint32_t add, rt_sph_columns *cols);
} rt_sph_host;

/* Steps the host's columns (cols: count rows of x..vz and density) in place from now on; the
 * solver's own particles are dropped. Checks them like rt_sph_add_particles (a NaN/Inf refuses
 * the binding, naming the row; positions are moved into the domain), sets density to rho0, ids
 * restart at 0 in row order and the neighbour lists are rebuilt at the next substep. Bind again
 * after the host changed its rows (count or order); edited values need no call (moves are seen
 * by the displacement check of rt_sph_step). Adds and emitters append through the host; the
 * host and its columns must outlive the binding, which rt_sph_clear ends. */
vfx_result rt_sph_bind(rt_sph *sim, const rt_sph_host *host, const rt_sph_columns *cols,
                       char *err, size_t errlen);
/* Removes every particle (capacity, colliders, emitters and time are kept); ids restart at 0.
 * Ends a binding (the host's rows are left alone). */
void rt_sph_clear(rt_sph *sim);
/* Adds a lattice of spacing dx filling [lo, hi] (cell centres), at rest; count in *added. */
vfx_result rt_sph_add_block(rt_sph *sim, const float lo[3], const float hi[3], uint32_t *added,
                            char *err, size_t errlen);
/* Number of particles that rt_sph_add_particles had to move into the domain so far. */
uint32_t rt_sph_clamped_on_add(const rt_sph *sim);
/* Adds a static or moving collider; its index in *index when not NULL. */
vfx_result rt_sph_add_collider(rt_sph *sim, const rt_sph_collider *c, uint32_t *index,
                               char *err, size_t errlen);
/* Adds a solid triangle mesh (closed, any winding; e.g. from rt_mesh_import) as a collider
 * (motion->no_slip makes it no-slip):
 * its signed distance is sampled once on a grid of ~H/2 (at most 64 nodes per axis, brute
 * force over <= 20,000 triangles, inside by generalised winding number) and interpolated.
 * motion (NULL = static) moves it rigidly: centre(t) - centre(0) is added to the mesh. */
vfx_result rt_sph_add_mesh_collider(rt_sph *sim, const float *positions, uint32_t vertex_count,
                                     const uint32_t *indices, uint32_t index_count,
                                     const rt_sph_collider *motion, uint32_t *index,
                                     char *err, size_t errlen);
/* Signed distance from p to collider `index` at the current time (positive on the fluid side;
 * +Inf beyond a mesh's grid); NaN for a bad index. */
float rt_sph_collider_distance(const rt_sph *sim, uint32_t index, const float p[3]);
/* Centre and velocity of collider `index` at the current time (as the walls use them). */
vfx_result rt_sph_collider_motion(const rt_sph *sim, uint32_t index, float pos[3], float vel[3]);
/* Adds an emitter that injects disc-shaped layers of particles each time they have moved dx. */
vfx_result rt_sph_add_emitter(rt_sph *sim, const rt_sph_emitter *e, char *err, size_t errlen);

/* Advances by frame_dt seconds in adaptive substeps (see the report). VFX_ERR_NUMERIC when a
 * substep cannot be made stable (message names the particle); the state is then the last good
 * one. frame_dt must be finite and >= 0. */
vfx_result rt_sph_step(rt_sph *sim, float frame_dt, rt_sph_report *report, char *err,
                       size_t errlen);
/* rt_sph_settle: damped steps before a scene's frame 0, so a fresh block (the calibrated lattice)
 * starts in the solver's own hydrostatic equilibrium instead of sinking into it. Zero means the
 * default. */
typedef struct rt_sph_settle_desc {
    uint32_t max_steps;   /* at most this many steps (default 120) */
    float step_dt;        /* each a rt_sph_step of this dt [s] (default 1/60) */
    float damping;        /* velocities multiplied by this after each step (default 0.9; 0..1) */
    float speed_tol;      /* stop once a step ends below this max speed [m/s] (default 0.03) */
    bool quasi_static;    /* velocities zeroed after every step instead of damped: each step's max
                           * speed is then how far the solver's step moves a fluid at rest */
    uint32_t progress_every; /* progress(...) after the first step, every this many and at the end (default 20) */
    void (*progress)(void *user, uint32_t step, uint32_t max_steps, float max_speed, float compression);
    void *user;
} rt_sph_settle_desc;
typedef struct rt_sph_settle_report {
    uint32_t steps;        /* steps taken */
    float max_speed_first; /* max speed after the first step [m/s] */
    float max_speed_last;  /* after the last step, before its damping (the velocities are then zeroed) */
    float compression;     /* mean compression after the last step */
    double cpu_s;          /* process CPU seconds the settle took (all threads) */
} rt_sph_settle_report;
/* Steps with the velocities damped until the max speed falls below speed_tol or max_steps are
 * taken, then zeroes the velocities and sets the clock (and the colliders' motion) back to where
 * it was: the state is the settled positions at rest. NULL desc: defaults. */
vfx_result rt_sph_settle(rt_sph *sim, const rt_sph_settle_desc *desc, rt_sph_settle_report *report, char *err,
                         size_t errlen);
/* The Chebyshev weight PBF applies in its k-th iteration (1-based; 1 for k <= 1) at spectral
 * radius rho, by the recurrence the solver steps through (Wang 2015). */
float rt_sph_chebyshev_weight(float rho, uint32_t k);
/* An impulse where something hit the fluid (a beam striking the water; docs/simulation.md
 * "Impacts"): every particle within `radius` of `centre` gets its velocity's component along
 * u = normalize(unit(x - centre) - 0.7 dir) (dir: the hitting thing's direction of travel, NULL or
 * zero for none) raised to speed (1 - r / radius)^2 when it is below that, never lowered. So a
 * particle never leaves an impulse faster than |v| + speed, and repeated impulses (a beam held on
 * the water) never drive the component past speed. Returns the particles changed; 0 for a
 * non-positive or non-finite radius or speed. Call between steps. */
uint32_t rt_sph_impulse(rt_sph *sim, const float centre[3], const float dir[3], float radius, float speed);
/* The SoA columns (see the validity note above). */
rt_sph_columns rt_sph_get_columns(rt_sph *sim);
/* Pressure [Pa] of row i from the last density pass (0 when i is out of range). */
float rt_sph_pressure(const rt_sph *sim, uint32_t i);
/* Fluid volume fraction at p: sum_j (m/rho0) W_poly6(p - x_j) over the fluid share of the
 * kernel (walls excluded), ~1 inside the fluid, 1/2 on its surface, 0 in air or in a solid;
 * NaN for non-finite p. Uses the grid of the last rebuild and the current positions. */
float rt_sph_volume_fraction(const rt_sph *sim, const float p[3]);
/* Simulated time since creation [s]. */
double rt_sph_time(const rt_sph *sim);
/* Bytes allocated by the solver (columns, grid, Verlet and exact neighbour lists, chunk
 * reductions). */
size_t rt_sph_memory_bytes(const rt_sph *sim);
/* Number of worker threads in use (including the calling thread). */
uint32_t rt_sph_thread_count(const rt_sph *sim);

/* Closed-form wall integrals (exposed for tests): fraction of the poly6 kernel mass beyond a
 * plane at distance d (0.5 at d = 0, 0 at d >= H), and minus its derivative in d [1/m]. */
double rt_sph_wall_density_fraction(double d, double H);
double rt_sph_wall_density_gradient(double d, double H);
/* Friction velocity u* [m/s] of a smooth no-slip wall (wall shear stress tau = rho u*^2) for a
 * tangential speed u_t at distance y with kinematic viscosity nu: the linear sublayer
 * u_t/u* = y u* / nu below y+ = 11.06, the log law u_t/u* = ln(y u* / nu)/0.41 + 5.2 above.
 * 0 when any argument is <= 0 or not finite. */
double rt_sph_wall_friction_velocity(double u_t, double y, double nu);

#endif
