// Diffuse particles (Ihmsen, Akinci, Akinci & Teschner 2012, "Unified spray, foam and bubbles
// for particle-based fluids"), one MODE_* per dispatch, over the fluid's hashed grid (aniso.comp's
// cells and hash; the neighbours of x are the fluid particles within h):
//   MODE_NORMAL    per fluid particle: the colour-field normal n = sum_j x_ij W_ij normalised, and
//                  how far the neighbourhood's centre lies from it, |sum_j x_ij W_ij| / (h sum_j W_ij),
//                  which tells the surface (about 0.3) from the inside (about 0): the wave crest
//                  is counted between surface particles only (inside, the normals are noise)
//   MODE_GENERATE  per fluid particle: trapped air I_ta = sum_j |v_ij| (1 - v^_ij . x^_ij) W_ij,
//                  wave crest I_wc = sum_j (1 - n_i . n_j) W_ij over the neighbours behind the
//                  normal (x^_ji . n_i < 0), counted when v^_i . n_i >= 0.6, energy E = |v|^2;
//                  n = Phi(E) (k_ta Phi(I_ta) + k_wc Phi(I_wc)) dt new particles (Phi the clamp
//                  of eq. 1; where Phi(E) = 0 the neighbours are not visited), placed in a cylinder of radius h/2 around the particle along its
//                  velocity, appended to the pool while it has room
//   MODE_EMIT      per drop thrown where a beam strikes the water (u_imp: point and normal of
//                  each impact, u_imp_per drops each): a spray drop placed 0.6-1.2 h above the
//                  surface within 0.75 h of the point, launched along the normal tilted outwards
//                  (a crown) at 0.35-1 x u_imp_speed v_ref; appended to the pool like generated
//                  particles (they count in the generated counter); then, with u_steam_per,
//                  that many steam puffs an impact (class 3): placed 0.15-0.5 h above the
//                  point (against gravity) within 0.8 h of it across, rising at 0.25-0.5 x the steam's
//                  terminal speed (buoyancy brings it up to speed) and drifting outwards, with
//                  a lifetime of 0.75-1 x u_steam_life
//   MODE_PREP      one invocation: the pool's count clamped to the cap, the advection's
//                  indirect dispatch
//   MODE_ADVECT    per diffuse particle: its fluid neighbours within h classify it (fewer than
//                  spray_below: spray, more than bubble_above: bubble, else foam); spray falls
//                  ballistically, foam moves with the fluid's velocity (kernel-weighted mean)
//                  and ages, a bubble is pushed up by buoyancy and dragged to the fluid's
//                  velocity; survivors are appended to the other half of the pool. Steam
//                  (class 3, only MODE_EMIT makes it) is never re-classified and visits no
//                  neighbour: in air it relaxes at u_steam_drag a second towards rising at
//                  u_steam_rise v_ref against gravity plus a swirl fixed in space (buoyancy
//                  and drag), and ages; it is dropped at the end of its lifetime
//   MODE_FINAL     one invocation: the draw's indirect arguments, the next frame's count, the
//                  generated count into the counters
// W(r) = 1 - r / h within h (the paper's weighting). Speeds are in units of v_ref = sqrt(|g| h).
// Every loop is bounded: the cells (at most 5^3), the candidates (MAX_CAND), the new particles
// of a fluid particle (MAX_NEW), the pool (the cap).
#if defined(MODE_PREP) || defined(MODE_FINAL)
layout(local_size_x = 1) in;
#else
layout(local_size_x = 64) in;
#endif
layout(std430, binding = 0) readonly buffer PX { float px[]; };
layout(std430, binding = 1) readonly buffer PY { float py[]; };
layout(std430, binding = 2) readonly buffer PZ { float pz[]; };
layout(std430, binding = 3) readonly buffer Vel { vec4 vel[]; };
// the effect's counter buffer: slots 27-31 are this pass's
layout(std430, binding = 4) buffer Counters { uint c_slots_[27]; uint c_spray, c_foam, c_bubble, c_generated, c_steam; };
layout(std430, binding = 5) readonly buffer Start { uint start[]; };
// 0-2 the advection's dispatch, 3 the pool's count, 4-7 the draw's (4, instances, 0, 0),
// 8 survivors, 9 generated this frame (asked for, kept or not)
layout(std430, binding = 6) buffer Header { uint hdr[16]; };
layout(std430, binding = 7) readonly buffer Sorted { vec4 sorted[]; };
layout(std430, binding = 8) buffer Normal { vec4 nrm[]; };
layout(std430, binding = 9) buffer Pot { vec4 pot[]; };
// 2 vec4 a particle: position and lifetime; velocity and class (0 spray, 1 foam, 2 bubble, 3 steam)
layout(std430, binding = 10) buffer PoolIn { vec4 pin[]; };
layout(std430, binding = 11) buffer PoolOut { vec4 pout[]; };
uniform uint u_count;       // fluid particles
uniform uint u_cap;         // the pool's cap
uniform uint u_buckets;
uniform vec3 u_g0;
uniform float u_cs;         // the grid's cell
uniform float u_h, u_dt, u_vref;
uniform vec3 u_gravity;
uniform vec2 u_ta, u_wc, u_ek;
uniform float u_rate_ta, u_rate_wc, u_life, u_buoy, u_drag;
uniform uint u_spray_below, u_bubble_above, u_seed;
uniform vec3 u_lo, u_hi;    // the fluid's box: a diffuse particle far outside it is dropped
uniform vec4 u_imp[16];     // MODE_EMIT: per impact its point and unit normal (xyz)
uniform uint u_imp_n, u_imp_per;
uniform float u_imp_speed;
uniform uint u_steam_per;   // MODE_EMIT: steam puffs an impact
uniform float u_steam_life, u_steam_rise, u_steam_drag;

#define MAX_CAND 4096u
#define MAX_NEW 8u
#define SURFACE 0.12      // neighbourhood centre offset / h from which a particle is at the surface
#define CREST_VN 0.6      // v^ . n^ from which a particle moves along its normal (the paper's)

ivec3 cell_of(vec3 p)
{
    return ivec3(clamp(floor((p - u_g0) / u_cs), vec3(-1.0e9), vec3(1.0e9)));
}

uint bucket_of(ivec3 c)
{
    uvec3 u = uvec3(c);
    return ((u.x * 73856093u) ^ (u.y * 19349663u) ^ (u.z * 83492791u)) & (u_buckets - 1u);
}

bool finite3(vec3 v) { return !(any(isnan(v)) || any(isinf(v))); }

// pcg hash: the generation's random numbers from (fluid particle, frame, k): repeatable
uint pcg(uint v)
{
    uint s = v * 747796405u + 2891336453u;
    uint w = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return (w >> 22u) ^ w;
}
float rnd(inout uint s) { s = pcg(s); return float(s >> 8) * (1.0 / 16777216.0); }

float phi(float I, vec2 t) { return (min(I, t.y) - min(I, t.x)) / (t.y - t.x); }

// Visits the fluid particles within h of p: the cells that can hold them (h / cell of them
// each way), the candidates of each bucket that lie in the visited cell (hash collisions).
#define FOR_NEIGHBOURS(p, BODY)                                                                 \
    {                                                                                           \
        int reach = int(ceil(u_h / u_cs));                                                      \
        ivec3 c0 = cell_of(p);                                                                  \
        uint cand = 0u;                                                                         \
        float H2 = u_h * u_h;                                                                   \
        for (int dz = -reach; dz <= reach; ++dz)                                                \
        for (int dy = -reach; dy <= reach; ++dy)                                                \
        for (int dx = -reach; dx <= reach; ++dx) {                                              \
            ivec3 c = c0 + ivec3(dx, dy, dz);                                                   \
            uint b = bucket_of(c);                                                              \
            uint a = start[b], e = start[b + 1u];                                               \
            e = min(e, a + (MAX_CAND - min(cand, MAX_CAND)));                                   \
            cand += e - a;                                                                      \
            for (uint jj = a; jj < e; ++jj) {                                                   \
                vec4 q = sorted[jj];                                                            \
                vec3 d = p - q.xyz;                                                             \
                float r2 = dot(d, d);                                                           \
                if (!(r2 < H2) || cell_of(q.xyz) != c) continue;                               \
                uint j = floatBitsToUint(q.w);                                                  \
                float r = sqrt(r2), W = 1.0 - r / u_h;                                          \
                BODY                                                                            \
            }                                                                                   \
        }                                                                                       \
    }

void main()
{
#if defined(MODE_PREP)
    uint n = min(hdr[3], u_cap);
    hdr[3] = n;
    hdr[0] = (n + 63u) / 64u; hdr[1] = 1u; hdr[2] = 1u;
    hdr[8] = 0u;
#elif defined(MODE_FINAL)
    hdr[4] = 4u; hdr[5] = hdr[8]; hdr[6] = 0u; hdr[7] = 0u;
    hdr[3] = hdr[8];
    c_generated = hdr[9];
    hdr[9] = 0u;
#elif defined(MODE_EMIT)
    uint k = gl_GlobalInvocationID.x;
    uint nspray = u_imp_n * u_imp_per;
    if (k >= nspray + u_imp_n * u_steam_per) return;
    bool steam = k >= nspray;
    uint e = steam ? (k - nspray) / u_steam_per : k / u_imp_per;
    vec3 c = u_imp[2u * e].xyz, nrm = u_imp[2u * e + 1u].xyz;
    if (!finite3(c) || !(dot(nrm, nrm) > 0.5)) return;
    uint s = pcg(k ^ pcg(u_seed ^ 0x9e3779b9u));
    vec3 ref = abs(nrm.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    vec3 e1 = normalize(cross(nrm, ref)), e2 = cross(nrm, e1);
    float th = 6.2831853 * rnd(s), rr = sqrt(rnd(s));
    vec3 side = cos(th) * e1 + sin(th) * e2;
    if (steam) {
        // a puff just above the hit, rising against gravity and drifting outwards
        vec3 up = -normalize(u_gravity);
        float vt = u_steam_rise * u_vref;
        side -= dot(side, up) * up;   // across gravity: a puff is never born below the hit
        side = dot(side, side) > 1.0e-6 ? normalize(side) : vec3(0.0);
        vec3 xs = c + up * u_h * (0.15 + 0.35 * rnd(s)) + side * (rr * 0.8 * u_h);
        vec3 vs = up * vt * (0.25 + 0.25 * rnd(s)) + side * vt * (0.2 + 0.6 * rr);
        float ls = u_steam_life * (0.75 + 0.25 * rnd(s));
        atomicAdd(hdr[9], 1u);
        uint as = atomicAdd(hdr[3], 1u);
        if (as >= u_cap) return;
        pin[2u * as] = vec4(xs, ls);
        pin[2u * as + 1u] = vec4(vs, 3.0);
        return;
    }
    vec3 x = c + nrm * u_h * (0.6 + 0.6 * rnd(s)) + side * (rr * 0.75 * u_h);
    float sp = u_imp_speed * u_vref * (0.35 + 0.65 * rnd(s));
    vec3 v = sp * normalize(nrm + side * (0.3 + 0.9 * rr));
    float life = u_life * (0.5 + 0.5 * rnd(s));
    atomicAdd(hdr[9], 1u);
    uint at = atomicAdd(hdr[3], 1u);
    if (at >= u_cap) return;
    pin[2u * at] = vec4(x, life);
    pin[2u * at + 1u] = vec4(v, 0.0);
#elif defined(MODE_ADVECT)
    uint i = gl_GlobalInvocationID.x;
    if (i >= hdr[3]) return;
    vec4 a = pin[2u * i], b = pin[2u * i + 1u];
    vec3 x = a.xyz, v = b.xyz;
    float life = a.w;
    if (uint(b.w) == 3u) {
        // steam: buoyancy and drag relax it towards rising at the terminal speed, plus a swirl
        // fixed in space (across the rise, 0.5 of it) that spreads the puffs; no neighbours
        vec3 up = -normalize(u_gravity);
        float vt = u_steam_rise * u_vref;
        vec3 q = x / u_h;
        vec3 sw = vec3(sin(1.7 * q.y + 2.1 * q.z), 0.0, cos(1.9 * q.y + 1.3 * q.x)) * 0.5 * vt;
        sw -= dot(sw, up) * up;
        v += min(u_steam_drag * u_dt, 1.0) * (vt * up + sw - v);
        x += v * u_dt;
        life -= u_dt;
        float ms = 8.0 * u_h;
        bool in_s = all(greaterThan(x, u_lo - vec3(ms))) && all(lessThan(x, u_hi + vec3(ms, 4.0 * ms, ms)));
        if (!(life > 0.0) || !finite3(x) || !finite3(v) || !in_s) return;
        uint ks = atomicAdd(hdr[8], 1u);
        pout[2u * ks] = vec4(x, life);
        pout[2u * ks + 1u] = vec4(v, 3.0);
        atomicAdd(c_steam, 1u);
        return;
    }
    uint n = 0u;
    float K = 0.0;
    vec3 vf = vec3(0.0);
    FOR_NEIGHBOURS(x, {
        ++n;
        K += W;
        vf += W * vel[j].xyz;
    })
    vf = K > 0.0 ? vf / K : v;
    uint cls = n < u_spray_below ? 0u : (n > u_bubble_above ? 2u : 1u);
    if (cls == 0u) {
        v += u_gravity * u_dt;
        x += v * u_dt;
    } else if (cls == 1u) {
        v = vf;
        x += vf * u_dt;
        life -= u_dt;
    } else {
        v += -u_buoy * u_gravity * u_dt + min(u_drag * u_dt, 1.0) * (vf - v);
        x += v * u_dt;
    }
    float m = 8.0 * u_h;
    bool inside = all(greaterThan(x, u_lo - vec3(m))) && all(lessThan(x, u_hi + vec3(m, 4.0 * m, m)));
    if (!(life > 0.0) || !finite3(x) || !finite3(v) || !inside) return;
    uint k = atomicAdd(hdr[8], 1u);
    pout[2u * k] = vec4(x, life);
    pout[2u * k + 1u] = vec4(v, float(cls));
    if (cls == 0u) atomicAdd(c_spray, 1u);
    else if (cls == 1u) atomicAdd(c_foam, 1u);
    else atomicAdd(c_bubble, 1u);
#else
    uint i = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u;
    if (i >= u_count) return;
    vec3 p = vec3(px[i], py[i], pz[i]);
    if (!finite3(p)) {
#if defined(MODE_NORMAL)
        nrm[i] = vec4(0.0);
#else
        pot[i] = vec4(0.0);
#endif
        return;
    }
#if defined(MODE_NORMAL)
    vec3 g = vec3(0.0);
    float S = 0.0;
    FOR_NEIGHBOURS(p, {
        g += W * d;
        S += W;
    })
    float off = S > 0.0 ? length(g) / (u_h * S) : 0.0;
    nrm[i] = vec4(dot(g, g) > 0.0 ? normalize(g) : vec3(0.0), off);
#else
    vec3 v = vel[i].xyz;
    float sp = length(v);
    float ek = sp * sp / (u_vref * u_vref);
    // Phi(E) is 0 at or below the energy clamp's minimum: no particle can come of this one, so
    // its neighbours are not visited (most of a calm pool; the potentials there read 0)
    if (!(ek > u_ek.x)) {
        pot[i] = vec4(0.0, 0.0, ek, 0.0);
        return;
    }
    vec4 ni = nrm[i];
    bool surf = ni.w >= SURFACE;
    float ta = 0.0, wc = 0.0;
    FOR_NEIGHBOURS(p, {
        if (j != i) {
            vec3 vij = v - vel[j].xyz;
            float lv = length(vij);
            if (lv > 0.0 && r > 0.0) ta += lv * (1.0 - dot(vij / lv, d / r)) * W;
            vec4 nj = nrm[j];
            // x^_ji . n_i < 0 with x_ji = -d: the neighbour lies behind the normal (convex)
            if (surf && nj.w >= SURFACE && dot(d, ni.xyz) > 0.0) wc += (1.0 - dot(ni.xyz, nj.xyz)) * W;
        }
    })
    if (!(sp > 0.0) || dot(v / sp, ni.xyz) < CREST_VN) wc = 0.0;
    ta /= u_vref;
    float want = phi(ek, u_ek) * (u_rate_ta * phi(ta, u_ta) + u_rate_wc * phi(wc, u_wc)) * u_dt;
    pot[i] = vec4(ta, wc, ek, want);
    if (!(want > 0.0)) return;
    uint s = pcg(i ^ pcg(u_seed));
    uint m = min(uint(floor(want + rnd(s))), MAX_NEW);
    if (m == 0u) return;
    atomicAdd(hdr[9], m);
    uint base = atomicAdd(hdr[3], m);
    if (base >= u_cap) return;
    m = min(m, u_cap - base);
    vec3 dir = v / sp;
    vec3 ref = abs(dir.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    vec3 e1 = normalize(cross(dir, ref)), e2 = cross(dir, e1);
    for (uint k = 0u; k < m; ++k) {
        float rr = 0.5 * u_h * sqrt(rnd(s)), th = 6.2831853 * rnd(s), hh = rnd(s) * sp * u_dt;
        vec3 off = rr * (cos(th) * e1 + sin(th) * e2);
        float life = u_life * (0.5 + 0.5 * rnd(s));
        pin[2u * (base + k)] = vec4(p + off + hh * dir, life);
        // the paper's: the fluid's velocity plus the offset's direction (a spread of |v| / 4)
        pin[2u * (base + k) + 1u] = vec4(v + 0.25 * sp * off / (0.5 * u_h), 1.0);
    }
#endif
#endif
}
