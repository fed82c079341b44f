// Steam puffs (steam.vert): a soft disc, a Gaussian cut smoothly to 0 at the quad's edge, broken
// into wisps by a value noise fixed in the world that the puffs drift through (neighbouring puffs
// read the same field, so a cloud of them shows shared wisps, not a pile of discs). Premultiplied
// over the frame; it fades out softly where the host's geometry or the water's front is near
// behind the puff's plane instead of being cut there.
#include "common/depth.glsl"
layout(binding = 0) uniform sampler2D u_dist;
layout(binding = 1) uniform sampler2D u_scene_depth;
uniform mat4 u_inv_view_proj;
uniform vec3 u_eye;
uniform float u_h;
uniform bool u_has_depth;
in vec2 v_c;
in vec3 v_world;
flat in vec4 v_col;
flat in float v_r;
out vec4 o_color;

float steam_hash(vec3 p)
{
    p = fract(p * 0.3183099 + 0.1) * 17.0;
    return fract(p.x * p.y * p.z * (p.x + p.y + p.z));
}

float steam_noise(vec3 x)
{
    vec3 i = floor(x), f = fract(x);
    f = f * f * (3.0 - 2.0 * f);
    return mix(mix(mix(steam_hash(i), steam_hash(i + vec3(1, 0, 0)), f.x),
                   mix(steam_hash(i + vec3(0, 1, 0)), steam_hash(i + vec3(1, 1, 0)), f.x), f.y),
               mix(mix(steam_hash(i + vec3(0, 0, 1)), steam_hash(i + vec3(1, 0, 1)), f.x),
                   mix(steam_hash(i + vec3(0, 1, 1)), steam_hash(i + vec3(1, 1, 1)), f.x), f.y), f.z);
}

void main()
{
    float r2 = dot(v_c, v_c);
    if (r2 >= 1.0) discard;
    float w = exp(-3.0 * r2) * (1.0 - r2);
    vec3 q = v_world / (0.8 * u_h);
    w *= mix(0.2, 1.7, 0.65 * steam_noise(q) + 0.35 * steam_noise(2.3 * q));
    ivec2 pix = ivec2(gl_FragCoord.xy);
    vec2 ndc = (vec2(pix) + 0.5) / vec2(textureSize(u_dist, 0)) * 2.0 - 1.0;
    float d = length(v_world - u_eye);
    if (u_has_depth) {
        float sd = volfx_depth_distance(u_inv_view_proj, u_eye, ndc, texelFetch(u_scene_depth, pix, 0).r);
        w *= clamp((sd - d) / (0.5 * v_r), 0.0, 1.0);
    }
    float front = texelFetch(u_dist, pix, 0).r;
    if (front >= 0.0)
        w *= clamp(1.0 - (d - front) / (0.5 * v_r), 0.0, 1.0);
    float a = v_col.a * w;
    if (!(a > 1.0 / 512.0)) discard;
    // lit from above: the top of a puff brighter than its underside (the vapour shades itself)
    o_color = vec4(v_col.rgb * mix(0.6, 1.05, 0.5 + 0.5 * v_c.y) * a, a);
}
