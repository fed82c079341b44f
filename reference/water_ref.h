/* water_ref.h — float64 reference renderer of the metaball isosurface of seed 000 (Mishima et
 * al.): I(x) = sqrt(sum_j P(|x - p_j|)) - T, by dense sampling along each pixel ray plus
 * bisection, with a uniform grid (cell = h) so only particles within h of a sample are summed.
 * Independent of the GPU paths: it shares only the definitions (kernel, threshold, camera). */
#ifndef REF_WATER_REF_H
#define REF_WATER_REF_H

#include <stddef.h>
#include <stdint.h>

/* Kernel P(r) for 0 <= r <= h (0 beyond) and its derivative dP/dr. */
typedef struct ref_water_kernel {
    double (*value)(double r, double h);
    double (*deriv)(double r, double h);
} ref_water_kernel;

/* The paper's kernel (eq. 7): P(r) = (1 - r/h)^2. */
ref_water_kernel ref_water_kernel_paper(void);

/* Pinhole camera, issue-7 convention: pixel (i,j) from top-left, ray through the pixel centre. */
typedef struct ref_water_camera {
    double eye[3], forward[3], up[3];
    double fov_y; /* radians */
    uint32_t width, height;
} ref_water_camera;

typedef struct ref_water_params {
    double h;            /* influence radius (paper 0.61) */
    double threshold;    /* T (paper 0.765625) */
    double step;         /* dense sampling step along the ray; 0 -> h/32 */
    double t_max;        /* farthest distance searched; 0 -> no limit beyond the particles' box */
    ref_water_kernel kernel;
    /* per-particle kernels (NULL: isotropic): 6 doubles a particle (xx xy xz yy yz zz) of a
     * symmetric positive definite G; particle j adds P(|G_j (x - p_j)|) */
    const double *G;
} ref_water_params;

/* Paper defaults: h = 0.61, T = 0.765625, step h/32, paper kernel. */
ref_water_params ref_water_default_params(void);

typedef struct ref_water_stats {
    uint32_t nan_skipped;  /* particles with a non-finite coordinate: skipped and counted */
    uint64_t samples;      /* field evaluations */
    uint32_t hits;
} ref_water_stats;

/* Ray direction (unit) of pixel (i,j). */
void ref_water_pixel_dir(const ref_water_camera *cam, uint32_t i, uint32_t j, double dir[3]);

/* I(x) and its gradient (grad optional) by brute force over all particles (tests, normals). */
double ref_water_field(const float *x, const float *y, const float *z, uint32_t n,
                           const ref_water_params *p, const double pos[3], double grad[3]);

/* Renders dist[width*height] (distance along the ray to the first crossing of I = 0 from below,
 * -1 for a miss; 0 when the eye itself is inside) and, if normal != NULL, normal[3*w*h]
 * (unit, -grad I, i.e. pointing out of the fluid; 0 for misses). Particles are columns x,y,z.
 * Returns 0, or -1 with err filled (bad camera/params, out of memory). */
int ref_water_render(const ref_water_camera *cam, const float *x, const float *y,
                         const float *z, uint32_t n, const ref_water_params *p, float *dist,
                         float *normal, ref_water_stats *stats, char err[256]);

/* Anisotropic kernels (Yu & Turk 2013) as the plugin defines them (docs/water.md), computed
 * independently: brute-force neighbours, cyclic Jacobi to convergence, all in double. */
typedef struct ref_water_aniso_params {
    double h;                /* kernel radius */
    double radius;           /* neighbourhood radius in units of h */
    double max_stretch;      /* kr */
    uint32_t min_neighbours; /* Ne: fewer -> isotropic */
    double scale;            /* ks (stretched particles only) */
    double smoothing;        /* lambda (0: none) */
} ref_water_aniso_params;

/* For each particle: centre[3 i..] (moved by the smoothing), G[6 i..] and its neighbours within
 * the radius (nbrs, optional). Non-finite particles: no neighbour, the identity, centre as is. */
void ref_water_aniso_kernels(const float *x, const float *y, const float *z, uint32_t n,
                             const ref_water_aniso_params *p, double *centre, double *G, uint32_t *nbrs);

/* Eigenvalues (ascending) and eigenvectors (columns of V, row-major 3x3) of the symmetric
 * (xx xy xz yy yz zz), by cyclic Jacobi to convergence in double. */
void ref_water_eigen_sym3(const double a[6], double ev[3], double V[9]);

/* Error of a rendered image (dist, normal optional) against the reference (ref_dist, ref_normal). */
typedef struct ref_water_error {
    double hole_rate;       /* fraction of reference hits the renderer misses */
    double false_hit_rate;  /* fraction of reference misses the renderer hits */
    double dist_mean_rel_h; /* mean |t - t_ref| / h over pixels both hit */
    double dist_p99_rel_h;  /* 99th percentile of the same */
    double normal_mean_deg; /* mean angle between normals over pixels both hit (0 without normals) */
    double normal_p99_deg;
    uint32_t ref_hits, both_hit;
} ref_water_error;

/* Compares n pixels. Returns 0, or -1 (out of memory). */
int ref_water_compare(const float *dist, const float *normal, const float *ref_dist,
                          const float *ref_normal, size_t n, double h, ref_water_error *out);

/* Paper's Fig. 9 layout: 24x24 square layers with `spacing`, stacked in y until n particles,
 * centred on the origin in x,z with the bottom layer at y = 0. */
void ref_water_layers(uint32_t n, double spacing, float *x, float *y, float *z);

/* n particles in `blobs` gaussian clusters (sigma) at random centres in [-extent, extent]^3,
 * deterministic from seed. */
void ref_water_blobs(uint32_t n, uint32_t blobs, double extent, double sigma, uint64_t seed,
                         float *x, float *y, float *z);

#endif
