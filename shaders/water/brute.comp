// Baseline (vfx_water_params.method = BRUTE): per pixel, march the ray over ALL particles.
// Same sampling rule as the paper's method (start at the nearest sphere of influence, step w,
// at most max_samples samples, eq. 5 interpolation then eq. 6 regula falsi), so errors compare.
#include "common/depth.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = 0) readonly buffer PX { float px[]; };
layout(std430, binding = 1) readonly buffer PY { float py[]; };
layout(std430, binding = 2) readonly buffer PZ { float pz[]; };
layout(r32f, binding = 0) uniform writeonly image2D u_dist;
layout(binding = 1) uniform sampler2D u_scene_depth;
uniform mat4 u_inv_view_proj;
uniform vec3 u_eye;
uniform uint u_count;
uniform float u_h, u_T, u_step;
uniform uint u_max_samples, u_refine_iters;
uniform bool u_has_depth;

// llvmpipe ends every loop of an invocation after 65535 iterations in all (a budget shared by
// all loops of the shader, LP_MAX_TGSI_LOOP_ITERATIONS): a plain loop over N particles per
// sample ran out at ~65535 / N samples, which left holes (0.64% at 4,096 particles, 100% at
// 16,384). The loops over particles therefore take 32 particles per iteration.
#define X32(M, j) X8(M, j) X8(M, j + 8u) X8(M, j + 16u) X8(M, j + 24u)
#define X8(M, j) M(j) M(j + 1u) M(j + 2u) M(j + 3u) M(j + 4u) M(j + 5u) M(j + 6u) M(j + 7u)
#define POT(j) { vec3 d = x - vec3(px[j], py[j], pz[j]); float r2 = dot(d, d); \
    if (r2 < h2) { float q = 1.0 - sqrt(r2) / u_h; s += q * q; } }
float field(vec3 x)
{
    float s = 0.0, h2 = u_h * u_h;
    uint j = 0u;
    // NaN positions fail the r2 < h2 comparison: skipped
    for (; j + 32u <= u_count; j += 32u) { X32(POT, j) }
    for (; j < u_count; ++j) POT(j)
    return sqrt(s) - u_T;
}

void main()
{
    ivec2 pix = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(u_dist);
    if (any(greaterThanEqual(pix, size))) return;
    vec2 ndc = (vec2(pix) + 0.5) / vec2(size) * 2.0 - 1.0;
    vec3 dir = volfx_ray_dir(u_inv_view_proj, u_eye, ndc);
    float t_scene = 3.0e38;
    if (u_has_depth)
        t_scene = volfx_depth_distance(u_inv_view_proj, u_eye, ndc, texelFetch(u_scene_depth, pix, 0).r);
    // eq. 1 per pixel, exact sphere instead of the cube face: the nearest entry into any
    // particle's sphere of influence.
    float t0 = 3.0e38;
#define ENTRY(j) { vec3 oc = u_eye - vec3(px[j], py[j], pz[j]); \
    float b = dot(oc, dir), c = dot(oc, oc) - u_h * u_h, disc = b * b - c; \
    if (disc >= 0.0) t0 = min(t0, max(0.0, -b - sqrt(disc))); }
    uint j = 0u;
    for (; j + 32u <= u_count; j += 32u) { X32(ENTRY, j) }
    for (; j < u_count; ++j) ENTRY(j)
    float result = -1.0;
    if (t0 < t_scene) {
        float t_prev = t0, f_prev = field(u_eye + t0 * dir);
        if (f_prev >= 0.0) result = t0;
        for (uint k = 1u; k < u_max_samples && result < 0.0; ++k) {
            float t = t0 + float(k) * u_step;
            if (t > t_scene) break;
            float f = field(u_eye + t * dir);
            if (f >= 0.0) {
                float a = t_prev, fa = f_prev, b = t, fb = f;
                float tt = (a * fb - b * fa) / (fb - fa); // eq. 5
                for (uint it = 0u; it < u_refine_iters; ++it) { // eq. 6
                    float ft = field(u_eye + tt * dir);
                    if (ft > 0.0) { b = tt; fb = ft; } else { a = tt; fa = ft; }
                    tt = (a * fb - b * fa) / (fb - fa);
                }
                result = tt <= t_scene ? tt : -1.0;
            }
            t_prev = t;
            f_prev = f;
        }
    }
    imageStore(u_dist, pix, vec4(result));
}
