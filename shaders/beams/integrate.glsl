// integrate.glsl — the beams' integrate pass but for H of one beam along a ray: the targets, the
// beams' buffers, the ramps and main(). Its includer declares the joints (volfx_joint), includes
// beams/beam_field.glsl, common/frame.glsl and beams/frame.glsl before it, and defines
// volfx_beam_h after it: integrate.frag the closed form; the lab's march.frag its baseline.

in vec2 v_ndc;
#ifdef VOLFX_BEAMS_WATER
layout(location = 0) out vec2 o_acc;    // H in front of the water, H behind it
layout(location = 1) out vec4 o_light;
layout(location = 2) out vec4 o_behind; // the light behind the water's surface (the water refracts it)
#else
layout(location = 0) out float o_acc;
layout(location = 1) out vec4 o_light;
#endif
// the light's cap: 12 stops above white (tone-mapped white long before), so the light and the
// bloom chain's sum of up to 9 levels stay finite in their RGBA16F targets (largest 65504)
const float LIGHT_MAX = 4096.0;

struct Beam {
    vec4 m_l;    // head relative to the eye, length
    vec4 d_r;    // unit direction, support radius
    vec4 ab_eps; // a, b, eps, 1 / flow wavelength
    vec4 color;  // rgb (thesis ramp: times intensity and 2^exposure)
    vec4 look;   // intensity, 2^exposure / c, flow amount, flow phase
    uvec4 mode;  // smooth falloff, thesis ramp, first joint, joint count (>= 2: a polyline)
    vec4 an0;    // anatomy: head radius (0 -> R), orb radius (0: none), orb strength, 0
    vec4 an1;    // anatomy: taper, surge, 1 / surge wavelength, surge phase
    vec4 look2;  // core (0: version 2's ramp), flow kind (1: spiral), spiral twist, 0
};
layout(std430, binding = 0) readonly buffer Beams { Beam beams[]; };
layout(std430, binding = 1) readonly buffer Ranges { uvec2 ranges[]; };
layout(std430, binding = 2) readonly buffer List { uint list[]; };

layout(binding = 0) uniform sampler2D u_scene_depth;
layout(binding = 1) uniform sampler2D u_water_dist;

float volfx_hash(float n) { return fract(sin(n * 12.9898) * 43758.5453); }

// value noise in [0, 1], two octaves, smooth in x
float volfx_flow_noise(float x)
{
    float i = floor(x), f = fract(x), u = f * f * (3.0 - 2.0 * f);
    float n = mix(volfx_hash(i), volfx_hash(i + 1.0), u);
    float x2 = 2.03 * x + 17.0, i2 = floor(x2), f2 = fract(x2), u2 = f2 * f2 * (3.0 - 2.0 * f2);
    return 0.65 * n + 0.35 * mix(volfx_hash(i2), volfx_hash(i2 + 1.0), u2);
}

// the beam coordinate u (from the head along D, clamped to [0, L]) where the ray t V passes
// nearest the axis: the flow's noise is sampled there, so H stays the exact integral
float volfx_nearest_u(vec3 M, vec3 D, float L, vec3 V)
{
    float b = dot(V, D), d = dot(V, -M), e = dot(D, -M), den = 1.0 - b * b;
    float u = den > 1e-6 ? (e - b * d) / den : e;
    return clamp(u, 0.0, L);
}

#ifdef VOLFX_BEAMS_ANATOMY
// where the ray t V passes the point P: (distance, signed offset along side)
vec2 volfx_pass_point(vec3 P, vec3 V, vec3 side)
{
    vec3 off = max(dot(P, V), 0.0) * V - P;
    return vec2(length(off), dot(off, side));
}

// the ray's nearest approach to the straight axis: (u, distance, signed offset across)
vec3 volfx_nearest(vec3 M, vec3 D, float L, vec3 V)
{
    float u = volfx_nearest_u(M, D, L, V);
    vec3 n = cross(D, V);
    float nn = length(n);
    vec2 dp = volfx_pass_point(M + u * D, V, nn > 1e-6 ? n / nn : vec3(0.0));
    return vec3(u, dp);
}

// light of a hue-keeping beam (docs/beams.md "Colour"): rgb, the colour C (brightest channel
// normalised to 1) x (1 - exp(-x)), so it never passes the intensity and the tone map keeps it
// saturated, plus the core W x C; a, the core's white W (bounded by 3 x intensity, weighted by
// exp(-(d / (core R))^2) where the ray passes at distance d of the axis, the head or the orb),
// which the composite adds as white and the bloom never sees: the bloom is of hued light only
vec4 volfx_core_ramp(Beam bm, float x, float d_axis, vec3 V)
{
    vec3 C = bm.color.rgb / max(max(bm.color.r, bm.color.g), max(bm.color.b, 1e-6));
    float core = bm.look2.x;
    float R = bm.d_r.w, Rh = bm.an0.x > 0.0 ? bm.an0.x : R;
    float q = d_axis / (core * R);
    float w = exp(-q * q);
    if (bm.ab_eps.x > 0.0) {
        float qh = volfx_pass_point(bm.m_l.xyz, V, vec3(0.0)).x / (core * Rh);
        w = max(w, exp(-qh * qh));
    }
    if (bm.an0.y > 0.0 && bm.an0.z > 0.0) {
        vec3 S = bm.mode.w >= 2u ? volfx_joint(bm.mode.z + bm.mode.w - 1u) : bm.m_l.xyz + bm.m_l.w * bm.d_r.xyz;
        float qo = volfx_pass_point(S, V, vec3(0.0)).x / (core * bm.an0.y);
        w = max(w, exp(-qo * qo));
    }
    float W = 3.0 * w * (1.0 - exp(-x * x / 9.0));
    return bm.look.x * vec4(C * (1.0 - exp(-x) + W), W);
}
#endif

#ifdef VOLFX_BEAMS_POLYLINE
// the same for a polyline: arc length from J0 at the nearest approach to the nearest segment
float volfx_poly_nearest_u(uint first, int nj, vec3 V)
{
    float best = 1e30, u = 0.0, s = 0.0;
    for (int k = 0; k + 1 < nj; ++k) {
        vec3 A = volfx_joint(first + uint(k)), e = volfx_joint(first + uint(k + 1)) - A;
        float len = length(e);
        if (!(len > 0.0))
            continue;
        vec3 D = e / len;
        float uk = volfx_nearest_u(A, D, len, V);
        vec3 P = A + uk * D;
        float t = max(dot(P, V), 0.0);
        float d2 = dot(t * V - P, t * V - P);
        if (d2 < best) {
            best = d2;
            u = s + uk;
        }
        s += len;
    }
    return u;
}

#ifdef VOLFX_BEAMS_ANATOMY
// the same as volfx_nearest for a polyline: (arc length, distance, signed offset across)
vec3 volfx_poly_nearest(uint first, int nj, vec3 V)
{
    float best = 1e30, s = 0.0;
    vec3 res = vec3(0.0, 1e30, 0.0);
    for (int k = 0; k + 1 < nj; ++k) {
        vec3 A = volfx_joint(first + uint(k)), e = volfx_joint(first + uint(k + 1)) - A;
        float len = length(e);
        if (!(len > 0.0))
            continue;
        vec3 r = volfx_nearest(A, e / len, len, V);
        if (r.y < best) {
            best = r.y;
            res = vec3(s + r.x, r.y, r.z);
        }
        s += len;
    }
    return res;
}
#endif
#endif

// H of one beam along the pixel ray t V over [t0, t1] (the includer's)
float volfx_beam_h(Beam bm, vec3 V, float t0, float t1);

// The light of a hot-ramp beam whose H along the ray is h > 0: rgb, and a = the hue-keeping
// ramp's white core (the composite adds it as white; the bloom never sees it)
vec4 volfx_beam_light(Beam bm, float h, vec3 V)
{
    // capped where the pixel is white anyway: beam_settings.c 1e-30 or exposure 64 made
    // x * x Inf, the ramp Inf / Inf NaN, and the beam vanished (issue 28)
    float x = min(h * bm.look.y, LIGHT_MAX);
#ifdef VOLFX_BEAMS_POLYLINE
    bool poly = bm.mode.w >= 2u;
#endif
#ifdef VOLFX_BEAMS_ANATOMY
    if (bm.look2.x > 0.0 || bm.look2.y > 0.0) {
#ifdef VOLFX_BEAMS_POLYLINE
        vec3 nr = poly ? volfx_poly_nearest(bm.mode.z, int(bm.mode.w), V)
                       : volfx_nearest(bm.m_l.xyz, bm.d_r.xyz, bm.m_l.w, V);
#else
        vec3 nr = volfx_nearest(bm.m_l.xyz, bm.d_r.xyz, bm.m_l.w, V);
#endif
        if (bm.look.z > 0.0) {
            float ph = nr.x * bm.ab_eps.w - bm.look.w, n;
            if (bm.look2.y > 0.0) { // a helix: stripes slanted by twist wavelengths across the tube
                float phi = asin(clamp(nr.z / bm.d_r.w, -1.0, 1.0));
                float c = 0.5 + 0.5 * cos(6.2831853 * (ph + bm.look2.z * phi / 3.14159265));
                n = c * c;
            } else {
                n = volfx_flow_noise(ph);
            }
            x *= 1.0 + bm.look.z * (2.0 * n - 1.0);
        }
        if (bm.look2.x > 0.0)
            return volfx_core_ramp(bm, x, nr.y, V);
    } else
#endif
    if (bm.look.z > 0.0) {
#ifdef VOLFX_BEAMS_POLYLINE
        float u = poly ? volfx_poly_nearest_u(bm.mode.z, int(bm.mode.w), V)
                       : volfx_nearest_u(bm.m_l.xyz, bm.d_r.xyz, bm.m_l.w, V);
#else
        float u = volfx_nearest_u(bm.m_l.xyz, bm.d_r.xyz, bm.m_l.w, V);
#endif
        x *= 1.0 + bm.look.z * (2.0 * volfx_flow_noise(u * bm.ab_eps.w - bm.look.w) - 1.0);
    }
    float x2 = x * x;
    return vec4(bm.look.x * x * (bm.color.rgb + (1.0 - bm.color.rgb) * (x2 / (x2 + 9.0))), 0.0);
}

// the thesis ramp's light of the summed H of its beams (tint: their H-weighted colour sum)
vec3 volfx_thesis_light(float Hth, vec3 tint)
{
    if (!(Hth > 0.0))
        return vec3(0.0);
    float I = u_smooth_saturation != 0 ? 1.0 - exp(-Hth / u_c) : min(Hth / u_c, 1.0);
    return tint / Hth * I;
}

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 p = vfx_inv_cam_view_proj * vec4(v_ndc, 0.0, 1.0);
    vec3 V = normalize(p.xyz / p.w);
    float tmax = u_far;
    float depth = texelFetch(u_scene_depth, px, 0).r;
    if (depth < 1.0) {
        vec4 s = vfx_inv_cam_view_proj * vec4(v_ndc, depth * 2.0 - 1.0, 1.0);
        tmax = min(tmax, length(s.xyz / s.w));
    }
    // the water's surface splits the ray: [0, tw] is seen over the water, [tw, tmax] through it
    // (the closed form is additive: H(0, tmax) = H(0, tw) + H(tw, tmax))
    float tw = tmax;
    if (u_has_water != 0) {
        float wd = texelFetch(u_water_dist, px, 0).r;
        if (wd >= 0.0)
            tw = min(tmax, wd);
    }
    uvec2 range = ranges[(px.y / u_tile_px) * u_tiles_x + px.x / u_tile_px];
    float H = 0.0, Hth = 0.0;
    vec3 tint = vec3(0.0);
    vec4 light = vec4(0.0); // rgb; a: the hue-keeping beams' white cores (added by the composite, not bloomed)
#ifdef VOLFX_BEAMS_WATER
    float Hb = 0.0, Hth_b = 0.0;
    vec3 tint_b = vec3(0.0);
    vec4 behind = vec4(0.0);
    bool split = tw < tmax;
    // With water the pass draws three times (beams_effect.c integrate_draws): VOLFX_BEAMS_MARK
    // stencils the pixels with water in front (split), this program without VOLFX_BEAMS_DRY
    // draws those, with it the others (no part behind: one integral a beam, not two)
#ifdef VOLFX_BEAMS_MARK
    if (!split)
        discard;
    o_acc = vec2(0.0);
    o_light = vec4(0.0);
    o_behind = vec4(0.0);
    return;
#endif
#endif
    for (uint k = 0u; k < range.y; ++k) {
        Beam bm = beams[list[range.x + k]];
        float h = volfx_beam_h(bm, V, 0.0, tw);
        H += h;
#ifdef VOLFX_BEAMS_WATER
        // behind the surface: the light of the whole ray less the light in front, so that where
        // the water is clear the two add up to the beam's light without water (the ramp is not
        // linear in H); a pixel without water in front (the dry draw) has nothing behind
#ifdef VOLFX_BEAMS_DRY
        float hb = 0.0;
#else
        float hb = split ? volfx_beam_h(bm, V, tw, tmax) : 0.0;
#endif
        Hb += hb;
        if (bm.mode.y != 0u) {
            Hth += h, Hth_b += hb;
            tint += h * bm.color.rgb, tint_b += hb * bm.color.rgb;
        } else {
            vec4 lf = h > 0.0 ? volfx_beam_light(bm, h, V) : vec4(0.0);
            light += lf;
#ifndef VOLFX_BEAMS_DRY
            if (hb > 0.0)
                behind += max(volfx_beam_light(bm, h + hb, V) - lf, vec4(0.0));
#endif
        }
#else
        if (bm.mode.y != 0u) {
            Hth += h;
            tint += h * bm.color.rgb;
        } else if (h > 0.0) {
            light += volfx_beam_light(bm, h, V);
        }
#endif
    }
    light.rgb += volfx_thesis_light(Hth, tint);
#ifdef VOLFX_BEAMS_WATER
#ifndef VOLFX_BEAMS_DRY
    if (Hth_b > 0.0)
        behind.rgb += max(volfx_thesis_light(Hth + Hth_b, tint + tint_b) - volfx_thesis_light(Hth, tint), vec3(0.0));
#endif
    o_acc = vec2(H, Hb);
    o_behind = min(behind, vec4(LIGHT_MAX));
#else
    o_acc = H;
#endif
    o_light = min(light, vec4(LIGHT_MAX)); // finite whatever the gain
}
