/* volume_shield.c — the energy-shield look of a scene volume (volume_shield.h): boundary faces
 * found once by sorting the tets' faces, then per frame a rim term from the faces' world-space
 * normals and the view, and rings around each beam's strike point, added to the scalar. */
#include "volume_shield.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct game_shield {
    uint32_t *faces;        /* 3 point indices per boundary face, counter-clockwise seen from outside */
    uint32_t face_count;
    uint32_t point_count;
    float *world;           /* 3 per point: this frame's world positions */
    float *normal;          /* 3 per point: area-weighted boundary normal (0 off the boundary) */
    uint32_t *source;       /* per point: the boundary vertex whose normal its rim uses (itself on the
                             * boundary, the nearest in tet edges within SOURCE_HOPS inside, else ~0u) */
};

/* How many tet edges inward the rim reaches (it fades by the distance to the sphere anyway). */
enum { SOURCE_HOPS = 4 };
#define NO_SOURCE 0xffffffffu

typedef struct face_key {
    uint32_t v[3];          /* sorted */
    uint32_t tet, slot;     /* which tet, which face of it (the vertex left out) */
} face_key;

static int cmp_face(const void *a, const void *b)
{
    const face_key *x = a, *y = b;
    for (int k = 0; k < 3; ++k)
        if (x->v[k] != y->v[k])
            return x->v[k] < y->v[k] ? -1 : 1;
    return 0;
}

static void sort3(uint32_t v[3])
{
    uint32_t t;
    if (v[0] > v[1]) t = v[0], v[0] = v[1], v[1] = t;
    if (v[1] > v[2]) t = v[1], v[1] = v[2], v[2] = t;
    if (v[0] > v[1]) t = v[0], v[0] = v[1], v[1] = t;
}

/* The face of tet t opposite vertex `slot`, wound so its normal points away from that vertex. */
static void oriented_face(const float *P, const uint32_t *t, uint32_t slot, uint32_t out[3])
{
    uint32_t f[3], k = 0;
    for (uint32_t j = 0; j < 4; ++j)
        if (j != slot)
            f[k++] = t[j];
    const float *a = &P[3 * f[0]], *b = &P[3 * f[1]], *c = &P[3 * f[2]], *o = &P[3 * t[slot]];
    double e1[3], e2[3], n[3], d = 0;
    for (int r = 0; r < 3; ++r)
        e1[r] = (double)b[r] - a[r], e2[r] = (double)c[r] - a[r];
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    for (int r = 0; r < 3; ++r)
        d += n[r] * ((double)o[r] - a[r]);
    out[0] = f[0];
    out[1] = d > 0 ? f[2] : f[1]; /* the left-out vertex is behind the face */
    out[2] = d > 0 ? f[1] : f[2];
}

/* Gives every point within SOURCE_HOPS tet edges of the shell the nearest boundary vertex in
 * edges (a breadth-first search from all boundary vertices at once), so the rim is not a layer
 * one tet thick: with the interior vertices at 0, each tet under the silhouette interpolated the
 * rim down to nothing over its own depth, and the uneven tets beaded the rim. False when out of
 * memory. */
static bool rim_sources(game_shield *s, const uint32_t *tets, uint32_t tet_count)
{
    const uint32_t np = s->point_count;
    uint32_t *start = calloc((size_t)np + 1, sizeof *start), *adj = malloc((size_t)tet_count * 12 * sizeof *adj);
    uint32_t *queue = malloc((size_t)np * sizeof *queue), *hops = malloc((size_t)np * sizeof *hops);
    s->source = malloc((size_t)np * sizeof *s->source);
    bool ok = start && adj && queue && hops && s->source;
    if (ok) {
        /* every tet edge both ways (shared edges repeat: harmless for the search) */
        for (size_t i = 0; i < (size_t)tet_count * 4; ++i)
            start[tets[i] + 1] += 3;
        for (uint32_t i = 0; i < np; ++i)
            start[i + 1] += start[i];
        memcpy(hops, start, (size_t)np * sizeof *hops); /* hops: the fill cursor for now */
        for (uint32_t t = 0; t < tet_count; ++t)
            for (int a = 0; a < 4; ++a)
                for (int b = 0; b < 4; ++b)
                    if (a != b)
                        adj[hops[tets[4 * t + a]]++] = tets[4 * t + b];
        uint32_t head = 0, tail = 0;
        for (uint32_t i = 0; i < np; ++i)
            s->source[i] = NO_SOURCE, hops[i] = 0;
        for (uint32_t k = 0; k < s->face_count * 3; ++k) {
            uint32_t v = s->faces[k];
            if (s->source[v] == NO_SOURCE)
                s->source[v] = v, queue[tail++] = v;
        }
        while (head < tail) {
            uint32_t v = queue[head++];
            if (hops[v] >= SOURCE_HOPS)
                continue;
            for (uint32_t e = start[v]; e < start[v + 1]; ++e)
                if (s->source[adj[e]] == NO_SOURCE) {
                    s->source[adj[e]] = s->source[v], hops[adj[e]] = hops[v] + 1;
                    queue[tail++] = adj[e];
                }
        }
    }
    free(start);
    free(adj);
    free(queue);
    free(hops);
    return ok;
}

vfx_result game_shield_create(const float *points, uint32_t point_count, const uint32_t *tets,
                              uint32_t tet_count, float floor_y, game_shield **out)
{
    *out = NULL;
    for (size_t i = 0; i < (size_t)tet_count * 4; ++i)
        if (tets[i] >= point_count)
            return VFX_ERR_INVALID_ARGUMENT;
    face_key *keys = malloc((size_t)tet_count * 4 * sizeof *keys);
    game_shield *s = calloc(1, sizeof *s);
    if (!keys || !s) {
        free(keys);
        free(s);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    size_t n = 0;
    for (uint32_t t = 0; t < tet_count; ++t)
        for (uint32_t j = 0; j < 4; ++j) {
            face_key *k = &keys[n++];
            uint32_t m = 0;
            for (uint32_t q = 0; q < 4; ++q)
                if (q != j)
                    k->v[m++] = tets[4 * t + q];
            sort3(k->v);
            k->tet = t, k->slot = j;
        }
    qsort(keys, n, sizeof *keys, cmp_face);
    s->point_count = point_count;
    s->faces = malloc(n * 3 * sizeof *s->faces);
    s->world = malloc((size_t)point_count * 3 * sizeof *s->world);
    s->normal = malloc((size_t)point_count * 3 * sizeof *s->normal);
    if (!s->faces || !s->world || !s->normal) {
        free(keys);
        game_shield_destroy(s);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    /* a floor face has all three vertices within a thousandth of the mesh's height of it */
    float hi = floor_y;
    for (uint32_t i = 0; i < point_count; ++i)
        hi = fmaxf(hi, points[3 * i + 1]);
    const float tol = 1e-3f * (hi - floor_y);
    for (size_t i = 0; i < n;) {
        size_t j = i + 1;
        while (j < n && cmp_face(&keys[i], &keys[j]) == 0)
            ++j;
        if (j == i + 1) { /* a face of one tet only: the boundary */
            const face_key *k = &keys[i];
            bool floor = true;
            for (int r = 0; r < 3; ++r)
                floor &= fabsf(points[3 * k->v[r] + 1] - floor_y) <= tol;
            if (!floor)
                oriented_face(points, &tets[4 * k->tet], k->slot, &s->faces[3 * s->face_count++]);
        }
        i = j;
    }
    free(keys);
    if (!rim_sources(s, tets, tet_count)) {
        game_shield_destroy(s);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    *out = s;
    return VFX_OK;
}

void game_shield_destroy(game_shield *s)
{
    if (!s)
        return;
    free(s->faces);
    free(s->world);
    free(s->normal);
    free(s->source);
    free(s);
}

uint32_t game_shield_faces(const game_shield *s)
{
    return s ? s->face_count : 0;
}

/* Where beam b strikes the sphere (C, R), with a strength in [0, 1]: the first crossing of its
 * axis segment (travelling from its source end M + L D towards its head M), or, for an axis
 * passing outside, the sphere's point nearest it while that gap is under two beam radii.
 * Bending beams (joints) are left out. Returns 0 when the beam does not reach the sphere. */
static int strike_point(const vfx_beam *b, const double C[3], double R, double S[3], double *strength)
{
    const vfx_beam *v = b;
    if (b->joint_count >= 2)
        return 0;
    double D[3] = {v->dir[0], v->dir[1], v->dir[2]}, m[3], dl = 0;
    for (int k = 0; k < 3; ++k)
        dl += D[k] * D[k];
    dl = sqrt(dl);
    if (!(dl > 0))
        return 0;
    double md = 0, mm = 0;
    for (int k = 0; k < 3; ++k) {
        D[k] /= dl;
        m[k] = v->head[k] - C[k];
        md += m[k] * D[k];
        mm += m[k] * m[k];
    }
    double L = v->length > 0 ? v->length : 0;
    double disc = md * md - (mm - R * R); /* |m + u D|^2 = R^2 at u = -md -+ sqrt(disc) */
    if (disc >= 0) {
        double u = -md + sqrt(disc); /* the larger root: where the axis enters, coming from the source */
        if (u >= 0 && u <= L) {
            for (int k = 0; k < 3; ++k)
                S[k] = C[k] + m[k] + u * D[k];
            *strength = 1;
            return 1;
        }
    }
    double u = -md;
    u = u < 0 ? 0 : u > L ? L : u;
    double p[3], pl = 0;
    for (int k = 0; k < 3; ++k) {
        p[k] = m[k] + u * D[k];
        pl += p[k] * p[k];
    }
    pl = sqrt(pl);
    double gap = pl - R, reach = 2.0 * v->radius;
    if (!(pl > 0) || !(gap < reach))
        return 0;
    for (int k = 0; k < 3; ++k)
        S[k] = C[k] + p[k] * (R / pl);
    *strength = gap <= 0 ? 1 : 1 - gap / reach;
    return 1;
}

static void to_world(const float *M, const float *q, float *w)
{
    for (int r = 0; r < 3; ++r)
        w[r] = M[r] * q[0] + M[4 + r] * q[1] + M[8 + r] * q[2] + M[12 + r];
}

/* This frame's world positions and boundary vertex normals (area-weighted face normals). */
static void frame_geometry(game_shield *s, const game_shield_frame *f)
{
    bool identity = true;
    for (int i = 0; i < 16 && f->model; ++i)
        identity &= f->model[i] == 0;
    for (uint32_t i = 0; i < s->point_count; ++i) {
        if (identity || !f->model)
            memcpy(&s->world[3 * i], &f->points[3 * i], 3 * sizeof(float));
        else
            to_world(f->model, &f->points[3 * i], &s->world[3 * i]);
    }
    memset(s->normal, 0, (size_t)s->point_count * 3 * sizeof *s->normal);
    for (uint32_t k = 0; k < s->face_count; ++k) {
        const uint32_t *t = &s->faces[3 * k];
        const float *a = &s->world[3 * t[0]], *b = &s->world[3 * t[1]], *c = &s->world[3 * t[2]];
        float e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        for (int j = 0; j < 3; ++j)
            for (int r = 0; r < 3; ++r)
                s->normal[3 * t[j] + r] += n[r];
    }
}

/* How much of the shell a vertex is: 1 on the boundary, else fading out over 15% of the radius
 * of the sphere (C, R), 0 beyond. */
static double shell_weight(const float *n, const float *p, const double C[3], double R)
{
    if (n[0] != 0 || n[1] != 0 || n[2] != 0)
        return 1;
    double c[3] = {p[0] - C[0], p[1] - C[1], p[2] - C[2]};
    double g = fabs(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) - R) / (0.15 * R);
    return g < 1 ? 1 - g : 0;
}

void game_shield_apply(game_shield *s, const rt_scene_volume_animation *an, const game_shield_frame *f,
                       float *scalar)
{
    if (!s || (an->rim_gain <= 0 && an->hit_gain <= 0))
        return;
    frame_geometry(s, f);
    /* the dome's sphere in world space: centre and radius through the model matrix */
    float cw[3], ew[3], e[3] = {f->center[0] + f->radius, f->center[1], f->center[2]};
    bool identity = true;
    for (int i = 0; i < 16 && f->model; ++i)
        identity &= f->model[i] == 0;
    if (identity || !f->model) {
        memcpy(cw, f->center, sizeof cw);
        memcpy(ew, e, sizeof ew);
    } else {
        to_world(f->model, f->center, cw);
        to_world(f->model, e, ew);
    }
    const double C[3] = {cw[0], cw[1], cw[2]};
    const double R = sqrt(((double)ew[0] - cw[0]) * (ew[0] - cw[0]) + ((double)ew[1] - cw[1]) * (ew[1] - cw[1]) +
                          ((double)ew[2] - cw[2]) * (ew[2] - cw[2]));
    if (an->rim_gain > 0)
        for (uint32_t i = 0; i < s->point_count; ++i) {
            if (s->source[i] == NO_SOURCE)
                continue; /* deep inside the mesh */
            /* the normal of the nearest boundary vertex, seen from this vertex, weighted by how
             * much of the shell it is: the rim reaches into the shell evenly */
            const float *n = &s->normal[3 * s->source[i]], *p = &s->world[3 * i];
            const double w = shell_weight(&s->normal[3 * i], p, C, R);
            float nl = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            if (!(nl > 0) || !(w > 0))
                continue;
            double v[3] = {f->eye[0] - p[0], f->eye[1] - p[1], f->eye[2] - p[2]};
            double vl = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            if (!(vl > 0))
                continue;
            double c = fabs((n[0] * v[0] + n[1] * v[1] + n[2] * v[2]) / (nl * vl));
            scalar[i] += (float)(w * an->rim_gain * pow(1 - (c < 1 ? c : 1), an->rim_power));
        }
    if (an->hit_gain <= 0 || !f->beams)
        return;
    const double k = 2 * M_PI / an->hit_wavelength;
    for (uint32_t b = 0; b < f->beam_count; ++b) {
        double S[3], strength;
        if (!strike_point(&f->beams[b], C, R, S, &strength))
            continue;
        /* rings r = speed t + n wavelength, each a raised cosine, fading with distance, in the
         * shell only: the boundary vertices and, fading out over 15% of the radius, those near
         * the sphere. Added to every vertex, each ring was a spherical shell through the whole
         * dome, and seen through the volume the shells blurred into a haze over the statue
         * (frames 30, 90, 400: no ring could be told apart) */
        for (uint32_t i = 0; i < s->point_count; ++i) {
            const float *p = &s->world[3 * i];
            const double shell = shell_weight(&s->normal[3 * i], p, C, R);
            if (!(shell > 0))
                continue;
            double d[3] = {p[0] - S[0], p[1] - S[1], p[2] - S[2]};
            double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            if (r > 4 * an->hit_reach)
                continue;
            double ring = 0.5 + 0.5 * cos(k * (r - an->hit_speed * f->time));
            scalar[i] += (float)(shell * strength * an->hit_gain * ring * ring * exp(-r / an->hit_reach));
        }
    }
}
