/* sph_collide.c — colliders: planes, spheres, boxes and triangle meshes (a signed distance
 * field sampled once), static or moving as paddles. */
#include "sim/sph_collide.h"

#include <stdlib.h>
#include <string.h>

vfx_result rt_sph_add_collider(rt_sph *s, const rt_sph_collider *c, uint32_t *index, char *err,
                               size_t errlen)
{
    if (!s || !c)
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_collider: NULL solver or collider");
    if (s->ncol >= SPH_MAX_COLLIDERS) {
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_collider: at most %u colliders", SPH_MAX_COLLIDERS);
    }
    rt_sph_collider k = *c;
    if (!sph_finite3(k.center) || !sph_finite3(k.normal) || !sph_finite3(k.half) || !sph_finite3(k.motion_axis) ||
        !isfinite(k.radius) || !isfinite(k.motion_amplitude) || !isfinite(k.motion_frequency)) {
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_collider: collider %u has a non-finite field", s->ncol);
    }
    if (!(k.motion_ramp_s >= 0.f && k.motion_ramp_s <= 1e6f)) {
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_collider: collider %u has motion_ramp_s %g "
                       "(0 to 1e6 s)", s->ncol, (double)k.motion_ramp_s);
    }
    if (k.kind == RT_SPH_PLANE) {
        float l = sqrtf(k.normal[0] * k.normal[0] + k.normal[1] * k.normal[1] + k.normal[2] * k.normal[2]);
        if (!(l > 1e-6f)) {
            return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_collider: plane %u has a zero normal", s->ncol);
        }
        for (int a = 0; a < 3; ++a)
            k.normal[a] /= l;
    } else if (k.kind == RT_SPH_SPHERE) {
        if (!(k.radius > 0.f)) {
            return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_collider: sphere %u needs radius > 0 (got %g)", s->ncol, (double)k.radius);
        }
    } else if (k.kind == RT_SPH_BOX) {
        if (!(k.half[0] > 0.f && k.half[1] > 0.f && k.half[2] > 0.f)) {
            return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_collider: box %u needs half extents > 0", s->ncol);
        }
    } else {
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_collider: unknown kind %d", (int)k.kind);
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
                                     const rt_sph_collider *motion, uint32_t *index, char *err,
                                     size_t errlen)
{
    if (!s)
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_mesh_collider: NULL solver");
    if (s->ncol >= SPH_MAX_COLLIDERS) {
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_mesh_collider: at most %u colliders", SPH_MAX_COLLIDERS);
    }
    if (!positions || !indices || vertex_count == 0 || index_count < 3 || index_count % 3 != 0) {
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_mesh_collider: need vertices and a multiple of 3 indices (got %u "
                "vertices, %u indices)", vertex_count, index_count);
    }
    if (index_count / 3 > SPH_MAX_MESH_TRIANGLES) {
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_mesh_collider: %u triangles, at most %u (the distance field is "
                "built by brute force)", index_count / 3, SPH_MAX_MESH_TRIANGLES);
    }
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t v = 0; v < vertex_count; ++v)
        for (int a = 0; a < 3; ++a) {
            float x = positions[3 * v + a];
            if (!isfinite(x)) {
                return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_mesh_collider: vertex %u is not finite", v);
            }
            lo[a] = x < lo[a] ? x : lo[a];
            hi[a] = x > hi[a] ? x : hi[a];
        }
    for (uint32_t i = 0; i < index_count; ++i)
        if (indices[i] >= vertex_count) {
            return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_mesh_collider: triangle %u uses vertex %u of %u", i / 3,
                    indices[i], vertex_count);
        }
    sph_collider_state st = {0};
    if (motion) {
        st.c = *motion;
        if (!sph_finite3(st.c.center) || !sph_finite3(st.c.motion_axis) || !isfinite(st.c.motion_amplitude) ||
            !isfinite(st.c.motion_frequency) || !(st.c.motion_ramp_s >= 0.f && st.c.motion_ramp_s <= 1e6f)) {
            return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "rt_sph_add_mesh_collider: motion has a non-finite "
                           "field or a motion_ramp_s outside 0 to 1e6 s");
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
        return rt_errf(err, errlen, VFX_ERR_OUT_OF_MEMORY, "rt_sph_add_mesh_collider: out of memory for a %zu-node distance field", total);
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

float rt_sph_surface_distance(const sph_collider_state *st, float px, float py, float pz, float n[3])
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
    return rt_sph_surface_distance(&s->col[index], p[0], p[1], p[2], n);
}

vfx_result rt_sph_collider_motion(const rt_sph *s, uint32_t index, float pos[3], float vel[3])
{
    if (!s || index >= s->ncol || !pos || !vel)
        return VFX_ERR_INVALID_ARGUMENT;
    for (int a = 0; a < 3; ++a)
        pos[a] = s->col[index].pos[a], vel[a] = s->col[index].vel[a];
    return VFX_OK;
}

void rt_sph_update_colliders(rt_sph *s, double t)
{
    for (uint32_t i = 0; i < s->ncol; ++i) {
        sph_collider_state *st = &s->col[i];
        const rt_sph_collider *c = &st->c;
        double w = 2.0 * SPH_PI * c->motion_frequency, amp = c->motion_amplitude, damp = 0.0;
        if (c->motion_ramp_s > 0.f && t < c->motion_ramp_s) {
            /* r = u^2 (3 - 2u), u = t / ramp: zero speed at t = 0, r' = 0 where the ramp ends */
            double u = t > 0.0 ? t / c->motion_ramp_s : 0.0;
            damp = amp * 6.0 * u * (1.0 - u) / c->motion_ramp_s;
            amp *= u * u * (3.0 - 2.0 * u);
        }
        double off = amp * sin(w * t), vel = amp * w * cos(w * t) + damp * sin(w * t);
        for (int a = 0; a < 3; ++a) {
            st->pos[a] = c->center[a] + (float)(off * c->motion_axis[a]);
            st->vel[a] = (float)(vel * c->motion_axis[a]);
        }
    }
}
