// Spray and foam: a soft disc, premultiplied, lit by the same dusk sky the water reflects.
// Hidden behind the host's geometry; under the water's surface it fades over half an h, so
// foam shows on the crests and spray in the air, and the body keeps its colour below.
#include "common/depth.glsl"
#include "common/sky.glsl"
layout(binding = 0) uniform sampler2D u_dist;
layout(binding = 1) uniform sampler2D u_scene_depth;
uniform mat4 u_inv_view_proj;
uniform vec3 u_eye;
uniform float u_h;
uniform bool u_has_depth, u_hdr;
in vec2 v_c;
in vec3 v_world;
flat in float v_a;
out vec4 o_color;
// the sample host's default sun (shade.frag's), normalised
const vec3 SPRAY_SUN = vec3(-0.4653, 0.3619, -0.8079);
void main()
{
    float r2 = dot(v_c, v_c);
    if (r2 >= 1.0) discard;
    ivec2 pix = ivec2(gl_FragCoord.xy);
    vec2 ndc = (vec2(pix) + 0.5) / vec2(textureSize(u_dist, 0)) * 2.0 - 1.0;
    float d = length(v_world - u_eye);
    if (u_has_depth && d > volfx_depth_distance(u_inv_view_proj, u_eye, ndc, texelFetch(u_scene_depth, pix, 0).r))
        discard;
    float front = texelFetch(u_dist, pix, 0).r;
    float under = front >= 0.0 ? max(d - front, 0.0) : 0.0;
    float a = v_a * (1.0 - r2) * (1.0 - r2) * exp(-under / (0.5 * u_h)) * 0.85;
    if (a <= 0.0) discard;
    // white water scatters the sky and the sun from every side: the sky above, the horizon
    // towards the sun, the sun itself
    vec3 sun_h = normalize(vec3(SPRAY_SUN.x, 0.15, SPRAY_SUN.z));
    vec3 light = 0.5 * (volfx_sky(vec3(0.0, 1.0, 0.0), SPRAY_SUN) + volfx_sky(sun_h, SPRAY_SUN))
               + 0.35 * vec3(1.0, 0.62, 0.32);
    // white water stays white under a coloured sky: mostly the light's luminance, a little of its hue
    float lum = dot(light, vec3(0.2126, 0.7152, 0.0722));
    vec3 col = 1.2 * mix(vec3(lum), light, 0.25);
    if (!u_hdr) col = min(col, vec3(1.0));
    o_color = vec4(col * a, a);
}
