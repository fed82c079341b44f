// Test probe (tests/beams/test_beam_field.c): the closed form of beam_field.glsl evaluated on the
// test's rays, called as integrate.frag calls it, so that the tests check the shader itself against
// the float64 references. Positions are relative to each ray's origin, as the effect packs them.
layout(local_size_x = 64) in;
struct ProbeCase {
    vec4 m_l;     // head (relative to the ray origin), length
    vec4 d_r;     // unit direction, radius
    vec4 ab_eps;  // a, b, eps, smooth support (1) or hard (0)
    vec4 an0;     // anatomy: head radius, orb radius, orb strength, 0 (all 0 with an1: none)
    vec4 an1;     // taper, surge, 1 / surge wavelength, surge phase
    vec4 v_t0;    // unit ray direction, t0
    vec4 t1_poly; // t1, first joint, joint count (0: straight), 0
};
layout(std430, binding = 0) readonly buffer Cases { ProbeCase cases[]; };
layout(std430, binding = 1) readonly buffer Joints { vec4 joints[]; }; // relative to the ray origin
layout(std430, binding = 2) writeonly buffer Result { float h_out[]; };
uniform uint u_count;
vec3 volfx_joint(uint i) { return joints[i].xyz; }
// every variant of the closed form, as integrate.frag compiles them
#define VOLFX_BEAMS_SMOOTH 1
#define VOLFX_BEAMS_POLYLINE 1
#define VOLFX_BEAMS_ANATOMY 1
#include "beams/beam_field.glsl"

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_count)
        return;
    ProbeCase c = cases[i];
    bool soft = c.ab_eps.w > 0.5;
    vec3 V = c.v_t0.xyz;
    float t0 = c.v_t0.w, t1 = c.t1_poly.x, h;
    uint first = uint(c.t1_poly.y);
    int nj = int(c.t1_poly.z);
    bool anat = any(notEqual(c.an0, vec4(0.0))) || any(notEqual(c.an1, vec4(0.0)));
    if (nj >= 2) {
        float eps = max(c.ab_eps.z, VOLFX_BEAM_EPS_FLOOR * c.d_r.w);
        h = volfx_polyline_integral(first, nj, c.d_r.w, c.an0.x > 0.0 ? 0.0 : c.ab_eps.x, c.ab_eps.y, c.ab_eps.z,
                                    soft, V, t0, t1);
        if (c.an0.x > 0.0 && c.ab_eps.x > 0.0)
            h += c.ab_eps.x * volfx_prim_piece(V, volfx_joint(first), vec3(0.0), 0.0, false, c.an0.x, eps, t0, t1,
                                               soft);
        if (c.an0.y > 0.0 && c.an0.z > 0.0 && t1 > t0)
            h += c.an0.z * volfx_prim_piece(V, volfx_joint(first + uint(nj) - 1u), vec3(0.0), 0.0, false, c.an0.y,
                                            eps, t0, t1, soft);
    } else if (anat) {
        h = volfx_beam_integral_anat(c.m_l.xyz, c.d_r.xyz, c.m_l.w, c.d_r.w, c.ab_eps.x, c.ab_eps.y, c.ab_eps.z, soft,
                                     c.an0, c.an1, V, t0, t1);
    } else {
        h = volfx_beam_integral(c.m_l.xyz, c.d_r.xyz, c.m_l.w, c.d_r.w, c.ab_eps.x, c.ab_eps.y, c.ab_eps.z, soft, V,
                                t0, t1);
    }
    h_out[i] = h;
}
