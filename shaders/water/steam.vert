// Steam puffs (diffuse class 3: shaders/water/diffuse.comp makes them at a beam's impact on the
// water), one instance a pool entry (the indirect draw's count is the pool's; the other classes
// are sent outside the clip volume, as is a puff around the eye). A camera-facing quad whose
// radius grows from u_radius at birth to u_radius1 at the end of its lifetime u_steam_life (the
// vapour spreads as it rises), its opacity fading in over the first tenth of its life and out to
// 0 at its end. Its light is taken once at the puff's centre (a soft puff shows no gradient worth
// a per-fragment light loop): the white-water light of the sky and sun, and (WATER_EFFECT_LIGHTS)
// the fluence of the plugin's own lights scattered evenly, so steam beside a strike glows in the
// beam's colour.
#include "common/sky.glsl"
#include "water/white.glsl"
#include "water/effect_lights.glsl"
layout(std430, binding = 0) readonly buffer Pool { vec4 pool[]; };
uniform mat4 u_view_proj;
uniform vec3 u_eye;
uniform float u_radius, u_radius1, u_steam_life;
uniform bool u_hdr;
out vec2 v_c;           // the corner (-1..1)
out vec3 v_world;
flat out vec4 v_col;    // the puff's light (rgb) and its peak opacity (a)
flat out float v_r;     // its radius
// peak opacity of a young puff: overlapping puffs build a cloud, a lone one stays a veil
#define STEAM_ALPHA 0.35
void main()
{
    uint i = uint(gl_InstanceID);
    vec4 a = pool[2u * i], b = pool[2u * i + 1u];
    vec3 p = a.xyz;
    vec2 c = vec2(gl_VertexID & 1, gl_VertexID >> 1) * 2.0 - 1.0;
    float t = clamp(1.0 - a.w / u_steam_life, 0.0, 1.0);   // the fraction of its life gone
    float r = mix(u_radius, u_radius1, sqrt(t));
    vec3 e = p - u_eye;
    float d = length(e);
    if (uint(b.w) != 3u || !(d > 2.0 * r)) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        return;
    }
    vec3 w = e / d;
    vec3 ref = abs(w.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    vec3 sx = normalize(cross(w, ref)), sy = cross(sx, w);
    v_c = c;
    v_r = r;
    v_world = p + r * (c.x * sx + c.y * sy);
    // a grey-white scatterer (albedo 0.8), like the spray under the plugin's lights
    vec3 col = 0.8 * water_white_light();
#ifdef WATER_EFFECT_LIGHTS
    vec3 fl_spec, fl, fl_irr;
    water_effect_lights(p, w, WATER_LIGHT_LOBE, vec3(0.0), fl_spec, fl, fl_irr);
    col += 0.8 * 0.0795775 * fl;
#endif
    // scaled, not clamped, into range: steam in a beam's light keeps the beam's hue
    if (!u_hdr) col /= max(1.0, max(col.r, max(col.g, col.b)));
    v_col = vec4(col, STEAM_ALPHA * smoothstep(0.0, 0.08, t) * (1.0 - smoothstep(0.35, 1.0, t)));
    gl_Position = u_view_proj * vec4(v_world, 1.0);
}
