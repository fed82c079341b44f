// lights_probe.comp — tests only (tests/water/test_water_lights.c; the lab's shader table, never
// libvolfx's): evaluates the water's effect-light terms (water/effect_lights.glsl) for a list of
// cases, so the test holds the GLSL itself to a float64 quadrature.
layout(local_size_x = 64) in;
#include "water/effect_lights.glsl"
struct ProbeCase {
    vec4 x_s;     // surface point, lobe width
    vec4 r_kind;  // reflected ray (unit), kind (0 point, 1 line)
    vec4 p0_hmin; // light start, h_min
    vec4 p1;      // light end
    vec4 n;       // the surface's normal (unit) for the irradiance
};
layout(std430, binding = 0) readonly buffer Cases { ProbeCase cases[]; };
layout(std430, binding = 1) writeonly buffer Results { vec4 results[]; };  // spec, fluence, irradiance
uniform uint u_count;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_count)
        return;
    ProbeCase c = cases[i];
    vec3 t = c.r_kind.w > 0.5 ? water_line_light(c.x_s.xyz, c.r_kind.xyz, c.x_s.w, c.p0_hmin.xyz, c.p1.xyz, c.p0_hmin.w, c.n.xyz)
                              : water_point_light(c.x_s.xyz, c.r_kind.xyz, c.x_s.w, c.p0_hmin.xyz, c.p0_hmin.w, c.n.xyz);
    results[i] = vec4(t, 0.0);
}
