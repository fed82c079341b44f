// Camera rays and host depth, shared by every effect. A pixel's ray goes from the eye through
// the pixel centre (docs/architecture.md gives the convention); distances are along the
// normalised ray direction, so effects can compare them directly.

// World position of the point at window depth `depth` (0..1) under pixel `ndc`.
vec3 volfx_unproject(mat4 inv_view_proj, vec2 ndc, float depth)
{
    vec4 p = inv_view_proj * vec4(ndc, depth * 2.0 - 1.0, 1.0);
    return p.xyz / p.w;
}

// Normalised ray direction from the eye through `ndc`.
vec3 volfx_ray_dir(mat4 inv_view_proj, vec3 eye, vec2 ndc)
{
    return normalize(volfx_unproject(inv_view_proj, ndc, 0.5) - eye);
}

// Distance along the ray to the host surface at window depth `depth`; +inf-like for the far
// plane (depth >= 1) so an empty background does not clip effects.
float volfx_depth_distance(mat4 inv_view_proj, vec3 eye, vec2 ndc, float depth)
{
    if (depth >= 1.0)
        return 3.0e38;
    return length(volfx_unproject(inv_view_proj, ndc, depth) - eye);
}
