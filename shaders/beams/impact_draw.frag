// impact_draw.frag — the impacts' radiance (linear, added into the beams' light before bloom).
// Glow and sparks are hidden where the host's surface is nearer than they are (a small
// tolerance: the glow lies on the surface); the flare is at a hit the camera sees.
#include "common/frame.glsl"
#include "beams/impact_depth.glsl"
in vec2 v_c;
in vec3 v_rel;
flat in vec3 v_rgb;
layout(location = 0) out vec4 o_light;
void main()
{
#if !defined(FLARE)
    vec3 S;
    float d = length(v_rel);
    if (impact_surface(ivec2(gl_FragCoord.xy), S) && d > length(S) + 0.02 + 0.01 * d)
        discard;
#endif
    float r2 = dot(v_c, v_c);
#if defined(GLOW)
    float k = max(1.0 - r2, 0.0);
    o_light = vec4(v_rgb * k * k, 0.0);
#elif defined(SPARK)
    float k = max(1.0 - v_c.x * v_c.x, 0.0);
    o_light = vec4(v_rgb * k, 0.0);
#else
    // a white-hot core in the beam's colour, and a four-point star of thin rays
    float core = exp(-14.0 * r2), halo = exp(-4.0 * r2) * max(1.0 - r2, 0.0);
    float rays = (exp(-120.0 * v_c.y * v_c.y) + exp(-120.0 * v_c.x * v_c.x)) * max(1.0 - sqrt(r2), 0.0);
    vec3 c = v_rgb * (2.5 * halo + 1.5 * rays) + vec3(6.0) * core * (0.5 + 0.5 * v_rgb);
    o_light = vec4(c, 0.0);
#endif
}
