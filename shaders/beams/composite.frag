// Adds the beams' light (linear radiance) and, when on, the bloom chain's top level into the
// host frame (blend ONE, ONE): an HDR host keeps it linear, an 8-bit one clamps.
#include "beams/frame.glsl"

layout(binding = 0) uniform sampler2D u_light;
layout(binding = 1) uniform sampler2D u_bloom_tex;
in vec2 v_uv;
out vec4 o_color;

void main()
{
    vec4 l4 = texelFetch(u_light, ivec2(gl_FragCoord.xy), 0);
    vec3 L = l4.rgb + vec3(l4.a); // a: the white cores (integrate.frag), kept out of the bloom
    if (u_bloom != 0)
        L += u_bloom_gain * texture(u_bloom_tex, v_uv).rgb;
    if (!(L.r + L.g + L.b > 0.0))
        discard;
    // at most half the largest half float: added to a host colour below that, an RGBA16F frame
    // stays finite whatever bloom_strength (up to 1e6) does to the capped light (issue 28)
    o_color = vec4(min(L, vec3(32768.0)), 0.0);
}
