/* sim_system.c — see sim_system.h. */
#include "sim/sim_system.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <time.h>

#define SIM_NO_TABLE UINT32_MAX
/* The world bumps a table's revision once per component a system declared as written when
 * that system has run (world.c); this system writes position, velocity and density. */
#define SIM_OWN_BUMPS 3u

struct rt_sim_system {
    rt_world *world;
    rt_sph *sph;
    rt_particle_components pc;
    rt_sph_report report;
    /* The table whose columns the solver steps in place, and the revision it will have when
     * nobody else touched it since our last run (anything else: bind again). */
    uint32_t table;
    uint64_t revision;
    bool bound;
    /* the clock (rt_sim_system_set_clock) and the last frame's figures */
    float step_dt;
    uint32_t max_steps;
    double accum;
    rt_sim_stats stats;
    void (*sink)(void *user, const char *name, double value);
    void *sink_user;
    /* rt_sim_system_settle_next: pending until the next run */
    bool settle;
    rt_sph_settle_desc settle_desc;
    rt_logger log;
    /* rt_sim_system_warn_slow: the bound, whether it was said, the settle's start */
    double slow_s;
    bool slow_said;
    double settle_t0;
    char label[96];   /* " (NAME)" of rt_sim_system_set_label, or "" */
    rt_sim_device dev; /* rt_sim_system_set_device (step NULL: none) */
    bool dev_started, ran;
    double origin[3]; /* added to the tank in messages (rt_sim_system_set_label) */
};

static double wall_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Says once, through the logger, that one solver step took `took` wall seconds, above the bound. */
static void warn_slow(rt_sim_system *s, double took, const char *when)
{
    if (s->slow_said || !(s->slow_s > 0.0) || !(took > s->slow_s))
        return;
    s->slow_said = true;
    const rt_sph_desc *p = rt_sph_params(s->sph);
    const float *lo = p->domain_min, *hi = p->domain_max;
    rt_logf(&s->log, VFX_LOG_WARN, "fluid simulation: one solver step of %u particles (spacing %g m) in the tank "
            "[%g, %g, %g]..[%g, %g, %g] took %.3g s %s, above %.3g s: each frame takes up to %u such steps; fewer "
            "particles (a larger spacing) make it faster", rt_sph_get_columns(s->sph).count, (double)p->spacing,
            lo[0] + s->origin[0], lo[1] + s->origin[1], lo[2] + s->origin[2], hi[0] + s->origin[0],
            hi[1] + s->origin[1], hi[2] + s->origin[2], took, when,
            s->slow_s, s->step_dt > 0.f ? s->max_steps : 1u);
}

/* Steps the bound solver over the frame's dt: once, or by the clock's whole steps. */
static vfx_result sim_advance(rt_sim_system *s, float frame_dt, const rt_sph_settle_report *settled, char *err,
                              size_t errlen)
{
    rt_sim_stats st = {.dropped_s = s->stats.dropped_s, .settle_steps = settled->steps, .settle_cpu_s = settled->cpu_s};
    rt_sph_report sum = {0};
    vfx_result r = VFX_OK;
    double t0 = wall_s();
    uint32_t n = 1;
    float dt = frame_dt;
    if (s->step_dt > 0.f) {
        s->accum += frame_dt;
        /* 1e-3 of a step: a frame of step_dt (rounded to float) is one step; the remainder may
         * then be a little negative, which the next frame makes up */
        double k = floor(s->accum / s->step_dt + 1e-3);
        n = k > s->max_steps ? s->max_steps : (uint32_t)k;
        if (k > s->max_steps) {
            st.dropped_s += s->accum - s->max_steps * (double)s->step_dt;
            s->accum = s->max_steps * (double)s->step_dt;
        }
        s->accum -= n * (double)s->step_dt;
        dt = s->step_dt;
    }
    for (uint32_t i = 0; i < n && !r; ++i) {
        rt_sph_report rep;
        double ts = wall_s();
        r = s->dev_started ? s->dev.step(s->dev.user, dt, &rep, err, errlen) : rt_sph_step(s->sph, dt, &rep, err, errlen);
        warn_slow(s, wall_s() - ts, "(wall clock)");
        st.steps += rep.substeps;
        st.iterations += rep.iterations;
        st.simulated_s += rep.simulated_time;
        sum = rep;
        sum.substeps = st.steps;
    }
    if (n == 0) /* no whole step this frame: the state's figures as they are */
        r = s->dev_started ? s->dev.step(s->dev.user, 0.f, &sum, err, errlen) : rt_sph_step(s->sph, 0.f, &sum, err, errlen);
    double wall = wall_s() - t0;
    st.realtime_factor = wall > 0 ? st.simulated_s / wall : 0;
    st.max_speed = sum.max_speed;
    st.density_error = sum.mean_density_error;
    st.device = s->dev_started ? s->dev.id : 0;
    s->report = sum;
    s->stats = st;
    if (s->sink) {
        s->sink(s->sink_user, "sim.steps", st.steps);
        s->sink(s->sink_user, "sim.iterations", st.iterations);
        s->sink(s->sink_user, "sim.realtime_factor", st.realtime_factor);
        s->sink(s->sink_user, "sim.max_speed", st.max_speed);
        s->sink(s->sink_user, "sim.density_error", st.density_error);
        s->sink(s->sink_user, "sim.settle_steps", st.settle_steps);
        s->sink(s->sink_user, "sim.device", st.device);
    }
    return r;
}

/* The columns of `table` (count 0 when it is empty or unknown). */
static void table_columns(rt_sim_system *s, uint32_t table, rt_sph_columns *c)
{
    *c = (rt_sph_columns){0};
    rt_component terms[3] = {s->pc.position, s->pc.velocity, s->pc.density};
    rt_query_iter it = rt_query_begin(s->world, terms, 3);
    while (rt_query_next(&it)) {
        if (it.table != table)
            continue;
        *c = (rt_sph_columns){it.rows,
                              rt_query_column(&it, s->pc.position, 0), rt_query_column(&it, s->pc.position, 1),
                              rt_query_column(&it, s->pc.position, 2), rt_query_column(&it, s->pc.velocity, 0),
                              rt_query_column(&it, s->pc.velocity, 1), rt_query_column(&it, s->pc.velocity, 2),
                              rt_query_column(&it, s->pc.density, 0), NULL};
        return;
    }
}

/* rt_sph_host: the solver's cell sort reorders the whole table. */
static vfx_result host_permute(void *user, const uint32_t *perm, rt_sph_columns *c)
{
    rt_sim_system *s = user;
    vfx_result r = rt_world_table_permute(s->world, s->table, perm);
    if (r)
        return r;
    table_columns(s, s->table, c);
    return VFX_OK;
}

/* rt_sph_host: particles the emitters (or rt_sph_add_*) make are new entities of the table. */
static vfx_result host_append(void *user, uint32_t add, rt_sph_columns *c)
{
    rt_sim_system *s = user;
    rt_component terms[4] = {s->pc.position, s->pc.velocity, s->pc.density, s->pc.radius};
    uint32_t nterms = 3;
    rt_query_iter it = rt_query_begin(s->world, terms, 3);
    while (rt_query_next(&it))
        if (it.table == s->table && rt_query_column(&it, s->pc.radius, 0))
            nterms = 4; /* same component set, same table */
    rt_entity *ids = malloc((size_t)add * sizeof *ids);
    if (!ids)
        return VFX_ERR_OUT_OF_MEMORY;
    vfx_result r = rt_world_spawn(s->world, add, terms, nterms, ids);
    uint32_t table = SIM_NO_TABLE;
    it = rt_query_begin(s->world, terms, 3);
    while (!r && rt_query_next(&it))
        if (it.rows >= add && it.entities[it.rows - 1] == ids[add - 1])
            table = it.table;
    free(ids);
    if (r)
        return r;
    table_columns(s, s->table, c);
    if (s->table != SIM_NO_TABLE && table != s->table && c->count) {
        return rt_world_fail(s->world, VFX_ERR_UNSUPPORTED, "vfx.sim.sph: emitted particles landed "
                             "in another table than the simulated ones (they carry other components)");
    }
    s->table = table;
    table_columns(s, table, c);
    return VFX_OK;
}

/* The one table holding the simulated particles (SIM_NO_TABLE when none has rows); an error
 * when they are spread over several. */
static vfx_result find_table(rt_sim_system *s, uint32_t *table)
{
    rt_component terms[3] = {s->pc.position, s->pc.velocity, s->pc.density};
    uint32_t tables = 0;
    *table = SIM_NO_TABLE;
    rt_query_iter it = rt_query_begin(s->world, terms, 3);
    while (rt_query_next(&it))
        if (tables++ == 0)
            *table = it.table;
    if (tables > 1) {
        return rt_world_fail(s->world, VFX_ERR_UNSUPPORTED, "vfx.sim.sph: the particles are in %u "
                             "tables (entities with different component sets); the solver steps "
                             "one table in place", tables);
    }
    return VFX_OK;
}

static vfx_result sim_run(rt_world *w, const rt_system_ctx *ctx)
{
    rt_sim_system *s = ctx->user;
    char err[512] = "";
    uint32_t table;
    vfx_result r = find_table(s, &table);
    if (r)
        return r;
    if (table == SIM_NO_TABLE)
        table = s->table; /* emptied (or never made): emitters refill the same table */
    /* The solver's columns are the table's, so value edits between frames are already in them
     * (moves are caught by the step's displacement check). A structural change (spawn,
     * despawn, reorder) or a write by another system moves the revision: bind again, which
     * checks the values and rebuilds the neighbour lists. */
    /* a device steps its own copy of the first bound state: the table is not bound again */
    bool same = s->dev_started || (s->bound && table == s->table &&
                (table == SIM_NO_TABLE || rt_world_table_revision(w, table) == s->revision));
    if (!same) {
        s->table = table;
        rt_sph_columns c;
        table_columns(s, table, &c);
        rt_sph_host host = {s, host_permute, host_append};
        if ((r = rt_sph_bind(s->sph, &host, &c, err, sizeof err))) {
            rt_sph_clear(s->sph); /* the old binding's columns may have moved */
            s->bound = false;
            return rt_world_fail(w, r, "vfx.sim.sph%s: %s", s->label, err);
        }
        s->bound = true;
    }
    s->ran = true;
    if (s->dev.step && !s->dev_started) {
        if ((r = s->dev.start(s->dev.user, s->sph, err, sizeof err)))
            return rt_world_fail(w, r, "vfx.sim.sph%s: %s", s->label, err);
        s->dev_started = true;
    }
    rt_sph_settle_report settled = {0};
    if (s->settle) {
        s->settle = false;
        s->settle_t0 = wall_s();
        r = s->dev_started ? s->dev.settle(s->dev.user, &s->settle_desc, &settled, err, sizeof err)
                           : rt_sph_settle(s->sph, &s->settle_desc, &settled, err, sizeof err);
        if (r)
            return rt_world_fail(w, r, "vfx.sim.sph%s: settling: %s", s->label, err);
        rt_logf(&s->log, VFX_LOG_INFO, "fluid settled before frame 0: %u steps, max speed %.3f m/s at the last, "
                "mean compression %.2f%%, %.2f CPU s; velocities zeroed", settled.steps,
                (double)settled.max_speed_last, 100.0 * settled.compression, settled.cpu_s);
    }
    /* A failed step leaves the last good (finite) state in the columns. */
    r = sim_advance(s, ctx->dt, &settled, err, sizeof err);
    if (s->table != SIM_NO_TABLE)
        s->revision = rt_world_table_revision(w, s->table) + SIM_OWN_BUMPS;
    return r ? rt_world_fail(w, r, "vfx.sim.sph%s: %s", s->label, err) : VFX_OK;
}

vfx_result rt_sim_system_create(rt_world *world, const rt_sph_desc *desc, rt_sim_system **out,
                                 char *err, size_t err_len)
{
    char dummy[8];
    if (!err || err_len == 0)
        err = dummy, err_len = sizeof dummy;
    err[0] = 0;
    if (!world || !out) {
        snprintf(err, err_len, "rt_sim_system_create: world and out are required");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    *out = NULL;
    rt_sim_system *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, err_len, "rt_sim_system_create: out of memory");
        return VFX_ERR_OUT_OF_MEMORY;
    }
    s->world = world;
    s->table = SIM_NO_TABLE;
    vfx_result r = rt_particles_register(world, &s->pc);
    if (r) {
        snprintf(err, err_len, "rt_sim_system_create: %s", rt_world_last_error(world));
        free(s);
        return r;
    }
    r = rt_sph_create(desc, &s->sph, err, err_len);
    if (r) {
        free(s);
        return r;
    }
    rt_component rw[3] = {s->pc.position, s->pc.velocity, s->pc.density};
    rt_system_desc sd = {.name = "vfx.sim.sph", .phase = RT_PHASE_SIMULATE, .reads = rw, .read_count = 3,
                          .writes = rw, .write_count = SIM_OWN_BUMPS, .fn = sim_run, .user = s};
    r = rt_world_add_system(world, &sd);
    if (r) {
        snprintf(err, err_len, "rt_sim_system_create: %s", rt_world_last_error(world));
        rt_sim_system_destroy(s);
        return r;
    }
    *out = s;
    return VFX_OK;
}

void rt_sim_system_destroy(rt_sim_system *s)
{
    if (!s)
        return;
    if (s->dev.destroy)
        s->dev.destroy(s->dev.user);
    rt_sph_destroy(s->sph);
    free(s);
}

rt_sph *rt_sim_system_solver(rt_sim_system *s) { return s ? s->sph : NULL; }
const rt_sph_report *rt_sim_system_report(const rt_sim_system *s) { return s ? &s->report : NULL; }


vfx_result rt_sim_system_set_clock(rt_sim_system *s, float step_dt, uint32_t max_steps)
{
    if (!s || !(step_dt >= 0.f) || !isfinite(step_dt) || (step_dt > 0.f && max_steps == 0))
        return VFX_ERR_INVALID_ARGUMENT;
    s->step_dt = step_dt;
    s->max_steps = max_steps;
    s->accum = 0.0;
    return VFX_OK;
}

/* rt_sph_settle's progress, as a log line */
static void settle_progress(void *user, uint32_t step, uint32_t max_steps, float max_speed, float compression)
{
    rt_sim_system *s = user;
    if (step == 1) /* rt_sph_settle reports its first step for this: the bound is said before the rest */
        warn_slow(s, wall_s() - s->settle_t0, "(wall clock, settling before frame 0)");
    if (step == 1 && step != max_steps && s->settle_desc.progress_every != 1)
        return;
    rt_logf(&s->log, VFX_LOG_INFO, "settling the fluid: step %u of at most %u, max speed %.3f m/s, mean "
            "compression %.2f%%", step, max_steps, (double)max_speed, 100.0 * compression);
}

vfx_result rt_sim_system_settle_next(rt_sim_system *s, const rt_sph_settle_desc *desc, const rt_logger *log)
{
    if (!s)
        return VFX_ERR_INVALID_ARGUMENT;
    s->settle_desc = desc ? *desc : (rt_sph_settle_desc){0};
    s->settle_desc.progress = settle_progress;
    s->settle_desc.user = s;
    if (log)
        s->log = *log;
    s->settle = true;
    return VFX_OK;
}

vfx_result rt_sim_system_set_label(rt_sim_system *s, const char *name, const double origin[3])
{
    if (!s)
        return VFX_ERR_INVALID_ARGUMENT;
    for (int k = 0; k < 3; ++k)
        s->origin[k] = origin ? origin[k] : 0.0;
    if (!name || !name[0])
        s->label[0] = 0;
    else
        snprintf(s->label, sizeof s->label, " (%.90s)", name);
    return VFX_OK;
}

vfx_result rt_sim_system_warn_slow(rt_sim_system *s, double seconds, const rt_logger *log)
{
    if (!s || !(seconds >= 0.0) || !isfinite(seconds))
        return VFX_ERR_INVALID_ARGUMENT;
    s->slow_s = seconds;
    s->slow_said = false;
    if (log)
        s->log = *log;
    return VFX_OK;
}

const rt_sim_stats *rt_sim_system_stats(const rt_sim_system *s) { return s ? &s->stats : NULL; }

void rt_sim_system_set_stats_sink(rt_sim_system *s, void (*sink)(void *user, const char *name, double value),
                                  void *user)
{
    if (s)
        s->sink = sink, s->sink_user = user;
}

vfx_result rt_sim_system_set_device(rt_sim_system *s, const rt_sim_device *dev)
{
    if (!s || !dev || s->ran || s->dev.step || !dev->start || !dev->step || !dev->settle || !dev->impulse ||
        !dev->destroy)
        return VFX_ERR_INVALID_ARGUMENT;
    s->dev = *dev;
    return VFX_OK;
}

uint32_t rt_sim_system_impulse(rt_sim_system *s, const float centre[3], const float dir[3], float radius, float speed)
{
    if (!s)
        return 0;
    if (!s->dev_started)
        return rt_sph_impulse(s->sph, centre, dir, radius, speed);
    s->dev.impulse(s->dev.user, centre, dir, radius, speed);
    return 1;
}
