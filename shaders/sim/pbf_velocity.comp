// Velocity edits between steps: MODE 0 scales every velocity (the settle's damping, 0 at its end);
// MODE 1 is an impulse where something hit the fluid (sph_impulse.c rt_sph_impulse): within
// `radius` of the centre, the velocity's component along u = normalize(unit(x - centre) - 0.7 dir)
// raised to speed (1 - r / radius)^2 when below it, never lowered.
#include "sim/pbf_common.glsl"
layout(std430, binding = 0) readonly buffer Pos { vec4 pos[]; };
layout(std430, binding = 2) buffer Vel { vec4 vel[]; };
uniform int u_mode;
uniform float u_scale;
uniform vec4 u_centre;   // centre, radius
uniform vec4 u_dir;      // unit direction of travel (or 0), speed

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= PBF_N)
        return;
    if (u_mode == 0) {
        vel[i].xyz *= u_scale;
        return;
    }
    vec3 o = pos[i].xyz - u_centre.xyz;
    float radius = u_centre.w, r2 = dot(o, o);
    if (!(r2 < radius * radius))
        return;
    float r = sqrt(r2), w = 1.0 - r / radius;
    vec3 u = (r > 1e-6 * radius ? o / r : u_dir.xyz) - 0.7 * u_dir.xyz;
    float ul = length(u);
    if (!(ul > 0.0))
        return;
    vec3 v = vel[i].xyz;
    float vu = dot(v, u) / ul, want = u_dir.w * w * w;
    if (vu >= want)
        return;
    vel[i].xyz = v + ((want - vu) / ul) * u;
}
