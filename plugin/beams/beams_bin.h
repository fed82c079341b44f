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

/* A beam's support for the per-tile test: the points within r of the polyline p[0..n) (relative
 * to the eye; a straight beam is its head and end, n = 2); n = 0: the rectangle alone decides. */
#define VOLFX_BEAMS_BIN_MAX_POINTS 6
typedef struct volfx_beams_capsule {
    double p[VOLFX_BEAMS_BIN_MAX_POINTS][3], r;
    uint32_t n;
} volfx_beams_capsule;

/* Every tile's cone of pixel rays (camera-relative): cones[t] = unit centre direction xyz and the
 * sine of the half-angle holding the tile's four corners (so every pixel ray of the tile), from
 * inv_cam_vp (the frame gate's inverse camera-relative view-projection). */
void volfx_beams_grid_cones(const volfx_beams_grid *g, const float inv_cam_vp[16], float (*cones)[4]);

/* False only when no ray of the cone can come within c->r of the capsule's polyline (so the beam
 * adds exactly 0 to every pixel of the tile): conservative, with a margin above float32 rounding. */
bool volfx_beams_capsule_touches(const volfx_beams_capsule *c, const float cone[4]);

/* Fills ranges (2 per tile: offset into list, count) and list (beam indices in increasing
 * order per tile; room for volfx_beams_bin_pairs) from n rectangles, each tile of a rectangle
 * kept when caps is NULL or volfx_beams_capsule_touches(caps + i, cones[tile]); *pairs gets the
 * entries written. Returns the number of tiles with no beam. */
uint32_t volfx_beams_bin_fill(const volfx_beams_grid *g, const uint32_t (*rects)[4], const bool *visible, uint32_t n,
                              const volfx_beams_capsule *caps, const float (*cones)[4], uint32_t *ranges,
                              uint32_t *list, uint64_t *pairs);

#endif
