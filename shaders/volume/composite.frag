// Composites the CPU cell-projection image (premultiplied RGBA, already clipped by the host's
// depth) over the host frame: blend ONE, ONE_MINUS_SRC_ALPHA.
layout(binding = 0) uniform sampler2D u_image;
out vec4 o_color;

void main()
{
    vec4 c = texelFetch(u_image, ivec2(gl_FragCoord.xy), 0);
    if (c.a <= 0.0 && dot(c.rgb, vec3(1.0)) <= 0.0)
        discard;
    o_color = c;
}
