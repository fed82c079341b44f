// The foam layer (plugin/water/water_foam.c, docs/water.md "Foam layer"): a foam density on a 2D
// grid over the water's x and z, texel (i, j) centred at u_grid.xy + (i + 0.5, j + 0.5) u_cell.
// One MODE_* per dispatch:
//   MODE_VELOCITY  per fluid particle: its velocity (units of u_vref, clamped to VEL_MAX, in
//                  fixed point) and a count of 1 added to the 3 x 3 texels around its own: a
//                  texel's velocity is the mean over the water's depth around it (the
//                  depth-averaged velocity of shallow-water flow), with no holes where the
//                  particles are a texel apart
//   MODE_DEPOSIT   per diffuse particle of class foam: u_deposit (density a second, over h^2)
//                  x dt splatted bilinearly (mass and centre kept exactly), in fixed point
//   MODE_STEP      per texel: the density last update at the point the velocity carried it
//                  from (semi-Lagrangian, bilinear), plus the explicit 5-point diffusion there,
//                  faded over dt by dd/dt = -(d + FOAM_THIN) / lifetime (10 times faster where no
//                  water lies under the texel) and held at 0 or above, plus this update's
//                  deposit. The previous grid may differ (the water's box grew): it is sampled at
//                  the world position, 0 outside it.
#if defined(MODE_STEP)
layout(local_size_x = 8, local_size_y = 8) in;
#else
layout(local_size_x = 64) in;
#endif
layout(std430, binding = 0) readonly buffer PX { float px[]; };
layout(std430, binding = 1) readonly buffer PY { float py[]; };
layout(std430, binding = 2) readonly buffer PZ { float pz[]; };
layout(std430, binding = 3) readonly buffer Vel { vec4 vel[]; };
// 3 ints a texel: the sums of the x and z velocities x VEL_SCALE, the particles counted
layout(std430, binding = 4) buffer VSum { int vsum[]; };
// 1 uint a texel: deposit x D_SCALE
layout(std430, binding = 5) buffer Dep { uint dep[]; };
layout(std430, binding = 6) readonly buffer Header { uint hdr[16]; };
layout(std430, binding = 7) readonly buffer Pool { vec4 pool[]; };
layout(binding = 0) uniform sampler2D u_prev;        // last update's density (linear, 0 outside)
layout(r32f, binding = 0) writeonly uniform image2D u_next;
uniform uint u_count;           // fluid particles
uniform vec2 u_grid;            // world x, z of texel (0, 0)'s corner
uniform float u_cell;
uniform ivec2 u_size;
uniform vec4 u_prev_grid;       // the previous grid: x0, z0, 1 / (cell nx), 1 / (cell nz)
uniform vec2 u_prev_texel;      // its texel in uv
uniform float u_dt, u_vref, u_decay, u_dry_decay, u_kdiff, u_deposit;

// fixed point: velocities to 1/4096 of v_ref; a texel's sum overflows past 2^31 / (VEL_MAX
// VEL_SCALE) = 32,768 particles around it (3 x 3 texels of at most 2 h, particles about h / 2
// apart: water 110 h deep); the deposit to 1/65536 of a density of 1
#define VEL_SCALE 4096.0
#define VEL_MAX 16.0
#define D_SCALE 65536.0
// The fade of thin foam. A raft of foam lasts (its bubbles shield each other while the films
// drain), a sparse scatter of lone bubbles on open water bursts within a fraction of that: the
// fade dd/dt = -(d + FOAM_THIN) / lifetime gives a density d a finite life, lifetime
// ln(1 + d / FOAM_THIN) (d = 3: 2.6 lifetimes; d = 0.1: 0.3), instead of the pure exponential's
// thin haze that lingers wherever the flow spread it. Under a steady source (a beam held on the
// water, a breaking wave) the patch ends where the drifting foam has thinned to nothing: a bounded
// patch, not a sheet over the pool (which a bright light turns white: 1 - e^-d of even d = 0.3
// is a quarter of the surface's light from the foam). 0.3: cover 1 - e^-0.3 = 0.26 at the
// floor, the thinnest foam that reads as a layer rather than specks.
#define FOAM_THIN 0.3

bool finite3(vec3 v) { return !(any(isnan(v)) || any(isinf(v))); }

// The 4 texels around world (x, z) and their bilinear weights; false when none is on the grid.
void bilinear(vec2 xz, out ivec2 t0, out vec2 f)
{
    vec2 g = (xz - u_grid) / u_cell - 0.5;
    vec2 b = floor(g);
    t0 = ivec2(clamp(b, vec2(-4.0), vec2(u_size + 4)));
    f = g - b;
}

bool on_grid(ivec2 t) { return all(greaterThanEqual(t, ivec2(0))) && all(lessThan(t, u_size)); }

void main()
{
#if defined(MODE_VELOCITY)
    uint i = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u;
    if (i >= u_count) return;
    vec3 p = vec3(px[i], py[i], pz[i]);
    vec3 v = vel[i].xyz / u_vref;
    if (!finite3(p) || !finite3(v)) return;
    // whole numbers: a uniform flow gives every texel exactly round(u VEL_SCALE) / VEL_SCALE
    ivec2 u = ivec2(round(clamp(v.xz, vec2(-VEL_MAX), vec2(VEL_MAX)) * VEL_SCALE));
    ivec2 c = ivec2(floor((p.xz - u_grid) / u_cell));
    for (int k = 0; k < 9; ++k) {
        ivec2 t = c + ivec2(k % 3 - 1, k / 3 - 1);
        if (!on_grid(t)) continue;
        uint at = 3u * uint(t.y * u_size.x + t.x);
        atomicAdd(vsum[at], u.x);
        atomicAdd(vsum[at + 1u], u.y);
        atomicAdd(vsum[at + 2u], 1);
    }
#elif defined(MODE_DEPOSIT)
    uint i = gl_GlobalInvocationID.x;
    if (i >= hdr[3]) return;
    vec4 a = pool[2u * i], b = pool[2u * i + 1u];
    if (uint(b.w) != 1u || !finite3(a.xyz)) return;  // foam only: spray flies, bubbles are under
    ivec2 t0;
    vec2 f;
    bilinear(a.xz, t0, f);
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1), t = t0 + o;
        if (!on_grid(t)) continue;
        float w = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
        uint q = uint(round(w * u_deposit * D_SCALE));
        if (q > 0u) atomicAdd(dep[uint(t.y * u_size.x + t.x)], q);
    }
#else
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(t, u_size))) return;
    uint at = uint(t.y * u_size.x + t.x);
    vec2 x = u_grid + (vec2(t) + 0.5) * u_cell;
    float wsum = float(vsum[3u * at + 2u]);
    vec2 v = wsum > 0.0 ? vec2(float(vsum[3u * at]), float(vsum[3u * at + 1u])) / (wsum * VEL_SCALE) * u_vref
                        : vec2(0.0);
    vec2 uv = (x - v * u_dt - u_prev_grid.xy) * u_prev_grid.zw;
    float c = texture(u_prev, uv).r;
    float lap = texture(u_prev, uv + vec2(u_prev_texel.x, 0.0)).r + texture(u_prev, uv - vec2(u_prev_texel.x, 0.0)).r
              + texture(u_prev, uv + vec2(0.0, u_prev_texel.y)).r + texture(u_prev, uv - vec2(0.0, u_prev_texel.y)).r
              - 4.0 * c;
    float keep = wsum > 0.0 ? u_decay : u_dry_decay;
    // the fade clamped before the deposit is added: this update's deposit is kept whole
    float d = max((c + u_kdiff * lap) * keep - FOAM_THIN * (1.0 - keep), 0.0) + float(dep[at]) / D_SCALE;
    imageStore(u_next, t, vec4(max(d, 0.0)));
#endif
}
