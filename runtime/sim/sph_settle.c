/* sph_settle.c — a fresh block settled into the solver's own equilibrium before frame 0.
 *
 * The calibrated lattice is at rho0 everywhere, but neither solver holds a fluid at rho0: each
 * needs its hydrostatic compression (PBF: ~0.8% mean on the default pool, from its fixed
 * iteration count), and PBF's free top layer, sitting straight on the one below, rolls into its
 * hollows. Started from the lattice the pool sinks into that state at up to 0.8-1 m/s
 * (docs/simulation.md "Start at rest"). Damped steps do the same sinking before frame 0; the
 * clock is held, so the colliders stay at their rest pose and the scene's time starts at 0; the
 * emitters do not run. */
#include "sim/sph_collide.h"
#include "core/error.h"

#include <time.h>

/* The process's CPU seconds (all threads), for the settle reports. */
static double process_cpu_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* The desc checked (refused naming `who`) and its zero fields given the defaults. */
static vfx_result settle_resolve(const rt_sph_settle_desc *desc, rt_sph_settle_desc *d, const char *who, char *err,
                                 size_t errlen)
{
    *d = desc ? *desc : (rt_sph_settle_desc){0};
    if (!(d->step_dt >= 0.f) || !isfinite(d->step_dt) || !(d->damping >= 0.f && d->damping <= 1.f) ||
        !(d->speed_tol >= 0.f) || !isfinite(d->speed_tol)) {
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "%s: step_dt %g, damping %g or speed_tol "
                       "%g out of range (finite, >= 0; damping <= 1)", who, (double)d->step_dt,
                       (double)d->damping, (double)d->speed_tol);
    }
    d->max_steps = d->max_steps ? d->max_steps : 120u;
    d->step_dt = d->step_dt > 0.f ? d->step_dt : 1.f / 60.f;
    d->damping = d->damping > 0.f ? d->damping : 0.9f;
    d->speed_tol = d->speed_tol > 0.f ? d->speed_tol : 0.03f;
    d->progress_every = d->progress_every ? d->progress_every : 20u;
    return VFX_OK;
}

vfx_result rt_sph_settle_run(rt_sph *s, const char *who, const rt_sph_settle_desc *desc, const rt_sph_settle_ops *ops,
                             rt_sph_settle_report *rep, char *err, size_t errlen)
{
    rt_sph_settle_desc d;
    rt_sph_settle_report out = {0};
    vfx_result r = settle_resolve(desc, &d, who, err, errlen);
    if (r != VFX_OK)
        return r;
    const double t_start = s->time, c0 = process_cpu_s();
    for (uint32_t k = 0; k < d.max_steps && *ops->count; ++k) {
        /* the step's constraints hold at s->time + dt: held at the start time */
        s->time = t_start - d.step_dt;
        rt_sph_report sr;
        if ((r = ops->step(ops->solver, d.step_dt, &sr, err, errlen)))
            break;
        out.steps = k + 1;
        out.max_speed_last = sr.max_speed;
        out.compression = sr.mean_density_error;
        if (k == 0)
            out.max_speed_first = sr.max_speed;
        const bool done = sr.max_speed < d.speed_tol || k + 1 == d.max_steps;
        ops->damp(ops->solver, done || d.quasi_static ? 0.f : d.damping, &sr);
        if (d.progress && (k == 0 || (k + 1) % d.progress_every == 0 || done))
            d.progress(d.user, k + 1, d.max_steps, sr.max_speed, sr.mean_density_error);
        if (done)
            break;
    }
    s->time = t_start;
    rt_sph_update_colliders(s, t_start);
    out.cpu_s = process_cpu_s() - c0;
    if (rep)
        *rep = out;
    return r;
}

static vfx_result cpu_step(void *s, float dt, rt_sph_report *rep, char *err, size_t errlen)
{
    return rt_sph_step(s, dt, rep, err, errlen);
}

static void cpu_damp(void *solver, float factor, const rt_sph_report *rep)
{
    (void)rep;
    rt_sph *s = solver;
    for (uint32_t i = 0; i < s->n; ++i)
        s->vx[i] *= factor, s->vy[i] *= factor, s->vz[i] *= factor;
}

vfx_result rt_sph_settle(rt_sph *s, const rt_sph_settle_desc *desc, rt_sph_settle_report *rep, char *err,
                         size_t errlen)
{
    if (rep)
        *rep = (rt_sph_settle_report){0};
    if (!s)
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_settle: NULL solver");
    const uint32_t nem = s->nem; /* the emitters wait for frame 0 */
    s->nem = 0;
    const rt_sph_settle_ops ops = {cpu_step, cpu_damp, s, &s->n};
    vfx_result r = rt_sph_settle_run(s, "rt_sph_settle", desc, &ops, rep, err, errlen);
    s->nem = nem;
    return r;
}
