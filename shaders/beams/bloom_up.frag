// Bloom, upsample: a 3x3 tent (1 2 1 / 2 4 2 / 1 2 1, /16) of the smaller level, added onto the
// next larger one (blend ONE, ONE), so the top level ends as the sum of every level.
layout(binding = 0) uniform sampler2D u_src;
in vec2 v_uv;
out vec4 o_color;

void main()
{
    vec2 t = 1.0 / vec2(textureSize(u_src, 0));
    vec3 s = 4.0 * texture(u_src, v_uv).rgb;
    s += 2.0 * (texture(u_src, v_uv + vec2(t.x, 0.0)).rgb + texture(u_src, v_uv - vec2(t.x, 0.0)).rgb
                + texture(u_src, v_uv + vec2(0.0, t.y)).rgb + texture(u_src, v_uv - vec2(0.0, t.y)).rgb);
    s += texture(u_src, v_uv + t).rgb + texture(u_src, v_uv - t).rgb
         + texture(u_src, v_uv + vec2(t.x, -t.y)).rgb + texture(u_src, v_uv + vec2(-t.x, t.y)).rgb;
    o_color = vec4(s / 16.0, 1.0);
}
