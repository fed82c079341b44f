// impact_hit.comp — one invocation per beam: where the beam's axis, walked from its source to its
// head and on past the head by R, first goes from in front of the host's depth to behind it.
// The surface is the nearer of the host's depth and the water's (a beam striking the water is an
// impact on it, flagged for the host's fluid). The crossing is bisected to float precision; it is an impact only if the surface there is the
// one the crossing went through (the point within a few pixel footprints of the surface seen at
// its pixel), so a beam passing behind a pillar is not an impact. A hit emits this frame's sparks
// and one glow spot (energy x dt, so the glow's level does not depend on the frame rate).
#include "common/frame.glsl"
#include "beams/impact_depth.glsl"
layout(local_size_x = 64) in;

const uint MAX_SPARKS = 2048u, MAX_GLOWS = 512u;
const int SAMPLES = 128;   // along the whole axis
const int BISECT = 24;

// The crossing between a (in front) and b (behind), bisected; true and P, S, n when it is the
// surface's own.
bool refine(vec3 a, vec3 b, out vec3 P, out vec3 S, out vec3 n)
{
    vec3 Sb, nb;
    int cb = impact_classify(b, Sb, nb);
    for (int i = 0; i < BISECT; ++i) {
        vec3 m = 0.5 * (a + b), Sm, nm;
        int c = impact_classify(m, Sm, nm);
        if (c == 0)
            return false;
        if (c == 2)
            b = m, Sb = Sm, nb = nm;
        else
            a = m;
    }
    P = 0.5 * (a + b), S = Sb, n = nb;
    float dist = length(P);
    // a pixel's footprint at P, over the cosine between the surface and the view ray
    float foot = 2.0 * dist / (abs(vfx_proj[1][1]) * vfx_planes_size.w);
    float tol = 3.0 * foot / max(abs(dot(n, P / max(dist, 1e-30))), 0.2) + 1e-4 * dist;
    return cb == 2 && length(P - S) <= tol;
}

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_counts.x)
        return;
    hits[3u * i] = vec4(0.0);
    ImpactBeam bm = ibeams[i];
    int n = int(bm.info.x);
    if (n < 2)
        return;
    float R = bm.color.w;
    // the path: source p[n-1] .. head p[0], then R past the head along the first segment
    vec3 ext = bm.p[0].xyz - bm.p[1].xyz;
    float el = length(ext);
    vec3 tip = bm.p[0].xyz + (el > 0.0 ? ext / el * R : vec3(0.0));
    float total = R;
    for (int k = 1; k < n; ++k)
        total += length(bm.p[k].xyz - bm.p[k - 1].xyz);
    float step = max(total / float(SAMPLES), 1e-6);
    vec3 prev = bm.p[n - 1].xyz, S, nrm;
    int pc = impact_classify(prev, S, nrm);
    bool found = false;
    vec3 P;
    for (int k = n - 1; k >= 0 && !found; --k) {
        vec3 A = bm.p[k].xyz, B = k > 0 ? bm.p[k - 1].xyz : tip;
        int m = max(int(ceil(length(B - A) / step)), 1);
        for (int j = 1; j <= m && !found; ++j) {
            vec3 Q = mix(A, B, float(j) / float(m));
            int c = impact_classify(Q, S, nrm);
            if (pc == 1 && c == 2)
                found = refine(prev, Q, P, S, nrm);
            prev = Q, pc = c;
        }
    }
    if (!found)
        return;
    vec3 pos = P + u_eye_dt.xyz;
    hits[3u * i] = vec4(pos, 1.0);
    ivec2 hp;
    bool water = impact_project(P, hp) && impact_water_at(hp);
    hits[3u * i + 1u] = vec4(nrm, water ? 1.0 : 0.0); // w: the surface hit is the water's
    hits[3u * i + 2u] = bm.color;
    atomicAdd(counters[0], 1u);
    atomicAdd(counters[2], 1u); // the glow spot below (impact_step counted the older ones)
    float dt = u_eye_dt.w;
    // sparks: a cone around the reflection of the beam's direction and the normal
    vec3 dir = el > 0.0 ? -ext / el : -nrm;
    vec3 refl = normalize(reflect(dir, nrm) + nrm);
    vec3 t1 = normalize(cross(nrm, abs(nrm.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0)));
    vec3 t2 = cross(nrm, t1);
    uint emit = u_counts.y;
    uint first = emit > 0u ? atomicAdd(counters[3], emit) : 0u;
    atomicAdd(counters[1], emit);
    for (uint k = 0u; k < emit; ++k) {
        uint seed = (u_counts.z * 7919u + i * 104729u + k * 2654435761u);
        float u1 = impact_hash(seed), u2 = impact_hash(seed ^ 0x9e3779b9u), u3 = impact_hash(seed + 17u);
        float u4 = impact_hash(seed * 3u + 5u);
        float phi = 6.2831853 * u1, ct = mix(0.15, 1.0, u2), st = sqrt(1.0 - ct * ct);
        vec3 d = normalize(mix(refl, ct * nrm + st * (cos(phi) * t1 + sin(phi) * t2), 0.7));
        if (dot(d, nrm) < 0.05)
            d = normalize(d + nrm * (0.05 - dot(d, nrm) + 0.05));
        float speed = mix(1.5, 5.5, u3);
        uint s = (first + k) % MAX_SPARKS;
        sparks[3u * s] = vec4(pos + nrm * 0.01, 0.0);
        sparks[3u * s + 1u] = vec4(d * speed, mix(0.35, 1.1, u4));
        sparks[3u * s + 2u] = vec4(bm.color.rgb, 0.0);
    }
    uint g = atomicAdd(counters[4], 1u) % MAX_GLOWS;
    float tau = u_params.w;
    glows[3u * g] = vec4(pos + nrm * 0.004, 0.0);
    glows[3u * g + 1u] = vec4(nrm, 1.8 * R);
    glows[3u * g + 2u] = vec4(bm.color.rgb * (dt / tau), 4.0 * tau);
}
