// GPU-resident particles (docs/water.md "Input"): one column of the host's GL buffer, `u_stride`
// floats from one particle to the next, starting `u_base` floats into the range bound at
// binding 0 (the host's offset rounded down to GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT, the
// remainder here), copied into the water's own layout at particle `u_first`. One MODE_* a
// dispatch:
//   MODE_POS  xyz into the three position columns (NaN and Inf copied as they are: the passes
//             skip them, as they do the CPU path's), and the box of the finite ones, the count
//             of the others and of those outside u_lo..u_hi (the box this frame's passes use)
//             reduced into Box (per work group in shared memory, then one atomic each)
//   MODE_VEL  xyz into the diffuse particles' velocity (vec4, w 0; a non-finite one is at rest,
//             as on the CPU path)
//   MODE_KERNEL  the 6 floats of the kernel column (xx xy xz yy yz zz) unchanged into the host
//             kernels' buffer, 6 floats a particle (checked after, on the CPU: water_aniso.c)
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Src { float src[]; };
#ifdef MODE_POS
layout(std430, binding = 1) writeonly buffer PX { float px[]; };
layout(std430, binding = 2) writeonly buffer PY { float py[]; };
layout(std430, binding = 3) writeonly buffer PZ { float pz[]; };
// lo and hi as order-preserving keys of the floats' bits (key(a) < key(b) iff a < b)
layout(std430, binding = 5) buffer Box { uint b_lo[3]; uint b_hi[3]; uint b_bad; uint b_outside; };
uniform vec3 u_lo, u_hi;
shared uint s_lo[3], s_hi[3], s_bad, s_outside;
#elif defined(MODE_KERNEL)
layout(std430, binding = 1) writeonly buffer Kern { float kern[]; };
#else
layout(std430, binding = 1) writeonly buffer Vel { vec4 vel[]; };
#endif
uniform uint u_count, u_base, u_stride, u_first;

uint order_key(float f)
{
    uint u = floatBitsToUint(f);
    return (u & 0x80000000u) != 0u ? ~u : u | 0x80000000u;
}

void main()
{
    uint i = gl_GlobalInvocationID.x;
    bool live = i < u_count;
    uint s = u_base + (live ? i : 0u) * u_stride;
#ifdef MODE_KERNEL
    if (live)
        for (uint k = 0u; k < 6u; ++k) kern[6u * (u_first + i) + k] = src[s + k];
#else
    vec3 v = live ? vec3(src[s], src[s + 1u], src[s + 2u]) : vec3(0.0);
    bool finite = !any(isnan(v)) && !any(isinf(v));
#ifdef MODE_POS
    if (gl_LocalInvocationIndex == 0u) {
        for (int k = 0; k < 3; ++k) { s_lo[k] = 0xffffffffu; s_hi[k] = 0u; }
        s_bad = 0u;
        s_outside = 0u;
    }
    barrier();
    if (live) {
        px[u_first + i] = v.x;
        py[u_first + i] = v.y;
        pz[u_first + i] = v.z;
        if (finite) {
            for (int k = 0; k < 3; ++k) {
                atomicMin(s_lo[k], order_key(v[k]));
                atomicMax(s_hi[k], order_key(v[k]));
            }
            if (any(lessThan(v, u_lo)) || any(greaterThan(v, u_hi))) atomicAdd(s_outside, 1u);
        } else {
            atomicAdd(s_bad, 1u);
        }
    }
    barrier();
    if (gl_LocalInvocationIndex == 0u) {
        for (int k = 0; k < 3; ++k) {
            atomicMin(b_lo[k], s_lo[k]);
            atomicMax(b_hi[k], s_hi[k]);
        }
        atomicAdd(b_bad, s_bad);
        atomicAdd(b_outside, s_outside);
    }
#else
    if (live) vel[u_first + i] = vec4(finite ? v : vec3(0.0), 0.0);
#endif
#endif
}
