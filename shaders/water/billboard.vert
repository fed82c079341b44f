// Seed 000 billboard: per particle the eye-facing front face of the cube around its sphere of
// influence, built here straight from the position columns (no CPU geometry). Instances are
// particles; 4 vertices as a strip. A non-finite particle is sent outside the clip volume.
layout(std430, binding = 0) readonly buffer PX { float px[]; };
layout(std430, binding = 1) readonly buffer PY { float py[]; };
layout(std430, binding = 2) readonly buffer PZ { float pz[]; };
#include "water/frame.glsl"
flat out vec3 v_p;
void main()
{
    uint i = uint(gl_InstanceID);
    vec3 p = vec3(px[i], py[i], pz[i]);
    vec2 c = vec2(gl_VertexID & 1, gl_VertexID >> 1) * 2.0 - 1.0;
    v_p = p;
    if (any(isnan(p)) || any(isinf(p))) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        return;
    }
    vec3 v = p - u_eye;
    float d = length(v);
    // Eye in or near the cube (its face would cross the near plane): cover the whole screen;
    // the fragment clamps t at 0.
    if (d - u_h * 1.7320508 < 2.0 * u_near) {
        gl_Position = vec4(c, 0.0, 1.0);
        return;
    }
    v /= d;
    vec3 ref = abs(v.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    vec3 r = normalize(cross(v, ref)), u = cross(r, v);
    // The face at distance d - h with half-size h covers the sphere's silhouette (half-angle
    // asin(h/d) < atan(h/(d-h))).
    vec3 corner = p - u_h * v + u_h * (c.x * r + c.y * u);
    gl_Position = u_view_proj * vec4(corner, 1.0);
}
