// PBF position pass (sph_pbf.c pbf_delta): dp_i = -V ks sum_j (l_i + l_j + s_corr) (H - r)^2 d/r
// + l_i grad C_wall, at most H/2 long, then the Chebyshev extrapolation from the iterate before
// this one (x = omega (x' - x_prev) + x_prev; omega 1 is a plain Jacobi update) and the clamp to
// the walls, into the next iterate.
#include "sim/pbf_common.glsl"
layout(std430, binding = 0) readonly buffer Cur { vec4 cur[]; };
layout(std430, binding = 2) readonly buffer Id { uint id[]; };
layout(std430, binding = 3) readonly buffer X0 { vec4 x0[]; };
layout(std430, binding = 4) readonly buffer WallC { vec4 wallc[]; };
layout(std430, binding = 5) readonly buffer Lam { float lam[]; };
// the iterate before the current one and the next: the same buffer from the third iteration on
// (each row reads its own previous value before writing it)
layout(std430, binding = 6) buffer Prev { vec4 prev[]; };
layout(std430, binding = 7) buffer Next { vec4 next[]; };
uniform float u_omega;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= PBF_N)
        return;
    float H = PBF_H, H2 = PBF_H2, eps2 = 1e-12 * H2;
    float Vks = PBF_MASS / PBF_RHO0 * u_k0.w, sk = u_k3.x, iwdq = u_k3.y;
    vec3 p = cur[i].xyz;
    uint idi = id[i];
    float li = lam[i];
    vec3 s = vec3(0.0);
    ivec3 c = pbf_cell(x0[i].xyz);
    for (int k = 0; k < 25; ++k) {
        uvec2 r = pbf_row(c, k);
        for (uint j = r.x; j < r.y; ++j) {
            if (j == i)
                continue;
            vec3 d = p - cur[j].xyz;
            float r2 = dot(d, d);
            if (!(r2 < H2))
                continue;
            if (!(r2 > eps2)) {
                s += (li + lam[j] - sk) * H * H * pbf_coincident_dir(idi, id[j]);
                continue;
            }
            float t = H2 - r2, w = t * t * t * iwdq, w2 = w * w;
            float rl = sqrt(r2), hr = max(H - rl, 0.0);
            s += ((li + lam[j] - sk * w2 * w2) * hr * hr / rl) * d;
        }
    }
    vec3 dp = -Vks * s + li * wallc[i].yzw;
    float dl = length(dp), maxd = u_k3.z;
    if (dl > maxd)
        dp *= maxd / dl;
    vec3 q = p + dp;
    if (u_omega != 1.0) {
        vec3 b = prev[i].xyz;
        q = u_omega * (q - b) + b;
    }
    next[i] = vec4(pbf_clamp(q), 1.0);
}
