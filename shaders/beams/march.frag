// march.frag — the lab's ray-marching baseline of the beams' integrate pass (plugin/lab/lab_beams.c,
// vfx_lab_beams): the product's pass (beams/integrate.glsl: targets, ramps, the water's split)
// with H sampled from the raw density, u_march_samples midpoints per ray, instead of the closed
// form. In the lab's shader table only: libvolfx carries none of it.
layout(std430, binding = 4) readonly buffer Joints { vec4 joints[]; }; // xyz relative to the eye
vec3 volfx_joint(uint i) { return joints[i].xyz; }
#include "beams/beam_field.glsl"
#include "common/frame.glsl"
#include "beams/frame.glsl"
#include "beams/integrate.glsl"

uniform int u_march_samples; // samples per ray (the lab sets it: vfx_lab_beams.march_samples)

// the raw density (for the ray-marching baseline), P relative to the eye
float volfx_beam_density(vec3 M, vec3 D, float L, float R, float a, float b, float eps_in, bool soft,
                         vec3 P)
{
    float eps = max(eps_in, VOLFX_BEAM_EPS_FLOOR * R);
    vec3 d = P - M;
    float d2 = dot(d, d), u = dot(d, D), rho = 0.0;
    float wh = soft ? (1.0 - d2 / (R * R)) * (1.0 - d2 / (R * R)) : 1.0;
    if (d2 <= R * R)
        rho += a * wh / sqrt(d2 + eps * eps);
    vec3 q = u < 0.0 ? d : (u > L ? d - L * D : d - u * D);
    float r2 = dot(q, q);
    float wt = soft ? (1.0 - r2 / (R * R)) * (1.0 - r2 / (R * R)) : 1.0;
    if (r2 <= R * R)
        rho += b * wt / sqrt(r2 + eps * eps);
    return rho;
}

#ifdef VOLFX_BEAMS_POLYLINE
// the raw polyline density (ray-marching baseline)
float volfx_polyline_density(uint first, int nj, float R, float a, float b, float eps_in, bool soft, vec3 P)
{
    float eps = max(eps_in, VOLFX_BEAM_EPS_FLOOR * R), rho = 0.0;
    vec3 d0 = P - volfx_joint(first);
    float d2 = dot(d0, d0), r2 = 1e30;
    for (int k = 0; k + 1 < nj; ++k) {
        vec3 A = volfx_joint(first + uint(k)), e = volfx_joint(first + uint(k + 1)) - A, w = P - A;
        float ee = dot(e, e), u = ee > 0.0 ? clamp(dot(w, e) / ee, 0.0, 1.0) : 0.0;
        vec3 q = w - u * e;
        r2 = min(r2, dot(q, q));
    }
    float wh = soft ? (1.0 - d2 / (R * R)) * (1.0 - d2 / (R * R)) : 1.0;
    float wt = soft ? (1.0 - r2 / (R * R)) * (1.0 - r2 / (R * R)) : 1.0;
    if (d2 <= R * R)
        rho += a * wh / sqrt(d2 + eps * eps);
    if (r2 <= R * R)
        rho += b * wt / sqrt(r2 + eps * eps);
    return rho;
}
#endif

// H of one beam along the pixel ray t V over [t0, t1]: the baseline, midpoint samples of the
// raw density over the ray's chord through the beam's bounding sphere
float volfx_beam_h(Beam bm, vec3 V, float t0, float t1)
{
    bool soft = bm.mode.x != 0u;
#ifdef VOLFX_BEAMS_POLYLINE
    bool poly = bm.mode.w >= 2u;
#endif
    float h;
    vec3 C = bm.m_l.xyz + 0.5 * bm.m_l.w * bm.d_r.xyz;
    float rad = 0.5 * bm.m_l.w + bm.d_r.w;
    float tc = dot(C, V);
    float disc = rad * rad - (dot(C, C) - tc * tc);
    h = 0.0;
    if (disc > 0.0) {
        float ta = max(tc - sqrt(disc), t0), tb = min(tc + sqrt(disc), t1);
        float dt = (tb - ta) / float(u_march_samples);
        for (int i = 0; i < u_march_samples && tb > ta; ++i) {
            vec3 P = (ta + (float(i) + 0.5) * dt) * V;
#ifdef VOLFX_BEAMS_POLYLINE
            if (poly)
                h += volfx_polyline_density(bm.mode.z, int(bm.mode.w), bm.d_r.w, bm.ab_eps.x, bm.ab_eps.y,
                                            bm.ab_eps.z, soft, P) * dt;
            else
#endif
                h += volfx_beam_density(bm.m_l.xyz, bm.d_r.xyz, bm.m_l.w, bm.d_r.w, bm.ab_eps.x,
                                        bm.ab_eps.y, bm.ab_eps.z, soft, P) * dt;
        }
    }
    return h;
}
