/* sph_pbf.c — Position Based Fluids (Macklin & Mueller 2013) on the WCSPH solver's columns,
 * neighbour lists, walls and worker pool: a step predicts positions under gravity, finds the
 * neighbours once (Verlet walk or rebuild), then projects the density constraints
 * C_i = rho_i/rho0 - 1 >= 0 by a fixed number of Jacobi iterations, and derives the
 * velocities from the moved positions; XSPH viscosity and (optional) vorticity confinement
 * act on the velocities after. Every pass is a gather over fixed lists, so with a fixed
 * iteration count the result does not depend on the thread count.
 *
 * The multipliers start from zero in every iteration (the paper's scheme) and are projected
 * (lambda <= 0: the constraint only pushes, so the deficient density at a free surface does not
 * pull particles together). The Jacobi update is damped by the constraint-force mixing eps
 * (pbf_relaxation, a fraction of the lattice's sum |grad C|^2): at 0.05 of it the iteration
 * amplified the highest-frequency modes (measured, docs/simulation-pbf.md).
 *
 * The iterates are accelerated by Chebyshev semi-iteration (Wang 2015, for PBD's Jacobi):
 * x_k+1 = omega_k+1 (Jacobi(x_k) - x_k-1) + x_k-1, from the second iteration on, with the weights
 * of an assumed spectral radius (pbf_chebyshev_rho). Its only state is the iterate before the
 * current one, which the ping-pong buffers already hold, so it costs one multiply-add per
 * particle and iteration; 5 accelerated iterations compress the default pool less than the old
 * 6 plain ones (docs/simulation-pbf.md, "Chebyshev acceleration").
 *
 * RT_SPH_PBF_WARM_START (an experiment, off by default): each particle keeps its pressure p_i
 * between steps in pr (Pa; lambda_i = -p_i dt^2 / rho0), a step first applies the correction of
 * last step's pressures, and a fresh fluid starts from the hydrostatic rho0 |g| depth. Measured
 * unstable with 3 iterations (the carried pressure acts as an integral of the compression). */
#include "sim/sph_collide.h"
#include "sim/sph_simd.h"
#include "sim/sph_wall.h"
#include "core/error.h"

#include <stdlib.h>
#include <string.h>

/* ---- parameters ---------------------------------------------------------------------------- */

static void pbf_calibrate(rt_sph *s)
{
    /* sum_j |grad_j C_i|^2 = sum_j (V ks (H - r)^2)^2 on the lattice the solver fills blocks
     * with (the gradient sum itself vanishes there): the scale of the constraint's stiffness,
     * which the mixing eps and the s_corr amplitude are given relative to */
    const double dx = s->p.spacing, V = s->mass / s->p.rest_density, H = s->H;
    int R = (int)ceil(s->p.support_ratio) + 1;
    double D = 0.0;
    for (int i = -R; i <= R; ++i)
        for (int j = -R; j <= R; ++j)
            for (int k = -R; k <= R; ++k) {
                double r = sqrt((double)(i * i + j * j + k * k)) * dx;
                if (r <= 0.0 || r >= H)
                    continue;
                double g = V * s->k_spiky * (H - r) * (H - r);
                D += g * g;
            }
    s->pbf_D0 = (float)D;
    s->pbf_eps = s->p.pbf_relaxation * (float)D;
    double dq = s->p.pbf_scorr_dq * H, t = H * H - dq * dq;
    s->pbf_wdq = (float)(t * t * t);
}

/* ---- wall terms ------------------------------------------------------------------------------ */

/* The walls' share of the density constraint at p: rho0 * (missing fraction) in *wall_rho, the
 * gradient of the missing fraction (grad C_i from the walls) in g, and 1 / (the kernel's
 * fraction inside the fluid, held at 0.2) in *inv_gam. */
static void pbf_walls(const rt_sph *s, float px, float py, float pz, float *wall_rho, float g[3],
                      float *inv_gam)
{
    sph_wall_hit w[SPH_MAX_WALLS];
    float fr[SPH_MAX_WALLS], inside, extra;
    int nw = rt_sph_gather_walls(s, px, py, pz, w, SPH_MAX_WALLS);
    g[0] = g[1] = g[2] = 0.f;
    *inv_gam = 1.f;
    if (!nw) {
        *wall_rho = 0.f;
        return;
    }
    sph_wall_share(s, w, nw, fr, &inside, &extra);
    *wall_rho = s->p.rest_density * (1.f - inside + extra);
    float gam = inside - extra;
    *inv_gam = gam > 0.2f ? 1.f / gam : 5.f;
    int nb = sph_walls_box(w, nw);
    for (int k = 0; k < nw; ++k) {
        /* box walls through 1 - prod(1 - f): d/dx = sum_k prod_{l != k} (1 - f_l) df_k/dx */
        float others = 1.f;
        if (k < nb)
            for (int l = 0; l < nb; ++l)
                if (l != k)
                    others *= 1.f - fr[l];
        /* f falls with the distance d, which grows along the normal n into the fluid */
        float gr = others * s->wall_scale * (float)rt_sph_wall_density_gradient(w[k].d, s->H);
        g[0] -= gr * w[k].n[0], g[1] -= gr * w[k].n[1], g[2] -= gr * w[k].n[2];
    }
}

/* Moves p out of every collider and the domain box to the clamp margin (positions only). */
void rt_sph_pbf_clamp(const rt_sph *s, float p[3])
{
    const float margin = 0.25f * s->p.spacing;
    for (uint32_t c = 0; c < s->ncol; ++c) {
        if (sph_collider_beyond(&s->col[c], p[0], p[1], p[2], margin))
            continue;
        float n[3];
        float d = rt_sph_surface_distance(&s->col[c], p[0], p[1], p[2], n);
        if (d < margin)
            for (int a = 0; a < 3; ++a)
                p[a] += (margin - d) * n[a];
    }
    const float *lo = s->p.domain_min, *hi = s->p.domain_max;
    for (int a = 0; a < 3; ++a)
        p[a] = sph_clampf(p[a], lo[a] + margin, hi[a] - margin);
}

/* The walls' terms during the iterations: evaluated once per step, in the first iteration's
 * lambda pass at the predicted position x0 (s->x..), kept in the scratch columns tmp (wall density)
 * and ax..az (its gradient, free until the viscosity pass), and carried to the iterate x to first
 * order, wall_rho(x) = wall_rho(x0) + rho0 grad . (x - x0). The iterations move a particle by a
 * fraction of a spacing, where the wall integrals are smooth; evaluating them in every pass of
 * every iteration was 19% of PBF's instructions (callgrind, default pool). The warm-start
 * experiment, whose first correction runs before any lambda pass, evaluates them every time.
 * Inlined into both pair passes: as a call it took 10% of PBF's cycles for 4% of its
 * instructions (perf, default pool, 1 thread); inlined, the frame's median CPU fell ~5%. */
static inline __attribute__((always_inline)) void pbf_walls_iter(rt_sph *s, uint32_t i, float px, float py,
                                                                 float pz, bool lambda_pass, float *wall_rho,
                                                                 float g[3])
{
    float ig;
    if (__builtin_expect((s->p.flags & RT_SPH_PBF_WARM_START) != 0, 0)) {
        pbf_walls(s, px, py, pz, wall_rho, g, &ig);
        return;
    }
    if (lambda_pass && s->pbf_iter == 0) {
        pbf_walls(s, px, py, pz, wall_rho, g, &ig);
        s->tmp[i] = *wall_rho, s->ax[i] = g[0], s->ay[i] = g[1], s->az[i] = g[2];
        return;
    }
    g[0] = s->ax[i], g[1] = s->ay[i], g[2] = s->az[i];
    float w = s->tmp[i];
    if (w != 0.f || g[0] != 0.f || g[1] != 0.f || g[2] != 0.f) {
        w += s->p.rest_density * (g[0] * (px - s->x[i]) + g[1] * (py - s->y[i]) + g[2] * (pz - s->z[i]));
        w = w > 0.f ? w : 0.f;
    }
    *wall_rho = w;
}

/* ---- passes ---------------------------------------------------------------------------------- */

/* v += dt g (speed held at the limit), x += dt v, clamped to the walls with v following the
 * clamp; displacement since the last rebuild. */
static void pbf_predict_chunk(rt_sph *s, uint32_t chunk)
{
    uint32_t b, e;
    sph_chunk_rows(s, chunk, &b, &e);
    const float dt = s->pbf_dt, inv_dt = 1.f / dt, *g = s->p.gravity;
    const float vlim = s->p.velocity_limit, vlim2 = vlim * vlim;
    sph_chunk_out acc = s->out[chunk];
    float disp2 = 0.f;
    for (uint32_t i = b; i < e; ++i) {
        float v[3] = {s->vx[i] + dt * g[0], s->vy[i] + dt * g[1], s->vz[i] + dt * g[2]};
        float v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        if (!isfinite(v2)) {
            v[0] = v[1] = v[2] = 0.f;
            if (acc.bad == UINT32_MAX)
                acc.bad = i, acc.bad_kind = 1, acc.bad_value = v2;
        } else if (v2 > vlim2) {
            float k = vlim / sqrtf(v2);
            v[0] *= k, v[1] *= k, v[2] *= k;
            acc.clamped++;
        }
        float p[3] = {s->x[i] + dt * v[0], s->y[i] + dt * v[1], s->z[i] + dt * v[2]}, q[3] = {p[0], p[1], p[2]};
        rt_sph_pbf_clamp(s, q);
        for (int a = 0; a < 3; ++a)
            v[a] += (q[a] - p[a]) * inv_dt;
        s->x[i] = q[0], s->y[i] = q[1], s->z[i] = q[2];
        s->vx[i] = v[0], s->vy[i] = v[1], s->vz[i] = v[2];
        float ex = q[0] - s->x0[i], ey = q[1] - s->y0[i], ez = q[2] - s->z0[i];
        float d2 = ex * ex + ey * ey + ez * ez;
        disp2 = d2 > disp2 ? d2 : disp2;
    }
    acc.disp2_max = disp2;
    s->out[chunk] = acc;
}

/* The constraint of each particle at the current iterate: density (particles and walls), its
 * gradients, and the multiplier's change; the pressure follows (projected: p >= 0). */
static void pbf_lambda_chunk(rt_sph *s, uint32_t chunk)
{
    uint32_t b, e;
    sph_chunk_rows(s, chunk, &b, &e);
    const float H = s->H, H2 = s->H2, eps2 = 1e-12f * H2, rho0 = s->p.rest_density;
    const float Vks = s->mass / rho0 * s->k_spiky, mk = s->mass * s->k_poly6;
    const float dt2 = s->pbf_dt * s->pbf_dt, to_l = dt2 / rho0, eps = s->pbf_eps_step;
    const bool warm = (s->p.flags & RT_SPH_PBF_WARM_START) != 0;
    const float *X = s->pc[0], *Y = s->pc[1], *Z = s->pc[2];
    /* the position pass's pair terms, when it reads them (sph_pbf_lin.c) */
    const bool store = s->pbf_store;
    float *PE[3] = {NULL, NULL, NULL};
    if (store)
        rt_sph_pbf_pair_arrays(s, chunk, PE);
    sph_chunk_out acc = s->out[chunk];
    for (uint32_t i = b; i < e; ++i) {
        const float px = X[i], py = Y[i], pz = Z[i];
        const uint32_t off = s->nb_start[i];
        const uint32_t *L = s->cnb[chunk] + off;
        const uint32_t nn = s->nb_count[i];
        float sw = H2 * H2 * H2, gx = 0.f, gy = 0.f, gz = 0.f, g2 = 0.f;
        uint32_t k = 0, coincident = 0;
#if SPH_SSE
        {
            const __m128 vpx = _mm_set1_ps(px), vpy = _mm_set1_ps(py), vpz = _mm_set1_ps(pz);
            const __m128 vH = _mm_set1_ps(H), vH2 = _mm_set1_ps(H2), veps = _mm_set1_ps(eps2);
            const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.f);
            __m128 w4 = zero, gx4 = zero, gy4 = zero, gz4 = zero, g24 = zero;
            for (; k + 4 <= nn; k += 4) {
                uint32_t j0 = L[k], j1 = L[k + 1], j2 = L[k + 2], j3 = L[k + 3];
                __m128 dx = vpx - _mm_setr_ps(X[j0], X[j1], X[j2], X[j3]);
                __m128 dy = vpy - _mm_setr_ps(Y[j0], Y[j1], Y[j2], Y[j3]);
                __m128 dz = vpz - _mm_setr_ps(Z[j0], Z[j1], Z[j2], Z[j3]);
                __m128 r2 = dx * dx + dy * dy + dz * dz;
                __m128 t = _mm_max_ps(vH2 - r2, zero);
                w4 += t * t * t;
                __m128 valid = _mm_cmpgt_ps(r2, veps);
                coincident += (0x4332322132212110ull >> (4 * (~_mm_movemask_ps(valid) & 15))) & 15u;
                __m128 rl = _mm_sqrt_ps(r2), hr = _mm_max_ps(vH - rl, zero);
                __m128 hr2 = hr * hr;
                __m128 q = _mm_and_ps(valid, hr2 * (one / rl)); /* |G_ij| / (Vks r) */
                __m128 qx = q * dx, qy = q * dy, qz = q * dz;    /* G_ij / Vks */
                gx4 += qx, gy4 += qy, gz4 += qz;
                g24 += _mm_and_ps(valid, hr2 * hr2);
                if (store) {
                    _mm_storeu_ps(PE[0] + off + k, qx), _mm_storeu_ps(PE[1] + off + k, qy);
                    _mm_storeu_ps(PE[2] + off + k, qz);
                }
            }
            sw += sph_hsum(w4);
            gx = -sph_hsum(gx4), gy = -sph_hsum(gy4), gz = -sph_hsum(gz4), g2 = sph_hsum(g24);
        }
#endif
        const uint32_t coincident4 = coincident; /* of the stored pairs */
        for (; k < nn; ++k) {
            uint32_t j = L[k];
            float dx = px - X[j], dy = py - Y[j], dz = pz - Z[j];
            float r2 = dx * dx + dy * dy + dz * dz;
            float t = H2 - r2 > 0.f ? H2 - r2 : 0.f;
            sw += t * t * t;
            if (r2 > eps2) {
                float rl = sqrtf(r2), hr = H - rl > 0.f ? H - rl : 0.f, q = hr * hr / rl;
                gx -= q * dx, gy -= q * dy, gz -= q * dz;
                g2 += hr * hr * hr * hr;
            } else {
                coincident++;
            }
        }
        for (uint32_t k2 = 0; coincident && k2 < nn; ++k2) {
            uint32_t j = L[k2];
            float dx = px - X[j], dy = py - Y[j], dz = pz - Z[j];
            if (!(dx * dx + dy * dy + dz * dz <= eps2))
                continue;
            float u[3];
            rt_sph_coincident_dir(s->id[i], s->id[j], u); /* (H - 0)^2 along a fixed axis */
            gx -= H * H * u[0], gy -= H * H * u[1], gz -= H * H * u[2];
            g2 += H * H * H * H;
            coincident--;
        }
        float wall_rho, gw[3];
        pbf_walls_iter(s, i, px, py, pz, true, &wall_rho, gw);
        if (store)
            rt_sph_pbf_store_particle(s, i, coincident4);
        float rho = mk * sw + wall_rho;
        float Gx = Vks * gx + gw[0], Gy = Vks * gy + gw[1], Gz = Vks * gz + gw[2];
        /* the paper's denominator |grad_i C_i|^2 + sum_j |grad_j C_i|^2 + eps: grad_i C_i . A_i
         * (i's own move per unit multiplier) can be near zero or negative at a wall */
        float D = Gx * Gx + Gy * Gy + Gz * Gz + Vks * Vks * g2 + eps;
        float C = rho / rho0 - 1.f;
        float l_old = warm ? -s->pr[i] * to_l : 0.f;
        float l_new = l_old - C / D;
        l_new = l_new < 0.f ? l_new : 0.f; /* pressure >= 0: the constraint only pushes */
        s->drho[i] = l_new - l_old;        /* this iteration's multiplier */
        s->pr[i] = -l_new / to_l;
        s->rho[i] = rho;
        float err = C;
        if (err > acc.rho_err_max)
            acc.rho_err_max = err;
        if (!isfinite(rho) && acc.bad == UINT32_MAX)
            acc.bad = i, acc.bad_kind = 1, acc.bad_value = rho;
    }
    s->out[chunk] = acc;
}

typedef struct pbf_delta_args {
    const float *lam; /* multipliers (scaled by lam_scale) */
    float lam_scale;
    bool scorr;
    bool stored;      /* the lambda pass's pair terms (no s_corr, lam_scale 1): sph_pbf_lin.c */
} pbf_delta_args;

/* Position correction of each particle from the multipliers (this iteration's, or the warm
 * start's pressures): dp_i = -sum_j (l_i + l_j + s_corr) G_ij d_ij + l_i grad C_wall, written
 * to the next iterate, clamped to the walls. */
static void pbf_delta(rt_sph *s, uint32_t chunk, const pbf_delta_args *a)
{
    uint32_t b, e;
    sph_chunk_rows(s, chunk, &b, &e);
    const float H = s->H, H2 = s->H2, eps2 = 1e-12f * H2, rho0 = s->p.rest_density;
    const float Vks = s->mass / rho0 * s->k_spiky, ls = a->lam_scale;
    const float maxd = 0.5f * s->H;
    /* s_corr = -k (W(r)/W(dq))^4, as a multiplier: k in units of the lattice's 1/D0 */
    const float sk = a->scorr ? s->p.pbf_scorr_k / s->pbf_D0 : 0.f, iwdq = 1.f / s->pbf_wdq;
    const float *X = s->pc[0], *Y = s->pc[1], *Z = s->pc[2], *Lm = a->lam;
    float *NX = s->pn[0], *NY = s->pn[1], *NZ = s->pn[2];
    float *PE[3] = {NULL, NULL, NULL};
    if (a->stored)
        rt_sph_pbf_pair_arrays(s, chunk, PE);
    for (uint32_t i = b; i < e; ++i) {
        const float px = X[i], py = Y[i], pz = Z[i], li = ls * Lm[i];
        const uint32_t off = s->nb_start[i];
        const uint32_t *L = s->cnb[chunk] + off;
        const uint32_t nn = s->nb_count[i];
        float sx = 0.f, sy = 0.f, sz = 0.f;
        uint32_t k = 0, coincident = 0;
#if SPH_SSE
        if (a->stored) {
            /* the same operations on the lambda pass's stored gradients q_ij d_ij (q masked to 0
             * for coincident pairs, counted there): bitwise the sums below, without the position
             * gathers, the square root and the division; s_corr is off here (sk = 0) */
            const float *GX = PE[0] + off, *GY = PE[1] + off, *GZ = PE[2] + off;
            const __m128 vli = _mm_set1_ps(li), zero = _mm_setzero_ps();
            __m128 sx4 = zero, sy4 = zero, sz4 = zero;
            for (; k + 4 <= nn; k += 4) {
                __m128 lj = _mm_setr_ps(Lm[L[k]], Lm[L[k + 1]], Lm[L[k + 2]], Lm[L[k + 3]]);
                __m128 coef = vli + lj;
                sx4 += coef * _mm_loadu_ps(GX + k), sy4 += coef * _mm_loadu_ps(GY + k), sz4 += coef * _mm_loadu_ps(GZ + k);
            }
            sx = sph_hsum(sx4), sy = sph_hsum(sy4), sz = sph_hsum(sz4);
            coincident = rt_sph_pbf_stored_coincident(s, i);
        } else {
            const __m128 vpx = _mm_set1_ps(px), vpy = _mm_set1_ps(py), vpz = _mm_set1_ps(pz);
            const __m128 vH = _mm_set1_ps(H), vH2 = _mm_set1_ps(H2), veps = _mm_set1_ps(eps2);
            const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.f), vli = _mm_set1_ps(li);
            const __m128 vls = _mm_set1_ps(ls), vsk = _mm_set1_ps(sk), viw = _mm_set1_ps(iwdq);
            __m128 sx4 = zero, sy4 = zero, sz4 = zero;
            for (; k + 4 <= nn; k += 4) {
                uint32_t j0 = L[k], j1 = L[k + 1], j2 = L[k + 2], j3 = L[k + 3];
                __m128 dx = vpx - _mm_setr_ps(X[j0], X[j1], X[j2], X[j3]);
                __m128 dy = vpy - _mm_setr_ps(Y[j0], Y[j1], Y[j2], Y[j3]);
                __m128 dz = vpz - _mm_setr_ps(Z[j0], Z[j1], Z[j2], Z[j3]);
                __m128 lj = vls * _mm_setr_ps(Lm[j0], Lm[j1], Lm[j2], Lm[j3]);
                __m128 r2 = dx * dx + dy * dy + dz * dz;
                __m128 valid = _mm_cmpgt_ps(r2, veps);
                coincident += (0x4332322132212110ull >> (4 * (~_mm_movemask_ps(valid) & 15))) & 15u;
                __m128 t = _mm_max_ps(vH2 - r2, zero);
                __m128 w = t * t * t * viw, w2 = w * w;
                __m128 rl = _mm_sqrt_ps(r2), hr = _mm_max_ps(vH - rl, zero);
                __m128 q = _mm_and_ps(valid, hr * hr * (one / rl));
                __m128 coef = vli + lj - vsk * w2 * w2; /* times G_ij / Vks, as the stored path */
                sx4 += coef * (q * dx), sy4 += coef * (q * dy), sz4 += coef * (q * dz);
            }
            sx = sph_hsum(sx4), sy = sph_hsum(sy4), sz = sph_hsum(sz4);
        }
#endif
        for (; k < nn; ++k) {
            uint32_t j = L[k];
            float dx = px - X[j], dy = py - Y[j], dz = pz - Z[j];
            float r2 = dx * dx + dy * dy + dz * dz;
            if (!(r2 > eps2)) {
                coincident++;
                continue;
            }
            float t = H2 - r2 > 0.f ? H2 - r2 : 0.f;
            float w = t * t * t * iwdq, w2 = w * w;
            float rl = sqrtf(r2), hr = H - rl > 0.f ? H - rl : 0.f;
            float coef = (li + ls * Lm[j] - sk * w2 * w2) * hr * hr / rl;
            sx += coef * dx, sy += coef * dy, sz += coef * dz;
        }
        for (uint32_t k2 = 0; coincident && k2 < nn; ++k2) {
            uint32_t j = L[k2];
            float dx = px - X[j], dy = py - Y[j], dz = pz - Z[j];
            if (!(dx * dx + dy * dy + dz * dz <= eps2))
                continue;
            float u[3];
            rt_sph_coincident_dir(s->id[i], s->id[j], u);
            float coef = (li + ls * Lm[j] - sk) * H * H;
            sx += coef * u[0], sy += coef * u[1], sz += coef * u[2];
            coincident--;
        }
        /* the walls through i's own constraint only (the paper's dp_i = l_i grad_i C_i +
         * sum_j l_j grad_i C_j: a wall has no constraint of its own). Measured against the
         * wall as a mirror image (2 l_i) over the kernel's fluid share, as sph_wall_accel does
         * for WCSPH: 4,281 against 828 of 17,484 particles faster than 0.1 m/s after 2 s of a
         * resting pool (docs/simulation-pbf.md) */
        float wall_rho, gw[3];
        pbf_walls_iter(s, i, px, py, pz, false, &wall_rho, gw);
        (void)wall_rho;
        float d[3] = {-Vks * sx + li * gw[0], -Vks * sy + li * gw[1], -Vks * sz + li * gw[2]};
        float dl = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (dl > maxd) /* only in collapsed inputs (many particles on one point) */
            for (int q = 0; q < 3; ++q)
                d[q] *= maxd / dl;
        float p[3] = {px + d[0], py + d[1], pz + d[2]};
        if (s->cheb_omega != 1.f) { /* Chebyshev: from the iterate before this one */
            const float w = s->cheb_omega;
            p[0] = w * (p[0] - s->cheb_prev[0][i]) + s->cheb_prev[0][i];
            p[1] = w * (p[1] - s->cheb_prev[1][i]) + s->cheb_prev[1][i];
            p[2] = w * (p[2] - s->cheb_prev[2][i]) + s->cheb_prev[2][i];
        }
        if (!a->stored || rt_sph_pbf_may_reach_wall(s, i, p))
            rt_sph_pbf_clamp(s, p);
        NX[i] = p[0], NY[i] = p[1], NZ[i] = p[2];
    }
}

static void pbf_delta_chunk(rt_sph *s, uint32_t chunk)
{
    pbf_delta_args a = {s->drho, 1.f, !(s->p.flags & RT_SPH_PBF_NO_SCORR) && s->p.pbf_scorr_k > 0.f, false};
    pbf_delta(s, chunk, &a);
}

/* The same from the pair terms the lambda pass stored (s->pbf_store). */
static void pbf_delta_store_chunk(rt_sph *s, uint32_t chunk)
{
    pbf_delta_args a = {s->drho, 1.f, false, true};
    pbf_delta(s, chunk, &a);
}

static void pbf_warm_chunk(rt_sph *s, uint32_t chunk)
{
    /* lambda = -p dt^2 / rho0 */
    pbf_delta_args a = {s->pr, -s->pbf_dt * s->pbf_dt / s->p.rest_density, false, false};
    pbf_delta(s, chunk, &a);
}

/* v += (x_final - x_predicted) / dt, x = x_final (speed held at the limit). */
static void pbf_finish_chunk(rt_sph *s, uint32_t chunk)
{
    uint32_t b, e;
    sph_chunk_rows(s, chunk, &b, &e);
    const float inv_dt = 1.f / s->pbf_dt, vlim = s->p.velocity_limit, vlim2 = vlim * vlim;
    const float *PX = s->pc[0], *PY = s->pc[1], *PZ = s->pc[2];
    sph_chunk_out acc = s->out[chunk];
    for (uint32_t i = b; i < e; ++i) {
        float v[3] = {s->vx[i] + (PX[i] - s->x[i]) * inv_dt, s->vy[i] + (PY[i] - s->y[i]) * inv_dt,
                      s->vz[i] + (PZ[i] - s->z[i]) * inv_dt};
        float v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        if (!isfinite(v2) || !isfinite(PX[i] + PY[i] + PZ[i])) {
            /* keep the predicted (finite) position at rest */
            s->vx[i] = s->vy[i] = s->vz[i] = 0.f;
            if (acc.bad == UINT32_MAX)
                acc.bad = i, acc.bad_kind = 1, acc.bad_value = v2;
            continue;
        }
        if (v2 > vlim2) {
            float k = vlim / sqrtf(v2);
            v[0] *= k, v[1] *= k, v[2] *= k;
            acc.clamped++;
        }
        s->x[i] = PX[i], s->y[i] = PY[i], s->z[i] = PZ[i];
        s->vx[i] = v[0], s->vy[i] = v[1], s->vz[i] = v[2];
    }
    s->out[chunk] = acc;
}

/* Wall-law friction of the no-slip walls (the shear of sph_wall_accel) as a velocity change
 * over dt, never beyond stopping the particle relative to the wall. */
static void pbf_friction(const rt_sph *s, float px, float py, float pz, float v[3])
{
    sph_wall_hit w[SPH_MAX_WALLS];
    float fr[SPH_MAX_WALLS], inside, extra;
    int nw = rt_sph_gather_walls(s, px, py, pz, w, SPH_MAX_WALLS);
    if (!nw)
        return;
    sph_wall_share(s, w, nw, fr, &inside, &extra);
    for (int k = 0; k < nw; ++k) {
        if (!w[k].no_slip)
            continue;
        const float *wv = w[k].vel, *wn = w[k].n;
        float rx = v[0] - wv[0], ry = v[1] - wv[1], rz = v[2] - wv[2];
        float vn = rx * wn[0] + ry * wn[1] + rz * wn[2];
        float tx = rx - vn * wn[0], ty = ry - vn * wn[1], tz = rz - vn * wn[2];
        float ut = sqrtf(tx * tx + ty * ty + tz * tz);
        if (!(ut > 0.f))
            continue;
        float y = w[k].d > 0.25f * s->p.spacing ? w[k].d : 0.25f * s->p.spacing;
        float us = (float)rt_sph_wall_friction_velocity(ut, y, s->p.kinematic_viscosity);
        float gr = (float)rt_sph_wall_density_gradient(w[k].d, s->H);
        float dv = s->pbf_dt * us * us * s->fric_scale * gr;
        float f = dv < ut ? dv / ut : 1.f;
        v[0] -= f * tx, v[1] -= f * ty, v[2] -= f * tz;
    }
}

/* At the final positions: density (for the report and the columns), XSPH viscosity
 * v_i += c sum_j V (v_j - v_i) W_ij, the vorticity omega_i = sum_j V v_ij x grad_j W_ij (for the
 * confinement pass) and the no-slip walls' friction; the new velocities go to pn. */
static void pbf_visc_chunk(rt_sph *s, uint32_t chunk)
{
    uint32_t b, e;
    sph_chunk_rows(s, chunk, &b, &e);
    const float H = s->H, H2 = s->H2, eps2 = 1e-12f * H2, rho0 = s->p.rest_density;
    const float V = s->mass / rho0, mk = s->mass * s->k_poly6, ks = s->k_spiky;
    const float c = (s->p.flags & RT_SPH_PBF_NO_XSPH) ? 0.f : s->p.pbf_xsph;
    const bool vort = s->p.pbf_vorticity > 0.f;
    const float *X = s->x, *Y = s->y, *Z = s->z, *VX = s->vx, *VY = s->vy, *VZ = s->vz;
    sph_chunk_out acc = s->out[chunk];
    for (uint32_t i = b; i < e; ++i) {
        const float px = X[i], py = Y[i], pz = Z[i], vxi = VX[i], vyi = VY[i], vzi = VZ[i];
        const uint32_t *L = s->cnb[chunk] + s->nb_start[i];
        const uint32_t nn = s->nb_count[i];
        float sw = H2 * H2 * H2, ux = 0.f, uy = 0.f, uz = 0.f, wx = 0.f, wy = 0.f, wz = 0.f;
        uint32_t k = 0;
#if SPH_SSE
        if (!vort) {
            const __m128 vpx = _mm_set1_ps(px), vpy = _mm_set1_ps(py), vpz = _mm_set1_ps(pz);
            const __m128 vvx = _mm_set1_ps(vxi), vvy = _mm_set1_ps(vyi), vvz = _mm_set1_ps(vzi);
            const __m128 vH2 = _mm_set1_ps(H2), zero = _mm_setzero_ps();
            __m128 w4 = zero, ux4 = zero, uy4 = zero, uz4 = zero;
            for (; k + 4 <= nn; k += 4) {
                uint32_t j0 = L[k], j1 = L[k + 1], j2 = L[k + 2], j3 = L[k + 3];
                __m128 dx = vpx - _mm_setr_ps(X[j0], X[j1], X[j2], X[j3]);
                __m128 dy = vpy - _mm_setr_ps(Y[j0], Y[j1], Y[j2], Y[j3]);
                __m128 dz = vpz - _mm_setr_ps(Z[j0], Z[j1], Z[j2], Z[j3]);
                __m128 r2 = dx * dx + dy * dy + dz * dz;
                __m128 t = _mm_max_ps(vH2 - r2, zero), w = t * t * t;
                w4 += w;
                ux4 += (_mm_setr_ps(VX[j0], VX[j1], VX[j2], VX[j3]) - vvx) * w;
                uy4 += (_mm_setr_ps(VY[j0], VY[j1], VY[j2], VY[j3]) - vvy) * w;
                uz4 += (_mm_setr_ps(VZ[j0], VZ[j1], VZ[j2], VZ[j3]) - vvz) * w;
            }
            sw += sph_hsum(w4), ux = sph_hsum(ux4), uy = sph_hsum(uy4), uz = sph_hsum(uz4);
        }
#endif
        for (; k < nn; ++k) {
            uint32_t j = L[k];
            float dx = px - X[j], dy = py - Y[j], dz = pz - Z[j];
            float r2 = dx * dx + dy * dy + dz * dz;
            float t = H2 - r2 > 0.f ? H2 - r2 : 0.f, w = t * t * t;
            float dvx = VX[j] - vxi, dvy = VY[j] - vyi, dvz = VZ[j] - vzi;
            sw += w;
            ux += dvx * w, uy += dvy * w, uz += dvz * w;
            if (vort && r2 > eps2) {
                /* grad_j W_ij = +ks (H - r)^2 d / r, d = x_i - x_j */
                float rl = sqrtf(r2), hr = H - rl > 0.f ? H - rl : 0.f, q = hr * hr / rl;
                float gx = q * dx, gy = q * dy, gz = q * dz;
                wx += dvy * gz - dvz * gy, wy += dvz * gx - dvx * gz, wz += dvx * gy - dvy * gx;
            }
        }
        float wall_rho, gw[3], ig;
        pbf_walls(s, px, py, pz, &wall_rho, gw, &ig);
        float rho = mk * sw + wall_rho;
        s->rho[i] = rho;
        const float cw = c * V * s->k_poly6;
        float v[3] = {vxi + cw * ux, vyi + cw * uy, vzi + cw * uz};
        if (s->friction)
            pbf_friction(s, px, py, pz, v);
        s->pn[0][i] = v[0], s->pn[1][i] = v[1], s->pn[2][i] = v[2];
        if (vort) {
            s->ax[i] = V * ks * wx, s->ay[i] = V * ks * wy, s->az[i] = V * ks * wz;
            s->tmp[i] = sqrtf(s->ax[i] * s->ax[i] + s->ay[i] * s->ay[i] + s->az[i] * s->az[i]);
        }
        float err = (rho - rho0) / rho0;
        if (err > acc.rho_err_max)
            acc.rho_err_max = err;
        if (err > 0.f)
            acc.rho_err_sum += err;
        acc.pairs += nn;
    }
    s->out[chunk] = acc;
}

/* v = the new velocities (+ dt eps N x omega with vorticity confinement, N = eta/|eta|,
 * eta = sum_j V |omega_j| grad_i W_ij); energies and the largest speed. */
static void pbf_commit_chunk(rt_sph *s, uint32_t chunk)
{
    uint32_t b, e;
    sph_chunk_rows(s, chunk, &b, &e);
    const float H = s->H, H2 = s->H2, eps2 = 1e-12f * H2, m = s->mass;
    const float V = m / s->p.rest_density, ks = s->k_spiky, ve = s->p.pbf_vorticity * s->pbf_dt;
    const bool vort = s->p.pbf_vorticity > 0.f;
    const float *g = s->p.gravity, *lo = s->p.domain_min;
    sph_chunk_out acc = s->out[chunk];
    double ke = 0.0, pe = 0.0;
    for (uint32_t i = b; i < e; ++i) {
        float v[3] = {s->pn[0][i], s->pn[1][i], s->pn[2][i]};
        if (vort) {
            const uint32_t *L = s->cnb[chunk] + s->nb_start[i];
            float ex = 0.f, ey = 0.f, ez = 0.f;
            for (uint32_t k = 0; k < s->nb_count[i]; ++k) {
                uint32_t j = L[k];
                float dx = s->x[i] - s->x[j], dy = s->y[i] - s->y[j], dz = s->z[i] - s->z[j];
                float r2 = dx * dx + dy * dy + dz * dz;
                if (!(r2 > eps2))
                    continue;
                float rl = sqrtf(r2), hr = H - rl > 0.f ? H - rl : 0.f, q = -s->tmp[j] * hr * hr / rl;
                ex += q * dx, ey += q * dy, ez += q * dz;
            }
            float el = sqrtf(ex * ex + ey * ey + ez * ez);
            if (el > 0.f) {
                (void)V, (void)ks; /* |eta| normalises: V ks drop out */
                float nx = ex / el, ny = ey / el, nz = ez / el;
                const float ox = s->ax[i], oy = s->ay[i], oz = s->az[i];
                v[0] += ve * (ny * oz - nz * oy), v[1] += ve * (nz * ox - nx * oz), v[2] += ve * (nx * oy - ny * ox);
            }
        }
        s->vx[i] = v[0], s->vy[i] = v[1], s->vz[i] = v[2];
        float v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        if (v2 > acc.v2_max)
            acc.v2_max = v2;
        ke += 0.5 * (double)m * v2;
        pe -= (double)m * (g[0] * (s->x[i] - lo[0]) + g[1] * (s->y[i] - lo[1]) + g[2] * (s->z[i] - lo[2]));
    }
    acc.ke = ke, acc.pe = pe;
    s->out[chunk] = acc;
}

/* pr gathered in the sorted order of the last rebuild (tmp as the target). */
static void pbf_permute_pr_chunk(rt_sph *s, uint32_t chunk)
{
    uint32_t b, e;
    sph_chunk_rows(s, chunk, &b, &e);
    for (uint32_t i = b; i < e; ++i)
        s->tmp[i] = s->pr[s->perm[i]];
}

/* ---- a step ----------------------------------------------------------------------------------- */

/* Pressures of rows without one: the hydrostatic rho0 |g| depth below the highest particle of
 * the same column (a fresh fluid: every row) or 0 (rows added to a running fluid). */
static void pbf_init_pressure(rt_sph *s)
{
    uint32_t from = s->pbf_valid <= s->n ? s->pbf_valid : 0;
    if (from >= s->n) {
        s->pbf_valid = s->n;
        return;
    }
    const float *g = s->p.gravity;
    float gl = sqrtf(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    for (uint32_t i = from; i < s->n; ++i)
        s->pr[i] = 0.f;
    if (from == 0 && gl > 0.f) {
        int a = fabsf(g[0]) >= fabsf(g[1]) && fabsf(g[0]) >= fabsf(g[2]) ? 0 : (fabsf(g[1]) >= fabsf(g[2]) ? 1 : 2);
        int u = (a + 1) % 3, w = (a + 2) % 3;
        float up = g[a] < 0.f ? 1.f : -1.f, c = s->p.spacing;
        const float *lo = s->p.domain_min, *hi = s->p.domain_max;
        float *P[3] = {s->x, s->y, s->z};
        double nu = ceil((hi[u] - lo[u]) / c), nw = ceil((hi[w] - lo[w]) / c);
        while (nu * nw > (double)(1u << 22))
            c *= 2.f, nu = ceil((hi[u] - lo[u]) / c), nw = ceil((hi[w] - lo[w]) / c);
        int NU = (int)nu, NW = (int)nw;
        float *top = malloc((size_t)NU * (size_t)NW * sizeof *top);
        if (top) { /* out of memory: zero pressures, the iterations build them up */
            for (size_t q = 0; q < (size_t)NU * (size_t)NW; ++q)
                top[q] = -INFINITY;
            for (uint32_t i = 0; i < s->n; ++i) {
                size_t q = (size_t)sph_cell_coord(P[u][i], lo[u], 1.f / c, NU) * (size_t)NW +
                           (size_t)sph_cell_coord(P[w][i], lo[w], 1.f / c, NW);
                float h = up * P[a][i];
                top[q] = h > top[q] ? h : top[q];
            }
            for (uint32_t i = 0; i < s->n; ++i) {
                size_t q = (size_t)sph_cell_coord(P[u][i], lo[u], 1.f / c, NU) * (size_t)NW +
                           (size_t)sph_cell_coord(P[w][i], lo[w], 1.f / c, NW);
                s->pr[i] = s->p.rest_density * gl * (top[q] - up * P[a][i]);
            }
            free(top);
        }
    }
    s->pbf_valid = s->n;
}

/* Neighbours at the current (predicted) positions: a rebuild (sort, cell scan recording the
 * Verlet lists; pressures follow the sort) when a particle has moved half the skin since the
 * last one, else a Verlet walk; both write the exact lists (r < H) the iterations walk. */
static vfx_result pbf_neighbours(rt_sph *s, rt_sph_report *rep, char *err, size_t errlen)
{
    bool rebuild = !s->verlet || !s->lists_valid || !(4.f * s->disp2_max < s->skin * s->skin);
    if (rebuild) {
        vfx_result r = rt_sph_build_grid(s, err, errlen);
        if (r)
            return r;
        rt_sph_parallel(s, pbf_permute_pr_chunk, false);
        float *t = s->pr;
        s->pr = s->tmp, s->tmp = t;
        rep->neighbor_rebuilds++;
        s->dens_mode = s->verlet ? 1 : 0;
    } else {
        s->dens_mode = 2;
    }
    /* the lists alone: every pass after this evaluates its own density (the WCSPH density
     * pass's sum, wall terms and EOS were 2% of PBF's instructions, callgrind) */
    rt_sph_parallel(s, rt_sph_lists_chunk, true);
    if (s->verlet && rebuild) {
        s->lists_valid = !atomic_load(&s->nb_oom);
        s->disp2_max = 0.f;
    }
    if (atomic_exchange(&s->nb_oom, false)) {
        s->lists_valid = false;
        return rt_errf(err, errlen, VFX_ERR_OUT_OF_MEMORY,
                       "rt_sph_step: out of memory for the neighbour lists of %u particles", s->n);
    }
    for (uint32_t c = 0; c < sph_chunk_count(s); ++c)
        rep->skin_pairs += s->out[c].skin_pairs;
    return VFX_OK;
}

/* The value the first bad row reported (NaN or Inf). */
static float pbf_bad_value(const rt_sph *s)
{
    for (uint32_t c = 0; c < sph_chunk_count(s); ++c)
        if (s->out[c].bad != UINT32_MAX)
            return s->out[c].bad_value;
    return NAN;
}

static uint32_t pbf_first_bad(const rt_sph *s)
{
    for (uint32_t c = 0; c < sph_chunk_count(s); ++c)
        if (s->out[c].bad != UINT32_MAX)
            return s->out[c].bad;
    return UINT32_MAX;
}

/* The mixing eps of a call of frame_dt: pbf_relaxation D0 at pbf_max_step and above, and
 * (pbf_max_step / frame_dt)^2 times that below it. A fixed iteration count removes a fixed
 * fraction of the compression per step, so without the scaling a shorter step makes a stiffer
 * fluid whose rest state is less compressed: a pool at rest from steps of 1/60 s released its
 * 1.3% in one step of 1e-5 s, 2 mm per particle over 1e-5 s, and flew at 190 m/s. With eps ~
 * 1/dt^2 (a compliance fixed in physical units, as XPBD's alpha / dt^2) the rest compression
 * and the velocities the corrections make do not depend on the call's dt. The call's CFL
 * substeps keep its eps: they stiffen a fast flow, as before (scaled per substep, the dam
 * break's mean compression went from 1.1% to 13%). docs/simulation-pbf.md, "Step length". */
static float pbf_step_eps(const rt_sph *s, float dt)
{
    const float ref = s->p.pbf_max_step;
    if (!(dt < ref))
        return s->pbf_eps;
    /* held at 1e6 (a step of 1.7e-8 s at the default): below, no correction is representable */
    const float k = ref / dt < 1e6f ? ref / dt : 1e6f;
    return s->pbf_eps * k * k;
}

/* Wang 2015's weight of iteration it (0-based) from the one before: omega_1 = 1, omega_2 =
 * 2 / (2 - rho^2), omega_k+1 = 4 / (4 - rho^2 omega_k). */
static float pbf_chebyshev_next(float rho2, uint32_t it, float omega)
{
    return it == 0 ? 1.f : it == 1 ? 2.f / (2.f - rho2) : 4.f / (4.f - rho2 * omega);
}

void rt_sph_pbf_constants(rt_sph *s, float frame_dt, float *D0, float *eps, float *wdq)
{
    if (s->pbf_D0 == 0.f)
        pbf_calibrate(s);
    *D0 = s->pbf_D0, *eps = pbf_step_eps(s, frame_dt), *wdq = s->pbf_wdq;
}

float rt_sph_chebyshev_weight(float rho, uint32_t k)
{
    float omega = 1.f;
    for (uint32_t it = 0; it < k; ++it)
        omega = pbf_chebyshev_next(rho * rho, it, omega);
    return omega;
}

static vfx_result pbf_substep(rt_sph *s, float dt, rt_sph_report *rep, char *err, size_t errlen)
{
    s->pbf_dt = dt;
    s->cheb_omega = 1.f;
    /* the position pass reads the lambda pass's pair terms (sph_pbf_lin.c) unless asked not to,
     * or for the warm-start experiment (its first correction has no lambda pass before it) or
     * the artificial pressure (its per-pair W is not stored) */
    s->pbf_store = !(s->p.flags & (RT_SPH_PBF_RECOMPUTE | RT_SPH_PBF_WARM_START)) &&
                   !(!(s->p.flags & RT_SPH_PBF_NO_SCORR) && s->p.pbf_scorr_k > 0.f);
    rt_sph_update_colliders(s, s->time + dt); /* the constraints hold at the end of the step */
    rt_sph_parallel(s, pbf_predict_chunk, true);
    uint32_t nch = sph_chunk_count(s);
    float d2 = 0.f;
    for (uint32_t c = 0; c < nch; ++c) {
        d2 = s->out[c].disp2_max > d2 ? s->out[c].disp2_max : d2;
        rep->speed_clamped += s->out[c].clamped;
    }
    s->disp2_max = d2;
    vfx_result r = pbf_neighbours(s, rep, err, errlen);
    if (r)
        return r;
    /* iterates: the predicted positions, then xn.. and vxn.. in turn */
    float *bufA[3] = {s->xn, s->yn, s->zn}, *bufB[3] = {s->vxn, s->vyn, s->vzn};
    float *cur[3] = {s->x, s->y, s->z};
    int next_is_a = 1;
    memcpy(s->pc, cur, sizeof cur);
    if (s->p.flags & RT_SPH_PBF_WARM_START) {
        memcpy(s->pn, bufA, sizeof bufA);
        rt_sph_parallel(s, pbf_warm_chunk, false);
        memcpy(s->pc, bufA, sizeof bufA);
        next_is_a = 0;
    }
    if (s->pbf_store && (r = rt_sph_pbf_lin_reserve(s, err, errlen)))
        return r;
    /* Chebyshev weights (Wang 2015): omega_1 = 1, omega_2 = 2 / (2 - rho^2), omega_k+1 =
     * 4 / (4 - rho^2 omega_k); x_k+1 = omega (Jacobi(x_k) - x_k-1) + x_k-1 */
    const float rho2 = (s->p.flags & RT_SPH_PBF_NO_CHEBYSHEV) ? 0.f : s->p.pbf_chebyshev_rho * s->p.pbf_chebyshev_rho;
    float omega = 1.f;
    float *prev[3] = {s->x, s->y, s->z};
    for (uint32_t it = 0; it < s->p.pbf_iterations; ++it) {
        s->pbf_iter = it;
        rt_sph_parallel(s, pbf_lambda_chunk, true);
        memcpy(s->pn, next_is_a ? bufA : bufB, sizeof bufA);
        omega = rho2 == 0.f ? 1.f : pbf_chebyshev_next(rho2, it, omega);
        s->cheb_omega = omega;
        memcpy(s->cheb_prev, prev, sizeof prev);
        memcpy(prev, s->pc, sizeof prev);
        rt_sph_parallel(s, s->pbf_store ? pbf_delta_store_chunk : pbf_delta_chunk, false);
        memcpy(s->pc, s->pn, sizeof s->pc);
        next_is_a = !next_is_a;
        rep->iterations++;
    }
    s->cheb_omega = 1.f;
    rt_sph_parallel(s, pbf_finish_chunk, false);
    uint32_t bad = pbf_first_bad(s);
    for (uint32_t c = 0; c < nch; ++c)
        rep->speed_clamped += s->out[c].clamped;
    /* the velocities after viscosity into the free iterate buffer */
    memcpy(s->pn, next_is_a ? bufA : bufB, sizeof bufA);
    rt_sph_parallel(s, pbf_visc_chunk, true);
    rt_sph_parallel(s, pbf_commit_chunk, false);
    if (bad == UINT32_MAX)
        bad = pbf_first_bad(s);
    if (bad != UINT32_MAX) {
        return rt_errf(err, errlen, VFX_ERR_NUMERIC, "rt_sph_step: particle %u (row %u) got a non-finite "
                       "position, velocity or density (%g) at t=%.6g s (PBF, step %.3g s) near (%g, %g, %g); it was "
                       "left at its predicted position, at rest. The projection overflowed there: particles "
                       "closer than float32 resolves (a tank far from the origin) or a step far above the "
                       "spacing's (pbf_cfl)", s->id[bad], bad, (double)pbf_bad_value(s), s->time, (double)dt,
                       (double)s->x[bad], (double)s->y[bad], (double)s->z[bad]);
    }
    return VFX_OK;
}

/* End-state figures from the chunk reductions of the last step's closing passes. */
static void pbf_reduce_report(rt_sph *s, rt_sph_report *rep)
{
    float emax = 0.f, v2 = 0.f;
    double esum = 0.0, ke = 0.0, pe = 0.0;
    uint64_t pairs = 0;
    for (uint32_t c = 0; c < sph_chunk_count(s); ++c) {
        const sph_chunk_out *o = &s->out[c];
        emax = o->rho_err_max > emax ? o->rho_err_max : emax;
        v2 = o->v2_max > v2 ? o->v2_max : v2;
        esum += o->rho_err_sum, ke += o->ke, pe += o->pe, pairs += o->pairs;
    }
    rep->max_density_error = emax;
    rep->mean_density_error = s->n ? (float)(esum / s->n) : 0.f;
    rep->max_speed = sqrtf(v2);
    rep->kinetic_energy = ke;
    rep->potential_energy = pe;
    rep->internal_energy = 0.0;
    rep->neighbor_pairs += pairs;
    s->pbf_vmax = rep->max_speed;
}

/* A call without steps: the densities and energies of the state as it is. */
static vfx_result pbf_state_report(rt_sph *s, rt_sph_report *rep, char *err, size_t errlen)
{
    vfx_result r = pbf_neighbours(s, rep, err, errlen);
    if (r)
        return r;
    float *A[3] = {s->xn, s->yn, s->zn};
    memcpy(s->pn, A, sizeof A);
    s->pbf_dt = 1.f; /* no friction applies: the velocities are not kept */
    bool fr = s->friction;
    s->friction = false;
    rt_sph_parallel(s, pbf_visc_chunk, true);
    s->friction = fr;
    /* energies without touching the velocities */
    double ke = 0.0, pe = 0.0;
    float v2m = 0.f;
    const float m = s->mass, *g = s->p.gravity, *lo = s->p.domain_min;
    for (uint32_t i = 0; i < s->n; ++i) {
        float v2 = s->vx[i] * s->vx[i] + s->vy[i] * s->vy[i] + s->vz[i] * s->vz[i];
        v2m = v2 > v2m ? v2 : v2m;
        ke += 0.5 * (double)m * v2;
        pe -= (double)m * (g[0] * (s->x[i] - lo[0]) + g[1] * (s->y[i] - lo[1]) + g[2] * (s->z[i] - lo[2]));
    }
    for (uint32_t c = 0; c < sph_chunk_count(s); ++c)
        s->out[c].ke = s->out[c].pe = 0.0, s->out[c].v2_max = 0.f;
    if (s->n)
        s->out[0].ke = ke, s->out[0].pe = pe, s->out[0].v2_max = v2m;
    pbf_reduce_report(s, rep);
    return VFX_OK;
}

vfx_result rt_sph_pbf_step(rt_sph *s, float frame_dt, rt_sph_report *rep, char *err, size_t errlen)
{
    if (s->pbf_D0 == 0.f)
        pbf_calibrate(s);
    /* steps: no longer than pbf_max_step, and no particle moving more than pbf_cfl H in one
     * (the speed at the start plus what gravity adds over the frame) */
    const float *g = s->p.gravity;
    float gl = sqrtf(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]), vmax = 0.f;
    for (uint32_t i = 0; i < s->n; ++i) {
        float v2 = s->vx[i] * s->vx[i] + s->vy[i] * s->vy[i] + s->vz[i] * s->vz[i];
        vmax = v2 > vmax ? v2 : vmax;
    }
    vmax = sqrtf(vmax);
    double steps = ceil((double)frame_dt / s->p.pbf_max_step - 1e-6);
    double cfl = ceil((double)frame_dt * (vmax + gl * frame_dt) / (s->p.pbf_cfl * s->H) - 1e-6);
    if (cfl > steps)
        steps = cfl;
    if (steps > s->p.max_substeps)
        steps = s->p.max_substeps, rep->cap_hit = true;
    uint32_t n = frame_dt > 0.f ? (uint32_t)(steps > 1 ? steps : 1) : 0;
    float dt = n ? frame_dt / (float)n : 0.f;
    rep->dt_min = n ? dt : 0.0;
    rep->dt_max = rep->dt_last = n ? dt : 0.0;
    rep->dt_limit = cfl > ceil((double)frame_dt / s->p.pbf_max_step - 1e-6) ? RT_SPH_DT_CFL : RT_SPH_DT_FRAME;
    s->pbf_eps_step = pbf_step_eps(s, frame_dt);
    vfx_result r = VFX_OK;
    if (s->verlet && s->lists_valid && s->n) {
        rt_sph_parallel(s, rt_sph_disp_chunk, false); /* columns may have been moved by hand */
        float d2 = 0.f;
        for (uint32_t c = 0; c < sph_chunk_count(s); ++c)
            d2 = s->out[c].disp2_max > d2 ? s->out[c].disp2_max : d2;
        s->disp2_max = d2;
    }
    for (uint32_t k = 0; k < n; ++k) {
        if (s->nem && (r = rt_sph_emit(s, k ? dt : 0.0, &rep->emitted, err, errlen)))
            break;
        pbf_init_pressure(s);
        if (s->n && (r = pbf_substep(s, dt, rep, err, errlen)))
            break;
        s->time += dt;
        rep->substeps++;
        rep->simulated_time += dt;
    }
    if (!r && s->n && rep->substeps)
        pbf_reduce_report(s, rep);
    else if (!r && s->n) {
        pbf_init_pressure(s);
        r = pbf_state_report(s, rep, err, errlen);
    }
    return r;
}
