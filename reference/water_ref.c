/* water_ref.c — float64 metaball reference (see water_ref.h). */
#include "water_ref.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static double kernel_paper_value(double r, double h)
{
    if (r >= h) return 0.0;
    double q = 1.0 - r / h;
    return q * q;
}

static double kernel_paper_deriv(double r, double h)
{
    if (r >= h) return 0.0;
    return -2.0 * (1.0 - r / h) / h;
}

ref_water_kernel ref_water_kernel_paper(void)
{
    ref_water_kernel k = {kernel_paper_value, kernel_paper_deriv};
    return k;
}

ref_water_params ref_water_default_params(void)
{
    ref_water_params p;
    memset(&p, 0, sizeof p);
    p.h = 0.61;
    p.threshold = 0.765625;
    p.step = 0.61 / 32.0;
    p.kernel = ref_water_kernel_paper();
    return p;
}

static void normalize3(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0) { v[0] /= l; v[1] /= l; v[2] /= l; }
}

static void cross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

void ref_water_pixel_dir(const ref_water_camera *cam, uint32_t i, uint32_t j, double dir[3])
{
    double f[3] = {cam->forward[0], cam->forward[1], cam->forward[2]}, r[3], u[3];
    normalize3(f);
    cross3(f, cam->up, r);
    normalize3(r);
    cross3(r, f, u);
    double th = tan(0.5 * cam->fov_y);
    double sx = (2.0 * (i + 0.5) / cam->width - 1.0) * th * (double)cam->width / cam->height;
    double sy = (1.0 - 2.0 * (j + 0.5) / cam->height) * th;
    for (int k = 0; k < 3; ++k) dir[k] = f[k] + sx * r[k] + sy * u[k];
    normalize3(dir);
}

static int finite3(float a, float b, float c) { return isfinite(a) && isfinite(b) && isfinite(c); }

/* Sum of P and of dP * (x - p)/r over the given particle indices (or all when idx == NULL). */
static void accumulate(const float *x, const float *y, const float *z, const uint32_t *idx,
                       uint32_t count, const ref_water_params *p, const double pos[3],
                       double *sum, double g[3])
{
    double h2 = p->h * p->h;
    for (uint32_t k = 0; k < count; ++k) {
        uint32_t j = idx ? idx[k] : k;
        if (!idx && !finite3(x[j], y[j], z[j])) continue;
        double d[3] = {pos[0] - x[j], pos[1] - y[j], pos[2] - z[j]};
        if (p->G) { /* y = G d; grad P(|y|) = P'(r) G y / r */
            const double *m = p->G + 6 * (size_t)j;
            double yv[3] = {m[0] * d[0] + m[1] * d[1] + m[2] * d[2], m[1] * d[0] + m[3] * d[1] + m[4] * d[2],
                            m[2] * d[0] + m[4] * d[1] + m[5] * d[2]};
            double r2 = yv[0] * yv[0] + yv[1] * yv[1] + yv[2] * yv[2];
            if (r2 >= h2) continue;
            double r = sqrt(r2);
            *sum += p->kernel.value(r, p->h);
            if (g && r > 0) {
                double s = p->kernel.deriv(r, p->h) / r;
                g[0] += s * (m[0] * yv[0] + m[1] * yv[1] + m[2] * yv[2]);
                g[1] += s * (m[1] * yv[0] + m[3] * yv[1] + m[4] * yv[2]);
                g[2] += s * (m[2] * yv[0] + m[4] * yv[1] + m[5] * yv[2]);
            }
            continue;
        }
        double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if (r2 >= h2) continue;
        double r = sqrt(r2);
        *sum += p->kernel.value(r, p->h);
        if (g && r > 0) {
            double s = p->kernel.deriv(r, p->h) / r;
            g[0] += s * d[0]; g[1] += s * d[1]; g[2] += s * d[2];
        }
    }
}

static double field_from_sum(double sum, const ref_water_params *p, double g[3])
{
    double s = sqrt(sum);
    if (g) {
        /* d sqrt(S) = dS / (2 sqrt S); S = 0 means no particle in reach: gradient 0. */
        double f = s > 0 ? 0.5 / s : 0.0;
        g[0] *= f; g[1] *= f; g[2] *= f;
    }
    return s - p->threshold;
}

double ref_water_field(const float *x, const float *y, const float *z, uint32_t n,
                           const ref_water_params *p, const double pos[3], double grad[3])
{
    double sum = 0, g[3] = {0, 0, 0};
    accumulate(x, y, z, NULL, n, p, pos, &sum, grad ? g : NULL);
    double v = field_from_sum(sum, p, grad ? g : NULL);
    if (grad) memcpy(grad, g, sizeof g);
    return v;
}

/* Uniform grid of cell >= h over the finite particles' box: a sample's neighbours lie in the
 * 3x3x3 cells around it. */
typedef struct ref_grid {
    double lo[3], hi[3], cell;
    int dim[3];
    uint32_t *start; /* dim product + 1 */
    uint32_t *items;
} ref_grid;

static int grid_build(ref_grid *gr, const float *x, const float *y, const float *z, uint32_t n,
                      double h, uint32_t *nan_skipped)
{
    memset(gr, 0, sizeof *gr);
    uint32_t finite = 0, skipped = 0;
    for (int k = 0; k < 3; ++k) { gr->lo[k] = INFINITY; gr->hi[k] = -INFINITY; }
    for (uint32_t j = 0; j < n; ++j) {
        if (!finite3(x[j], y[j], z[j])) { ++skipped; continue; }
        double q[3] = {x[j], y[j], z[j]};
        for (int k = 0; k < 3; ++k) {
            if (q[k] < gr->lo[k]) gr->lo[k] = q[k];
            if (q[k] > gr->hi[k]) gr->hi[k] = q[k];
        }
        ++finite;
    }
    *nan_skipped = skipped;
    if (finite == 0) return 0;
    gr->cell = h;
    /* Cap the cell count (h tiny against the extent): larger cells stay correct, only slower. */
    for (;;) {
        double cells = 1;
        for (int k = 0; k < 3; ++k) {
            gr->dim[k] = (int)floor((gr->hi[k] - gr->lo[k]) / gr->cell) + 1;
            cells *= gr->dim[k];
        }
        if (cells <= (double)(1u << 22)) break;
        gr->cell *= 2;
    }
    size_t ncell = (size_t)gr->dim[0] * gr->dim[1] * gr->dim[2];
    gr->start = calloc(ncell + 1, sizeof *gr->start);
    gr->items = malloc((finite ? finite : 1) * sizeof *gr->items);
    if (!gr->start || !gr->items) return -1;
    uint32_t *cellof = malloc((size_t)n * sizeof *cellof);
    if (!cellof) return -1;
    for (uint32_t j = 0; j < n; ++j) {
        if (!finite3(x[j], y[j], z[j])) { cellof[j] = UINT32_MAX; continue; }
        double q[3] = {x[j], y[j], z[j]};
        int c[3];
        for (int k = 0; k < 3; ++k) {
            c[k] = (int)floor((q[k] - gr->lo[k]) / gr->cell);
            if (c[k] >= gr->dim[k]) c[k] = gr->dim[k] - 1;
        }
        cellof[j] = (uint32_t)((c[2] * gr->dim[1] + c[1]) * gr->dim[0] + c[0]);
        gr->start[cellof[j] + 1]++;
    }
    for (size_t c = 0; c < ncell; ++c) gr->start[c + 1] += gr->start[c];
    uint32_t *fill = malloc((ncell + 1) * sizeof *fill);
    if (!fill) { free(cellof); return -1; }
    memcpy(fill, gr->start, (ncell + 1) * sizeof *fill);
    for (uint32_t j = 0; j < n; ++j)
        if (cellof[j] != UINT32_MAX) gr->items[fill[cellof[j]]++] = j;
    free(fill);
    free(cellof);
    return 0;
}

static void grid_free(ref_grid *gr)
{
    free(gr->start);
    free(gr->items);
}

static double grid_field(const ref_grid *gr, const float *x, const float *y, const float *z,
                         const ref_water_params *p, const double pos[3], double grad[3])
{
    double sum = 0, g[3] = {0, 0, 0};
    if (gr->start) {
        int c[3];
        for (int k = 0; k < 3; ++k) c[k] = (int)floor((pos[k] - gr->lo[k]) / gr->cell);
        for (int dz = -1; dz <= 1; ++dz) {
            int cz = c[2] + dz;
            if (cz < 0 || cz >= gr->dim[2]) continue;
            for (int dy = -1; dy <= 1; ++dy) {
                int cy = c[1] + dy;
                if (cy < 0 || cy >= gr->dim[1]) continue;
                for (int dx = -1; dx <= 1; ++dx) {
                    int cx = c[0] + dx;
                    if (cx < 0 || cx >= gr->dim[0]) continue;
                    size_t cell = ((size_t)cz * gr->dim[1] + cy) * gr->dim[0] + cx;
                    accumulate(x, y, z, gr->items + gr->start[cell],
                               gr->start[cell + 1] - gr->start[cell], p, pos, &sum,
                               grad ? g : NULL);
                }
            }
        }
    }
    double v = field_from_sum(sum, p, grad ? g : NULL);
    if (grad) memcpy(grad, g, sizeof g);
    return v;
}

/* Ray against the box [lo - h, hi + h]: entry/exit distances, 0 when the eye is inside. */
static int ray_box(const double o[3], const double d[3], const double lo[3], const double hi[3],
                   double pad, double *t0, double *t1)
{
    double a = 0, b = INFINITY;
    for (int k = 0; k < 3; ++k) {
        double l = lo[k] - pad, u = hi[k] + pad;
        if (fabs(d[k]) < 1e-300) {
            if (o[k] < l || o[k] > u) return 0;
            continue;
        }
        double ta = (l - o[k]) / d[k], tb = (u - o[k]) / d[k];
        if (ta > tb) { double s = ta; ta = tb; tb = s; }
        if (ta > a) a = ta;
        if (tb < b) b = tb;
    }
    *t0 = a;
    *t1 = b;
    return a <= b;
}

int ref_water_render(const ref_water_camera *cam, const float *x, const float *y,
                         const float *z, uint32_t n, const ref_water_params *p, float *dist,
                         float *normal, ref_water_stats *stats, char err[256])
{
    ref_water_stats st = {0, 0, 0};
    if (!cam || !p || !dist || cam->width == 0 || cam->height == 0 || !(cam->fov_y > 0) ||
        !(cam->fov_y < 3.1)) {
        snprintf(err, 256, "water_ref_render: bad camera (width %u height %u fov_y %g)",
                 cam ? cam->width : 0, cam ? cam->height : 0, cam ? cam->fov_y : 0.0);
        return -1;
    }
    if (!(p->h > 0) || !isfinite(p->h) || !(p->threshold > 0) || !p->kernel.value ||
        !p->kernel.deriv || p->step < 0) {
        snprintf(err, 256, "water_ref_render: bad params (h %g, T %g, step %g)", p->h,
                 p->threshold, p->step);
        return -1;
    }
    if (n > 0 && (!x || !y || !z)) {
        snprintf(err, 256, "water_ref_render: %u particles but a NULL column", n);
        return -1;
    }
    double step = p->step > 0 ? p->step : p->h / 32.0;
    /* the farthest a particle's kernel reaches: h / the smallest eigenvalue of its G */
    double reach = p->h;
    for (uint32_t j = 0; p->G && j < n; ++j) {
        double ev[3], V[9];
        ref_water_eigen_sym3(p->G + 6 * (size_t)j, ev, V);
        if (ev[0] > 0 && p->h / ev[0] > reach) reach = p->h / ev[0];
    }
    ref_grid gr;
    if (grid_build(&gr, x, y, z, n, reach, &st.nan_skipped) != 0) {
        grid_free(&gr);
        snprintf(err, 256, "water_ref_render: out of memory for the grid of %u particles", n);
        return -1;
    }
    size_t npix = (size_t)cam->width * cam->height;
    for (size_t k = 0; k < npix; ++k) dist[k] = -1.0f;
    if (normal) memset(normal, 0, 3 * npix * sizeof *normal);
    for (uint32_t j = 0; j < cam->height && gr.start; ++j) {
        for (uint32_t i = 0; i < cam->width; ++i) {
            double d[3], t0, t1;
            ref_water_pixel_dir(cam, i, j, d);
            if (!ray_box(cam->eye, d, gr.lo, gr.hi, reach, &t0, &t1)) continue;
            if (p->t_max > 0 && t1 > p->t_max) t1 = p->t_max;
            double tprev = t0, fprev = 0, thit = -1;
            for (double t = t0; t <= t1 + step; t += step) {
                double tt = t > t1 ? t1 : t;
                double q[3] = {cam->eye[0] + tt * d[0], cam->eye[1] + tt * d[1], cam->eye[2] + tt * d[2]};
                double f = grid_field(&gr, x, y, z, p, q, NULL);
                st.samples++;
                if (f >= 0) {
                    if (tt == t0) { thit = t0; break; } /* eye inside (or on) the fluid */
                    double a = tprev, b = tt, fa = fprev;
                    (void)fa;
                    for (int it = 0; it < 60 && b - a > 1e-12 * (1 + b); ++it) {
                        double m = 0.5 * (a + b);
                        double qm[3] = {cam->eye[0] + m * d[0], cam->eye[1] + m * d[1], cam->eye[2] + m * d[2]};
                        st.samples++;
                        if (grid_field(&gr, x, y, z, p, qm, NULL) >= 0) b = m; else a = m;
                    }
                    thit = 0.5 * (a + b);
                    break;
                }
                tprev = tt;
                fprev = f;
                if (tt >= t1) break;
            }
            if (thit < 0) continue;
            size_t pix = (size_t)j * cam->width + i;
            dist[pix] = (float)thit;
            st.hits++;
            if (normal) {
                double q[3] = {cam->eye[0] + thit * d[0], cam->eye[1] + thit * d[1], cam->eye[2] + thit * d[2]};
                double g[3];
                grid_field(&gr, x, y, z, p, q, g);
                double nn[3] = {-g[0], -g[1], -g[2]};
                normalize3(nn);
                for (int k = 0; k < 3; ++k) normal[3 * pix + k] = (float)nn[k];
            }
        }
    }
    grid_free(&gr);
    if (stats) *stats = st;
    return 0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int ref_water_compare(const float *dist, const float *normal, const float *ref_dist,
                          const float *ref_normal, size_t n, double h, ref_water_error *out)
{
    memset(out, 0, sizeof *out);
    double *de = malloc((n ? n : 1) * sizeof *de), *ne = malloc((n ? n : 1) * sizeof *ne);
    if (!de || !ne) { free(de); free(ne); return -1; }
    size_t holes = 0, false_hits = 0, ref_miss = 0, both = 0;
    for (size_t k = 0; k < n; ++k) {
        int rh = ref_dist[k] >= 0, gh = dist[k] >= 0;
        if (rh) out->ref_hits++; else ref_miss++;
        if (rh && !gh) holes++;
        if (!rh && gh) false_hits++;
        if (rh && gh) {
            de[both] = fabs((double)dist[k] - ref_dist[k]) / h;
            ne[both] = 0;
            if (normal && ref_normal) {
                double c = 0, la = 0, lb = 0;
                for (int i = 0; i < 3; ++i) {
                    c += (double)normal[3 * k + i] * ref_normal[3 * k + i];
                    la += (double)normal[3 * k + i] * normal[3 * k + i];
                    lb += (double)ref_normal[3 * k + i] * ref_normal[3 * k + i];
                }
                double cc = (la > 0 && lb > 0) ? c / sqrt(la * lb) : -1;
                if (cc > 1) cc = 1;
                if (cc < -1) cc = -1;
                ne[both] = acos(cc) * 180.0 / 3.14159265358979323846;
            }
            both++;
        }
    }
    out->both_hit = (uint32_t)both;
    out->hole_rate = out->ref_hits ? (double)holes / out->ref_hits : 0;
    out->false_hit_rate = ref_miss ? (double)false_hits / ref_miss : 0;
    if (both) {
        double sd = 0, sn = 0;
        for (size_t k = 0; k < both; ++k) { sd += de[k]; sn += ne[k]; }
        out->dist_mean_rel_h = sd / both;
        out->normal_mean_deg = sn / both;
        qsort(de, both, sizeof *de, cmp_double);
        qsort(ne, both, sizeof *ne, cmp_double);
        size_t q = (size_t)ceil(0.99 * both) - 1;
        out->dist_p99_rel_h = de[q];
        out->normal_p99_deg = ne[q];
    }
    free(de);
    free(ne);
    return 0;
}

void ref_water_layers(uint32_t n, double spacing, float *x, float *y, float *z)
{
    for (uint32_t k = 0; k < n; ++k) {
        uint32_t layer = k / 576, in = k % 576;
        x[k] = (float)(((double)(in % 24) - 11.5) * spacing);
        z[k] = (float)(((double)(in / 24) - 11.5) * spacing);
        y[k] = (float)(layer * spacing);
    }
}

/* splitmix64: a local state, no globals. */
static uint64_t next_u64(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static double next_unit(uint64_t *s) { return ((next_u64(s) >> 11) + 0.5) * (1.0 / 9007199254740992.0); }

void ref_water_blobs(uint32_t n, uint32_t blobs, double extent, double sigma, uint64_t seed,
                         float *x, float *y, float *z)
{
    uint64_t s = seed;
    if (blobs == 0) blobs = 1;
    for (uint32_t k = 0; k < n; ++k) {
        uint32_t b = k % blobs;
        uint64_t cs = seed ^ (0xabcdef12345ull * (b + 1));
        double c[3];
        for (int i = 0; i < 3; ++i) c[i] = (2 * next_unit(&cs) - 1) * extent;
        double g[3];
        for (int i = 0; i < 3; ++i) { /* Box-Muller */
            double u1 = next_unit(&s), u2 = next_unit(&s);
            g[i] = sqrt(-2 * log(u1)) * cos(2 * 3.14159265358979323846 * u2);
        }
        x[k] = (float)(c[0] + sigma * g[0]);
        y[k] = (float)(c[1] + sigma * g[1]);
        z[k] = (float)(c[2] + sigma * g[2]);
    }
}

void ref_water_eigen_sym3(const double a[6], double ev[3], double V[9])
{
    double A[3][3] = {{a[0], a[1], a[2]}, {a[1], a[3], a[4]}, {a[2], a[4], a[5]}};
    double Q[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int sweep = 0; sweep < 64; ++sweep) {
        double off = fabs(A[0][1]) + fabs(A[0][2]) + fabs(A[1][2]);
        double diag = fabs(A[0][0]) + fabs(A[1][1]) + fabs(A[2][2]);
        if (!(off > 1e-300) || off <= 1e-18 * diag) break;
        for (int p = 0; p < 2; ++p)
            for (int q = p + 1; q < 3; ++q) {
                if (A[p][q] == 0.0) continue;
                double th = (A[q][q] - A[p][p]) / (2.0 * A[p][q]);
                double t = (th >= 0 ? 1.0 : -1.0) / (fabs(th) + sqrt(th * th + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 3; ++k) {
                    double akp = A[k][p], akq = A[k][q];
                    A[k][p] = c * akp - s * akq;
                    A[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; ++k) {
                    double apk = A[p][k], aqk = A[q][k];
                    A[p][k] = c * apk - s * aqk;
                    A[q][k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 3; ++k) {
                    double qkp = Q[k][p], qkq = Q[k][q];
                    Q[k][p] = c * qkp - s * qkq;
                    Q[k][q] = s * qkp + c * qkq;
                }
            }
    }
    int o[3] = {0, 1, 2}; /* ascending */
    for (int i = 0; i < 3; ++i)
        for (int j = i + 1; j < 3; ++j)
            if (A[o[j]][o[j]] < A[o[i]][o[i]]) { int t = o[i]; o[i] = o[j]; o[j] = t; }
    for (int i = 0; i < 3; ++i) {
        ev[i] = A[o[i]][o[i]];
        for (int k = 0; k < 3; ++k) V[3 * k + i] = Q[k][o[i]];
    }
}

void ref_water_aniso_kernels(const float *x, const float *y, const float *z, uint32_t n,
                             const ref_water_aniso_params *p, double *centre, double *G, uint32_t *nbrs)
{
    double R = p->radius * p->h, R2 = R * R;
    for (uint32_t i = 0; i < n; ++i) {
        double pi[3] = {x[i], y[i], z[i]};
        double axes[3] = {1, 1, 1}, V[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        uint32_t nb = 0;
        for (int k = 0; k < 3; ++k) centre[3 * (size_t)i + k] = pi[k];
        if (finite3(x[i], y[i], z[i])) {
            double W = 0, s1[3] = {0, 0, 0}, s2[6] = {0, 0, 0, 0, 0, 0};
            for (uint32_t j = 0; j < n; ++j) { /* brute force: every particle */
                if (!finite3(x[j], y[j], z[j])) continue;
                double d[3] = {(double)x[j] - pi[0], (double)y[j] - pi[1], (double)z[j] - pi[2]};
                double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                if (!(r2 < R2)) continue;
                double r = sqrt(r2) / R, w = 1.0 - r * r * r;
                W += w;
                for (int k = 0; k < 3; ++k) s1[k] += w * d[k];
                s2[0] += w * d[0] * d[0]; s2[1] += w * d[0] * d[1]; s2[2] += w * d[0] * d[2];
                s2[3] += w * d[1] * d[1]; s2[4] += w * d[1] * d[2]; s2[5] += w * d[2] * d[2];
                if (j != i) ++nb;
            }
            double m[3] = {s1[0] / W, s1[1] / W, s1[2] / W};
            for (int k = 0; k < 3; ++k) centre[3 * (size_t)i + k] = pi[k] + p->smoothing * m[k];
            if (nb >= p->min_neighbours) {
                double C[6] = {s2[0] / W - m[0] * m[0], s2[1] / W - m[0] * m[1], s2[2] / W - m[0] * m[2],
                               s2[3] / W - m[1] * m[1], s2[4] / W - m[1] * m[2], s2[5] / W - m[2] * m[2]};
                double ev[3];
                ref_water_eigen_sym3(C, ev, V);
                double e1 = ev[2];
                if (e1 > 1e-12 * R2) {
                    double s[3], prod = 1;
                    for (int k = 0; k < 3; ++k) { s[k] = ev[k] > e1 / p->max_stretch ? ev[k] : e1 / p->max_stretch; prod *= s[k]; }
                    for (int k = 0; k < 3; ++k) axes[k] = s[k] / cbrt(prod) * p->scale;
                } else {
                    for (int k = 0; k < 9; ++k) V[k] = k % 4 == 0;
                }
            }
        }
        if (nbrs) nbrs[i] = nb;
        /* G = V diag(1 / axes) V^T */
        double *g = G + 6 * (size_t)i;
        int idx[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
        for (int e = 0; e < 6; ++e) {
            double acc = 0;
            for (int k = 0; k < 3; ++k) acc += V[3 * idx[e][0] + k] * V[3 * idx[e][1] + k] / axes[k];
            g[e] = acc;
        }
    }
}
