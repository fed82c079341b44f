// impact_step.comp — the impacts' particles, one step of dt: each live spark falls under gravity
// with air drag, its path swept against the host's depth in a few samples; where a sample goes
// behind the surface's tangent plane (and not far behind it: a spark passing behind an object
// flies on) the spark is put back on that plane and its velocity reflected on the normal (with
// restitution and friction). A spark that leaves the view, or goes out of sight behind a
// surface, dies: there is no depth to bounce on there (it could fall through a floor unseen and
// show below it when the camera moves). Glow spots age. Live sparks and glows are counted.
#include "common/frame.glsl"
#include "beams/impact_depth.glsl"
layout(local_size_x = 64) in;

const uint MAX_SPARKS = 2048u, MAX_GLOWS = 512u;
const int SWEEP = 4;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    float dt = u_eye_dt.w;
    if (i < MAX_GLOWS) {
        vec4 g = glows[3u * i];
        float life = glows[3u * i + 2u].w;
        if (life > 0.0 && g.w < life) {
            g.w += dt;
            glows[3u * i].w = g.w;
            if (g.w < life)
                atomicAdd(counters[2], 1u);
        }
    }
    if (i >= MAX_SPARKS)
        return;
    vec4 a = sparks[3u * i], b = sparks[3u * i + 1u];
    if (!(b.w > 0.0) || a.w >= b.w)
        return;
    vec3 v = b.xyz;
    v.y -= u_params.y * dt;
    v *= exp(-0.8 * dt);
    vec3 P0 = a.xyz - u_eye_dt.xyz, P1 = P0 + v * dt, S, n;
    float thick = 1.5 * length(v) * dt + 0.05;
    bool hidden = false;
    for (int k = 1; k <= SWEEP; ++k) {
        vec3 Q = mix(P0, P1, float(k) / float(SWEEP));
        if (impact_classify(Q, S, n) != 2)
            continue;
        if (hidden = dot(S - Q, n) >= thick)
            break;
        {
            P1 = Q - dot(Q - S, n) * n + 0.003 * n;
            float vn = dot(v, n);
            if (vn < 0.0)
                v = 0.75 * (v - vn * n) - 0.4 * vn * n;
            break;
        }
    }
    ivec2 px;
    a.xyz = P1 + u_eye_dt.xyz;
    a.w = impact_project(P1, px) && !hidden ? a.w + dt : b.w;
    sparks[3u * i] = a;
    sparks[3u * i + 1u] = vec4(v, b.w);
    if (a.w < b.w)
        atomicAdd(counters[1], 1u);
}
