// Per pixel: H = sum over the beams binned to this pixel's tile of the closed-form integral
// (beam_field.glsl) from the eye to the first surface (host depth, water); the pass's body is
// beams/integrate.glsl, this file its H. With VOLFX_BEAMS_WATER the ray is split at the water's
// surface: the part in front goes to the light (composited over the water), the part behind it to
// its own target, which the water's shading sees through its refraction (docs/beams.md "In the
// water"). Writes H (R32F, read_raw) and the beams' linear radiance (RGBA16F): each hot-ramp beam
// through its own ramp, the thesis-ramp beams through the clamp of their summed H (docs/beams.md
// "Emission").
layout(std430, binding = 4) readonly buffer Joints { vec4 joints[]; }; // xyz relative to the eye
vec3 volfx_joint(uint i) { return joints[i].xyz; }
#include "beams/beam_field.glsl"
#include "common/frame.glsl"
#include "beams/frame.glsl"
#include "beams/integrate.glsl"

// H of one beam along the pixel ray t V over [t0, t1]: the closed form (beam_field.glsl)
float volfx_beam_h(Beam bm, vec3 V, float t0, float t1)
{
    bool soft = bm.mode.x != 0u;
#ifdef VOLFX_BEAMS_POLYLINE
    bool poly = bm.mode.w >= 2u;
#endif
    float h;
#ifdef VOLFX_BEAMS_POLYLINE
    if (poly) {
#ifdef VOLFX_BEAMS_ANATOMY
        // the head at its own radius and the orb at the last joint: sphere pieces
        float eps = max(bm.ab_eps.z, VOLFX_BEAM_EPS_FLOOR * bm.d_r.w);
        h = volfx_polyline_integral(bm.mode.z, int(bm.mode.w), bm.d_r.w, bm.an0.x > 0.0 ? 0.0 : bm.ab_eps.x,
                                    bm.ab_eps.y, bm.ab_eps.z, soft, V, t0, t1);
        if (bm.an0.x > 0.0 && bm.ab_eps.x > 0.0)
            h += bm.ab_eps.x * volfx_prim_piece(V, volfx_joint(bm.mode.z), vec3(0.0), 0.0, false, bm.an0.x, eps,
                                                t0, t1, soft);
        if (bm.an0.y > 0.0 && bm.an0.z > 0.0 && t1 > t0)
            h += bm.an0.z * volfx_prim_piece(V, volfx_joint(bm.mode.z + bm.mode.w - 1u), vec3(0.0), 0.0, false,
                                             bm.an0.y, eps, t0, t1, soft);
#else
        h = volfx_polyline_integral(bm.mode.z, int(bm.mode.w), bm.d_r.w, bm.ab_eps.x, bm.ab_eps.y,
                                    bm.ab_eps.z, soft, V, t0, t1);
#endif
    } else
#endif
#ifdef VOLFX_BEAMS_ANATOMY
        h = volfx_beam_integral_anat(bm.m_l.xyz, bm.d_r.xyz, bm.m_l.w, bm.d_r.w, bm.ab_eps.x, bm.ab_eps.y,
                                     bm.ab_eps.z, soft, bm.an0, bm.an1, V, t0, t1);
#else
        h = volfx_beam_integral(bm.m_l.xyz, bm.d_r.xyz, bm.m_l.w, bm.d_r.w, bm.ab_eps.x, bm.ab_eps.y,
                                bm.ab_eps.z, soft, V, t0, t1);
#endif
    return h;
}
