/* sph_step.c — a frame: adaptive substeps (dt selection, the redo loop on a blow-up) and
 * the end-of-frame reductions of the report. */
#include "sim/sph_collide.h"

#include <stdlib.h>

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
 * cells, record the lists. Counts a rebuild in the report; an error when the host could not
 * reorder its rows (then nothing was computed). */
static vfx_result density_pass(rt_sph *s, rt_sph_report *rep, char *err, size_t errlen)
{
    bool rebuild = !s->verlet || !s->lists_valid || !(4.f * s->disp2_max < s->skin * s->skin);
    if (rebuild) {
        vfx_result r = rt_sph_build_grid(s, err, errlen);
        if (r)
            return r;
        rep->neighbor_rebuilds++;
        s->dens_mode = s->verlet ? 1 : 0;
    } else {
        s->dens_mode = 2;
    }
    rt_sph_parallel(s, rt_sph_density_chunk, true);
    if (s->verlet && rebuild) {
        s->lists_valid = !atomic_load(&s->nb_oom);
        s->disp2_max = 0.f;
    }
    return VFX_OK;
}

static void reduce_disp(rt_sph *s)
{
    uint32_t nchunks = sph_chunk_count(s);
    float d2 = 0.f;
    for (uint32_t c = 0; c < nchunks; ++c)
        d2 = s->out[c].disp2_max > d2 ? s->out[c].disp2_max : d2;
    s->disp2_max = d2;
}

/* The closing density pass and the end-state figures of the report. */
static vfx_result finish_report(rt_sph *s, rt_sph_report *rep, char *err, size_t errlen)
{
    vfx_result r = VFX_OK;
    uint32_t nchunks = sph_chunk_count(s);
    float emax = 0.f, v2 = 0.f;
    double esum = 0.0, ke = 0.0, pe = 0.0, ie = 0.0;
    const float m = s->mass;
    const float *g = s->p.gravity, *lo = s->p.domain_min;
    if (s->n) {
        s->want_energy = true;
        r = density_pass(s, rep, err, errlen);
        s->want_energy = false;
        if (atomic_exchange(&s->nb_oom, false))
            s->lists_valid = false; /* the sums below are partial; the next substep says why */
        for (uint32_t c = 0; !r && c < nchunks; ++c) {
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
    return r;
}

/* Maxima of the force pass over the chunks (speed, acceleration, sound speed); the pair
 * counts go to the report. */
static void reduce_forces(const rt_sph *s, rt_sph_report *rep, double *vmax, double *amax, double *cmax)
{
    uint32_t nchunks = sph_chunk_count(s);
    float v2 = 0.f, a2 = 0.f, c2 = 0.f;
    for (uint32_t c = 0; c < nchunks; ++c) {
        const sph_chunk_out *o = &s->out[c];
        v2 = o->v2_max > v2 ? o->v2_max : v2;
        a2 = o->a2_max > a2 ? o->a2_max : a2;
        c2 = o->c2_max > c2 ? o->c2_max : c2;
        rep->neighbor_pairs += o->pairs;
        rep->skin_pairs += o->skin_pairs;
    }
    *vmax = sqrt(v2), *amax = sqrt(a2), *cmax = sqrt(c2);
}

/* The substep's dt: the rest of the frame unless a CFL, acoustic, force or viscous condition
 * is shorter (which one in *lim). */
static double select_dt(const rt_sph *s, double remaining, double vmax, double amax, double cmax,
                        rt_sph_dt_limit *lim)
{
    const double h = s->h, lam = s->p.cfl;
    double dt = remaining;
    *lim = RT_SPH_DT_FRAME;
    double nu = s->p.viscosity * h * s->c0 / 10.0; /* artificial viscosity as nu, 3D */
    if (s->friction && s->p.kinematic_viscosity > nu)
        nu = s->p.kinematic_viscosity; /* keeps the explicit wall shear from overshooting */
    if (vmax > 0 && lam * h / vmax < dt)
        dt = lam * h / vmax, *lim = RT_SPH_DT_CFL;
    if (cmax > 0 && lam * h / cmax < dt)
        dt = lam * h / cmax, *lim = RT_SPH_DT_ACOUSTIC;
    if (amax > 0 && 0.25 * sqrt(h / amax) < dt)
        dt = 0.25 * sqrt(h / amax), *lim = RT_SPH_DT_FORCE;
    if (nu > 0 && 0.125 * h * h / nu < dt)
        dt = 0.125 * h * h / nu, *lim = RT_SPH_DT_VISCOUS;
    /* avoid a sliver substep at the end of the frame */
    if (*lim != RT_SPH_DT_FRAME && remaining < 1.5 * dt && remaining > dt)
        dt = 0.5 * remaining;
    return dt;
}

/* Integrates over *dt into the integration buffers, halving *dt while the result blows up;
 * an error (the state untouched) when it still does after max_redo halvings. */
static vfx_result integrate_redo(rt_sph *s, double *dt, rt_sph_report *rep, char *err,
                                 size_t errlen)
{
    uint32_t nchunks = sph_chunk_count(s);
    for (uint32_t tries = 0;; ++tries) {
        s->dt_try = (float)*dt;
        rt_sph_parallel(s, rt_sph_integrate_chunk, false);
        const sph_chunk_out *bo = NULL;
        uint32_t bad = first_bad(s, nchunks, &bo);
        if (bad == UINT32_MAX)
            return VFX_OK;
        if (bo->bad_kind == 1 || tries >= s->p.max_redo) {
            static const char *what[] = {"", "non-finite state", "speed", "density change"};
            return rt_errf(err, errlen, VFX_ERR_NUMERIC, "rt_sph_step: particle %u (row %u) blew up: %s %g (limit %g) "
                        "after %u dt halvings (dt %.3g s) at t=%.6g s; state left at the "
                        "last good substep", s->id[bad], bad, what[bo->bad_kind],
                        (double)bo->bad_value,
                        bo->bad_kind == 2 ? (double)s->p.velocity_limit
                                          : (double)s->p.density_change_limit,
                        tries, *dt, s->time);
        }
        *dt *= 0.5;
        rep->redo_count++;
    }
}

/* The passes of one substep with particles: density, forces, dt, integration, commit. */
static vfx_result substep(rt_sph *s, double remaining, rt_sph_report *rep, double *dt,
                          rt_sph_dt_limit *lim, char *err, size_t errlen)
{
    vfx_result res = density_pass(s, rep, err, errlen);
    if (res)
        return res;
    if (atomic_exchange(&s->nb_oom, false)) {
        s->lists_valid = false;
        return rt_errf(err, errlen, VFX_ERR_OUT_OF_MEMORY, "rt_sph_step: out of memory for the neighbour lists of %u particles", s->n);
    }
    rt_sph_parallel(s, rt_sph_force_chunk, false);
    const sph_chunk_out *bo = NULL;
    uint32_t bad = first_bad(s, sph_chunk_count(s), &bo);
    if (bad != UINT32_MAX) {
        return rt_errf(err, errlen, VFX_ERR_NUMERIC, "rt_sph_step: particle %u (row %u) has a non-finite density or "
                    "force (%g) at t=%.6g s; state left at the last good substep",
                    s->id[bad], bad, (double)bo->bad_value, s->time);
    }
    double vmax, amax, cmax;
    reduce_forces(s, rep, &vmax, &amax, &cmax);
    *dt = select_dt(s, remaining, vmax, amax, cmax, lim);
    if ((res = integrate_redo(s, dt, rep, err, errlen)))
        return res;
    rt_sph_commit_state(s);
    if (s->verlet)
        reduce_disp(s);
    return VFX_OK;
}

vfx_result rt_sph_step(rt_sph *s, float frame_dt, rt_sph_report *report, char *err, size_t errlen)
{
    rt_sph_report rep = {0};
    if (report)
        *report = rep;
    if (!s)
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_step: NULL solver");
    if (!isfinite(frame_dt) || frame_dt < 0.f) {
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_step: frame_dt %g must be finite and >= 0", (double)frame_dt);
    }
    if (s->p.solver == RT_SPH_SOLVER_PBF) {
        vfx_result pr = rt_sph_pbf_step(s, frame_dt, &rep, err, errlen);
        if (report)
            *report = rep;
        return pr;
    }
    double t = 0.0;
    rep.dt_min = INFINITY;
    vfx_result res = VFX_OK;
    if (s->verlet && s->lists_valid && s->n) {
        /* the columns are writable between steps: measure how far they were moved */
        rt_sph_parallel(s, rt_sph_disp_chunk, false);
        reduce_disp(s);
    }
    while (t < (double)frame_dt * (1.0 - 1e-9)) {
        if (rep.substeps >= s->p.max_substeps) {
            rep.cap_hit = true;
            break;
        }
        if (s->nem) {
            res = rt_sph_emit(s, rep.substeps ? rep.dt_last : 0.0, &rep.emitted, err, errlen);
            if (res)
                break;
        }
        rt_sph_update_colliders(s, s->time);
        double dt = (double)frame_dt - t;
        rt_sph_dt_limit lim = RT_SPH_DT_FRAME;
        if (s->n && (res = substep(s, (double)frame_dt - t, &rep, &dt, &lim, err, errlen)))
            break;
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
    /* a failed step's message stays: the closing pass writes err only when the step succeeded */
    vfx_result fr = finish_report(s, &rep, res ? NULL : err, res ? 0 : errlen);
    if (!res)
        res = fr;
    if (report)
        *report = rep;
    return res;
}
