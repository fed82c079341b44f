// Per-pixel steps of the seed-000 pipeline between billboard passes, one MODE_* define each.
// Pixel state (st): x = flag (0 marching, 1 surface bracketed, 2 left the particles or hit the
// host depth, 3 sample cap reached), y/z = distance and I of the last outside sample, w = samples
// taken. br = (t_neg, I_neg, t_pos, I_pos), the bracket of eqs. 5-6.
#include "common/depth.glsl"
#include "water/frame.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = 4) buffer Counters {
    uint c_culled, c_frags, c_samples, c_found, c_cap, c_left, c_gculled, c_gfrags;
};
layout(binding = 1) uniform sampler2D u_scene_depth;

float scene_t(ivec2 pix)
{
    if (!u_has_depth) return 3.0e38;
    vec2 ndc = (vec2(pix) + 0.5) / vec2(u_size) * 2.0 - 1.0;
    return volfx_depth_distance(u_inv_view_proj, u_eye, ndc, texelFetch(u_scene_depth, pix, 0).r);
}

#if defined(MODE_UPDATE)
layout(rgba32f, binding = 0) uniform image2D u_st;
layout(rgba32f, binding = 1) uniform image2D u_br;
layout(r32f, binding = 2) uniform readonly image2D u_cur;
layout(r32f, binding = 3) uniform writeonly image2D u_next;
layout(binding = 0) uniform sampler2D u_pot;
#elif defined(MODE_PYR0)
layout(r32f, binding = 2) uniform readonly image2D u_cur;
layout(rg32f, binding = 5) uniform writeonly image2D u_dst;
#elif defined(MODE_PYRDOWN)
layout(rg32f, binding = 5) uniform writeonly image2D u_dst;
layout(rg32f, binding = 6) uniform readonly image2D u_src;
#elif defined(MODE_INTERP) || defined(MODE_REFINE) || defined(MODE_FINAL)
layout(rgba32f, binding = 0) uniform image2D u_st;
layout(rgba32f, binding = 1) uniform image2D u_br;
layout(r32f, binding = 2) uniform image2D u_t;
layout(r32f, binding = 3) uniform writeonly image2D u_out;
layout(binding = 0) uniform sampler2D u_pot;
#if defined(MODE_FINAL)
layout(r32f, binding = 4) uniform readonly image2D u_cur;   // the sample the loop would take next
#endif
#elif defined(MODE_POTSUM)
layout(std430, binding = 0) readonly buffer PX { float px[]; };
layout(std430, binding = 1) readonly buffer PY { float py[]; };
layout(std430, binding = 2) readonly buffer PZ { float pz[]; };
layout(r32f, binding = 2) uniform readonly image2D u_cur;
layout(rgba16f, binding = 5) uniform writeonly image2D u_potout;
#endif

// eq. 5, guarded: equal values (flat bracket) give the midpoint.
float interp(vec4 b)
{
    float den = b.w - b.y;
    if (b.x == b.z || abs(den) < 1e-12) return 0.5 * (b.x + b.z);
    return (b.x * b.w - b.z * b.y) / den;
}

void main()
{
    ivec2 pix = ivec2(gl_GlobalInvocationID.xy);
#if defined(MODE_PYRDOWN)
    ivec2 dsz = imageSize(u_dst);
    if (any(greaterThanEqual(pix, dsz))) return;
    ivec2 ssz = imageSize(u_src);
    vec2 mm = vec2(1.0e30, -1.0e30);
    for (int k = 0; k < 4; ++k) {
        ivec2 q = min(pix * 2 + ivec2(k & 1, k >> 1), ssz - 1);
        vec2 v = imageLoad(u_src, q).rg;
        mm = vec2(min(mm.x, v.x), max(mm.y, v.y));
    }
    imageStore(u_dst, pix, vec4(mm, 0.0, 0.0));
    return;
#else
    if (any(greaterThanEqual(pix, u_size))) return;
#endif
#if defined(MODE_UPDATE)
    vec4 s = imageLoad(u_st, pix);
    if (s.x != 0.0) { imageStore(u_next, pix, vec4(1.0e30)); return; }
    float t = imageLoad(u_cur, pix).r;
    float tlim = min(u_t_end, scene_t(pix));
    vec4 pot = texelFetch(u_pot, pix, 0);
    if (t >= 1.0e29 || t > tlim) {
        s.x = 2.0;
    } else {
        for (int k = 0; k < NS; ++k) {
            float ts = t + float(k) * u_step;
            if (ts > tlim) { s.x = 2.0; break; }
            if (uint(s.w) >= u_max_samples) { s.x = 3.0; break; }
            s.w += 1.0;
            atomicAdd(c_samples, 1u);
            float I = sqrt(max(pot[k], 0.0)) - u_T;
            if (I >= 0.0) {
                imageStore(u_br, pix, s.w == 1.0 ? vec4(ts, I, ts, I) : vec4(s.y, s.z, ts, I));
                s.x = 1.0;
                break;
            }
            s.y = ts;
            s.z = I;
        }
    }
    imageStore(u_st, pix, s);
    imageStore(u_next, pix, vec4(s.x == 0.0 ? t + float(NS) * u_step : 1.0e30));
#elif defined(MODE_PYR0)
    float t = imageLoad(u_cur, pix).r;
    // 1e30: stopped ray; < 0: a miss of the final distance image (gradient pass)
    vec2 mm = t >= 1.0e29 || t < 0.0 ? vec2(1.0e30, -1.0e30) : vec2(t, t + float(NS - 1) * u_step);
    imageStore(u_dst, pix, vec4(mm, 0.0, 0.0));
#elif defined(MODE_INTERP)
    vec4 s = imageLoad(u_st, pix);
    imageStore(u_t, pix, vec4(s.x == 1.0 ? interp(imageLoad(u_br, pix)) : 1.0e30));
#elif defined(MODE_REFINE)
    vec4 s = imageLoad(u_st, pix);
    vec4 b = imageLoad(u_br, pix);
    if (s.x != 1.0 || b.x == b.z) return;
    float tt = imageLoad(u_t, pix).r;
    float I = sqrt(max(texelFetch(u_pot, pix, 0).r, 0.0)) - u_T;
    if (I > 0.0) b.zw = vec2(tt, I); else b.xy = vec2(tt, I);   // eq. 6
    imageStore(u_br, pix, b);
    imageStore(u_t, pix, vec4(interp(b)));
#elif defined(MODE_FINAL)
    vec4 s = imageLoad(u_st, pix);
    float tt = imageLoad(u_t, pix).r;
    float r = -1.0;
    float ts = scene_t(pix);
    // The loop runs a fixed ceil(cap / NS) iterations, so a ray that spent its budget with its
    // next sample still inside the box and in front of the host depth ends with flag 0: that is
    // the cap (a hole of the method), not a ray that left. Regula falsi may land a hair behind
    // the host depth: hidden, so counted as left. The final class goes back into st.x
    // (1 found, 2 left, 3 cap) for volfx_water_debug_pixel_class.
    if (s.x == 0.0) {
        float tn = imageLoad(u_cur, pix).r;
        s.x = (tn >= 1.0e29 || tn > min(u_t_end, ts)) ? 2.0 : 3.0;
    }
    if (s.x == 1.0 && !(tt <= ts)) s.x = 2.0;
    if (s.x == 1.0) { r = tt; atomicAdd(c_found, 1u); }
    else if (s.x == 3.0) atomicAdd(c_cap, 1u);
    else atomicAdd(c_left, 1u);
    imageStore(u_st, pix, s);
    imageStore(u_out, pix, vec4(r));
#elif defined(MODE_POTSUM)
    float t = imageLoad(u_cur, pix).r;
    vec4 pot = vec4(0.0);
    if (t < 1.0e29) {
        vec2 ndc = (vec2(pix) + 0.5) / vec2(u_size) * 2.0 - 1.0;
        vec3 dir = volfx_ray_dir(u_inv_view_proj, u_eye, ndc);
        float h2 = u_h * u_h;
        for (uint j = 0u; j < u_count; ++j) {
            vec3 p = vec3(px[j], py[j], pz[j]);
            for (int k = 0; k < NS; ++k) {
                vec3 d = u_eye + (t + float(k) * u_step) * dir - p;
                float r2 = dot(d, d);
                if (r2 < h2) { float q = 1.0 - sqrt(r2) / u_h; pot[k] += q * q; }
            }
        }
    }
    imageStore(u_potout, pix, pot);
#endif
}
