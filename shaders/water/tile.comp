// Method TILE (ours, the default in scenes): particles binned per 8x8 screen tile on the GPU,
// then a per-pixel march over the tile's list that cannot end undecided. One MODE_* per dispatch:
//   MODE_COUNT    per particle: the tiles its cube of half-size h projects onto; count[tile] += 1
//                 (a particle over more than u_global_tiles tiles goes to the global list instead)
//   (prefix sum of count[] into start[]: common/scan.comp, plugin/gpu/scan.h)
//   MODE_SCATTER  per particle: entries[start[tile] + fill[tile]++] = position (while it fits
//                 the capacity; a tile that does not fit reads every particle instead)
//   MODE_MARCH    per pixel: exact ray interval from the tile's list (first sphere entry), then
//                 windows along the ray, each with a local list of the spheres that overlap it
//                 (exact potential there), steps of w with a per-interval upper bound of the
//                 field that opens dyadic subintervals where a feature could hide between two
//                 samples; regula falsi; gradient and back distance from the same lists.
//   MODE_FINISH   per pixel of the paper method that spent its sample cap: the same march from
//                 the paper's next sample, its last outside sample as the bracket's start.
//   MODE_REPROJECT per pixel of the previous frame: its hit point (world space, kept by the
//                 march) projected with this frame's camera; the 2x2 pixels around it take the
//                 nearest distance (atomicMin), each pixel's guess for MODE_MARCH (temporal reuse).
// MODE_MARCH's u_half: 0 every pixel; 1 the coarse pass (pixels with even x and y); 2 the other
// pixels, upsampled from their coarse neighbours where those agree, else appended to a list;
// 3 the listed pixels marched (an indirect dispatch: whole groups of pixels that all march).
// ANISO (any mode): per-particle kernels (water_aniso.c): particle i adds P(|G_i (x - c_i)|)
// around its centre c_i; along a ray |G (x - c)|^2 = a (t - tc)^2 + b2 with a = |G d|^2, so
// every sphere test below is the same quadratic with a per-entry a (isotropic: a = 1). The
// binning takes the ellipsoid's axis-aligned box and files it by its nearest possible entry.
// Every loop is bounded by a constant or by a list length; see docs/water-method.md "Method TILE".
#include "common/depth.glsl"
#if defined(MODE_MARCH) || defined(MODE_FINISH) || defined(MODE_REPROJECT)
layout(local_size_x = 8, local_size_y = 8) in;
#else
layout(local_size_x = 64) in;
#endif
layout(std430, binding = 0) readonly buffer PX { float px[]; };
layout(std430, binding = 1) readonly buffer PY { float py[]; };
layout(std430, binding = 2) readonly buffer PZ { float pz[]; };
layout(std430, binding = 3) buffer Count { uint tcount[]; };   // counts, then the scatter fill
// the water effect's counter buffer (march.comp's first 8 slots, grid.comp's next 2)
layout(std430, binding = 4) buffer Counters {
    uint c_culled_, c_frags_, c_samples, c_found, c_cap, c_left, c_gculled_, c_gfrags_, c_cells_, c_tests_,
         c_entries, c_finished, c_undecided, c_dense, c_tile_tests, c_subdiv, c_global, c_overflow,
         c_reused, c_fallback, c_skipped, c_proof, c_upsampled, c_remarched;
};
layout(std430, binding = 5) buffer Start { uint tstart[]; };
layout(std430, binding = 7) buffer Entries { vec4 entries[]; };
layout(std430, binding = 8) buffer Globals { uint gcount, gpad0, gpad1, gpad2; vec4 globals[]; };
#if defined(ANISO)
// per particle: centre (w bounding radius), G (xx xy xz yy), G (yz zz), half-extents
layout(std430, binding = 9) readonly buffer Kern { vec4 kern[]; };
layout(std430, binding = 10) buffer EntryId { uint eid[]; };   // the particle of each entry
#endif
// Every constant of a TILE frame, one std140 block uploaded once a frame by water_tile.c
// (tile_block mirrors it; binding TILE_UBO_BINDING there). Only the three switches that differ
// between the dispatches of one frame (u_half, u_temporal, u_reuse) are loose uniforms.
layout(std140, binding = 5) uniform WaterTile {
    mat4 u_view_proj;       // proj * view: binning and reprojection
    mat4 u_inv_view_proj;   // clip -> world: the march's rays
    vec3 u_eye;
    float u_h;
    ivec2 u_tiles;          // tiles across, down
    ivec2 u_size;           // pixels
    uint u_count;           // particles in the columns (non-finite included)
    uint u_cap;             // entries the Entries buffer holds
    uint u_global_tiles;    // a particle covering more tiles goes to the global list
    int u_tile_shift;       // tiles of 2^shift pixels a side: 8, or more when 8x8 tiles would pass the scan's 2^20
    // Depth slabs: within a tile the entries are in slab order of the distance from the eye (key
    // tile * u_slabs + slab), each entry's w the near bound of its slab, so a scan that only
    // needs spheres entering before some distance stops at the first entry whose slab starts
    // past it.
    uint u_slabs;
    float u_d0, u_ds;
    float u_rbound;         // ANISO: a bound of every particle's bounding radius (last_exit's early stop)
    float u_T, u_step, u_window, u_rho;
    uint u_refine_iters;
    bool u_has_depth, u_subdivide, u_local;
    // the bound-driven subdivision's depth: 4 at steps of h/8 (nodes of h/128), one more per
    // doubling of the step (at most 7 at steps of h), so the finest node stays h/128 or less
    int u_sub_depth;
    float u_half_tol;       // upsample: the neighbours' plane predictions agree within this
    float u_half_cos;       // upsample: the neighbours' normals agree within this cosine
    uint u_tile_pad0;
};
#if defined(MODE_MARCH) || defined(MODE_REPROJECT)
// temporal reuse: last frame's hit points (world space; x groups of 64 for the indirect dispatch,
// the count, then the points: only found pixels append, so a frame where the water covers a
// small part of the screen reprojects only that part), this frame's guesses per pixel (the
// float bits of a distance along the ray; 0xffffffff none)
layout(std430, binding = 12) buffer Hits { uint hit_groups, hit_gy, hit_gz, hit_count; vec4 hits[]; };
layout(std430, binding = 13) buffer Guess { uint guess[]; };
#endif
#if defined(MODE_MARCH)
// the pixels u_half 2 could not upsample: x groups of 64 for the indirect dispatch, the count,
// then pixel indices
layout(std430, binding = 14) buffer Remarch { uint rm_groups, rm_gy, rm_gz, rm_count; uint rm_pix[]; };
#endif

#if defined(MODE_COUNT) || defined(MODE_SCATTER)
// Tiles whose pixel centres the box p +- ext can cover (the cube of half-size h bounds the
// sphere of influence, the ellipsoid's axis-aligned box its ellipsoid, so a ray through a
// centre outside the rectangle misses it). false: off screen or behind.
bool tile_rect(vec3 p, vec3 ext, out ivec4 r)
{
    vec2 lo = vec2(3.0e38), hi = vec2(-3.0e38);
    int behind = 0, near = 0;
    for (int k = 0; k < 8; ++k) {
        vec3 c = p + ext * (vec3(k & 1, (k >> 1) & 1, k >> 2) * 2.0 - 1.0);
        vec4 q = u_view_proj * vec4(c, 1.0);
        if (q.w <= 0.0) { ++behind; continue; }
        if (q.w < 1.0e-6 * (abs(q.x) + abs(q.y) + 1.0e-30)) { ++near; continue; }
        vec2 ndc = q.xy / q.w;
        lo = min(lo, ndc);
        hi = max(hi, ndc);
    }
    if (behind == 8) return false;
    vec2 sz = vec2(u_size);
    if (behind + near > 0) {   // the cube crosses the eye plane: every tile
        lo = vec2(-1.0);
        hi = vec2(1.0);
    }
    // pixel-centre coordinates, clamped in float before any int conversion
    vec2 plo = clamp(floor((lo * 0.5 + 0.5) * sz - 0.5), vec2(-1.0), sz);
    vec2 phi = clamp(ceil((hi * 0.5 + 0.5) * sz - 0.5), vec2(-1.0), sz);
    if (phi.x < 0.0 || phi.y < 0.0 || plo.x > sz.x - 1.0 || plo.y > sz.y - 1.0) return false;
    ivec2 a = ivec2(max(plo, vec2(0.0))) >> u_tile_shift, b = ivec2(min(phi, sz - 1.0)) >> u_tile_shift;
    r = ivec4(a, min(b, u_tiles - 1));
    return true;
}
#endif

#if defined(MODE_MARCH) || defined(MODE_FINISH)
layout(binding = 1) uniform sampler2D u_scene_depth;
#if defined(MODE_MARCH)
// read back by u_half 2 at the coarse pixels (written by the u_half 1 dispatch before it)
layout(r32f, binding = 0) uniform image2D u_dist;
layout(rgba32f, binding = 1) uniform image2D u_grad;
layout(r32f, binding = 2) uniform image2D u_back;
uniform bool u_temporal;     // write this frame's hit points
uniform bool u_reuse;        // the guesses are this frame's (reprojected from the last)
uniform int u_half;
#else
layout(r32f, binding = 0) uniform writeonly image2D u_dist;
layout(rgba32f, binding = 1) uniform readonly image2D u_st;    // the paper's pixel state
layout(r32f, binding = 2) uniform readonly image2D u_next;     // the paper's next sample
#endif
#ifndef LOCAL_K
#define LOCAL_K 16
#endif
#define SUB_DEPTH_MAX 7
// temporal reuse: the proof's dyadic depth at most (nodes of 2 steps or more)
#define PROOF_DEPTH 4

// The pixel's list: its tile's entries (or every particle when the tile did not fit) and then
// the global list.
uint g_start, g_n, g_total;
bool g_over;
vec3 g_dir;

vec4 fetch(uint i)
{
#if defined(ANISO)
    if (i < g_n)
        return g_over ? vec4(kern[4u * i].xyz, 0.0) : entries[g_start + i];
#else
    if (i < g_n)
        return g_over ? vec4(px[i], py[i], pz[i], 0.0) : entries[g_start + i];
#endif
    return vec4(globals[i - g_n].xyz, 0.0);
}

// The ray against entry i's kernel at centre c: |G (x - c)|^2 = a (t - tc)^2 + b2 along the ray;
// pp (isotropic only) the centre's offset from the ray. a = 1 for the isotropic kernel.
#if defined(ANISO)
uint fetch_id(uint i)
{
    if (i < g_n)
        return g_over ? i : eid[g_start + i];
    return floatBitsToUint(globals[i - g_n].w);
}

mat3 kernel_of(uint id)
{
    vec4 m0 = kern[4u * id + 1u], m1 = kern[4u * id + 2u];
    return mat3(m0.x, m0.y, m0.z, m0.y, m0.w, m1.x, m0.z, m1.x, m1.y);
}

void ray_term(uint i, vec3 c, out float tc, out float b2, out float a, out vec3 pp)
{
    mat3 G = kernel_of(fetch_id(i));
    vec3 u = G * g_dir, mo = G * (c - u_eye);
    a = dot(u, u);
    tc = dot(u, mo) / a;
    vec3 w = mo - tc * u;   // perpendicular to u: b2 without the cancellation of |mo|^2 - a tc^2
    b2 = dot(w, w);
    pp = vec3(0.0);
}
#else
void ray_term(uint i, vec3 c, out float tc, out float b2, out float a, out vec3 pp)
{
    vec3 oc = c - u_eye;
    tc = dot(oc, g_dir);
    pp = oc - tc * g_dir;
    b2 = dot(pp, pp);
    a = 1.0;
}
#endif

// The local list of one window: per sphere (perpendicular offset of its centre from the ray,
// closest-approach distance tc), its squared offset and its entry distance. ANISO: L[j] is
// (the particle's id bits, a, 0, tc).
vec4 L[LOCAL_K];
float Lb[LOCAL_K], Le[LOCAL_K];
uint g_nl;
bool g_dense;   // evaluate over the whole list (a window could not hold its spheres)

// One term: closest approach tc, squared offset b2; at distance t (value) and its upper bound
// over [t0, t1] (the point of the interval nearest tc).
#define TERM(tc, b2, a) { float d = t - (tc); float r2 = (b2) + (a) * d * d; \
    if (r2 < h2) { float q = 1.0 - sqrt(r2) * ih; s += q * q; } \
    float dm = max(0.0, max(t0 - (tc), (tc) - t)); float rm = (b2) + (a) * dm * dm; \
    if (rm < h2) { float q = 1.0 - sqrt(rm) * ih; u += q * q; } }
#if defined(ANISO)
#define A_OF(j) L[j].y
#else
#define A_OF(j) 1.0
#endif

// Sum P at t and the bound of sum P over [t0, t]: u >= sum P anywhere in [t0, t].
vec2 field(float t, float t0)
{
    float s = 0.0, u = 0.0, h2 = u_h * u_h, ih = 1.0 / u_h;
    if (!g_dense) {
        for (uint j = 0u; j < g_nl; ++j) TERM(L[j].w, Lb[j], A_OF(j))
    } else {
        for (uint i = 0u; i < g_total; ++i) {
            float tc, b2, a; vec3 pp;
            ray_term(i, fetch(i).xyz, tc, b2, a, pp);
            TERM(tc, b2, a)
        }
    }
    return vec2(s, u);
}

// grad sum P and sum P at distance t (the same spheres as field()).
vec4 gradient(float t)
{
    vec4 g = vec4(0.0);
    float h2 = u_h * u_h;
    uint n = g_dense ? g_total : g_nl;
#if defined(ANISO)
    // grad P(|G (x - c)|) = P'(r) G y / r with y = G (x - c)
    vec3 x = u_eye + t * g_dir;
    for (uint j = 0u; j < n; ++j) {
        uint id = g_dense ? fetch_id(j) : floatBitsToUint(L[j].x);
        mat3 G = kernel_of(id);
        vec3 y = G * (x - kern[4u * id].xyz);
        float r2 = dot(y, y);
        if (r2 < h2 && r2 > 0.0) {
            float r = sqrt(r2), q = 1.0 - r / u_h;
            g.xyz += (-2.0 * q / (u_h * r)) * (G * y);
            g.w += q * q;
        } else if (r2 == 0.0) {
            g.w += 1.0;
        }
    }
    return g;
#endif
    for (uint j = 0u; j < n; ++j) {
        vec3 pp; float tc;
        if (g_dense) { vec3 oc = fetch(j).xyz - u_eye; tc = dot(oc, g_dir); pp = oc - tc * g_dir; }
        else { pp = L[j].xyz; tc = L[j].w; }
        vec3 d = (t - tc) * g_dir - pp;   // x - p
        float r2 = dot(d, d);
        if (r2 < h2 && r2 > 0.0) {
            float r = sqrt(r2), q = 1.0 - r / u_h;
            g.xyz += (-2.0 * q / (u_h * r)) * d;
            g.w += q * q;
        } else if (r2 == 0.0) {
            g.w += 1.0;
        }
    }
    return g;
}

// Collects the spheres overlapping [lo, b) into L, keeping those that enter first when they do
// not all fit: b shrinks to the entry of the first sphere left out, so L holds every sphere that
// overlaps [lo, b). Returns the nearest entry >= b of a sphere left out (3e38 if none).
float collect(float lo, inout float b, inout uint tests)
{
    g_nl = 0u;
    float next_e = 3.0e38, h2 = u_h * u_h, emax = -3.0e38;
    uint jmax = 0u;
    for (uint i = 0u; i < g_total; ++i) {
        ++tests;
        vec4 pe = fetch(i);
        if (!g_over && i < g_n && pe.w - u_h >= b) {
            // this and every later entry of the tile enter at or after b
            next_e = min(next_e, pe.w - u_h);
            i = g_n - 1u;
            continue;
        }
        float tc, b2, a; vec3 pp;
        ray_term(i, pe.xyz, tc, b2, a, pp);
        if (!(b2 < h2)) continue;          // misses the ray (or NaN)
#if defined(ANISO)
        float hc = sqrt((h2 - b2) / a), e = tc - hc;
        pp = vec3(uintBitsToFloat(fetch_id(i)), a, 0.0);
#else
        float hc = sqrt(h2 - b2), e = tc - hc;
#endif
        if (tc + hc <= lo) continue;       // behind the window
        if (e >= b) { next_e = min(next_e, e); continue; }
        uint j = g_nl;
        if (g_nl == uint(LOCAL_K)) {
            // full: the latest entry leaves (or the new one is not taken); b becomes its entry
            float out_e = max(e, emax);
            b = out_e;
            next_e = min(next_e, out_e);
            if (e >= emax) continue;
            j = jmax;
        } else {
            ++g_nl;
        }
        L[j] = vec4(pp, tc); Lb[j] = b2; Le[j] = e;
        if (g_nl == uint(LOCAL_K)) {
            // the slot of the latest entry among those with entry < b
            emax = -3.0e38;
            for (uint q = 0u; q < uint(LOCAL_K); ++q)
                if (Le[q] > emax) { emax = Le[q]; jmax = q; }
        }
    }
    return next_e;
}

// Farthest exit of the balls of radius rad around the pixel's spheres: the tile's entries from
// the far end, stopping once no nearer slab can reach past the best exit found.
float last_exit(float rad)
{
    float best = 0.0, r2 = rad * rad;
    for (uint i = g_total; i > 0u; --i) {
        vec4 pe = fetch(i - 1u);
#if defined(ANISO)
        // an entry of key k = dist - R + h in [w, w + ds) exits by dist + R rad / h
        if (!g_over && i - 1u < g_n && pe.w + u_ds - u_h + u_rbound * (1.0 + rad / u_h) <= best) break;
#else
        if (!g_over && i - 1u < g_n && pe.w + u_ds + rad <= best) break;
#endif
        float tc, b2, a; vec3 pp;
        ray_term(i - 1u, pe.xyz, tc, b2, a, pp);
        if (b2 < r2) best = max(best, tc + sqrt((r2 - b2) / a));
    }
    return best;
}

// Nearest entry >= t among the local list's spheres (3e38 if none).
float next_local_entry(float t)
{
    float e = 3.0e38;
    for (uint j = 0u; j < g_nl; ++j)
        if (Le[j] >= t) e = min(e, Le[j]);
    return e;
}

// true when the driver may have cut this invocation's loops short. llvmpipe (Mesa gallivm)
// gives an invocation 65,535 loop iterations in all, every loop together (LP_MAX_TGSI_LOOP_
// ITERATIONS, one counter per shader); past that each loop ends after its current iteration,
// silently: a tile list of ~90,000 entries (262,144 particles in a 0.8 box seen 12 pixels
// wide) drew no water while every pixel was counted as left (issue 28). A spent counter lets
// a loop of two iterations run once, so this probe, run last, says whether it was spent.
// The bound is not a constant (u_slabs >= 1 < 2^31), so the compiler cannot unroll the loop.
bool loop_budget_spent()
{
    uint n = 0u;
    for (uint k = 0u; k < 2u + (u_slabs >> 31); ++k) ++n;
    return n < 2u;
}
#endif

#if defined(MODE_MARCH)
// This frame's hit point, for the next frame's guesses (every pixel finds at most one).
void keep_hit(vec3 x)
{
    uint k = atomicAdd(hit_count, 1u);
    hits[k] = vec4(x, 1.0);
    if ((k & 63u) == 0u) atomicAdd(hit_groups, 1u);   // a new group of 64 begins
}

// u_half 2: the pixel from its 2 (same row or column) or 4 (diagonal) coarse neighbours when all
// of them are empty rays (they met no sphere of influence: a miss), or all hit one smooth
// surface: each neighbour's tangent plane predicts this ray's distance, the predictions agree
// within u_half_tol and the normals within u_half_cos; then the mean prediction and the mean
// gradient and back distance. false: the pixel is marched (edges, silhouettes, thin features).
bool upsample(ivec2 pix, float t_lim, uint pidx)
{
    if (g_total == 0u) {
        // no sphere reaches the tile: a miss without reading the neighbours
        imageStore(u_dist, pix, vec4(-1.0));
        atomicAdd(c_upsampled, 1u);
        atomicAdd(c_left, 1u);
        return true;
    }
    ivec2 nb[4];
    int nn = 2;
    if ((pix.x & 1) == 1 && (pix.y & 1) == 1) {
        nb[0] = pix + ivec2(-1, -1); nb[1] = pix + ivec2(1, -1); nb[2] = pix + ivec2(-1, 1); nb[3] = pix + ivec2(1, 1);
        nn = 4;
    } else if ((pix.x & 1) == 1) {
        nb[0] = pix - ivec2(1, 0); nb[1] = pix + ivec2(1, 0);
    } else {
        nb[0] = pix - ivec2(0, 1); nb[1] = pix + ivec2(0, 1);
    }
    int hit = 0, empty = 0;
    float pmin = 3.0e38, pmax = -3.0e38, psum = 0.0, bsum = 0.0;
    vec4 gsum = vec4(0.0);
    vec3 n0 = vec3(0.0);
    bool ok = true;
    for (int i = 0; i < nn; ++i) {
        if (any(greaterThanEqual(nb[i], u_size))) return false;
        float d = imageLoad(u_dist, nb[i]).r;
        float bk = imageLoad(u_back, nb[i]).r;
        if (d < 0.0) {
            if (bk < 0.0) ++empty;
            continue;
        }
        ++hit;
        vec4 g = imageLoad(u_grad, nb[i]);
        if (!(dot(g.xyz, g.xyz) > 0.0)) { ok = false; continue; }
        vec3 n = -normalize(g.xyz);
        if (hit == 1) n0 = n;
        else if (dot(n, n0) < u_half_cos) ok = false;
        vec3 dir = volfx_ray_dir(u_inv_view_proj, u_eye, (vec2(nb[i]) + 0.5) / vec2(u_size) * 2.0 - 1.0);
        float den = dot(g_dir, n);
        if (abs(den) < 0.05) { ok = false; continue; }   // a plane seen edge-on predicts nothing
        float pred = d * dot(dir, n) / den;
        pmin = min(pmin, pred);
        pmax = max(pmax, pred);
        psum += pred;
        gsum += g;
        bsum += bk;
    }
    float dist = -1.0;
    if (empty == nn) {
        dist = -1.0;
    } else if (hit == nn && ok && pmax - pmin <= u_half_tol) {
        dist = psum / float(nn);
        if (!(dist > 0.0 && dist <= t_lim)) return false;
        imageStore(u_grad, pix, gsum / float(nn));
        imageStore(u_back, pix, vec4(max(bsum / float(nn), dist)));
    } else {
        return false;
    }
    imageStore(u_dist, pix, vec4(dist));
    if (u_temporal && dist >= 0.0) keep_hit(u_eye + dist * g_dir);
    atomicAdd(c_upsampled, 1u);
    if (dist >= 0.0) atomicAdd(c_found, 1u);
    else atomicAdd(c_left, 1u);
    return true;
}
#endif

void main()
{
#if defined(MODE_COUNT) || defined(MODE_SCATTER)
    uint i = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u;
    if (i >= u_count) return;
    vec3 p = vec3(px[i], py[i], pz[i]);
    if (any(isnan(p)) || any(isinf(p))) return; // skipped (counted on the CPU)
    ivec4 r;
#if defined(ANISO)
    vec4 kc = kern[4u * i];
    p = kc.xyz;
    if (!tile_rect(p, kern[4u * i + 3u].xyz, r)) return;
    // filed by key = dist - R_i + h <= (its nearest entry) + h: the march's "w - h >= b" stops
    // stay exact; the CPU's d0 is lowered by the largest R_i - h so that key >= d0
    float dist = length(p - u_eye) - kc.w + u_h;
#else
    if (!tile_rect(p, vec3(u_h), r)) return;
    float dist = length(p - u_eye);
#endif
    uint area = uint(r.z - r.x + 1) * uint(r.w - r.y + 1);
    uint slab = uint(clamp(floor((dist - u_d0) / u_ds), 0.0, float(u_slabs - 1u)));
    float slab_lo = u_d0 + float(slab) * u_ds;
    if (area > u_global_tiles) {
#if defined(MODE_SCATTER)
        uint g = atomicAdd(gcount, 1u);   // the buffer holds every particle: always fits
#if defined(ANISO)
        globals[g] = vec4(p, uintBitsToFloat(i));
#else
        globals[g] = vec4(p, 0.0);
#endif
        atomicAdd(c_global, 1u);
#endif
        return;
    }
#if defined(MODE_COUNT)
    atomicAdd(c_entries, area);
#endif
    for (int y = r.y; y <= r.w; ++y)
        for (int x = r.x; x <= r.z; ++x) {
            uint tile = uint(y * u_tiles.x + x) * u_slabs + slab;
#if defined(MODE_COUNT)
            atomicAdd(tcount[tile], 1u);
#else
            uint k = tstart[tile] + atomicAdd(tcount[tile], 1u);
            if (k < u_cap) entries[k] = vec4(p, slab_lo);
#if defined(ANISO)
            if (k < u_cap) eid[k] = i;
#endif
#endif
        }
#elif defined(MODE_REPROJECT)
    // one of the previous frame's hit points onto this frame's pixels
    uint q = gl_WorkGroupID.x * 64u + gl_LocalInvocationIndex;
    if (q >= hit_count) return;
    vec4 hp = hits[q];
    vec4 c = u_view_proj * vec4(hp.xyz, 1.0);
    if (!(c.w > 0.0)) return;
    vec2 sp = (c.xy / c.w * 0.5 + 0.5) * vec2(u_size) - 0.5;   // pixel-centre coordinates
    if (!(all(greaterThan(sp, vec2(-1.0))) && all(lessThan(sp, vec2(u_size))))) return;
    // the four pixels around it: a start for each (a guess, proven or rejected by the march)
    ivec2 b = ivec2(floor(sp));
    uint d = floatBitsToUint(length(hp.xyz - u_eye));
    for (int k = 0; k < 4; ++k) {
        ivec2 p = b + ivec2(k & 1, k >> 1);
        if (all(greaterThanEqual(p, ivec2(0))) && all(lessThan(p, u_size)))
            atomicMin(guess[p.y * u_size.x + p.x], d);
    }
#elif defined(MODE_MARCH) || defined(MODE_FINISH)
    ivec2 pix = ivec2(gl_GlobalInvocationID.xy);
#if defined(MODE_MARCH)
    if (u_half == 1) pix *= 2;   // the coarse pass: one ray per 2x2 block
    if (u_half == 3) {
        uint k = gl_WorkGroupID.x * 64u + gl_LocalInvocationIndex;
        if (k >= rm_count) return;
        pix = ivec2(int(rm_pix[k] % uint(u_size.x)), int(rm_pix[k] / uint(u_size.x)));
    }
#endif
    if (any(greaterThanEqual(pix, u_size))) return;
#if defined(MODE_FINISH)
    vec4 st = imageLoad(u_st, pix);
    if (st.x != 3.0) return;     // only the paper's sample-cap pixels
#endif
    uint ti = uint((pix.y >> u_tile_shift) * u_tiles.x + (pix.x >> u_tile_shift)) * u_slabs;
    g_start = tstart[ti];
    g_n = tstart[ti + u_slabs] - g_start;
    g_over = g_start + g_n > u_cap;
    uint ng = gcount;
    if (g_over) { g_n = u_count; ng = 0u; }   // the tile did not fit: every particle
    g_total = g_n + ng;
    g_dense = !u_local;
    vec2 ndc = (vec2(pix) + 0.5) / vec2(u_size) * 2.0 - 1.0;
    g_dir = volfx_ray_dir(u_inv_view_proj, u_eye, ndc);
    float t_lim = u_has_depth ? volfx_depth_distance(u_inv_view_proj, u_eye, ndc, texelFetch(u_scene_depth, pix, 0).r) : 3.0e38;
    uint tests = 0u, nsamp = 0u, nsub = 0u, nproof = 0u, nskip = 0u;
    int reuse = 0;     // temporal: 1 the guess was used, 2 it was rejected (0 none)
    bool g_empty = false;  // the ray meets no sphere of influence at all
#if defined(MODE_MARCH)
    uint pidx = uint(pix.y * u_size.x + pix.x);
#if defined(UPSAMPLE_PASS)
    // u_half 2, compiled on its own: without the march below (dead after the return) the pass
    // costs llvmpipe a fraction of the whole program's per-invocation set-up
    if (((pix.x | pix.y) & 1) == 0) return;   // a coarse pixel: done by the u_half 1 pass
    if (upsample(pix, t_lim, pidx)) return;
    uint k = atomicAdd(rm_count, 1u);
    rm_pix[k] = pidx;
    if ((k & 63u) == 0u) atomicAdd(rm_groups, 1u);   // a new group of 64 begins
    atomicAdd(c_remarched, 1u);
    return;
#endif
#endif

    bool have_prev = false;
    float tp = 0.0, fp = 0.0, t = 0.0;
#if defined(MODE_MARCH)
    t = 0.0;           // the first window finds the first sphere entry
    float lo = 0.0;
    if (g_dense) {
        // no local lists (ablation): the first entry and the last exit from the whole list
        float e0 = 3.0e38, h2 = u_h * u_h;
        for (uint i = 0u; i < g_total; ++i) {
            float tc, b2, a; vec3 pp;
            ray_term(i, fetch(i).xyz, tc, b2, a, pp);
            if (b2 < h2) { float hc = sqrt((h2 - b2) / a); if (tc + hc > 0.0) e0 = min(e0, max(tc - hc, 0.0)); }
        }
        tests += g_total;
        t = e0;
        g_empty = e0 >= 3.0e38;
        if (t > 0.0 && t < 3.0e38) { have_prev = true; tp = t; fp = -u_T; }
        t_lim = min(t_lim, last_exit(u_h));
    }
#else
    t = imageLoad(u_next, pix).r;
    if (st.w > 0.0) { have_prev = true; tp = st.y; fp = st.z; }
    // the first window also covers the bracket's start (the paper's last outside sample)
    float lo = have_prev ? min(tp, t - u_step) : t - u_step;
#endif
    int state = 2;     // 1 found, 2 left (past the list or the host depth), 4 undecided
    float result = -1.0;
    float fa = 0.0, fb = 0.0, ta = 0.0, tb = 0.0;
    // Bounds: each window advances t by at least one step or jumps a gap to the next sphere
    // entry (every sphere is entered once); each window's steps are at most window / step + 1.
    const int MAX_WINDOWS = 4096, MAX_STEPS = 1 << 15;
    int steps = 0;
    for (int win = 0; win < MAX_WINDOWS && state == 2; ++win) {
        if (t > t_lim || t >= 3.0e38) break;   // 3e38: no sphere ahead
        // the window is as long as its K spheres reach: b is the entry of the first left out
        float b = 3.0e38;
        float next_e = 3.0e38;
        if (!g_dense) {
            next_e = collect(min(lo, t - u_step), b, tests);
            lo = 3.0e38;
#if defined(MODE_MARCH)
            if (win == 0) {
                // exact start: the first sphere entry (0 when the eye is inside one); the field
                // is 0 there (L holds the spheres that enter first)
                float e0 = 3.0e38;
                for (uint j = 0u; j < g_nl; ++j) e0 = min(e0, Le[j]);
                if (e0 >= 3.0e38) { g_empty = true; break; }
                t = max(e0, 0.0);
                if (t > 0.0) { have_prev = true; tp = t; fp = -u_T; }
            }
#endif
            if (b - t < u_step) {
                g_dense = true;
                atomicAdd(c_dense, 1u);
                t_lim = min(t_lim, last_exit(u_h));
            }
        }
        if (!g_dense && g_nl == 0u) {
            // nothing overlaps the window: the field is 0 up to the next entry
            if (next_e >= 3.0e38) break;
            t = next_e; tp = t; fp = -u_T; have_prev = true;
            continue;
        }
        float b_end = g_dense ? t_lim + u_step : b;
        if (!g_dense && b >= 3.0e38) b_end = 3.0e38;
#if defined(MODE_MARCH)
        if (win == 0 && u_reuse && guess[pidx] != 0xffffffffu) {
            // Temporal reuse: jump from the first sphere entry t towards last frame's surface
            // (reprojected) once [t, x] is proven empty of surface by the field's upper bound,
            // dyadically where the bound over a node allows an inside point, while its halves
            // are 2 steps or longer (a shorter node costs the march as few evaluations). A node
            // that cannot be proven (or holds an inside point) ends the proof: the march goes on
            // from the proven prefix as it would have from t. x: half a step before the guess,
            // inside the window (its local list is exact there) and the host depth.
            float x = min(min(uintBitsToFloat(guess[pidx]) - 0.5 * u_step, b_end - u_step),
                          min(t_lim, t + 32.0 * u_step));
            reuse = 2;
            if (have_prev && !g_dense && x >= t + u_step) {
                float w0 = x - t, lf = fp, done = t, T2 = u_T * u_T;
                int d = 0, k = 0;
                for (int it = 0; it < 2 << PROOF_DEPTH; ++it) {
                    float n0 = t + w0 * float(k) / float(1 << d), n1 = t + w0 * float(k + 1) / float(1 << d);
                    vec2 v = field(n1, n0);
                    ++nproof;
                    if (v.y >= T2 && d < PROOF_DEPTH && w0 >= 4.0 * u_step * float(1 << d)) { ++d; k *= 2; continue; }
                    if (v.y >= T2) break;   // not provable (or inside at n1): [t, n0] is
                    done = n1; lf = sqrt(v.x) - u_T;
                    while ((k & 1) == 1 && d > 0) { k >>= 1; --d; }
                    if (d == 0) break;      // the whole interval
                    ++k;
                }
                if (done >= t + u_step) {
                    reuse = 1;
                    nskip = uint((done - t) / u_step);
                    tp = done; fp = lf; t = done + u_step;
                }
            }
        }
#endif
        while (t < b_end && steps < MAX_STEPS) {
            // the last sample sits on t_lim (the host depth, or the list's last exit in the dense
            // march): a surface between the previous sample and it is bracketed even when the
            // step reaches past it (steps near h drew nothing before, issue 28)
            if (t > t_lim) {
                if (!have_prev || tp >= t_lim) break;
                t = t_lim;
            }
            ++steps;
            vec2 su = field(t, have_prev ? tp : t);
            ++nsamp;
            float f = sqrt(su.x) - u_T;
            if (f >= 0.0) {
                state = 1; ta = tp; fa = fp; tb = t; fb = f;
                if (!have_prev) { ta = t; fa = f; }
                break;
            }
            // both ends outside but the bound allows an inside point between them: open the
            // dyadic subintervals of [tp, t] whose bound allows one, left first, to depth 4
            if (u_subdivide && have_prev && su.y >= u_T * u_T) {
                // node (d, k) is [tp + w k / 2^d, tp + w (k + 1) / 2^d]; the value at its left
                // end is always known (tp's, or the right end of the node visited before it)
                float w = t - tp, lf = fp;
                int d = 1, k = 0;
                for (int it = 0; it < 2 << SUB_DEPTH_MAX; ++it) {
                    float n0 = tp + w * float(k) / float(1 << d), n1 = tp + w * float(k + 1) / float(1 << d);
                    vec2 v = field(n1, n0);
                    ++nsub;
                    float fv = sqrt(v.x) - u_T;
                    if (v.y >= u_T * u_T && d < u_sub_depth) { ++d; k *= 2; continue; } // open it
                    if (fv >= 0.0) {
                        state = 1; ta = n0; fa = lf; tb = n1; fb = fv;
                        break;
                    }
                    lf = fv;
                    // next node: climb while this one is a right child, then the right sibling
                    while ((k & 1) == 1 && d > 1) { k >>= 1; --d; }
                    if ((k & 1) == 1) break;   // (1, 1) done: the whole interval
                    ++k;
                }
                if (state == 1) break;
            }
            tp = t; fp = f; have_prev = true;
            if (su.x == 0.0 && !g_dense) {
                // no sphere at t: the field is 0 up to the next local entry (or the window end)
                float e = next_local_entry(t);
                if (e >= b) { t = b; break; }
                tp = e; fp = -u_T;
                t = e + u_step;
            } else {
                t += u_step;
            }
        }
        if (steps >= MAX_STEPS) { state = 4; break; }
        if (g_dense && state == 2) break;   // the dense march went to the end
    }
    if (state == 2 && steps >= MAX_STEPS) state = 4;
    if (state == 1) {
        // eq. 5 then regula falsi on the bracket (the window's spheres cover it)
        float tt = fb == fa ? 0.5 * (ta + tb) : (ta * fb - tb * fa) / (fb - fa);
        for (uint k = 0u; k < u_refine_iters && ta != tb; ++k) {
            float ft = sqrt(field(tt, tt).x) - u_T;
            if (ft > 0.0) { tb = tt; fb = ft; } else { ta = tt; fa = ft; }
            tt = fb == fa ? 0.5 * (ta + tb) : (ta * fb - tb * fa) / (fb - fa);
        }
        result = tt;
        if (!(result <= t_lim)) { result = -1.0; state = 2; }
    }
    if (loop_budget_spent()) { state = 4; result = -1.0; }   // undecided, counted: not a miss
    imageStore(u_dist, pix, vec4(result));
#if defined(MODE_MARCH)
    if (state == 1) {
        imageStore(u_grad, pix, gradient(result));
        imageStore(u_back, pix, vec4(last_exit(u_rho)));
    } else if (u_half == 1) {
        imageStore(u_back, pix, vec4(g_empty ? -1.0 : 0.0));   // the upsample's empty-ray flag
    }
    if (u_temporal && state == 1) keep_hit(u_eye + result * g_dir);
    if (reuse == 1) atomicAdd(c_reused, 1u);
    else if (reuse == 2) atomicAdd(c_fallback, 1u);
    if (nskip > 0u) atomicAdd(c_skipped, nskip);
    if (nproof > 0u) atomicAdd(c_proof, nproof);
    // (an atomic of 0 is skipped: most pixels of a game frame see no water)
    if (nsamp + nsub + nproof > 0u) atomicAdd(c_samples, nsamp + nsub + nproof);
    if (state == 1) atomicAdd(c_found, 1u);
    else if (state == 4) atomicAdd(c_undecided, 1u);
    else atomicAdd(c_left, 1u);
#else
    atomicAdd(c_finished, 1u);
    if (state == 4) atomicAdd(c_undecided, 1u);
#endif
    if (tests > 0u) atomicAdd(c_tile_tests, tests);
    if (nsub > 0u) atomicAdd(c_subdiv, nsub);
    if (g_over) atomicAdd(c_overflow, 1u);
#endif
}
