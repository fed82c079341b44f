// Anisotropic kernels (Yu & Turk 2013, "Reconstructing surfaces of particle-based fluids using
// anisotropic kernels"), for method TILE: per particle a matrix G such that the particle adds
// P(|G (x - c)|) (P the isotropic kernel of radius h) around a centre c. One MODE_* per dispatch:
//   MODE_COUNT    per particle: count[bucket of its cell] += 1 (hashed uniform grid, cell = the
//                 neighbourhood radius, so a particle's neighbours lie in its 27 cells)
//   (prefix sum of count[] into start[]: common/scan.comp, plugin/gpu/scan.h)
//   MODE_SCATTER  per particle: sorted[start[bucket] + fill[bucket]++] = (position, index)
//   MODE_CENTRE   per particle: the centre moved to the current position, the shape (G, the
//                 bounding radius and half-extents) kept from the last MODE_KERNEL (the half
//                 rate: the shapes follow every other upload; smoothing 0 only, where the
//                 centre is the position)
//   MODE_KERNEL   per particle: the weighted mean and covariance of its neighbours (weight
//                 1 - (r/R)^3 within R), the centre moved towards the mean by lambda, the
//                 covariance's eigen-decomposition (Jacobi, fixed sweeps), the axes (eigenvalues,
//                 the short ones raised to 1/kr of the longest, determinant normalised to 1,
//                 times ks; fewer than Ne neighbours: isotropic), divided by the radius column;
//                 or (HOST_KERNEL) the host's G divided by the radius column. Writes the centre,
//                 G, the bounding radius and the axis-aligned half-extents of the ellipsoid.
// Every loop is bounded: the 27 cells, the candidates of a particle (at most MAX_CAND), the
// Jacobi sweeps. Non-finite input gives the isotropic kernel (and the binning skips it).
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer PX { float px[]; };
layout(std430, binding = 1) readonly buffer PY { float py[]; };
layout(std430, binding = 2) readonly buffer PZ { float pz[]; };
layout(std430, binding = 3) buffer Count { uint count[]; };   // counts, then the scatter fill
// the water effect's counter buffer: slots 24, 25 are this pass's (tile.comp has 0-23)
layout(std430, binding = 4) buffer Counters { uint c_slots_[24]; uint c_stretched, c_isotropic; };
layout(std430, binding = 5) buffer Start { uint start[]; };
layout(std430, binding = 7) buffer Sorted { vec4 sorted[]; };   // xyz position, w the index's bits
// per particle 4 vec4: centre (w: bounding radius), G (xx xy xz yy), G (yz zz, 0, 0), half-extents
#if defined(MODE_CENTRE)
layout(std430, binding = 8) buffer Kern { vec4 kern[]; };
#else
layout(std430, binding = 8) writeonly buffer Kern { vec4 kern[]; };
#endif
layout(std430, binding = 9) writeonly buffer Nbr { uint nbr[]; };  // neighbours within R
layout(std430, binding = 10) readonly buffer Radius { float radius[]; };
layout(std430, binding = 11) readonly buffer HostG { float hostg[]; };   // 6 per particle
uniform uint u_count;
uniform uint u_buckets;     // a power of two
uniform vec3 u_g0;          // cell origin (the particles' box)
uniform float u_cs;         // cell size = R
uniform float u_h;
uniform float u_kr, u_ks, u_lambda;
uniform uint u_ne;
uniform bool u_radius, u_host, u_aniso;

#define MAX_CAND 8192u
#define SWEEPS 6

ivec3 cell_of(vec3 p)
{
    // clamped in float before the conversion: huge coordinates stay defined
    return ivec3(clamp(floor((p - u_g0) / u_cs), vec3(-1.0e9), vec3(1.0e9)));
}

uint bucket_of(ivec3 c)
{
    uvec3 u = uvec3(c);
    return ((u.x * 73856093u) ^ (u.y * 19349663u) ^ (u.z * 83492791u)) & (u_buckets - 1u);
}

#if defined(MODE_KERNEL)
// Cyclic Jacobi on the symmetric A (a00 a01 a02 a11 a12 a22): SWEEPS sweeps of the three
// rotations. On return w holds the eigenvalues and the columns of V the eigenvectors.
void jacobi(float a[6], out vec3 w, out mat3 V)
{
    mat3 A = mat3(a[0], a[1], a[2], a[1], a[3], a[4], a[2], a[4], a[5]);
    V = mat3(1.0);
    for (int s = 0; s < SWEEPS; ++s)
        for (int k = 0; k < 3; ++k) {
            int p = k == 2 ? 1 : 0, q = k == 0 ? 1 : 2;
            float apq = A[q][p];
            if (abs(apq) <= 1.0e-30 * (abs(A[p][p]) + abs(A[q][q])) || apq == 0.0) continue;
            float theta = (A[q][q] - A[p][p]) / (2.0 * apq);
            float t = sign(theta) / (abs(theta) + sqrt(theta * theta + 1.0));
            if (theta == 0.0) t = 1.0;
            float c = inversesqrt(t * t + 1.0), sn = t * c;
            mat3 J = mat3(1.0);
            J[p][p] = c; J[q][q] = c; J[q][p] = sn; J[p][q] = -sn;
            A = transpose(J) * A * J;
            V = V * J;
        }
    w = vec3(A[0][0], A[1][1], A[2][2]);
}
#endif

void main()
{
    uint i = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u;
    if (i >= u_count) return;
    vec3 p = vec3(px[i], py[i], pz[i]);
    bool finite = !(any(isnan(p)) || any(isinf(p)));
#if defined(MODE_COUNT)
    if (finite) atomicAdd(count[bucket_of(cell_of(p))], 1u);
#elif defined(MODE_SCATTER)
    if (finite) {
        uint b = bucket_of(cell_of(p));
        sorted[start[b] + atomicAdd(count[b], 1u)] = vec4(p, uintBitsToFloat(i));
    }
#elif defined(MODE_CENTRE)
    kern[4u * i].xyz = p;
#elif defined(MODE_KERNEL)
    float rho = u_radius ? radius[i] : 1.0;   // checked on the CPU: finite, in [1e-3, 1e3]
    vec3 axes = vec3(1.0);                     // semi-axes in units of h
    mat3 V = mat3(1.0);
    vec3 centre = p;
    uint n = 0u;
    bool stretched = false;
    if (u_host) {
        float g[6];
        for (int k = 0; k < 6; ++k) g[k] = hostg[6u * i + uint(k)];
        vec3 ev;
        jacobi(g, ev, V);
        axes = 1.0 / ev;   // eigenvalues checked on the CPU: in [1e-3, 1e3]
        stretched = true;
    } else if (u_aniso && finite) {
        float R = u_cs, R2 = R * R;
        ivec3 c0 = cell_of(p);
        float W = 0.0;
        vec3 s1 = vec3(0.0);
        float s2[6] = float[6](0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        uint cand = 0u;
        for (int k = 0; k < 27; ++k) {
            ivec3 c = c0 + ivec3(k % 3 - 1, (k / 3) % 3 - 1, k / 9 - 1);
            // a cell whose box lies R or more from p holds no neighbour: ~6 of the 27 on
            // average (the edge and corner cells), never read
            vec3 lo = u_g0 + vec3(c) * u_cs, dc = max(max(lo - p, p - (lo + u_cs)), vec3(0.0));
            if (dot(dc, dc) >= R2) continue;
            uint b = bucket_of(c);
            uint a = start[b], e = start[b + 1u];
            // bounded: at most MAX_CAND candidates in all (coincident heaps of particles)
            e = min(e, a + (MAX_CAND - min(cand, MAX_CAND)));
            cand += e - a;
            for (uint j = a; j < e; ++j) {
                vec4 q = sorted[j];
                vec3 d = q.xyz - p;                  // relative: no cancellation at large coordinates
                float r2 = dot(d, d);
                if (!(r2 < R2)) continue;
                // a bucket can hold other cells (hash collisions; two of the 27 cells may even
                // share one): a particle counts when its own cell is visited. Tested after the
                // distance (those of far cells fail that first), so ~1 candidate in 6 pays it
                if (cell_of(q.xyz) != c) continue;
                float r = sqrt(r2) / R, w = 1.0 - r * r * r;
                W += w;
                s1 += w * d;
                s2[0] += w * d.x * d.x; s2[1] += w * d.x * d.y; s2[2] += w * d.x * d.z;
                s2[3] += w * d.y * d.y; s2[4] += w * d.y * d.z; s2[5] += w * d.z * d.z;
                if (floatBitsToUint(q.w) != i) ++n;
            }
        }
        // W >= 1: the particle itself is among the candidates (weight 1)
        vec3 m = W > 0.0 ? s1 / W : vec3(0.0);
        centre = p + u_lambda * m;
        if (n >= u_ne && W > 0.0) {
            float C[6] = float[6](s2[0] / W - m.x * m.x, s2[1] / W - m.x * m.y, s2[2] / W - m.x * m.z,
                                  s2[3] / W - m.y * m.y, s2[4] / W - m.y * m.z, s2[5] / W - m.z * m.z);
            vec3 ev;
            jacobi(C, ev, V);
            float e1 = max(ev.x, max(ev.y, ev.z));
            // a degenerate or non-finite covariance (coincident particles, NaN) stays isotropic
            if (e1 > 1.0e-12 * R2 && !isinf(e1) && !isnan(e1)) {
                vec3 s = max(ev, vec3(e1 / u_kr));
                axes = s / pow(s.x * s.y * s.z, 1.0 / 3.0) * u_ks;
                stretched = all(greaterThan(axes, vec3(0.0))) && !any(isinf(axes)) && !any(isnan(axes));
                if (!stretched) { axes = vec3(1.0); V = mat3(1.0); }
            } else {
                V = mat3(1.0);
            }
        }
    }
    nbr[i] = n;   // 0 without a neighbour search (isotropic with a radius column, host kernels)
    axes *= rho;
    // G = V diag(1 / axes) V^T; half-extent along axis k: h |row k of V diag(axes)|
    mat3 G = V * mat3(1.0 / axes.x, 0.0, 0.0, 0.0, 1.0 / axes.y, 0.0, 0.0, 0.0, 1.0 / axes.z) * transpose(V);
    vec3 ext = vec3(length(vec3(V[0][0], V[1][0], V[2][0]) * axes), length(vec3(V[0][1], V[1][1], V[2][1]) * axes),
                    length(vec3(V[0][2], V[1][2], V[2][2]) * axes)) * u_h;
    float rmax = max(axes.x, max(axes.y, axes.z)) * u_h;
    kern[4u * i] = vec4(centre, rmax);
    kern[4u * i + 1u] = vec4(G[0][0], G[1][0], G[2][0], G[1][1]);
    kern[4u * i + 2u] = vec4(G[2][1], G[2][2], 0.0, 0.0);
    kern[4u * i + 3u] = vec4(ext, 0.0);
    if (u_aniso || u_host) {
        if (stretched) atomicAdd(c_stretched, 1u); else atomicAdd(c_isotropic, 1u);
    }
#endif
}
