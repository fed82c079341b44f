// Diffuse particles. SPLAT (additive into the RG16F layer the shading reads): R foam, a soft
// disc (1 - r^2)^2 counted where it lies at or above the water's front (fading over h/2 below
// it); G bubbles, a disc inside the water attenuated by the water in front of it,
// exp(-absorption x depth under the front). STREAK (premultiplied over the frame): spray as a
// capsule whose opacity is spread over its length (a fast drop streaks, it does not brighten),
// hidden behind the host's depth and fading fast under the water's front, lit by the sky, the sun
// and (WATER_EFFECT_LIGHTS) the plugin's own lights. Both are hidden behind the host's geometry.
#include "common/depth.glsl"
#include "common/sky.glsl"
#include "water/white.glsl"
#include "water/effect_lights.glsl"
layout(binding = 0) uniform sampler2D u_dist;
layout(binding = 1) uniform sampler2D u_scene_depth;
uniform mat4 u_inv_view_proj;
uniform vec3 u_eye;
uniform float u_h, u_radius, u_absorption;
uniform bool u_has_depth, u_hdr;
in vec2 v_c;
in vec3 v_world;
flat in float v_len;
flat in uint v_cls;
#if defined(SPLAT)
out vec2 o_layer;
#else
out vec4 o_color;
#endif
void main()
{
    ivec2 pix = ivec2(gl_FragCoord.xy);
    vec2 ndc = (vec2(pix) + 0.5) / vec2(textureSize(u_dist, 0)) * 2.0 - 1.0;
    float d = length(v_world - u_eye);
    if (u_has_depth && d > volfx_depth_distance(u_inv_view_proj, u_eye, ndc, texelFetch(u_scene_depth, pix, 0).r))
        discard;
    float front = texelFetch(u_dist, pix, 0).r;
    float under = front >= 0.0 ? d - front : -1.0;
#if defined(SPLAT)
    float r2 = dot(v_c, v_c);
    if (r2 >= 1.0) discard;
    float w = (1.0 - r2) * (1.0 - r2);
    if (v_cls == 2u && under > 0.0)
        o_layer = vec2(0.0, w * exp(-u_absorption * under));
    else   // foam, and a bubble that reached the surface
        o_layer = vec2(w * exp(-max(under, 0.0) / (0.5 * u_h)), 0.0);
#else
    float s = clamp(v_c.y, 0.0, v_len);
    float q2 = v_c.x * v_c.x + (v_c.y - s) * (v_c.y - s) / (u_radius * u_radius);
    if (q2 >= 1.0) discard;
    // the head brighter than the tail; the opacity spread over the streak's length
    float a = 0.9 * (1.0 - q2) * (1.0 - q2) * mix(0.35, 1.0, v_len > 0.0 ? s / v_len : 1.0)
            * u_radius / (u_radius + 0.5 * v_len);
    if (under > 0.0) a *= exp(-under / (0.25 * u_h));
    if (a <= 0.0) discard;
    vec3 col = water_white_light();
#ifdef WATER_EFFECT_LIGHTS
    // the plugin's lights (a beam's line, its head, its impact): a drop scatters their fluence
    // evenly, albedo 0.9 x fluence / 4 pi; a drop beside a strike shines in the beam's colour
    vec3 fl_spec, fl, fl_irr;
    water_effect_lights(v_world, normalize(v_world - u_eye), WATER_LIGHT_LOBE, vec3(0.0), fl_spec, fl, fl_irr);
    col += 0.9 * 0.0795775 * fl;
#endif
    if (!u_hdr) col = min(col, vec3(1.0));
    o_color = vec4(col * a, a);
#endif
}
