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
// The plugin's lights (vfx_light, get_lights of plugin api 3), relative to the origin like
// v_world: per light p0 + kind (0 point, 1 line), p1 + intensity, colour + radius.
#define RT_MAX_LIGHTS 32
uniform int u_light_count;
uniform vec4 u_lights[3 * RT_MAX_LIGHTS];
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

// Irradiance at x (unit normal n) of an isotropic segment p0..p1 of intensity I per unit length:
// E = I * integral over the segment of max(n.(p - x), 0) / |p - x|^3, in closed form. With
// p(t) = p0 + t d - x = a + t d, u = t + a.d and h^2 = |a|^2 - (a.d)^2 (distance to the line):
// integral of (A + B u) / (u^2 + h^2)^(3/2) du = A u / (h^2 sqrt(u^2 + h^2)) - B / sqrt(u^2 + h^2),
// A = n.a - (n.d)(a.d), B = n.d, after clipping the segment to the half-space n.(p - x) > 0
// (linear in t, so the clip is exact). Tested against float64 quadrature (test beams_impact_light).
float line_irradiance(vec3 x, vec3 n, vec3 p0, vec3 p1, float I)
{
    vec3 a = p0 - x, e = p1 - p0;
    float L = length(e);
    if (!(L > 1e-6)) {
        float d2 = max(dot(a, a), 1e-6);
        return I * L * max(dot(n, a), 0.0) / (d2 * sqrt(d2));
    }
    vec3 d = e / L;
    float al = dot(n, a), be = dot(n, d), t0 = 0.0, t1 = L;
    if (be > 0.0)
        t0 = max(t0, -al / be);
    else if (be < 0.0)
        t1 = min(t1, -al / be);
    else if (al <= 0.0)
        return 0.0;
    if (!(t1 > t0))
        return 0.0;
    float b = dot(a, d), h2 = max(dot(a, a) - b * b, 1e-8), A = al - be * b;
    float u0 = t0 + b, u1 = t1 + b, s0 = sqrt(u0 * u0 + h2), s1 = sqrt(u1 * u1 + h2);
    return I * max(A / h2 * (u1 / s1 - u0 / s0) - be * (1.0 / s1 - 1.0 / s0), 0.0);
}

// Irradiance at x (normal n) of the plugin's lights, in linear RGB.
vec3 plugin_lights(vec3 x, vec3 n)
{
    vec3 E = vec3(0.0);
    for (int i = 0; i < u_light_count && i < RT_MAX_LIGHTS; ++i) {
        vec4 a = u_lights[3 * i], b = u_lights[3 * i + 1], c = u_lights[3 * i + 2];
        if (a.w == 0.0) {
            vec3 v = a.xyz - x;
            float d2 = max(dot(v, v), 1e-6);
            if (d2 < c.w * c.w)
                E += c.rgb * (b.w * max(dot(n, v), 0.0) / (d2 * sqrt(d2)));
        } else {
            E += c.rgb * line_irradiance(x, n, a.xyz, b.xyz, b.w);
        }
    }
    return E;
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
        // a Lambertian surface of albedo u_color x checker: radiance = albedo E / pi
        o_color = vec4(u_color * checker * (0.25 + 0.75 * diffuse + plugin_lights(v_world, n) / 3.14159265), 1.0);
        return;
    }
    vec3 albedo = u_color * stone(p, n);
    vec3 sky_up = volfx_sky(vec3(0.0, 1.0, 0.0), l), sky_side = volfx_sky(vec3(n.x, 0.05, n.z), l);
    vec3 ambient = mix(sky_side, sky_up, clamp(n.y * 0.5 + 0.5, 0.0, 1.0)) * 1.5 + vec3(0.07, 0.07, 0.09);
    vec3 sun = vec3(1.0, 0.72, 0.48) * 1.7 * diffuse;
    vec3 c = albedo * (ambient + sun + plugin_lights(v_world, n) / 3.14159265);
    vec3 v = v_world - u_eye;
    float fog = 1.0 - exp(-u_fog * length(v));
    c = mix(c, volfx_sky(vec3(v.x, 0.02, v.z), l), fog);
    o_color = vec4(c, 1.0);
}
