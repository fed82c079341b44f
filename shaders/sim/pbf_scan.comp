// Exclusive prefix sum of the cell counts for the counting sort. One MODE a dispatch
// (sph_gpu.c runs them in this order):
//   MODE 0  per block of 1024 entries (256 threads x 4): data[] scanned into out[], the block's
//           total into blocks[b]
//   MODE 1  blocks[] scanned in place by one workgroup (each thread a contiguous run)
//   MODE 2  out[i] += blocks[i / 1024] (4 entries a thread, as MODE 0)
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Data { uint data[]; };
layout(std430, binding = 1) buffer Out { uint outv[]; };
layout(std430, binding = 2) buffer Blocks { uint blocks[]; };
uniform uint u_len;   // entries (MODE 0, 2) or blocks (MODE 1)
uniform int u_mode;
shared uint s_sum[256];

// exclusive scan of s_sum over the workgroup (Hillis-Steele); the total in the return value
uint scan_shared(uint t, uint v)
{
    s_sum[t] = v;
    barrier();
    for (uint o = 1u; o < 256u; o <<= 1) {
        uint add = t >= o ? s_sum[t - o] : 0u;
        barrier();
        s_sum[t] += add;
        barrier();
    }
    uint total = s_sum[255];
    uint ex = s_sum[t] - v;
    barrier();
    s_sum[t] = ex;
    return total;
}

void main()
{
    uint t = gl_LocalInvocationID.x;
    if (u_mode == 0) {
        uint base = gl_WorkGroupID.x * 1024u + t * 4u;
        uint v[4], run = 0u;
        for (uint k = 0u; k < 4u; ++k) {
            v[k] = base + k < u_len ? data[base + k] : 0u;
            run += v[k];
        }
        uint total = scan_shared(t, run);
        uint acc = s_sum[t];
        for (uint k = 0u; k < 4u; ++k) {
            if (base + k < u_len)
                outv[base + k] = acc;
            acc += v[k];
        }
        if (t == 0u)
            blocks[gl_WorkGroupID.x] = total;
    } else if (u_mode == 1) {
        uint per = (u_len + 255u) / 256u, b0 = t * per, b1 = min(b0 + per, u_len), run = 0u;
        for (uint b = b0; b < b1; ++b)
            run += blocks[b];
        scan_shared(t, run);
        uint acc = s_sum[t];
        for (uint b = b0; b < b1; ++b) {
            uint x = blocks[b];
            blocks[b] = acc;
            acc += x;
        }
    } else {
        uint base = gl_WorkGroupID.x * 1024u + t * 4u, add = blocks[gl_WorkGroupID.x];
        for (uint k = 0u; k < 4u; ++k)
            if (base + k < u_len)
                outv[base + k] += add;
    }
}
