// Host side of the effects layer (docs/integration.md "Effects layer"): the plugin's premultiplied
// RGBA16F layer, drawn over the host's output with blend ONE, ONE_MINUS_SRC_ALPHA, i.e.
// dst = layer.rgb + dst * (1 - layer.a).
layout(binding = 0) uniform sampler2D u_layer;
out vec4 o_color;

void main()
{
    o_color = texelFetch(u_layer, ivec2(gl_FragCoord.xy), 0);
}
