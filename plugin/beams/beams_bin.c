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

uint32_t volfx_beams_bin_fill(const volfx_beams_grid *g, const uint32_t (*rects)[4], const bool *visible, uint32_t n,
                              uint32_t *ranges, uint32_t *list)
{
    uint32_t ntiles = g->tiles_x * g->tiles_y;
    memset(ranges, 0, (size_t)ntiles * 2 * sizeof(uint32_t));
    for (uint32_t i = 0; i < n; ++i) {
        if (!visible[i])
            continue;
        for (uint32_t ty = rects[i][1]; ty <= rects[i][3]; ++ty)
            for (uint32_t tx = rects[i][0]; tx <= rects[i][2]; ++tx)
                ranges[2 * (ty * g->tiles_x + tx) + 1]++;
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
                list[ranges[2 * t] + ranges[2 * t + 1]++] = i;
            }
    }
    return empty;
}
