/* beams_bin.h — the beams' CPU tile binning (no GL): which screen tiles each beam can touch,
 * from its bounding sphere projected with the frame gate's camera-relative view-projection, and
 * the per-tile beam lists the integrate pass walks (ranges: offset and count per tile). */
#ifndef VOLFX_BEAMS_BIN_H
#define VOLFX_BEAMS_BIN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define VOLFX_BEAMS_TILE_PX 16

/* The screen in tiles of VOLFX_BEAMS_TILE_PX pixels. */
typedef struct volfx_beams_grid {
    uint32_t width, height;     /* pixels */
    uint32_t tiles_x, tiles_y;
} volfx_beams_grid;

/* The grid of a width x height target (both > 0). */
volfx_beams_grid volfx_beams_grid_of(uint32_t width, uint32_t height);

/* The tile rectangle rect = {x0, y0, x1, y1} (inclusive) that a sphere (centre rel_c relative to
 * the eye, radius rad) can touch under cam_vp (proj * view without translation); the whole
 * screen when the sphere reaches the eye's plane; false when it is off screen. Conservative:
 * never misses a pixel the sphere covers. */
bool volfx_beams_bin_rect(const volfx_beams_grid *g, const float cam_vp[16], const double rel_c[3], double rad,
                          uint32_t rect[4]);

/* Pairs (beam, tile) of n rectangles (visible[i] false: none), the size the list needs. */
uint64_t volfx_beams_bin_pairs(const uint32_t (*rects)[4], const bool *visible, uint32_t n);

/* Fills ranges (2 per tile: offset into list, count) and list (beam indices in increasing
 * order per tile; room for volfx_beams_bin_pairs) from n rectangles; returns the number of
 * tiles with no beam. */
uint32_t volfx_beams_bin_fill(const volfx_beams_grid *g, const uint32_t (*rects)[4], const bool *visible, uint32_t n,
                              uint32_t *ranges, uint32_t *list);

#endif
