/* sph_simd.h — SSE2 (every x86-64) for the CPU solvers' pair loops (sph_kernels.c, sph_pbf.c): they
 * take four pairs at a time where SPH_SSE is 1; elsewhere their scalar loops do the same sums. */
#ifndef RT_SPH_SIMD_H
#define RT_SPH_SIMD_H

#if defined(__SSE2__) && (defined(__GNUC__) || defined(__clang__))
#include <emmintrin.h>
#define SPH_SSE 1
/* The four lanes' sum, in the scalar loops' pairing: (l0 + l1) + (l2 + l3). */
static inline float sph_hsum(__m128 v)
{
    float l[4];
    _mm_storeu_ps(l, v);
    return (l[0] + l[1]) + (l[2] + l[3]);
}
#else
#define SPH_SSE 0
#endif

#endif
