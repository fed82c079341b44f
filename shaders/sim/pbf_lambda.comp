// PBF constraint pass (sph_pbf.c pbf_lambda_chunk): at the current iterate, the density from the
// neighbours and the walls, its gradients, and the multiplier lambda_i = min(0, -C_i / D_i),
// C_i = rho_i / rho0 - 1, D_i = |grad_i C_i|^2 + sum_j |grad_j C_i|^2 + eps (the constraint only
// pushes). The walls' terms are evaluated at the predicted position in the first iteration
// (kept in wallc) and carried to the iterate to first order after it, as the CPU solver does.
#include "sim/pbf_common.glsl"
layout(std430, binding = 0) readonly buffer Cur { vec4 cur[]; };
layout(std430, binding = 2) readonly buffer Id { uint id[]; };
layout(std430, binding = 3) readonly buffer X0 { vec4 x0[]; };
layout(std430, binding = 4) buffer WallC { vec4 wallc[]; };
layout(std430, binding = 5) writeonly buffer Lam { float lam[]; };
uniform uint u_iter;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= PBF_N)
        return;
    float H = PBF_H, H2 = PBF_H2, eps2 = 1e-12 * H2, rho0 = PBF_RHO0;
    float Vks = PBF_MASS / rho0 * u_k0.w, mk = PBF_MASS * u_k0.z;
    vec3 p = cur[i].xyz;
    uint idi = id[i];
    float sw = H2 * H2 * H2, g2 = 0.0;
    vec3 g = vec3(0.0);
    ivec3 c = pbf_cell(x0[i].xyz);
    for (int k = 0; k < 25; ++k) {
        uvec2 r = pbf_row(c, k);
        for (uint j = r.x; j < r.y; ++j) {
            if (j == i)
                continue;
            vec3 d = p - cur[j].xyz;
            float r2 = dot(d, d), t = max(H2 - r2, 0.0);
            if (!(r2 < H2))
                continue;
            sw += t * t * t;
            if (r2 > eps2) {
                float rl = sqrt(r2), hr = max(H - rl, 0.0);
                g -= (hr * hr / rl) * d;
                g2 += hr * hr * hr * hr;
            } else {
                g -= H * H * pbf_coincident_dir(idi, id[j]);
                g2 += H * H * H * H;
            }
        }
    }
    vec4 w;
    if (u_iter == 0u) {
        w = pbf_walls(p);
        wallc[i] = w;
    } else {
        w = wallc[i];
        if (w != vec4(0.0))
            w.x = max(w.x + rho0 * dot(w.yzw, p - x0[i].xyz), 0.0);
    }
    float rho = mk * sw + w.x;
    vec3 G = Vks * g + w.yzw;
    float D = dot(G, G) + Vks * Vks * g2 + u_k1.z;
    float C = rho / rho0 - 1.0;
    lam[i] = min(-C / D, 0.0);
}
