// PBF predict (sph_pbf.c pbf_predict_chunk): v += dt g (speed held at the limit), x += dt v,
// clamped to the walls with v following the clamp; then the particle's cell of H/2 is counted
// (its slot in the cell kept for the scatter).
#include "sim/pbf_common.glsl"
layout(std430, binding = 0) buffer Pos { vec4 pos[]; };
layout(std430, binding = 2) buffer Vel { vec4 vel[]; };
layout(std430, binding = 3) writeonly buffer Key { uvec2 key[]; };
layout(std430, binding = 4) buffer Count { uint count[]; };
layout(std430, binding = 5) buffer Stats { uint st_v2max, st_errmax, st_clamped, st_bad; };

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= PBF_N)
        return;
    float dt = PBF_DT, vlim = u_k1.w;
    vec3 v = vel[i].xyz + dt * u_grav.xyz;
    float v2 = dot(v, v);
    if (isnan(v2) || isinf(v2)) {
        v = vec3(0.0);
        atomicAdd(st_bad, 1u);
    } else if (v2 > vlim * vlim) {
        v *= vlim / sqrt(v2);
        atomicAdd(st_clamped, 1u);
    }
    vec3 p = pos[i].xyz + dt * v, q = pbf_clamp(p);
    v += (q - p) / dt;
    pos[i] = vec4(q, 1.0);
    vel[i] = vec4(v, 0.0);
    uint c = pbf_cell_index(pbf_cell(q));
    key[i] = uvec2(c, atomicAdd(count[c], 1u));
}
