// Diffuse particles' quads, one instance a pool entry (the indirect draw's count is the pool's).
// SPLAT: foam and bubbles, a camera-facing quad of radius u_radius (bubbles half of it).
// STREAK: spray, a camera-facing capsule of half-width u_radius from where the drop was
// u_shutter seconds ago to where it is (motion blur). The other classes (and steam, drawn by
// steam.vert) are sent outside the clip volume, as is a quad around the eye.
layout(std430, binding = 0) readonly buffer Pool { vec4 pool[]; };
uniform mat4 u_view_proj;
uniform vec3 u_eye;
uniform float u_radius, u_shutter;
out vec2 v_c;           // SPLAT: the corner (-1..1); STREAK: (across / r, along from the tail)
out vec3 v_world;
flat out float v_len;   // STREAK: the streak's length on the camera-facing plane
flat out uint v_cls;
void main()
{
    uint i = uint(gl_InstanceID);
    vec4 a = pool[2u * i], b = pool[2u * i + 1u];
    vec3 p = a.xyz, v = b.xyz;
    v_cls = uint(b.w);
    vec2 c = vec2(gl_VertexID & 1, gl_VertexID >> 1) * 2.0 - 1.0;
    vec3 e = p - u_eye;
    float d = length(e);
#if defined(SPLAT)
    bool drawn = v_cls == 1u || v_cls == 2u;   // steam (3) has its own draw, steam.vert
#else
    bool drawn = v_cls == 0u;
#endif
    if (!drawn || !(d > 2.0 * u_radius)) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        return;
    }
    vec3 w = e / d;
    vec3 ref = abs(w.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
#if defined(SPLAT)
    float r = v_cls == 2u ? 0.5 * u_radius : u_radius;
    vec3 sx = normalize(cross(w, ref)), sy = cross(sx, w);
    v_c = c;
    v_len = 0.0;
    v_world = p + r * (c.x * sx + c.y * sy);
#else
    float r = u_radius;
    vec3 ax = v * u_shutter;
    ax -= dot(ax, w) * w;                    // on the camera-facing plane
    float L = length(ax);
    vec3 along = L > 1.0e-6 * r ? ax / L : normalize(cross(w, ref));
    vec3 side = normalize(cross(along, w));
    float s = c.y < 0.0 ? -r : L + r;        // from behind the tail to past the head
    v_c = vec2(c.x, s);
    v_len = L;
    v_world = p - ax + s * along + c.x * r * side;
#endif
    gl_Position = u_view_proj * vec4(v_world, 1.0);
}
