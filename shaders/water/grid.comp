// Baseline GRID (vfx_water_params.method = GRID): a uniform particle grid built on the GPU,
// then a per-pixel ray march over it. One MODE_* define per dispatch:
//   MODE_COUNT    per particle: count[cell] += 1 (non-finite particles skipped)
//   (prefix sum of count[] into start[]: common/scan.comp, plugin/gpu/scan.h)
//   MODE_SCATTER  per particle: sorted[start[cell] + fill[cell]++] = position
//   MODE_MARCH    per pixel: the same sampling rule as brute.comp (step w, at most max_samples
//                 field samples, eq. 5 then eq. 6 regula falsi) with the field summed over the
//                 cells the sample's h-ball touches, and empty-space skipping along the ray.
// Cells are at least h wide, so a point's h-ball touches at most 3 cells per axis; the cells
// of one x-row are contiguous in sorted[], so a row of cells is one index range.
#include "common/depth.glsl"
#if defined(MODE_MARCH)
layout(local_size_x = 8, local_size_y = 8) in;
#else
layout(local_size_x = 64) in;
#endif
layout(std430, binding = 0) readonly buffer PX { float px[]; };
layout(std430, binding = 1) readonly buffer PY { float py[]; };
layout(std430, binding = 2) readonly buffer PZ { float pz[]; };
layout(std430, binding = 3) buffer Count { uint count[]; };   // counts, then the scatter fill
// the water effect's counter buffer (march.comp's layout; the first two and the gradient
// pass's two are not GRID's), copied into its fenced readback ring at the end of the frame
layout(std430, binding = 4) buffer Counters {
    uint c_culled_, c_frags_, c_samples, c_found, c_cap, c_left, c_gculled_, c_gfrags_, c_cells, c_tests;
};
layout(std430, binding = 5) buffer Start { uint start[]; };   // ncells + 1 entries (+ padding)
layout(std430, binding = 7) buffer Sorted { vec4 sorted[]; };
uniform uint u_count;   // particles in the columns (non-finite included)
uniform vec3 u_g0;      // grid origin
uniform float u_cs;     // cell size (>= h)
uniform ivec3 u_dims;

ivec3 cell_of(vec3 p)
{
    return clamp(ivec3(floor((p - u_g0) / u_cs)), ivec3(0), u_dims - 1);
}

uint linear(ivec3 c) { return uint(c.x + u_dims.x * (c.y + u_dims.y * c.z)); }

#if defined(MODE_MARCH)
layout(r32f, binding = 0) uniform writeonly image2D u_dist;
layout(binding = 1) uniform sampler2D u_scene_depth;
uniform mat4 u_inv_view_proj;
uniform vec3 u_eye;
uniform float u_h, u_T, u_step;
uniform uint u_max_samples, u_refine_iters;
uniform bool u_has_depth, u_seek_init, u_seek_gaps;
uniform vec3 u_blo, u_bhi; // particles' box grown by h: no potential outside it

// llvmpipe ends every loop of an invocation after 65535 iterations in all (one budget shared
// by all loops, LP_MAX_TGSI_LOOP_ITERATIONS), which would leave holes where rays take many
// samples in dense cells: the loops over a row's particles take 4 per iteration.
#define X4(M, j) M(j) M(j + 1u) M(j + 2u) M(j + 3u)

// sum_j P(|x - p_j|) over the cells x's h-ball touches.
float pot_sum(vec3 x)
{
    ivec3 lo = cell_of(x - vec3(u_h)), hi = cell_of(x + vec3(u_h));
    float s = 0.0, h2 = u_h * u_h;
    for (int z = lo.z; z <= hi.z; ++z)
        for (int y = lo.y; y <= hi.y; ++y) {
            uint row = linear(ivec3(0, y, z));
            uint a = start[row + uint(lo.x)], b = start[row + uint(hi.x) + 1u];
#define POT(j) { vec3 d = x - sorted[j].xyz; float r2 = dot(d, d); \
    if (r2 < h2) { float q = 1.0 - sqrt(r2) / u_h; s += q * q; } }
            uint j = a;
            for (; j + 4u <= b; j += 4u) { X4(POT, j) }
            for (; j < b; ++j) POT(j)
        }
    return s;
}

// Nearest t >= t0 where the ray enters (or already is in) the sphere of influence of a
// particle whose sphere can reach cell c: those are in c's 27 neighbours. 3e38 if none.
float next_entry(vec3 dir, float t0, ivec3 c, inout uint tests)
{
    ivec3 lo = max(c - 1, ivec3(0)), hi = min(c + 1, u_dims - 1);
    float best = 3.0e38, h2 = u_h * u_h;
    for (int z = lo.z; z <= hi.z; ++z)
        for (int y = lo.y; y <= hi.y; ++y) {
            uint row = linear(ivec3(0, y, z));
            uint a = start[row + uint(lo.x)], b = start[row + uint(hi.x) + 1u];
            tests += b - a;
#define ENTRY(j) { vec3 oc = u_eye - sorted[j].xyz; \
    float bb = dot(oc, dir), disc = bb * bb - (dot(oc, oc) - h2); \
    if (disc > 0.0) { float sq = sqrt(disc); if (-bb + sq > t0) best = min(best, max(t0, -bb - sq)); } }
            uint j = a;
            for (; j + 4u <= b; j += 4u) { X4(ENTRY, j) }
            for (; j < b; ++j) ENTRY(j)
        }
    return best;
}

// 1/dir with zero components replaced by 1/1e-20: an axis-parallel ray's slab bounds become
// huge but finite (0 * inf would be NaN, which min/max do not order).
vec3 safe_inv(vec3 d)
{
    return 1.0 / mix(d, vec3(1.0e-20), lessThan(abs(d), vec3(1.0e-20)));
}

// Distance along the ray at which it leaves cell c (the ray is in c at t).
float cell_exit(vec3 dir, ivec3 c)
{
    vec3 lo = u_g0 + vec3(c) * u_cs, hi = lo + vec3(u_cs);
    vec3 inv = safe_inv(dir);
    vec3 ta = (lo - u_eye) * inv, tb = (hi - u_eye) * inv;
    vec3 tm = max(ta, tb);
    return min(tm.x, min(tm.y, tm.z));
}
#endif

void main()
{
#if defined(MODE_COUNT) || defined(MODE_SCATTER)
    // 2D dispatch: past 65535 groups of 64 (4.2 M particles) the x count alone may not suffice
    uint i = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u;
    if (i >= u_count) return;
    vec3 p = vec3(px[i], py[i], pz[i]);
    if (any(isnan(p)) || any(isinf(p))) return; // skipped (counted on the CPU)
    uint c = linear(cell_of(p));
#if defined(MODE_COUNT)
    atomicAdd(count[c], 1u);
#else
    sorted[start[c] + atomicAdd(count[c], 1u)] = vec4(p, 0.0);
#endif
#elif defined(MODE_MARCH)
    ivec2 pix = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(u_dist);
    if (any(greaterThanEqual(pix, size))) return;
    vec2 ndc = (vec2(pix) + 0.5) / vec2(size) * 2.0 - 1.0;
    vec3 dir = volfx_ray_dir(u_inv_view_proj, u_eye, ndc);
    float t_scene = 3.0e38;
    if (u_has_depth)
        t_scene = volfx_depth_distance(u_inv_view_proj, u_eye, ndc, texelFetch(u_scene_depth, pix, 0).r);
    // ray against the particles' box grown by h (slabs)
    vec3 inv = safe_inv(dir);
    vec3 ta = (u_blo - u_eye) * inv, tb = (u_bhi - u_eye) * inv;
    vec3 tn = min(ta, tb), tf = max(ta, tb);
    float t_in = max(max(tn.x, max(tn.y, tn.z)), 0.0), t_out = min(tf.x, min(tf.y, tf.z));
    float t_lim = min(t_out, t_scene);
    float result = -1.0;
    uint n = 0u, cells = 0u, tests = 0u;
    int state = 2; // 1 found, 2 left the box or hit the host depth, 3 sample cap
    float eps = 1.0e-4 * u_cs;
    if (t_in <= t_lim) {
        // seeking: jump to the next sphere entry at or after t_seek, sampling no earlier than
        // t_min (the regular next sample). Cells whose neighbourhood holds no particle cost
        // one row-range lookup each (the DDA over empty cells).
        bool seeking = u_seek_init;
        float t = t_in, t_seek = t_in, t_min = t_in;
        float t_prev = 0.0, f_prev = 0.0;
        bool have_prev = false;
        int guard = 4 * (u_dims.x + u_dims.y + u_dims.z) + int(u_max_samples) + 16;
        for (int it = 0; it < 100000; ++it) {
            if (seeking) {
                if (t_seek > t_lim || guard-- <= 0) break;
                ivec3 c = cell_of(u_eye + t_seek * dir);
                float tx = cell_exit(dir, c);
                ++cells;
                float te = next_entry(dir, t_seek, c, tests);
                if (te > tx) { t_seek = max(tx, t_seek) + eps; continue; }
                t = max(te, t_min);
                seeking = false;
            }
            if (t > t_lim) break;
            if (n >= u_max_samples) { state = 3; break; }
            float s = pot_sum(u_eye + t * dir);
            float f = sqrt(s) - u_T;
            ++n;
            if (f >= 0.0) {
                state = 1;
                if (!have_prev) { result = t; break; }
                float a = t_prev, fa = f_prev, b = t, fb = f;
                float tt = (a * fb - b * fa) / (fb - fa); // eq. 5
                for (uint k = 0u; k < u_refine_iters; ++k) { // eq. 6
                    float ft = sqrt(pot_sum(u_eye + tt * dir)) - u_T;
                    if (ft > 0.0) { b = tt; fb = ft; } else { a = tt; fa = ft; }
                    tt = (a * fb - b * fa) / (fb - fa);
                }
                result = tt;
                break;
            }
            t_prev = t;
            f_prev = f;
            have_prev = true;
            // no particle within h of this sample: the field is 0 up to the next sphere entry
            if (u_seek_gaps && s == 0.0) {
                seeking = true;
                t_seek = t;
                t_min = t + u_step;
            } else {
                t += u_step;
            }
        }
    }
    if (result > t_scene) { result = -1.0; state = 2; }
    imageStore(u_dist, pix, vec4(result));
    atomicAdd(c_samples, n);
    atomicAdd(c_cells, cells);
    atomicAdd(c_tests, tests);
    if (state == 1) atomicAdd(c_found, 1u);
    else if (state == 3) atomicAdd(c_cap, 1u);
    else atomicAdd(c_left, 1u);
#endif
}
