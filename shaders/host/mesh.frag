// Host meshes. Default look: a lit surface with a checker so motion and refraction read well in
// tests and screenshots. Environment look (a scene's "environment"): stone tiles with grout and
// per-tile variation, a warm sun, a hemisphere ambient from the same sky the background and the
// water's reflections use, and fog towards the horizon colour.
#include "common/sky.glsl"
in vec3 v_normal;
in vec3 v_world;
uniform vec3 u_color;
uniform vec3 u_light_dir;
uniform int u_environment;
uniform vec3 u_eye;
uniform float u_fog;
uniform vec3 u_origin; // the scene's origin: v_world is relative to it, the patterns are the world's
out vec4 o_color;

float hash2(vec2 p)
{
    return fract(sin(dot(p, vec2(127.1, 311.7))) * 43758.5453);
}

// Tiles in the plane facing the normal's dominant axis: 0.5 m stones, 2 cm grout.
float stone(vec3 p, vec3 n)
{
    vec3 a = abs(n);
    vec2 uv = a.y > a.x && a.y > a.z ? p.xz : (a.x > a.z ? p.zy : p.xy);
    uv *= 2.0;
    vec2 cell = floor(uv);
    vec2 f = fract(uv);
    // far away a pixel covers many stones: fade the pattern to its mean instead of aliasing
    vec2 w = fwidth(uv);
    float aa = max(w.x, w.y);
    float edge = min(min(f.x, 1.0 - f.x), min(f.y, 1.0 - f.y));
    float grout = smoothstep(0.015, 0.05 + aa, edge);
    float tone = 0.82 + 0.22 * hash2(cell) + 0.05 * hash2(floor(uv * 7.0)) * (1.0 - smoothstep(0.05, 0.15, aa));
    return mix(0.86, mix(0.45, tone, grout), 1.0 - smoothstep(0.12, 0.45, aa));
}

void main()
{
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing)
        n = -n;
    vec3 l = normalize(u_light_dir);
    float diffuse = max(dot(n, l), 0.0);
    vec3 p = v_world + u_origin; // the patterns stay put in the world whatever the origin
    if (u_environment == 0) {
        vec3 c = floor(p * 2.0);
        float checker = mod(c.x + c.y + c.z, 2.0) * 0.15 + 0.85;
        o_color = vec4(u_color * checker * (0.25 + 0.75 * diffuse), 1.0);
        return;
    }
    vec3 albedo = u_color * stone(p, n);
    vec3 sky_up = volfx_sky(vec3(0.0, 1.0, 0.0), l), sky_side = volfx_sky(vec3(n.x, 0.05, n.z), l);
    vec3 ambient = mix(sky_side, sky_up, clamp(n.y * 0.5 + 0.5, 0.0, 1.0)) * 1.5 + vec3(0.07, 0.07, 0.09);
    vec3 sun = vec3(1.0, 0.72, 0.48) * 1.7 * diffuse;
    vec3 c = albedo * (ambient + sun);
    vec3 v = v_world - u_eye;
    float fog = 1.0 - exp(-u_fog * length(v));
    c = mix(c, volfx_sky(vec3(v.x, 0.02, v.z), l), fog);
    o_color = vec4(c, 1.0);
}
