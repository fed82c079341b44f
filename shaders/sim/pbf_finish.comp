// PBF velocity update (sph_pbf.c pbf_finish_chunk): v += (x_final - x_predicted) / dt with the
// speed held at the limit, x = x_final; a non-finite result keeps the predicted position at rest
// and is counted.
#include "sim/pbf_common.glsl"
layout(std430, binding = 0) readonly buffer Fin { vec4 fin[]; };
layout(std430, binding = 2) readonly buffer X0 { vec4 x0[]; };
layout(std430, binding = 3) buffer Vel { vec4 vel[]; };
layout(std430, binding = 4) writeonly buffer OutPos { vec4 out_pos[]; };
layout(std430, binding = 5) buffer Stats { uint st_v2max, st_errmax, st_clamped, st_bad; };

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= PBF_N)
        return;
    float vlim = u_k1.w;
    vec3 f = fin[i].xyz, p0 = x0[i].xyz;
    vec3 v = vel[i].xyz + (f - p0) / PBF_DT;
    float v2 = dot(v, v), fs = f.x + f.y + f.z;
    if (isnan(v2) || isinf(v2) || isnan(fs) || isinf(fs)) {
        vel[i] = vec4(0.0);
        out_pos[i] = vec4(p0, 1.0);
        atomicAdd(st_bad, 1u);
        return;
    }
    if (v2 > vlim * vlim) {
        v *= vlim / sqrt(v2);
        atomicAdd(st_clamped, 1u);
    }
    out_pos[i] = vec4(f, 1.0);
    vel[i] = vec4(v, 0.0);
}
