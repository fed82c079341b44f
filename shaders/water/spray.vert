// Spray and foam: per fast particle a camera-facing quad of radius u_radius. Instances are
// particles; a slow or non-finite one is sent outside the clip volume.
layout(std430, binding = 0) readonly buffer PX { float px[]; };
layout(std430, binding = 1) readonly buffer PY { float py[]; };
layout(std430, binding = 2) readonly buffer PZ { float pz[]; };
layout(std430, binding = 3) readonly buffer Speed { float speed[]; };
// the effect's counter buffer: slot 26 counts the isolated particles drawn as spray
layout(std430, binding = 4) buffer Counters { uint counters[]; };
// neighbours of each particle from the anisotropic kernels' pass (bound when u_min_nb > 0)
layout(std430, binding = 5) readonly buffer Neighbours { uint nb[]; };
uniform uint u_min_nb;  // fewer neighbours than this: isolated (0: no neighbour counts)
uniform mat4 u_view_proj;
uniform vec3 u_eye;
uniform float u_radius;
uniform vec2 u_speed;   // from where a particle shows, to where it is fully white
uniform float u_speed_isolated; // an isolated particle moving this fast is a flying drop
out vec2 v_c;           // the quad's corner coordinates (-1..1)
out vec3 v_world;
flat out float v_a;
void main()
{
    uint i = uint(gl_InstanceID);
    vec3 p = vec3(px[i], py[i], pz[i]);
    float s = speed[i];
    v_c = vec2(gl_VertexID & 1, gl_VertexID >> 1) * 2.0 - 1.0;
    vec3 v = p - u_eye;
    float d = length(v);
    // a drop that left the body: few neighbours and moving (one at rest on its own is a puddle)
    bool isolated = u_min_nb > 0u && nb[i] < u_min_nb && s >= u_speed_isolated;
    // slow, non-finite, or around the eye (a quad there would fill the screen)
    if (!(s >= u_speed.x || isolated) || any(isnan(p)) || any(isinf(p)) || !(d > 2.0 * u_radius)) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        return;
    }
    v /= d;
    vec3 ref = abs(v.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    vec3 r = normalize(cross(v, ref)), u = cross(r, v);
    v_world = p + u_radius * (v_c.x * r + v_c.y * u);
    v_a = max(smoothstep(u_speed.x, u_speed.y, s), isolated ? 0.8 : 0.0);
    if (isolated && !(s >= u_speed.x) && gl_VertexID == 0) atomicAdd(counters[26], 1u);
    gl_Position = u_view_proj * vec4(v_world, 1.0);
}
