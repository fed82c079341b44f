/* beams_impact.h — what happens where a beam meets the host's scene (issue 25): the hit of each
 * beam's axis with the host depth found on the GPU, a flare there, sparks (GPU particles that
 * bounce off the depth buffer and fade), a glow left on the surface that decays; and the lights
 * the beams cast on the host's scene (a line light per beam segment, a point light per head and
 * per impact). The beams effect feeds it each beam at update and calls one hook per frame. */
#ifndef VOLFX_BEAMS_IMPACT_H
#define VOLFX_BEAMS_IMPACT_H

#include <stdint.h>

#include "beams/beam_field.h"
#include "effect.h"

#define VOLFX_IMPACT_MAX_BEAMS 256u  /* beams past this make no impact (and no impact light) */
#define VOLFX_IMPACT_MAX_SPARKS 2048u /* the spark pool: never more alive */
#define VOLFX_IMPACT_MAX_GLOWS 512u   /* the surface glow ring */

typedef struct volfx_beams_impact volfx_beams_impact;

/* Makes the impact state: programs, pools (zeroed: no spark, no glow). */
vfx_result volfx_beams_impact_create(vfx_context *ctx, volfx_beams_impact **out);
/* Frees every GL object and allocation; NULL allowed. */
void volfx_beams_impact_destroy(vfx_context *ctx, volfx_beams_impact *im);

/* The beams of this update: n beams follow (n above VOLFX_IMPACT_MAX_BEAMS keeps the first ones);
 * false when the per-beam arrays cannot grow (the error is recorded). */
bool volfx_beams_impact_set_count(vfx_context *ctx, volfx_beams_impact *im, uint32_t n);
/* Beam i (< the count set): its axis (head, then along D or the polyline), its linear colour and
 * its radiance multiplier (intensity x 2^exposure). */
void volfx_beams_impact_set_beam(volfx_beams_impact *im, uint32_t i, const volfx_beam_d *b, const float rgb[3],
                                 float gain);

/* The hook, once a frame after the beams' integrate pass: finds each on-screen beam's hit with
 * the host depth, steps and emits sparks and glow, and adds flare, sparks and glow into `light`
 * (the beams' RGBA16F light target, w x h, before bloom). Nothing runs, no pass, when no beam is
 * on screen and the last read-back found no impact and nothing alive. Stats beams.impacts and
 * beams.sparks (read back without a stall: one to three frames late), beams.lights. */
vfx_result volfx_beams_impact_render(vfx_context *ctx, volfx_beams_impact *im, const volfx_frame_targets *t,
                                     unsigned light, double time, float dt);

/* The lights of the current beams (one line light per segment with b > 0, one point light per
 * head with a > 0) and of the last read-back impacts, positions relative to the frame's origin:
 * writes at most out->capacity of them, sets out->count and out->total. */
void volfx_beams_impact_lights(const volfx_beams_impact *im, vfx_lights *out);

/* Where a beam struck the water (the newest read-back: one to three frames late), for the host's
 * fluid: position relative to the origin, the surface's unit normal (facing the beam), the beam's
 * unit direction of travel there, its energy (the impact light's intensity, 8 x intensity x
 * 2^exposure x the colour's largest component), the beam's index. */
typedef vfx_impact_event volfx_impact_event;
/* Writes at most cap of this frame's impacts on the water into out (NULL with cap 0: count
 * only); returns how many there are. */
uint32_t volfx_beams_impact_water_events(const volfx_beams_impact *im, volfx_impact_event *out, uint32_t cap);

/* Tests: copies the last hit pass's hits (stalls): per beam 8 floats, the hit position relative
 * to the origin and 1 (0: no hit), the surface normal and 1 on the water (0: the host's scene). At most n beams; returns how many. */
uint32_t volfx_beams_impact_debug_hits(volfx_beams_impact *im, float (*out)[8], uint32_t n);
/* Tests: copies the spark pool (stalls): 12 floats a spark (position, age; velocity, lifetime;
 * colour, 0), age < 0 or age >= lifetime: dead. Returns the pool size. */
uint32_t volfx_beams_impact_debug_sparks(volfx_beams_impact *im, float (*out)[12], uint32_t n);
/* Tests: the last integrate pass's H split at the water's surface, 2 floats a pixel, top row first:
 * the integral from the eye to the nearer of the water and the scene, and from the water on to
 * the scene (0 without water in front). count >= 2 x width x height. */
vfx_result volfx_beams_debug_split(vfx_context *ctx, float *out, size_t count);
/* Tests and the lights entry point: the beams effect's impact state (NULL when beams are absent). */
volfx_beams_impact *volfx_beams_impact_of(vfx_context *ctx);

#endif
