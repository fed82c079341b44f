// Water shading from the distance image and the gradient / back-distance targets (the two
// billboard passes, or TILE's march from its lists): normal = -grad sum P normalised, Schlick
// Fresnel between the reflected environment (the host's cubemap, else the procedural dusk sky
// the sample host draws behind its scene, shaders/common/sky.glsl) and the refracted host colour, absorbed with Beer-Lambert over
// the thickness to the back of the water (clipped at the host depth) with the absorbed part
// partly scattered back as the tint (WATER_SCATTER), plus the sun's highlight. Misses are
// discarded so the host image shows through unchanged. An HDR host gets the highlight unclamped
// (it blooms); a display-colour host gets everything clamped to 1.
#include "common/depth.glsl"
#include "common/sky.glsl"
layout(binding = 0) uniform sampler2D u_dist;
layout(binding = 1) uniform sampler2D u_scene_color;
layout(binding = 2) uniform sampler2D u_grad;   // xyz = grad sum P, w = sum P
layout(binding = 3) uniform sampler2D u_back;   // farthest ball exit along the ray
layout(binding = 4) uniform sampler2D u_scene_depth;
layout(binding = 5) uniform samplerCube u_env;  // the host's environment (frame view 2)
uniform mat4 u_inv_view_proj;
uniform vec3 u_eye;
uniform float u_absorption, u_ior;
uniform vec3 u_tint;
uniform bool u_flat, u_has_color, u_has_depth, u_has_env, u_hdr;
out vec4 o_color;
#define WATER_SCATTER 0.35
// the sample host's default sun (scene environment.sun_dir), normalised
const vec3 WATER_SUN = vec3(-0.4653, 0.3619, -0.8079);

void main()
{
    ivec2 pix = ivec2(gl_FragCoord.xy);
    float t = texelFetch(u_dist, pix, 0).r;
    if (t < 0.0) discard;
    if (u_flat) { o_color = vec4(u_tint, 1.0); return; }
    vec2 size = vec2(textureSize(u_dist, 0));
    vec2 ndc = (vec2(pix) + 0.5) / size * 2.0 - 1.0;
    vec3 dir = volfx_ray_dir(u_inv_view_proj, u_eye, ndc);
    vec3 g = texelFetch(u_grad, pix, 0).xyz;
    // a zero gradient (the eye inside a symmetric blob) has no direction: face the viewer
    vec3 n = dot(g, g) > 0.0 ? -normalize(g) : -dir;
    float c = clamp(dot(-dir, n), 0.0, 1.0);
    float r0 = pow((u_ior - 1.0) / (u_ior + 1.0), 2.0);
    float fresnel = r0 + (1.0 - r0) * pow(1.0 - c, 5.0);
    vec3 r = reflect(dir, n);
    vec3 sky = u_has_env ? texture(u_env, r).rgb : volfx_sky(r, WATER_SUN);
    vec3 behind = vec3(0.1, 0.15, 0.2);
    if (u_has_color) {
        vec3 rd = refract(dir, n, 1.0 / u_ior);
        vec2 uv = (vec2(pix) + 0.5) / size + rd.xy * 0.03;
        behind = texture(u_scene_color, uv).rgb;
    }
    float back = texelFetch(u_back, pix, 0).r;
    if (u_has_depth)
        back = min(back, volfx_depth_distance(u_inv_view_proj, u_eye, ndc, texelFetch(u_scene_depth, pix, 0).r));
    float thickness = max(back - t, 0.0);
    // what the water takes out of the light from behind it comes back partly as its own
    // colour (light scattered in the body): a deep pool reads as tinted water, not black
    vec3 trans = exp(-u_absorption * thickness * (vec3(1.0) - u_tint));
    vec3 body = behind * trans + WATER_SCATTER * u_tint * (vec3(1.0) - trans);
    // the sun's highlight on the reflected ray: a warm glint on every wave facing it
    float sun = pow(max(dot(r, WATER_SUN), 0.0), 400.0);
    vec3 col = mix(body, sky, fresnel) + vec3(2.0, 1.5, 1.1) * sun;
    o_color = vec4(u_hdr ? col : min(col, vec3(1.0)), 1.0);
}
