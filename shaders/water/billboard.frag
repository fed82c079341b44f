// Fragment stage of the billboard passes, chosen by a define:
//   PASS_INIT (eq. 1): t = D.(P - O) - h, nearest kept by the depth test.
//   PASS_SKIP (eqs. 2-4): jump the next sample over gaps between candidate regions.
//   PASS_POT: additive blending of this particle's potential at NS samples (RGBA = 4 samples).
//   PASS_GRAD: at the found surface point, additive blending of grad P (xyz) and P (w): the
//     normal is -grad sum P normalised, without a per-pixel loop over the particles.
//   PASS_BACK: farthest exit of the ray from the balls of radius u_rho around the particles
//     (max blending): the back of the water for the absorption thickness.
#include "common/depth.glsl"
#include "water/frame.glsl"
flat in vec3 v_p;
uniform float u_rho;
layout(binding = 0) uniform sampler2D u_in;   // SKIP: t'_next; POT: sample; GRAD/BACK: surface
layout(binding = 1) uniform sampler2D u_pyr;  // POT: min/max pyramid (RG)
uniform int u_pyr_level;
uniform bool u_cull;
layout(std430, binding = 4) buffer Counters {
    uint c_culled, c_frags, c_samples, c_found, c_cap, c_left, c_gculled, c_gfrags;
};
out vec4 o_val;

// Every sample x of the pixel's tile has |x - O| in [min, max], so |x - P| >= |dc - |x - O||:
// the particle (distance dc from the eye) reaches none of them when this is true.
bool tile_misses(ivec2 pix, float dc)
{
    vec2 mm = texelFetch(u_pyr, pix >> u_pyr_level, u_pyr_level).rg;
    return dc - u_h > mm.y || dc + u_h < mm.x;
}

void main()
{
    ivec2 pix = ivec2(gl_FragCoord.xy);
    vec2 ndc = gl_FragCoord.xy / u_sizef * 2.0 - 1.0;
    vec3 dir = volfx_ray_dir(u_inv_view_proj, u_eye, ndc);
    float tb = dot(dir, v_p - u_eye);
#if defined(PASS_INIT)
    float t = max(tb - u_h, 0.0);
    if (tb < 0.0) discard; // candidate region wholly behind the eye
    o_val = vec4(t);
    gl_FragDepth = t / (t + 1.0);
#elif defined(PASS_SKIP)
    float tn = texelFetch(u_in, pix, 0).r;
    if (tn >= 1.0e29) discard;          // stopped or finished ray
    if (tb < tn) discard;               // eq. 3: region ends before the candidate sample
    float tf = tb - u_h;
    float nx = tf < tn ? tn : tf;       // eq. 4
    o_val = vec4(nx);
    gl_FragDepth = nx / (nx + 1.0);
#elif defined(PASS_GRAD)
    float t = texelFetch(u_in, pix, 0).r;
    if (t < 0.0) discard; // no water on this pixel
    if (u_cull && tile_misses(pix, length(v_p - u_eye))) {
        atomicAdd(c_gculled, 1u);
        discard;
    }
    vec3 d = u_eye + t * dir - v_p;
    float r = length(d);
    if (!(r < u_h)) discard; // outside the support (or NaN): adds nothing
    atomicAdd(c_gfrags, 1u);
    float q = 1.0 - r / u_h;
    // dP/dr = -2q/h along (x - p)/r; at r = 0 the cone tip has no direction: its symmetric
    // limit, 0, is taken.
    vec3 g = r > 0.0 ? (-2.0 * q / (u_h * r)) * d : vec3(0.0);
    o_val = vec4(g, q * q);
#elif defined(PASS_BACK)
    float t = texelFetch(u_in, pix, 0).r;
    if (t < 0.0) discard;
    vec3 oc = v_p - u_eye;
    float perp2 = dot(oc, oc) - tb * tb, rho2 = u_rho * u_rho;
    if (!(perp2 < rho2)) discard; // the ray misses this particle's ball (or NaN)
    float tx = tb + sqrt(rho2 - perp2);
    if (tx <= t) discard;
    o_val = vec4(tx);
#else
    float t = texelFetch(u_in, pix, 0).r;
    if (t >= 1.0e29) discard;
    float dc = length(v_p - u_eye);
    if (u_cull && tile_misses(pix, dc)) {
        atomicAdd(c_culled, 1u);
        discard;
    }
    atomicAdd(c_frags, 1u);
    vec4 pot = vec4(0.0);
    for (int s = 0; s < NS; ++s) {
        vec3 x = u_eye + (t + float(s) * u_step) * dir;
        float r = length(x - v_p);
        float q = max(1.0 - r / u_h, 0.0);
        pot[s] = q * q;
    }
    o_val = pot;
#endif
}
