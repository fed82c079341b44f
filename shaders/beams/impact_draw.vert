// impact_draw.vert — the impacts' quads, one instance each, additive into the beams' light:
// GLOW a spot lying on the surface (its tangent plane), fading as exp(-age / tau);
// SPARK a camera-facing streak from where the spark was u_params.z seconds ago to where it is;
// FLARE a camera-facing burst at a beam's hit. Dead entries are sent outside the clip volume.
#include "common/frame.glsl"
#include "beams/impact_depth.glsl"
out vec2 v_c;             // the quad's corner, -1..1 (SPARK: across, along)
out vec3 v_rel;           // camera-relative position (occlusion against the host depth)
flat out vec3 v_rgb;      // radiance at the centre
void main()
{
    uint i = uint(gl_InstanceID);
    vec2 c = vec2(gl_VertexID & 1, gl_VertexID >> 1) * 2.0 - 1.0;
    v_c = c;
    vec3 eye = u_eye_dt.xyz, w;
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
#if defined(GLOW)
    vec4 g = glows[3u * i], gn = glows[3u * i + 1u], ge = glows[3u * i + 2u];
    if (!(ge.w > 0.0) || g.w >= ge.w)
        return;
    vec3 n = gn.xyz;
    vec3 t1 = normalize(cross(n, abs(n.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0))), t2 = cross(n, t1);
    w = g.xyz + gn.w * (c.x * t1 + c.y * t2);
    v_rgb = ge.rgb * exp(-g.w / u_params.w);
#elif defined(SPARK)
    vec4 a = sparks[3u * i], b = sparks[3u * i + 1u];
    if (!(b.w > 0.0) || a.w >= b.w)
        return;
    float f = 1.0 - a.w / b.w;
    vec3 head = a.xyz - eye, tail = head - b.xyz * u_params.z;
    vec3 axis = head - tail;
    if (dot(axis, axis) < 1e-8)
        axis = vec3(0.0, 1e-4, 0.0);
    vec3 side = cross(axis, head);
    float sl = length(side);
    side = sl > 0.0 ? side / sl : vec3(1.0, 0.0, 0.0);
    float r = 0.006 + 0.003 * f;
    w = mix(tail, head, c.y * 0.5 + 0.5) + c.x * r * side + eye;
    v_rgb = mix(sparks[3u * i + 2u].rgb, vec3(1.0, 0.95, 0.8), 0.6 * f) * (8.0 * f * f);
#else
    vec4 h = hits[3u * i];
    if (h.w == 0.0)
        return;
    vec4 col = hits[3u * i + 2u];
    float pulse = 1.0 + 0.2 * sin(u_params.x * 37.0 + float(i) * 2.1);
    vec3 e = normalize(h.xyz - eye);
    vec3 sx = normalize(cross(e, abs(e.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0))), sy = cross(sx, e);
    float r = 3.0 * col.w * pulse;
    w = h.xyz + hits[3u * i + 1u].xyz * (0.3 * col.w) + r * (c.x * sx + c.y * sy);
    v_rgb = col.rgb * pulse;
#endif
    v_rel = w - eye;
    gl_Position = vfx_cam_view_proj * vec4(v_rel, 1.0);
}
