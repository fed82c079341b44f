// Exclusive prefix sum of u_n uint counts (plugin/gpu/scan.c), in two levels of 1024 entries:
// at most 1024 blocks, so 2^20 entries. One SCAN_* define per dispatch:
//   SCAN_BLOCKS  starts[i] = sum of counts[b*1024 .. i) within i's block b (one workgroup a
//                block); the block's total into blocks[b]
//   SCAN_TOP     blocks[] scanned in place the same way (one workgroup)
//   SCAN_ADD     starts[i] += blocks[i / 1024]
// The sums are of integers: any order of adding gives the same result.
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Counts { uint counts[]; };
layout(std430, binding = 1) buffer Starts { uint starts[]; };
layout(std430, binding = 2) buffer Blocks { uint blocks[]; };
uniform uint u_n; // entries to scan (SCAN_TOP: the blocks)

#if !defined(SCAN_ADD)
shared uint sh[256];
#endif

void main()
{
#if defined(SCAN_ADD)
    uint i = gl_GlobalInvocationID.x;
    if (i < u_n) starts[i] += blocks[i / 1024u];
#else
    // Each thread owns 4 consecutive entries; a Hillis-Steele scan of the 256 thread sums.
    uint lid = gl_LocalInvocationID.x, base = gl_WorkGroupID.x * 1024u + lid * 4u;
    uint v[4];
    uint tot = 0u;
    for (int k = 0; k < 4; ++k) {
#if defined(SCAN_TOP)
        v[k] = base + uint(k) < u_n ? blocks[base + uint(k)] : 0u;
#else
        v[k] = base + uint(k) < u_n ? counts[base + uint(k)] : 0u;
#endif
        tot += v[k];
    }
    sh[lid] = tot;
    barrier();
    for (uint off = 1u; off < 256u; off <<= 1) {
        uint add = lid >= off ? sh[lid - off] : 0u;
        barrier();
        sh[lid] += add;
        barrier();
    }
    uint run = sh[lid] - tot;
    for (int k = 0; k < 4; ++k) {
        if (base + uint(k) < u_n) {
#if defined(SCAN_TOP)
            blocks[base + uint(k)] = run;
#else
            starts[base + uint(k)] = run;
#endif
        }
        run += v[k];
    }
#if !defined(SCAN_TOP)
    if (lid == 255u) blocks[gl_WorkGroupID.x] = sh[255];
#endif
#endif
}
