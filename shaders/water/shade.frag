// Water shading from the distance image and the gradient / back-distance targets (the two
// billboard passes, or TILE's march from its lists): normal = -grad sum P normalised, Schlick
// Fresnel between the reflected environment (the host's cubemap, else the procedural dusk sky
// the sample host draws behind its scene, shaders/common/sky.glsl) and the light that comes
// through the water: the refracted ray is traced in screen space through the water's volume
// (between the front distance and the back distance of the pixel it crosses, clipped at the
// host depth) until it leaves it, so the thickness is the one along the refracted ray and the
// host colour is looked up where that ray leaves (REFRACT_*); Beer-Lambert over that thickness
// with the absorbed part partly scattered back as the tint (WATER_SCATTER), plus the sun's
// highlight. The reflected ray first looks for the host's scene in screen space (SSR: marched
// against the host depth, the host colour where it meets it, fading to the sky at the screen's
// edges); off screen or past the march it sees the cubemap or the sky. The diffuse particles'
// layer adds foam (white, opacity 1 - exp(-FOAM_K x thickness)) on the surface and the bubbles
// seen through the water. Misses are discarded so the host image shows through unchanged. An
// HDR host gets the highlight unclamped (it blooms); a display-colour host gets everything
// clamped to 1.
#include "common/depth.glsl"
#include "common/sky.glsl"
#include "water/white.glsl"
#include "water/effect_lights.glsl"
#include "water/effect_beams.glsl"
layout(binding = 0) uniform sampler2D u_dist;
layout(binding = 1) uniform sampler2D u_scene_color;
layout(binding = 2) uniform sampler2D u_grad;   // xyz = grad sum P, w = sum P
layout(binding = 3) uniform sampler2D u_back;   // farthest ball exit along the ray
layout(binding = 4) uniform sampler2D u_scene_depth;
layout(binding = 5) uniform samplerCube u_env;  // the host's environment (frame view 2)
layout(binding = 6) uniform sampler2D u_diffuse; // R foam thickness, G bubbles (u_has_diffuse)
layout(binding = 9) uniform sampler2D u_foam;    // the foam layer: density over world x, z (u_has_foam)
// the effect's counter buffer: slot 26 counts the reflected rays that met the host's scene
layout(std430, binding = 4) buffer Counters { uint c_slots_[26]; uint c_ssr_hits; };
uniform mat4 u_inv_view_proj, u_view_proj;
uniform vec3 u_eye;
uniform float u_h;                  // kernel radius: the smallest thickness the trace resolves
uniform bool u_refract_view;        // ablation: the view ray's thickness and a fixed offset
uniform float u_absorption, u_ior;
uniform vec3 u_tint;
uniform bool u_flat, u_has_color, u_has_depth, u_has_env, u_hdr, u_ssr, u_has_diffuse;
// the look's switches (the quality presets, water_params.c): the host image as the
// surroundings' light, the sun's GGX lobe (else the old narrow Phong glint)
uniform bool u_host_light, u_ggx;
// the foam layer (plugin/water/water_foam.c): its grid (x0, z0, 1 / width, 1 / depth); with
// u_foam_layer the diffuse layer's per-particle foam (R) is not drawn
uniform vec4 u_foam_grid;
uniform vec2 u_foam_offset;         // the frame's origin (x, z) modulo the froth's period
uniform bool u_has_foam, u_foam_layer;
out vec4 o_color;
// single scattering: the body's albedo (the share of the absorbed light that the water's
// particles scatter back towards the eye, lit by the water's light)
#define WATER_ALBEDO 1.0
// the sun's lobe on the surface: GGX, alpha = roughness^2 (calm water; the waves the normals
// carry make the glints)
#define WATER_GGX_ALPHA 0.01
// the host image's light: the mean of a WATER_HOST_GRID^2 grid of its pixels, weighted
#define WATER_HOST_GRID 4
#define WATER_HOST_K 0.6
// SSR: SSR_STEPS steps growing as k^2 over SSR_REACH x the eye's distance (at least 40 h), a
// hit where the ray passes behind the host depth by less than the step (or h), refined by
// SSR_BISECT halvings; both bounds hold for any input
#define SSR_STEPS 24
#define SSR_BISECT 5
#define SSR_REACH 2.0
// foam opacity per unit of splatted thickness, bubbles' brightness per unit
#define FOAM_K 0.6
#define BUBBLE_K 0.5
// The refracted ray's trace: REFRACT_STEPS even steps over twice the view ray's thickness (plus
// h), then REFRACT_BISECT halvings of the step where it left; both bounds hold for any input.
#define REFRACT_STEPS 16
#define REFRACT_BISECT 6

vec2 g_size;

// Cellular noise: the distance from x to the nearest of one jittered point per unit cell (about
// 0 at a bubble's centre, 0.5-0.8 at the walls between bubbles), repeating every `period` cells.
float water_cells(vec2 x, float period)
{
    vec2 c = floor(x), f = x - c;
    float d = 8.0;
    for (int j = -1; j <= 1; ++j)
        for (int i = -1; i <= 1; ++i) {
            vec2 o = vec2(i, j), q = mod(c + o, period);
            vec2 jit = fract(sin(vec2(dot(q, vec2(127.1, 311.7)), dot(q, vec2(269.5, 183.3)))) * 43758.5453);
            d = min(d, length(o + jit - f));
        }
    return d;
}

// The foam layer's cover at density d and world x, z: 1 - e^-d on average, as a froth: where thin
// only the walls between bubbles (cellular noise of two sizes, h/3 and h/9, fixed in the world)
// are white, and the bubbles fill in as it thickens. Where a pixel spans a bubble or more
// (fwidth of x, z) the froth gives way to its mean, the plain cover: no sub-pixel grain.
float water_foam_cover(float d, vec2 xz, float footprint)
{
    if (!(d > 1.0e-3))
        return 0.0;
    float c = 1.0 - exp(-d);
    // the world's x, z modulo the period: WATER_FOAM_NOISE_PERIOD large cells, 3 times as many small
    xz += u_foam_offset;
    float big = water_cells(xz / (0.33 * u_h), 4096.0), small = water_cells(xz / (0.11 * u_h), 3.0 * 4096.0);
    small = mix(small, 0.5, smoothstep(0.25, 0.7, footprint / (0.11 * u_h)));
    float walls = 0.65 * big + 0.35 * small;
    float froth = clamp(max(smoothstep(0.95 - 0.8 * c, 1.1 - 0.8 * c, walls), c * c) * min(3.0 * c, 1.0), 0.0, 1.0);
    return mix(froth, c, smoothstep(0.25, 0.7, footprint / (0.33 * u_h)));
}

// Is the point inside the water's screen-space volume? false off screen too; *pix its pixel.
bool in_water(vec3 y, out ivec2 pix)
{
    vec4 q = u_view_proj * vec4(y, 1.0);
    pix = ivec2(-1);
    if (!(q.w > 0.0)) return false;
    vec3 ndc = q.xyz / q.w;
    if (any(greaterThan(abs(ndc.xy), vec2(1.0)))) return false;
    pix = clamp(ivec2((ndc.xy * 0.5 + 0.5) * g_size), ivec2(0), ivec2(g_size) - 1);
    float d = length(y - u_eye);
    float front = texelFetch(u_dist, pix, 0).r;
    if (front < 0.0 || d < front || d > texelFetch(u_back, pix, 0).r) return false;
    // behind the host surface at that pixel: the ray has reached the pool's floor or a wall
    if (u_has_depth && ndc.z * 0.5 + 0.5 > texelFetch(u_scene_depth, pix, 0).r) return false;
    return true;
}

// Length of the refracted ray x + s rd inside the water, up to s_max; *exit_pix the pixel where
// it leaves (-1 when it leaves the screen, and then the length is where it did), *inside_pix
// the last sample's pixel that was inside (-1: none).
float refracted_thickness(vec3 x, vec3 rd, float s_max, out ivec2 exit_pix, out ivec2 inside_pix)
{
    float ds = s_max / float(REFRACT_STEPS), s0 = 0.0;
    ivec2 pix;
    exit_pix = ivec2(-1);
    inside_pix = ivec2(-1);
    for (int k = 1; k <= REFRACT_STEPS; ++k) {
        float s1 = ds * float(k);
        if (in_water(x + s1 * rd, pix)) { s0 = s1; inside_pix = pix; continue; }
        // left between s0 and s1: halve the step (the first sample sits just inside the front)
        exit_pix = pix;
        for (int b = 0; b < REFRACT_BISECT; ++b) {
            float sm = 0.5 * (s0 + s1);
            if (in_water(x + sm * rd, pix)) { s0 = sm; inside_pix = pix; }
            else { s1 = sm; exit_pix = pix; }
        }
        return 0.5 * (s0 + s1);
    }
    return s_max;
}

// Where the ray from x along r passes behind the host depth: *col the host colour there and
// *fade its weight (0 at the screen's edges and at the march's end); false when it leaves the
// screen, goes behind the eye or meets nothing.
bool ssr(vec3 x, vec3 r, float t, out vec3 col, out float fade)
{
    col = vec3(0.0);
    fade = 0.0;
    float reach = max(SSR_REACH * t, 40.0 * u_h), s0 = 0.0;
    for (int k = 1; k <= SSR_STEPS; ++k) {
        float f = float(k) / float(SSR_STEPS), s1 = reach * f * f;
        vec4 q = u_view_proj * vec4(x + s1 * r, 1.0);
        if (!(q.w > 0.0)) return false;
        vec3 ndc = q.xyz / q.w;
        if (any(greaterThan(abs(ndc.xy), vec2(1.0)))) return false;
        ivec2 pix = clamp(ivec2((ndc.xy * 0.5 + 0.5) * g_size), ivec2(0), ivec2(g_size) - 1);
        float z = texelFetch(u_scene_depth, pix, 0).r;
        if (ndc.z * 0.5 + 0.5 <= z || z >= 1.0) { s0 = s1; continue; }
        float scene = volfx_depth_distance(u_inv_view_proj, u_eye, ndc.xy, z);
        float behind = length(x + s1 * r - u_eye) - scene;
        // passed far behind a surface (the ray went under an object's edge): not this one
        if (behind > max(s1 - s0, u_h)) { s0 = s1; continue; }
        float a = s0, b = s1;
        for (int i = 0; i < SSR_BISECT; ++i) {
            float m = 0.5 * (a + b);
            vec4 qm = u_view_proj * vec4(x + m * r, 1.0);
            vec3 nm = qm.xyz / qm.w;
            ivec2 pm = clamp(ivec2((nm.xy * 0.5 + 0.5) * g_size), ivec2(0), ivec2(g_size) - 1);
            if (nm.z * 0.5 + 0.5 > texelFetch(u_scene_depth, pm, 0).r) { b = m; pix = pm; ndc = nm; }
            else a = m;
        }
        col = texelFetch(u_scene_color, pix, 0).rgb;
#ifdef WATER_BEAMS
        col += water_beams_seen(pix);
#endif
        vec2 edge = smoothstep(vec2(1.0), vec2(0.85), abs(ndc.xy));
        fade = edge.x * edge.y * (1.0 - f * f);
        return true;
    }
    return false;
}

// The surroundings' light from the host's image (what the host drew before the water: its
// lighting, whatever it is): the mean of a fixed grid of its pixels. Every pixel reads the
// same grid, so the light is one value a frame.
vec3 water_host_light()
{
    if (!u_host_light || !u_has_color)
        return vec3(0.0);
    vec3 sum = vec3(0.0);
    ivec2 size = textureSize(u_scene_color, 0);
    for (int j = 0; j < WATER_HOST_GRID; ++j)
        for (int i = 0; i < WATER_HOST_GRID; ++i)
            sum += min(texelFetch(u_scene_color, (ivec2(i, j) * 2 + 1) * size / (2 * WATER_HOST_GRID), 0).rgb, vec3(4.0));
    return WATER_HOST_K * sum / float(WATER_HOST_GRID * WATER_HOST_GRID);
}

// The body: Beer-Lambert over the refracted thickness (per channel, (1 - tint) x absorption),
// and the light the body scatters back: single scattering towards the deep colour (the tint
// times the water's light, WATER_ALBEDO), filling in as the water thickens. Shallow water
// (thickness << 1 / absorption) stays clear.
vec3 water_body(vec3 behind, float thickness, vec3 light)
{
    vec3 trans = exp(-u_absorption * thickness * (vec3(1.0) - u_tint));
    vec3 deep = WATER_ALBEDO * u_tint * light;
    return behind * trans + deep * (vec3(1.0) - trans);
}

// The surface: Schlick Fresnel (ior u_ior) between the body seen through it and the reflected
// environment, plus the sun's specular (GGX, Smith's visibility, Schlick's F at the half
// vector) or, with u_ggx off, the old narrow glint on the reflected ray.
vec3 water_surface(vec3 body, vec3 env, vec3 n, vec3 v)
{
    float c = clamp(dot(v, n), 0.0, 1.0);
    float r0 = pow((u_ior - 1.0) / (u_ior + 1.0), 2.0);
    float fresnel = r0 + (1.0 - r0) * pow(1.0 - c, 5.0);
    vec3 col = mix(body, env, fresnel);
    if (!u_ggx)
        return col + vec3(2.0, 1.5, 1.1) * pow(max(dot(reflect(-v, n), WATER_SUN), 0.0), 400.0);
    float nl = dot(n, WATER_SUN);
    if (nl <= 0.0 || c <= 0.0)
        return col;
    vec3 hv = normalize(v + WATER_SUN);
    float nh = max(dot(n, hv), 0.0), a2 = WATER_GGX_ALPHA * WATER_GGX_ALPHA;
    float dd = nh * nh * (a2 - 1.0) + 1.0;
    float D = a2 / (3.14159265 * dd * dd);
    float k = 0.5 * WATER_GGX_ALPHA;        // Smith-Schlick for GGX
    float vis = 1.0 / (4.0 * (c * (1.0 - k) + k) * (nl * (1.0 - k) + k));
    float F = r0 + (1.0 - r0) * pow(1.0 - max(dot(v, hv), 0.0), 5.0);
    // radiance = D F vis E_sun n.l, E_sun = pi x WATER_SUN_E (irradiance / pi)
    return col + D * F * vis * 3.14159265 * WATER_SUN_E * nl;
}

// The refracted ray's exit pixel is the host colour behind the water only if the host there is
// not in front of the water: an object standing in front of the surface (its outline near the
// pixel) would lend its colour. Then the trace falls back to the pixel where the ray was last
// inside the water, else the unrefracted pixel.
ivec2 water_behind_pixel(ivec2 pix, ivec2 ep, ivec2 inside, float exit_dist)
{
    if (ep.x < 0)
        return pix;
    if (!u_has_depth)
        return ep;
    vec2 endc = (vec2(ep) + 0.5) / g_size * 2.0 - 1.0;
    float host = volfx_depth_distance(u_inv_view_proj, u_eye, endc, texelFetch(u_scene_depth, ep, 0).r);
    float front = texelFetch(u_dist, ep, 0).r;
    // the host at the exit pixel lies in front of where the ray left the water (by more than
    // the trace's resolution) and in front of the water's front there: an occluder
    if (host < exit_dist - 2.0 * u_h && (front < 0.0 || host < front))
        return inside.x >= 0 ? inside : pix;
    return ep;
}

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
    vec3 r = reflect(dir, n);
    vec3 sky = u_has_env ? texture(u_env, r).rgb : volfx_sky(r, WATER_SUN);
    g_size = size;
    if (u_ssr && u_has_color && u_has_depth) {
        vec3 hit;
        float fade;
        if (ssr(u_eye + t * dir, r, t, hit, fade)) {
            sky = mix(sky, hit, fade);
            atomicAdd(c_ssr_hits, 1u);
        }
    }
    vec3 behind = vec3(0.1, 0.15, 0.2);
    float back = texelFetch(u_back, pix, 0).r;
    if (u_has_depth)
        back = min(back, volfx_depth_distance(u_inv_view_proj, u_eye, ndc, texelFetch(u_scene_depth, pix, 0).r));
    float thickness = max(back - t, 0.0);
    vec3 rd = refract(dir, n, 1.0 / u_ior);
    if (u_refract_view || dot(rd, rd) == 0.0) {
        if (u_has_color) behind = texture(u_scene_color, (vec2(pix) + 0.5) / size + rd.xy * 0.03).rgb;
    } else {
        ivec2 ep, inside;
        // a step past the front so the first sample is inside (the front's refine tolerance)
        vec3 x = u_eye + (t + 1.0e-3 * u_h) * dir;
        thickness = refracted_thickness(x, rd, 2.0 * thickness + u_h, ep, inside);
        ivec2 bp = water_behind_pixel(pix, ep, inside, length(x + thickness * rd - u_eye));
        if (u_has_color)
            behind = texelFetch(u_scene_color, bp, 0).rgb;
#ifdef WATER_BEAMS
        behind += water_beams_behind(bp);
#endif
    }
    // the water's light: the sky (the host's cubemap or the procedural sky), the sun through the
    // surface, the surroundings (the host's image), the plugin's lights at the surface
    vec3 zen = u_has_env ? texture(u_env, vec3(0.0, 1.0, 0.0)).rgb : volfx_sky(vec3(0.0, 1.0, 0.0), WATER_SUN);
    vec3 sun_h = normalize(vec3(WATER_SUN.x, 0.15, WATER_SUN.z));
    vec3 hor = u_has_env ? texture(u_env, sun_h).rgb : volfx_sky(sun_h, WATER_SUN);
    vec3 ambient = water_sky_ambient(zen, hor) + water_host_light();
    vec3 p = u_eye + t * dir;
    vec3 light = ambient + WATER_SUN_E * max(WATER_SUN.y, 0.0);
    vec3 body = water_body(behind, thickness, light);
    vec2 foam_bub = u_has_diffuse ? texelFetch(u_diffuse, pix, 0).rg : vec2(0.0);
    vec3 white = water_white(ambient, vec3(0.0, 1.0, 0.0));
    // bubbles: white specks behind the surface (already attenuated by the water in front)
    body += water_white(ambient, vec3(0.0)) * (1.0 - exp(-BUBBLE_K * foam_bub.g)) * u_tint * 1.5;
    vec3 col = water_surface(body, sky, n, -dir);
    vec3 fx_irr = vec3(0.0);   // the plugin's lights' irradiance on the surface (the foam's too)
#ifdef WATER_EFFECT_LIGHTS
    {
        // the beams' lights: a streak along the reflected beam (weighted by Fresnel) and the
        // glow scattered in the body (weighted by what the body absorbs), as water_surface and
        // water_body weigh the sun and the sky
        float c = clamp(dot(-dir, n), 0.0, 1.0);
        float r0 = pow((u_ior - 1.0) / (u_ior + 1.0), 2.0);
        float fresnel = r0 + (1.0 - r0) * pow(1.0 - c, 5.0);
        vec3 trans = exp(-u_absorption * thickness * (vec3(1.0) - u_tint));
        col += water_effect_light_radiance(p, r, n, fresnel, trans, u_tint, WATER_ALBEDO, fx_irr);
    }
#endif
    // foam on the surface hides what is under it, the glint too: the per-particle foam, or the
    // foam layer on the surface where it faces up, lit as a white scatterer with the surface's
    // normal (sun, sky, the host's light, the plugin's lights)
    if (!u_foam_layer)
        col = mix(col, white, 1.0 - exp(-FOAM_K * foam_bub.r));
    float foam_d = u_has_foam ? texture(u_foam, (p.xz - u_foam_grid.xy) * u_foam_grid.zw).r : 0.0;
    vec2 fw = fwidth(p.xz);
    float foam_a = water_foam_cover(foam_d, p.xz, max(fw.x, fw.y)) * smoothstep(-0.2, 0.5, n.y);
    if (foam_a > 0.0) {
        // a Lambertian scatterer under the lights too: albedo 0.9 x their irradiance / pi
        vec3 froth = water_white(ambient, n) + 0.9 * 0.3183099 * fx_irr;
        col = mix(col, froth, foam_a);
    }
    o_color = vec4(u_hdr ? col : min(col, vec3(1.0)), 1.0);
}
