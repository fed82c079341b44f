/* beam_field_f.h — the lab's float32 closed form of the beam integral (beam_field_f.c), for the
 * CPU benches; the shader (beams/beam_field.glsl) is what the plugin runs and the tests check. */
#ifndef VOLFX_LAB_BEAM_FIELD_F_H
#define VOLFX_LAB_BEAM_FIELD_F_H

#include "beam_field_d.h"

/* Integral over x in [x0, x1] of 1/sqrt((s x + beta)^2 + Q^2) in float (beam_field_d.h's _d). */
float volfx_beam_segment_integral_f(float x0, float x1, float s, float beta, float Q);
/* The smooth support's piece in float (beam_field_d.h's _d). */
float volfx_beam_segment_integral_smooth_f(float x0, float x1, float s, float beta, float Q, float h);
/* H of one beam along origin + t*dir (|dir| = 1), t in [t0, t1], float32 throughout. */
float volfx_beam_integral_f(const volfx_beam_d *beam, const float origin[3], const float dir[3], float t0, float t1);

#endif
