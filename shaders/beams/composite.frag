// Adds the beams' light to the host frame: intensity from H by clamping at c (the thesis) or a
// smooth saturation 1 - exp(-H/c), coloured by the H-weighted tint of the beams in the pixel.
uniform sampler2D u_acc;
uniform float u_c;
uniform int u_smooth;
out vec4 o_color;

void main()
{
    vec4 a = texelFetch(u_acc, ivec2(gl_FragCoord.xy), 0);
    float H = a.x;
    if (!(H > 0.0))
        discard;
    vec3 tint = a.yzw / H;
    float I = u_smooth != 0 ? 1.0 - exp(-H / u_c) : min(H / u_c, 1.0);
    o_color = vec4(tint * I, 0.0);
}
