// PBF closing pass (sph_pbf.c pbf_visc_chunk and pbf_commit_chunk, without vorticity, which the
// GPU solver refuses): at the final positions, the density (neighbours and walls), XSPH viscosity
// v_i += c V k_poly6 sum_j (v_j - v_i) (H^2 - r^2)^3 and the no-slip walls' wall-law friction;
// the end state's figures: the largest speed and compression (atomic maxima of the float bits,
// which order as the floats do for values >= 0) and per workgroup the sums of the compression,
// the kinetic and the potential energy (pbf_reduce.comp adds those in a fixed order).
#include "sim/pbf_common.glsl"
layout(std430, binding = 0) readonly buffer Pos { vec4 pos[]; };
layout(std430, binding = 2) readonly buffer Vin { vec4 vin[]; };
layout(std430, binding = 3) writeonly buffer Vout { vec4 vout[]; };
layout(std430, binding = 4) writeonly buffer Rho { float rho_out[]; };
layout(std430, binding = 5) buffer Stats { uint st_v2max, st_errmax, st_clamped, st_bad; };
layout(std430, binding = 6) writeonly buffer Partial { vec4 partial[]; };
shared vec4 s_part[128];

// friction velocity u* of a smooth wall (rt_sph_wall_friction_velocity, in float)
float pbf_friction_velocity(float ut, float y, float nu)
{
    if (!(ut > 0.0) || !(y > 0.0) || !(nu > 0.0))
        return 0.0;
    float us = sqrt(nu * ut / y);
    if (y * us / nu <= 11.06)
        return us;
    for (int it = 0; it < 40; ++it) {
        float lg = log(y * us / nu) / 0.41 + 5.2;
        float F = us * lg - ut, dF = lg + 1.0 / 0.41;
        float nx = us - F / dF;
        if (!(nx > 0.0))
            nx = 0.5 * us;
        bool done = abs(nx - us) <= 1e-7 * us;
        us = nx;
        if (done)
            break;
    }
    return us;
}

// one no-slip wall's friction over the step, never beyond stopping the particle relative to it
vec3 pbf_wall_friction(vec3 v, float d, vec3 n, vec3 wv)
{
    vec3 rel = v - wv, t = rel - dot(rel, n) * n;
    float ut = length(t);
    if (!(ut > 0.0))
        return v;
    float y = max(d, 0.25 * u_k2.y);
    float us = pbf_friction_velocity(ut, y, u_k2.w);
    float dv = PBF_DT * us * us * u_k1.y * pbf_wall_gradient(d);
    return v - (dv < ut ? dv / ut : 1.0) * t;
}

vec3 pbf_friction(vec3 p, vec3 v)
{
    float H = PBF_H;
    for (int a = 0; a < 3; ++a) {
        float d0 = p[a] - u_lo[a], d1 = u_hi[a] - p[a];
        vec3 n = vec3(0.0);
        n[a] = 1.0;
        if (d0 < H && ((u_counts.z >> uint(2 * a)) & 1u) != 0u)
            v = pbf_wall_friction(v, d0, n, vec3(0.0));
        if (d1 < H && ((u_counts.z >> uint(2 * a + 1)) & 1u) != 0u)
            v = pbf_wall_friction(v, d1, -n, vec3(0.0));
    }
    for (uint c = 0u; c < u_counts.y; ++c) {
        vec3 n;
        float d = pbf_surface(c, p, n);
        if (d < H && u_col[c].half_noslip.w > 0.5)
            v = pbf_wall_friction(v, d, n, u_col[c].vel.xyz);
    }
    return v;
}

void main()
{
    uint i = gl_GlobalInvocationID.x, t = gl_LocalInvocationID.x;
    vec4 part = vec4(0.0);
    if (i < PBF_N) {
        float H2 = PBF_H2, rho0 = PBF_RHO0, V = PBF_MASS / rho0;
        vec3 p = pos[i].xyz, vi = vin[i].xyz;
        float sw = H2 * H2 * H2;
        vec3 u = vec3(0.0);
        ivec3 c = pbf_cell(p);
        for (int k = 0; k < 25; ++k) {
            uvec2 r = pbf_row(c, k);
            for (uint j = r.x; j < r.y; ++j) {
                vec3 d = p - pos[j].xyz;
                float r2 = dot(d, d);
                if (j == i || !(r2 < H2))
                    continue;
                float tt = H2 - r2, w = tt * tt * tt;
                sw += w;
                u += (vin[j].xyz - vi) * w;
            }
        }
        float rho = PBF_MASS * u_k0.z * sw + pbf_walls(p).x;
        rho_out[i] = rho;
        vec3 v = vi + u_k2.z * V * u_k0.z * u;
        if (u_counts.w != 0u)
            v = pbf_friction(p, v);
        vout[i] = vec4(v, 0.0);
        float v2 = dot(v, v), err = (rho - rho0) / rho0;
        atomicMax(st_v2max, floatBitsToUint(v2));
        if (err > 0.0)
            atomicMax(st_errmax, floatBitsToUint(err));
        part = vec4(max(err, 0.0), 0.5 * PBF_MASS * v2, -PBF_MASS * dot(u_grav.xyz, p - u_lo.xyz), 0.0);
    }
    s_part[t] = part;
    barrier();
    for (uint o = 64u; o > 0u; o >>= 1) {
        if (t < o)
            s_part[t] += s_part[t + o];
        barrier();
    }
    if (t == 0u)
        partial[gl_WorkGroupID.x] = s_part[0];
}
