// pbf_common.glsl — what every pass of the GPU Position Based Fluids solver shares
// (runtime/sim/sph_gpu.c): the parameters, the colliders, the cell grid, the kernels' constants
// and the semi-analytic walls, each the GLSL twin of the CPU solver's (sph_pbf.c, sph_wall.c,
// sph_collide.c), in float where the CPU evaluates the wall integrals in double.
layout(local_size_x = 128) in;

layout(std140, binding = 0) uniform Params {
    vec4 u_lo;      // domain_min, w: H
    vec4 u_hi;      // domain_max, w: H^2
    vec4 u_grav;    // gravity, w: the step dt
    vec4 u_k0;      // mass, rho0, k_poly6, k_spiky
    vec4 u_k1;      // wall_scale, fric_scale, mixing eps of the step, velocity limit
    vec4 u_k2;      // 1 / cell, spacing, XSPH c, kinematic viscosity
    vec4 u_k3;      // s_corr k / D0, 1 / (H^2 - dq^2)^3, largest correction per iteration, 0
    ivec4 u_grid;   // cells per axis, cell count
    uvec4 u_counts; // particles, colliders, no-slip faces (RT_SPH_FACE_* bits), friction on
};

struct pbf_collider {
    vec4 pos_kind;     // centre now, kind (0 plane, 1 sphere, 2 box)
    vec4 normal_rad;   // plane normal, sphere radius
    vec4 half_noslip;  // box half extents, no-slip (1)
    vec4 vel;          // velocity now
};
layout(std140, binding = 1) uniform Colliders { pbf_collider u_col[64]; };

#define PBF_H u_lo.w
#define PBF_H2 u_hi.w
#define PBF_DT u_grav.w
#define PBF_MASS u_k0.x
#define PBF_RHO0 u_k0.y
#define PBF_N u_counts.x

// the cell of p, clamped to the grid (sph_cell_coord)
ivec3 pbf_cell(vec3 p)
{
    ivec3 c = ivec3((p - u_lo.xyz) * u_k2.x);
    return clamp(c, ivec3(0), u_grid.xyz - 1);
}

uint pbf_cell_index(ivec3 c) { return uint((c.z * u_grid.y + c.y) * u_grid.x + c.x); }

// fraction of the poly6 kernel's mass beyond a plane at distance d (rt_sph_wall_density_fraction)
float pbf_wall_fraction(float d)
{
    float H = PBF_H;
    if (d >= H)
        return 0.0;
    float u = max(d, 0.0) / H, u2 = u * u;
    float Pu = u * (1.0 + u2 * (-4.0 / 3.0 + u2 * (6.0 / 5.0 + u2 * (-4.0 / 7.0 + u2 / 9.0))));
    return 315.0 / 256.0 * (128.0 / 315.0 - Pu);
}

// minus its derivative in d (rt_sph_wall_density_gradient)
float pbf_wall_gradient(float d)
{
    float H = PBF_H;
    if (d >= H)
        return 0.0;
    float u = max(d, 0.0) / H, q = 1.0 - u * u;
    return 315.0 / 256.0 * q * q * q * q / H;
}

// signed distance to collider c (positive on the fluid side) and its outward normal
// (rt_sph_surface_distance without meshes, which the GPU solver refuses)
float pbf_surface(uint c, vec3 p, out vec3 n)
{
    vec3 d = p - u_col[c].pos_kind.xyz;
    float kind = u_col[c].pos_kind.w;
    if (kind < 0.5) {
        n = u_col[c].normal_rad.xyz;
        return dot(d, n);
    }
    if (kind < 1.5) {
        float l = length(d);
        n = l < 1e-12 ? vec3(0.0, 1.0, 0.0) : d / l;
        return l - u_col[c].normal_rad.w;
    }
    vec3 q = abs(d) - u_col[c].half_noslip.xyz, o = max(q, vec3(0.0));
    float ol2 = dot(o, o);
    if (ol2 > 0.0) {
        float ol = sqrt(ol2);
        n = vec3(d.x < 0.0 ? -o.x : o.x, d.y < 0.0 ? -o.y : o.y, d.z < 0.0 ? -o.z : o.z) / ol;
        return ol;
    }
    int a = q.x >= q.y && q.x >= q.z ? 0 : (q.y >= q.z ? 1 : 2);
    n = vec3(0.0);
    n[a] = d[a] < 0.0 ? -1.0 : 1.0;
    return q[a];
}

// moves p out of every collider and the domain box to the clamp margin dx/4 (rt_sph_pbf_clamp)
vec3 pbf_clamp(vec3 p)
{
    float margin = 0.25 * u_k2.y;
    for (uint c = 0u; c < u_counts.y; ++c) {
        vec3 n;
        float d = pbf_surface(c, p, n);
        if (d < margin)
            p += (margin - d) * n;
    }
    return clamp(p, u_lo.xyz + margin, u_hi.xyz - margin);
}

// the walls' density rho0 * (missing fraction) at p (x) and the gradient of the missing
// fraction (yzw) (sph_pbf.c pbf_walls): box faces through 1 - prod(1 - f), colliders added
vec4 pbf_walls(vec3 p)
{
    float H = PBF_H, ws = u_k1.x;
    float fb[6], db[6];
    float inside = 1.0, extra = 0.0;
    bool any = false;
    for (int a = 0; a < 3; ++a) {
        db[2 * a] = p[a] - u_lo[a];
        db[2 * a + 1] = u_hi[a] - p[a];
    }
    for (int k = 0; k < 6; ++k) {
        fb[k] = db[k] < H ? ws * pbf_wall_fraction(db[k]) : 0.0;
        any = any || db[k] < H;
        inside *= 1.0 - fb[k];
    }
    vec3 g = vec3(0.0);
    for (int k = 0; k < 6; ++k) {
        if (!(db[k] < H))
            continue;
        float others = 1.0;
        for (int l = 0; l < 6; ++l)
            if (l != k)
                others *= 1.0 - fb[l];
        float gr = others * ws * pbf_wall_gradient(db[k]);
        vec3 n = vec3(0.0);
        n[k >> 1] = (k & 1) == 0 ? 1.0 : -1.0;
        g -= gr * n;
    }
    for (uint c = 0u; c < u_counts.y; ++c) {
        vec3 n;
        float d = pbf_surface(c, p, n);
        if (!(d < H))
            continue;
        any = true;
        extra += ws * pbf_wall_fraction(d);
        g -= ws * pbf_wall_gradient(d) * n;
    }
    return any ? vec4(PBF_RHO0 * (1.0 - inside + extra), g) : vec4(0.0);
}

// 64-bit products and shifts on uvec2 (lo, hi): rt_sph_coincident_dir's hash without int64
uvec2 pbf_mul64(uvec2 a, uvec2 b)
{
    uint hi, lo;
    umulExtended(a.x, b.x, hi, lo);
    return uvec2(lo, hi + a.x * b.y + a.y * b.x);
}

// a deterministic, antisymmetric unit direction for two coincident particles of ids a, b
vec3 pbf_coincident_dir(uint a, uint b)
{
    uint lo = min(a, b), hi = max(a, b);
    uvec2 h = pbf_mul64(uvec2(lo, 0u), uvec2(0x7F4A7C15u, 0x9E3779B9u)) ^
              pbf_mul64(uvec2(hi, 0u), uvec2(0x27D4EB4Fu, 0xC2B2AE3Du));
    h ^= uvec2((h.x >> 29) | (h.y << 3), h.y >> 29);
    h = pbf_mul64(h, uvec2(0x1CE4E5B9u, 0xBF58476Du));
    h ^= uvec2(h.y, 0u);
    float th = float(h.x & 0xFFFFu) / 65536.0 * 6.283185307179586;
    float cz = float((h.x >> 16) & 0xFFFFu) / 65536.0 * 2.0 - 1.0;
    float sz = sqrt(1.0 - cz * cz), sg = a < b ? 1.0 : -1.0;
    return sg * vec3(sz * cos(th), sz * sin(th), cz);
}

// the sorted grid: start[c] .. start[c + 1] are the rows of cell c (cells of H/2, so the
// neighbours within H of a particle lie in the 5 x 5 x 5 cells around its own; each x-row of
// 5 cells is one index range)
layout(std430, binding = 1) readonly buffer Start { uint start[]; };

// the index range of row k (0..24) of the 5 x 5 rows around cell c (empty outside the grid)
uvec2 pbf_row(ivec3 c, int k)
{
    int z = c.z + k / 5 - 2, y = c.y + k % 5 - 2;
    if (z < 0 || z >= u_grid.z || y < 0 || y >= u_grid.y)
        return uvec2(0u);
    int x0 = max(c.x - 2, 0), x1 = min(c.x + 2, u_grid.x - 1);
    uint row = uint((z * u_grid.y + y) * u_grid.x);
    return uvec2(start[row + uint(x0)], start[row + uint(x1) + 1u]);
}
