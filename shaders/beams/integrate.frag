// Per pixel: H = sum over the beams binned to this pixel's tile of the closed-form integral
// from the eye to the first surface (host depth, water), or the ray-marching baseline when
// VOLFX_BEAMS_MARCH is defined. Writes (H, H-weighted tint) to an RGBA32F target.
#include "beams/beam_field.glsl"

in vec2 v_ndc;
layout(location = 0) out vec4 o_acc;

struct Beam {
    vec4 m_l;    // head relative to the eye, length
    vec4 d_r;    // unit direction, support radius
    vec4 ab_eps; // a, b, eps, unused
    vec4 color;
};
layout(std430, binding = 0) readonly buffer Beams { Beam beams[]; };
layout(std430, binding = 1) readonly buffer Ranges { uvec2 ranges[]; };
layout(std430, binding = 2) readonly buffer List { uint list[]; };

uniform mat4 u_inv_rot_view_proj; // inverse(proj * view without translation): eye at 0
uniform sampler2D u_scene_depth;
uniform sampler2D u_water_dist;
uniform bool u_has_water;
uniform float u_far;
uniform int u_tile_px;
uniform int u_tiles_x;
uniform int u_samples;

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 p = u_inv_rot_view_proj * vec4(v_ndc, 0.0, 1.0);
    vec3 V = normalize(p.xyz / p.w);
    float tmax = u_far;
    float depth = texelFetch(u_scene_depth, px, 0).r;
    if (depth < 1.0) {
        vec4 s = u_inv_rot_view_proj * vec4(v_ndc, depth * 2.0 - 1.0, 1.0);
        tmax = min(tmax, length(s.xyz / s.w));
    }
    if (u_has_water) {
        float wd = texelFetch(u_water_dist, px, 0).r;
        if (wd >= 0.0)
            tmax = min(tmax, wd);
    }
    uvec2 range = ranges[(px.y / u_tile_px) * u_tiles_x + px.x / u_tile_px];
    float H = 0.0;
    vec3 tint = vec3(0.0);
    for (uint k = 0u; k < range.y; ++k) {
        Beam bm = beams[list[range.x + k]];
        float h;
#ifdef VOLFX_BEAMS_MARCH
        // baseline: midpoint samples over the ray's chord through the beam's bounding sphere
        vec3 C = bm.m_l.xyz + 0.5 * bm.m_l.w * bm.d_r.xyz;
        float rad = 0.5 * bm.m_l.w + bm.d_r.w;
        float tc = dot(C, V);
        float disc = rad * rad - (dot(C, C) - tc * tc);
        h = 0.0;
        if (disc > 0.0) {
            float ta = max(tc - sqrt(disc), 0.0), tb = min(tc + sqrt(disc), tmax);
            float dt = (tb - ta) / float(u_samples);
            for (int i = 0; i < u_samples && tb > ta; ++i)
                h += volfx_beam_density(bm.m_l.xyz, bm.d_r.xyz, bm.m_l.w, bm.d_r.w, bm.ab_eps.x,
                                      bm.ab_eps.y, bm.ab_eps.z, (ta + (float(i) + 0.5) * dt) * V) * dt;
        }
#else
        h = volfx_beam_integral(bm.m_l.xyz, bm.d_r.xyz, bm.m_l.w, bm.d_r.w, bm.ab_eps.x, bm.ab_eps.y,
                              bm.ab_eps.z, V, 0.0, tmax);
#endif
        H += h;
        tint += h * bm.color.rgb;
    }
    o_acc = vec4(H, tint);
}
