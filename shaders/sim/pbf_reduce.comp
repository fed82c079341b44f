// Sums the per-workgroup partials of pbf_visc.comp in a fixed order (one workgroup) into the
// frame's stats slot: mean compression, kinetic and potential energy.
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Partial { vec4 partial[]; };
layout(std430, binding = 1) buffer Stats { uint st_v2max, st_errmax, st_clamped, st_bad; float st_errsum, st_ke, st_pe; };
uniform uint u_groups;
shared vec4 s_sum[256];

void main()
{
    uint t = gl_LocalInvocationID.x;
    vec4 acc = vec4(0.0);
    for (uint g = t; g < u_groups; g += 256u)
        acc += partial[g];
    s_sum[t] = acc;
    barrier();
    for (uint o = 128u; o > 0u; o >>= 1) {
        if (t < o)
            s_sum[t] += s_sum[t + o];
        barrier();
    }
    if (t == 0u) {
        st_errsum = s_sum[0].x;
        st_ke = s_sum[0].y;
        st_pe = s_sum[0].z;
    }
}
