// Bloom, downsample: the source (one level up, twice the size) averaged over a 4x4-texel
// footprint by five bilinear taps (centre weighted 4, four diagonal taps 1 each).
layout(binding = 0) uniform sampler2D u_src;
in vec2 v_uv;
out vec4 o_color;

void main()
{
    vec2 t = 1.0 / vec2(textureSize(u_src, 0));
    vec3 s = 4.0 * texture(u_src, v_uv).rgb;
    s += texture(u_src, v_uv + vec2(-t.x, -t.y)).rgb + texture(u_src, v_uv + vec2(t.x, -t.y)).rgb;
    s += texture(u_src, v_uv + vec2(-t.x, t.y)).rgb + texture(u_src, v_uv + vec2(t.x, t.y)).rgb;
    o_color = vec4(s * 0.125, 1.0);
}
