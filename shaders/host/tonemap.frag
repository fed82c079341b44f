// Host output: the HDR colour (linear radiance, RGBA16F) times the exposure, through the ACES
// filmic curve (Stephen Hill's fit of the RRT and sRGB ODT, linear in and out), into the 8-bit
// display target. Values the LDR pipeline wrote (meshes, <= 1) stay close to themselves; the
// beams' white-hot cores (>> 1) roll off to white instead of clipping per channel.
uniform sampler2D u_hdr;
uniform float u_exposure;
out vec4 o_color;

const mat3 ACES_IN = mat3(0.59719, 0.07600, 0.02840, 0.35458, 0.90834, 0.13383, 0.04823, 0.01566, 0.83777);
const mat3 ACES_OUT = mat3(1.60475, -0.10208, -0.00327, -0.53108, 1.10813, -0.07276, -0.07367, -0.00605, 1.07602);

vec3 rrt_odt_fit(vec3 v)
{
    vec3 a = v * (v + 0.0245786) - 0.000090537;
    vec3 b = v * (0.983729 * v + 0.4329510) + 0.238081;
    return a / b;
}

void main()
{
    vec4 c = texelFetch(u_hdr, ivec2(gl_FragCoord.xy), 0);
    vec3 v = ACES_OUT * rrt_odt_fit(ACES_IN * (max(c.rgb, vec3(0.0)) * u_exposure));
    o_color = vec4(clamp(v, 0.0, 1.0), c.a);
}
