// impact_depth.glsl — the host's depth buffer as a surface for the beams' impacts
// (plugin/beams/beams_impact.c): camera-relative points (eye at 0) projected with the frame
// gate's vfx_cam_view_proj, the surface point of a pixel and its normal from its neighbours. Also
// the impact's own std140 block (impact_block in beams_impact.c mirrors it) and its buffers.
layout(std140, binding = 5) uniform ImpactFrame {
    vec4 u_eye_dt;      // xyz: the eye relative to the origin (float), w: dt [s]
    vec4 u_params;      // x time (wrapped), y gravity [m/s^2], z spark shutter [s], w glow decay tau [s]
    uvec4 u_counts;     // x beams, y sparks emitted per hit this frame, z frame seed, w 1: water in the frame
};
struct ImpactBeam {
    vec4 p[6];          // axis, camera-relative: head p[0] .. source p[n-1]
    vec4 color;         // rgb: linear colour x gain, w: radius R
    uvec4 info;         // x: points n (0: no segment, no impact)
};
layout(std430, binding = 0) readonly buffer ImpactBeams { ImpactBeam ibeams[]; };
layout(std430, binding = 1) buffer Hits { vec4 hits[]; };       // 3 per beam: pos (w 1: hit), normal, colour
layout(std430, binding = 2) buffer Counters { uint counters[]; }; // hits, sparks alive, glows alive, spark cursor, glow cursor
layout(std430, binding = 3) buffer Sparks { vec4 sparks[]; };   // 3 per spark: pos+age, vel+life, colour
layout(std430, binding = 4) buffer Glows { vec4 glows[]; };     // 3 per glow: pos+age, normal+radius, energy+life
layout(binding = 0) uniform sampler2D u_depth;
layout(binding = 1) uniform sampler2D u_water;  // the water's ray distance (-1: none), when u_counts.w

// The pixel that camera-relative P falls in; false behind the eye or off screen.
bool impact_project(vec3 P, out ivec2 px)
{
    vec4 c = vfx_cam_view_proj * vec4(P, 1.0);
    px = ivec2(0);
    if (!(c.w > 0.0))
        return false;
    vec2 ndc = c.xy / c.w;
    if (!(abs(ndc.x) <= 1.0 && abs(ndc.y) <= 1.0))
        return false;
    vec2 size = vfx_planes_size.zw;
    px = ivec2(clamp(floor((ndc * 0.5 + 0.5) * size), vec2(0.0), size - 1.0));
    return true;
}

// Whether the surface seen at pixel px is the water's (nearer than the host's there).
bool impact_water_at(ivec2 px)
{
    if (u_counts.w == 0u)
        return false;
    float wd = texelFetch(u_water, px, 0).r;
    if (!(wd >= 0.0))
        return false;
    float d = texelFetch(u_depth, px, 0).r;
    if (d >= 1.0)
        return true;
    vec2 ndc = (vec2(px) + 0.5) / vfx_planes_size.zw * 2.0 - 1.0;
    vec4 s = vfx_inv_cam_view_proj * vec4(ndc, d * 2.0 - 1.0, 1.0);
    return wd < length(s.xyz / s.w);
}

// The surface seen at pixel px (its centre's ray at the host depth, or at the water's surface
// where that is nearer), camera-relative; false for the far plane with no water (sky: no surface).
bool impact_surface(ivec2 px, out vec3 S)
{
    float d = texelFetch(u_depth, px, 0).r;
    vec2 ndc = (vec2(px) + 0.5) / vfx_planes_size.zw * 2.0 - 1.0;
    if (impact_water_at(px)) {
        vec4 m = vfx_inv_cam_view_proj * vec4(ndc, 0.0, 1.0);
        S = normalize(m.xyz / m.w) * texelFetch(u_water, px, 0).r;
        return true;
    }
    vec4 s = vfx_inv_cam_view_proj * vec4(ndc, d * 2.0 - 1.0, 1.0);
    S = s.xyz / s.w;
    return d < 1.0;
}

// The unit normal at pixel px (surface point S), facing the eye: from the nearer neighbour on
// each axis, so a depth edge beside the pixel is not taken for a slope.
vec3 impact_normal(ivec2 px, vec3 S)
{
    ivec2 mx = ivec2(vfx_planes_size.zw) - 1;
    vec3 a, b, d[2];
    for (int k = 0; k < 2; ++k) {
        ivec2 o = k == 0 ? ivec2(1, 0) : ivec2(0, 1);
        bool ha = px[k] < mx[k] && impact_surface(px + o, a);
        bool hb = px[k] > 0 && impact_surface(px - o, b);
        vec3 da = a - S, db = S - b;
        d[k] = ha && (!hb || dot(da, da) <= dot(db, db)) ? da : (hb ? db : vec3(0.0));
    }
    vec3 n = cross(d[0], d[1]);
    float l = length(n);
    n = l > 0.0 ? n / l : -normalize(S);
    return dot(n, S) > 0.0 ? -n : n;
}

// 0: nothing known (off screen, behind the eye, sky); 1: P in front of the surface seen at its
// pixel; 2: behind it (beyond the surface's tangent plane). S, n: that surface point and normal.
int impact_classify(vec3 P, out vec3 S, out vec3 n)
{
    ivec2 px;
    S = vec3(0.0);
    n = vec3(0.0, 1.0, 0.0);
    if (!impact_project(P, px) || !impact_surface(px, S))
        return 0;
    n = impact_normal(px, S);
    return dot(P - S, n) < 0.0 ? 2 : 1;
}

float impact_hash(uint x)
{
    x ^= x >> 16; x *= 0x7feb352du; x ^= x >> 15; x *= 0x846ca68bu; x ^= x >> 16;
    return float(x >> 8) * (1.0 / 16777216.0);
}
