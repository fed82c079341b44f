// Water shading from the distance image: normal = -grad I (central differences of the field),
// Schlick Fresnel between a sky reflection and the refracted host colour, absorbed with
// Beer-Lambert over a thickness guess. Misses are discarded so the host image shows through.
#include "common/depth.glsl"
layout(std430, binding = 0) readonly buffer PX { float px[]; };
layout(std430, binding = 1) readonly buffer PY { float py[]; };
layout(std430, binding = 2) readonly buffer PZ { float pz[]; };
layout(binding = 0) uniform sampler2D u_dist;
layout(binding = 1) uniform sampler2D u_scene_color;
uniform mat4 u_inv_view_proj;
uniform vec3 u_eye;
uniform uint u_count;
uniform float u_h, u_absorption, u_ior;
uniform vec3 u_tint;
uniform bool u_flat, u_has_color;
out vec4 o_color;

float sum_p(vec3 x)
{
    float s = 0.0, h2 = u_h * u_h;
    for (uint j = 0u; j < u_count; ++j) {
        vec3 d = x - vec3(px[j], py[j], pz[j]);
        float r2 = dot(d, d);
        if (r2 < h2) { float q = 1.0 - sqrt(r2) / u_h; s += q * q; }
    }
    return sqrt(s);
}

void main()
{
    ivec2 pix = ivec2(gl_FragCoord.xy);
    float t = texelFetch(u_dist, pix, 0).r;
    if (t < 0.0) discard;
    if (u_flat) { o_color = vec4(u_tint, 1.0); return; }
    vec2 size = vec2(textureSize(u_dist, 0));
    vec2 ndc = (vec2(pix) + 0.5) / size * 2.0 - 1.0;
    vec3 dir = vfx_ray_dir(u_inv_view_proj, u_eye, ndc);
    vec3 x = u_eye + t * dir;
    float e = u_h * 0.02;
    vec3 g = vec3(sum_p(x + vec3(e, 0, 0)) - sum_p(x - vec3(e, 0, 0)),
                  sum_p(x + vec3(0, e, 0)) - sum_p(x - vec3(0, e, 0)),
                  sum_p(x + vec3(0, 0, e)) - sum_p(x - vec3(0, 0, e)));
    vec3 n = length(g) > 0.0 ? -normalize(g) : -dir;
    float c = clamp(dot(-dir, n), 0.0, 1.0);
    float r0 = pow((u_ior - 1.0) / (u_ior + 1.0), 2.0);
    float fresnel = r0 + (1.0 - r0) * pow(1.0 - c, 5.0);
    vec3 sky = mix(vec3(0.55, 0.65, 0.75), vec3(0.9, 0.95, 1.0), clamp(reflect(dir, n).y, 0.0, 1.0));
    vec3 behind = vec3(0.1, 0.15, 0.2);
    if (u_has_color) {
        vec3 rd = refract(dir, n, 1.0 / u_ior);
        vec2 uv = (vec2(pix) + 0.5) / size + rd.xy * 0.03;
        behind = texture(u_scene_color, uv).rgb;
    }
    // thickness guess: one influence diameter, the surface's local depth is not known here
    vec3 absorbed = behind * exp(-u_absorption * 2.0 * u_h * (vec3(1.0) - u_tint));
    o_color = vec4(mix(absorbed, sky, fresnel), 1.0);
}
