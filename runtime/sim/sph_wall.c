/* sph_wall.c — semi-analytic walls: the closed-form kernel integrals beyond a plane, the
 * smooth-wall law of the wall, and the wall terms the density and force passes add. */
#include "sim/sph_collide.h"
#include "sim/sph_wall.h"

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

/* ---- walls near a particle ----------------------------------------------------------------- */

int rt_sph_gather_walls(const rt_sph *s, float px, float py, float pz, sph_wall_hit *w, int max)
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
        if (sph_collider_beyond(&s->col[c], px, py, pz, s->H))
            continue;
        float n[3];
        float d = rt_sph_surface_distance(&s->col[c], px, py, pz, n);
        if (d < s->H) {
            w[k] = (sph_wall_hit){{n[0], n[1], n[2]}, d, {s->col[c].vel[0], s->col[c].vel[1], s->col[c].vel[2]},
                                  false, s->col[c].c.no_slip != 0};
            k++;
        }
    }
    return k;
}

void rt_sph_wall_accel(const rt_sph *s, const float p[3], const float vel[3], float pri, float rhoi,
                    float a[3], sph_wall_hit *walls)
{
    const float H = s->H, h = s->h, alpha = s->p.viscosity, c0 = s->c0, rho0 = s->p.rest_density;
    const float vxi = vel[0], vyi = vel[1], vzi = vel[2];
    float ax = a[0], ay = a[1], az = a[2];
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
     * Measured in a resting column (docs/simulation-wcsph.md): the earlier single-sided form
     * p_i/rho_i^2 read +58% in the wall layer and +26% overall; (1) without the image
     * viscosity pumped energy into a resting tank; (2) alone compressed the wall layer. */
    int nw = rt_sph_gather_walls(s, p[0], p[1], p[2], walls, SPH_MAX_WALLS);
    int nb = sph_walls_box(walls, nw);
    float fr[SPH_MAX_WALLS], gr[SPH_MAX_WALLS]; /* density fraction, its gradient */
    float inside, extra;
    sph_wall_share(s, walls, nw, fr, &inside, &extra);
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
    a[0] = ax, a[1] = ay, a[2] = az;
}
