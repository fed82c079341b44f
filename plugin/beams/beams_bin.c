/* beams_bin.c — the beams' CPU tile binning (beams_bin.h): a counting sort of (beam, tile)
 * pairs into per-tile lists, so each pixel of the integrate pass walks only the beams whose
 * bounds reach its tile. */
#include "beams/beams_bin.h"

#include <math.h>
#include <string.h>

volfx_beams_grid volfx_beams_grid_of(uint32_t width, uint32_t height)
{
    return (volfx_beams_grid){width, height, (width + VOLFX_BEAMS_TILE_PX - 1) / VOLFX_BEAMS_TILE_PX,
                              (height + VOLFX_BEAMS_TILE_PX - 1) / VOLFX_BEAMS_TILE_PX};
}

bool volfx_beams_bin_rect(const volfx_beams_grid *g, const float cam_vp[16], const double rel_c[3], double rad,
                          uint32_t rect[4])
{
    double minx = 1e30, miny = 1e30, maxx = -1e30, maxy = -1e30;
    for (int k = 0; k < 8; ++k) {
        double p[3] = {rel_c[0] + (k & 1 ? rad : -rad), rel_c[1] + (k & 2 ? rad : -rad),
                       rel_c[2] + (k & 4 ? rad : -rad)};
        double cl[4];
        for (int r = 0; r < 4; ++r)
            cl[r] = cam_vp[r] * p[0] + cam_vp[4 + r] * p[1] + cam_vp[8 + r] * p[2] + cam_vp[12 + r];
        if (!(cl[3] > 1e-6)) { /* behind or at the eye: cover everything */
            rect[0] = 0, rect[1] = 0, rect[2] = g->tiles_x - 1, rect[3] = g->tiles_y - 1;
            return true;
        }
        double x = cl[0] / cl[3], y = cl[1] / cl[3];
        minx = fmin(minx, x), maxx = fmax(maxx, x), miny = fmin(miny, y), maxy = fmax(maxy, y);
    }
    if (maxx < -1 || minx > 1 || maxy < -1 || miny > 1)
        return false;
    double px0 = (fmax(minx, -1) * 0.5 + 0.5) * g->width, px1 = (fmin(maxx, 1) * 0.5 + 0.5) * g->width;
    double py0 = (fmax(miny, -1) * 0.5 + 0.5) * g->height, py1 = (fmin(maxy, 1) * 0.5 + 0.5) * g->height;
    rect[0] = (uint32_t)fmin(floor(px0 / VOLFX_BEAMS_TILE_PX), g->tiles_x - 1);
    rect[2] = (uint32_t)fmin(floor(px1 / VOLFX_BEAMS_TILE_PX), g->tiles_x - 1);
    rect[1] = (uint32_t)fmin(floor(py0 / VOLFX_BEAMS_TILE_PX), g->tiles_y - 1);
    rect[3] = (uint32_t)fmin(floor(py1 / VOLFX_BEAMS_TILE_PX), g->tiles_y - 1);
    return true;
}

uint64_t volfx_beams_bin_pairs(const uint32_t (*rects)[4], const bool *visible, uint32_t n)
{
    uint64_t pairs = 0;
    for (uint32_t i = 0; i < n; ++i)
        if (visible[i])
            pairs += (uint64_t)(rects[i][2] - rects[i][0] + 1) * (rects[i][3] - rects[i][1] + 1);
    return pairs;
}

void volfx_beams_grid_cones(const volfx_beams_grid *g, const float inv_cam_vp[16], float (*cones)[4])
{
    for (uint32_t ty = 0; ty < g->tiles_y; ++ty)
        for (uint32_t tx = 0; tx < g->tiles_x; ++tx) {
            double dir[5][3];
            for (int k = 0; k < 5; ++k) { /* the four corners, then the centre */
                double px = (tx + (k == 4 ? 0.5 : (double)(k & 1))) * VOLFX_BEAMS_TILE_PX;
                double py = (ty + (k == 4 ? 0.5 : (double)(k >> 1))) * VOLFX_BEAMS_TILE_PX;
                double nx = 2.0 * px / g->width - 1.0, ny = 2.0 * py / g->height - 1.0, h[4], n = 0;
                for (int r = 0; r < 4; ++r)
                    h[r] = inv_cam_vp[r] * nx + inv_cam_vp[4 + r] * ny + inv_cam_vp[12 + r];
                for (int r = 0; r < 3; ++r)
                    dir[k][r] = h[r] / h[3], n += dir[k][r] * dir[k][r];
                n = sqrt(n);
                for (int r = 0; r < 3; ++r)
                    dir[k][r] /= n;
            }
            double cmin = 1.0;
            for (int k = 0; k < 4; ++k)
                cmin = fmin(cmin, dir[k][0] * dir[4][0] + dir[k][1] * dir[4][1] + dir[k][2] * dir[4][2]);
            float *c = cones[ty * g->tiles_x + tx];
            c[0] = (float)dir[4][0], c[1] = (float)dir[4][1], c[2] = (float)dir[4][2];
            /* corners bound the tile (the cone meets the image plane in an ellipse, a convex
             * set); 1% and 1e-4 over for the float rounding of the shader's pixel rays */
            c[3] = (float)(sqrt(fmax(0.0, 1.0 - cmin * cmin)) * 1.01 + 1e-4);
        }
}

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Squared distance between segments p0..p1 and q0..q1 (Ericson, Real-Time Collision Detection 5.1.9). */
static double seg_seg_d2(const double p0[3], const double p1[3], const double q0[3], const double q1[3])
{
    double d1[3], d2[3], r[3];
    for (int k = 0; k < 3; ++k)
        d1[k] = p1[k] - p0[k], d2[k] = q1[k] - q0[k], r[k] = p0[k] - q0[k];
    double a = dot3(d1, d1), e = dot3(d2, d2), f = dot3(d2, r), s = 0, t = 0;
    if (a <= 1e-300 && e <= 1e-300)
        return dot3(r, r);
    if (a <= 1e-300) {
        t = fmin(fmax(f / e, 0.0), 1.0);
    } else {
        double c = dot3(d1, r);
        if (e <= 1e-300) {
            s = fmin(fmax(-c / a, 0.0), 1.0);
        } else {
            double b = dot3(d1, d2), den = a * e - b * b;
            s = den > 0 ? fmin(fmax((b * f - c * e) / den, 0.0), 1.0) : 0.0;
            t = (b * s + f) / e;
            if (t < 0)
                t = 0, s = fmin(fmax(-c / a, 0.0), 1.0);
            else if (t > 1)
                t = 1, s = fmin(fmax((b - c) / a, 0.0), 1.0);
        }
    }
    double d = 0;
    for (int k = 0; k < 3; ++k) {
        double x = p0[k] + d1[k] * s - (q0[k] + d2[k] * t);
        d += x * x;
    }
    return d;
}

/* One segment a..b of the support against the cone (see volfx_beams_capsule_touches). */
static bool segment_touches(const double a[3], const double b[3], double r, const float cone[4])
{
    /* For P on the segment and a pixel ray V' within the cone's half-angle of its axis V:
     * dist(P, V') >= dist(P, V) - |P| sin(alpha) (the foot t'V' of P on V' has t' <= |P| and lies
     * within t' sin(alpha) of V). So a pixel ray can reach the capsule only if, on some piece of
     * the segment, dist(piece, V) <= r + sin(alpha) max|P| over the piece (|P| is convex: its max
     * is at an end). Eight pieces keep max|P| close to |P| along a long beam. */
    enum { PIECES = 8 };
    double v[3] = {cone[0], cone[1], cone[2]}, o[3] = {0, 0, 0};
    for (int j = 0; j < PIECES; ++j) {
        double p0[3], p1[3];
        for (int k = 0; k < 3; ++k) {
            p0[k] = a[k] + (b[k] - a[k]) * (double)j / PIECES;
            p1[k] = a[k] + (b[k] - a[k]) * (double)(j + 1) / PIECES;
        }
        double pmax = sqrt(fmax(dot3(p0, p0), dot3(p1, p1)));
        double reach = r * (1.0 + 1e-3) + cone[3] * pmax + 1e-5 * pmax; /* margin: float32 rays */
        /* the ray V as a segment long enough that no point beyond it is within reach */
        double len = 2.0 * pmax + reach + 1.0, q1[3] = {v[0] * len, v[1] * len, v[2] * len};
        if (seg_seg_d2(p0, p1, o, q1) <= reach * reach)
            return true;
    }
    return false;
}

bool volfx_beams_capsule_touches(const volfx_beams_capsule *c, const float cone[4])
{
    if (c->n == 0)
        return true;
    if (c->n == 1)
        return segment_touches(c->p[0], c->p[0], c->r, cone);
    for (uint32_t k = 0; k + 1 < c->n; ++k)
        if (segment_touches(c->p[k], c->p[k + 1], c->r, cone))
            return true;
    return false;
}

/* Beam i kept in tile t: in its rectangle and, when capsules are given, touching the tile's cone. */
static bool keep(const volfx_beams_capsule *caps, const float (*cones)[4], uint32_t i, uint32_t t)
{
    return !caps || volfx_beams_capsule_touches(&caps[i], cones[t]);
}

uint32_t volfx_beams_bin_fill(const volfx_beams_grid *g, const uint32_t (*rects)[4], const bool *visible, uint32_t n,
                              const volfx_beams_capsule *caps, const float (*cones)[4], uint32_t *ranges,
                              uint32_t *list, uint64_t *pairs)
{
    uint32_t ntiles = g->tiles_x * g->tiles_y;
    memset(ranges, 0, (size_t)ntiles * 2 * sizeof(uint32_t));
    for (uint32_t i = 0; i < n; ++i) {
        if (!visible[i])
            continue;
        for (uint32_t ty = rects[i][1]; ty <= rects[i][3]; ++ty)
            for (uint32_t tx = rects[i][0]; tx <= rects[i][2]; ++tx)
                ranges[2 * (ty * g->tiles_x + tx) + 1] += keep(caps, cones, i, ty * g->tiles_x + tx);
    }
    uint32_t offset = 0, empty = 0;
    for (uint32_t t = 0; t < ntiles; ++t) {
        ranges[2 * t] = offset;
        offset += ranges[2 * t + 1];
        empty += ranges[2 * t + 1] == 0;
        ranges[2 * t + 1] = 0; /* refilled below as a cursor */
    }
    for (uint32_t i = 0; i < n; ++i) {
        if (!visible[i])
            continue;
        for (uint32_t ty = rects[i][1]; ty <= rects[i][3]; ++ty)
            for (uint32_t tx = rects[i][0]; tx <= rects[i][2]; ++tx) {
                uint32_t t = ty * g->tiles_x + tx;
                if (keep(caps, cones, i, t))
                    list[ranges[2 * t] + ranges[2 * t + 1]++] = i;
            }
    }
    *pairs = offset;
    return empty;
}
