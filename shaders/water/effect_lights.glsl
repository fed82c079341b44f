// effect_lights.glsl — the water lit by the plugin's own lights (the beams' get_lights: a line
// light per beam segment, a point per head and impact; docs/water-look.md "Beams in the water,
// and the water lit by them").
// Two terms per light, both in closed form:
//
//  - specular: the surface's reflection lobe D(l) = exp((r.l - 1) / s^2) / N(s), a spherical
//    Gaussian around the reflected view ray r, normalised over the sphere
//    (N = 2 pi s^2 (1 - exp(-2 / s^2)), so its integral over every direction is 1), integrated
//    over the light: L = F x I x integral D(l(u)) du / d(u)^2 (a mirror with a blur: the radiance
//    of a line of I per unit length seen along r, spread over the lobe). A line light gives a
//    streak along the reflected beam.
//  - fluence: the light's fluence rate at the surface point, integral I du / d(u)^2 (isotropic
//    scattering: every direction counts; a spray drop scatters it).
//  - irradiance on the surface's normal n: integral I max(n.l, 0) du / d(u)^2, which the body and
//    the foam scatter as they scatter the sun's and the sky's (tint x E / pi, a Lambertian of the
//    water's deep colour where the water is opaque): the glow under a beam.
//
// On the segment p(u) = f + u e (f the foot of x on the line, e the unit direction, h = |f - x|)
// the direction from x is l = cos(phi) a + sin(phi) e with a = (f - x) / h and phi = atan(u / h),
// and du / d^2 = dphi / h. So the fluence is (phi1 - phi0) / h exactly; the irradiance on n is
// (1 / h) integral max(A cos(phi) + B sin(phi), 0) dphi (A = n.a, B = n.e) = (1 / h) integral
// R max(cos(phi - psi), 0) dphi (R = sqrt(A^2 + B^2), psi = atan(B, A)): over phi in [phi0, phi1]
// clipped to [psi - pi/2, psi + pi/2], R (sin(hi - psi) - sin(lo - psi)) / h exactly (phi stays in
// (-pi/2, pi/2), so the clip needs no wrap); and with
// r = cos(delta) (cos(phi*) a + sin(phi*) e) + sin(delta) (a x e) (spherical Pythagoras),
// r.l = cos(delta) cos(phi - phi*): the lobe along the segment is
// exp((cos(delta) - 1) / s^2) exp(c (cos(phi - phi*) - 1)), c = cos(delta) / s^2. With
// y = 2 sin((phi - phi*) / 2), cos(phi - phi*) - 1 = -y^2 / 2 exactly and
// dphi = dy / sqrt(1 - y^2 / 4) = dy (1 + y^2 / 8 + 3 y^4 / 128 + ..): keeping two terms, the
// integral is an erf difference plus y exp(-c y^2 / 2) end terms; the next term is
// 9 / (128 c^2) relative (3e-5 at c = 50, the widest lobe kept at s = 0.1). Lobes with
// cos(delta) < 1/2 are dropped: there D <= exp(-1 / (2 s^2)) of its peak (e^-50 at s = 0.1).
// h is clamped below at the caller's h_min (a beam is a tube, not a line: its light does not grow
// without bound at its axis). tests/water/test_water_lights.c holds both terms to a float64
// quadrature over the segment, through its probe shader in the lab's table.

float water_erf(float x)
{
    // Abramowitz & Stegun 7.1.26 (|error| <= 1.5e-7), odd extension
    float t = 1.0 / (1.0 + 0.3275911 * abs(x));
    float y = 1.0 - t * (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))))
                    * exp(-x * x);
    return x < 0.0 ? -y : y;
}

// The lobe's normalisation over the sphere: 1 / (2 pi s^2 (1 - exp(-2 / s^2))).
float water_lobe_norm(float s)
{
    return 1.0 / (6.2831853 * s * s * (1.0 - exp(-2.0 / (s * s))));
}

// Point light at p seen from x with the normal n: (specular lobe integral, fluence, irradiance on
// n), per unit intensity.
vec3 water_point_light(vec3 x, vec3 r, float s, vec3 p, float h_min, vec3 n)
{
    vec3 dx = p - x;
    float d2 = max(dot(dx, dx), h_min * h_min);
    float inv = inversesqrt(max(dot(dx, dx), 1e-30));
    float rl = dot(r, dx) * inv;
    return vec3(water_lobe_norm(s) * exp((rl - 1.0) / (s * s)), 1.0, max(dot(n, dx) * inv, 0.0)) / d2;
}

// Line light p0..p1 (intensity per unit length 1) seen from x with the reflected ray r, lobe
// width s (radians) and the normal n: (specular lobe integral, fluence, irradiance on n).
vec3 water_line_light(vec3 x, vec3 r, float s, vec3 p0, vec3 p1, float h_min, vec3 n)
{
    vec3 seg = p1 - p0;
    float len = length(seg);
    if (!(len > 0.0))
        return vec3(0.0);
    vec3 e = seg / len;
    float u0 = dot(p0 - x, e);               // the segment runs over [u0, u0 + len] from the foot
    vec3 f = p0 - u0 * e;                     // the foot of x on the line
    vec3 fa = f - x;
    float h_true = length(fa);
    float h = max(h_true, h_min);
    // a: toward the foot; any unit vector across e when x is on the line
    vec3 a = h_true > 1e-6 * len ? fa / h_true : normalize(cross(e, abs(e.x) < 0.9 ? vec3(1, 0, 0) : vec3(0, 1, 0)));
    float phi0 = atan(u0, h), phi1 = atan(u0 + len, h);
    float fluence = (phi1 - phi0) / h;
    float na = dot(n, a), ne = dot(n, e), psi = atan(ne, na);
    float lo = max(phi0, psi - 1.5707963), hi = min(phi1, psi + 1.5707963);
    float irr = hi > lo ? sqrt(na * na + ne * ne) * (sin(hi - psi) - sin(lo - psi)) / h : 0.0;
    float ra = dot(r, a), re = dot(r, e);
    float cd = sqrt(ra * ra + re * re);       // cos(delta)
    float spec = 0.0;
    if (cd > 0.5) {
        float ps = atan(re, ra);              // phi*
        float c = cd / (s * s), k = sqrt(0.5 * c);
        // y = 2 sin((phi - phi*) / 2): cos(phi - phi*) - 1 = -y^2 / 2 and dphi = dy (1 + y^2 / 8 + ..)
        float ya = 2.0 * sin(0.5 * clamp(phi0 - ps, -3.14159265, 3.14159265));
        float yb = 2.0 * sin(0.5 * clamp(phi1 - ps, -3.14159265, 3.14159265));
        float g = 1.2533141 / sqrt(c) * (water_erf(k * yb) - water_erf(k * ya)); // sqrt(pi / 2c) erf
        g = (1.0 + 0.125 / c) * g - 0.125 / c * (yb * exp(-0.5 * c * yb * yb) - ya * exp(-0.5 * c * ya * ya));
        spec = water_lobe_norm(s) * exp((cd - 1.0) / (s * s)) * g / h;
    }
    return vec3(spec, fluence, irr);
}

#ifdef WATER_EFFECT_LIGHTS
// The lights of this frame (plugin/water/water_lights.c fills it from get_lights once a frame;
// the program is built with WATER_EFFECT_LIGHTS only when there is at least one)
struct WaterLight {
    vec4 p0_kind;    // xyz, kind (0 point, 1 line)
    vec4 p1_hmin;    // xyz, h_min
    vec4 color_i;    // linear rgb x intensity
};
layout(std140, binding = 7) uniform WaterLights {
    uvec4 u_light_count;
    WaterLight u_lights[WATER_MAX_LIGHTS];
};

// Sum over the lights at surface point x with reflected ray r and normal n: rgb specular (before
// Fresnel), rgb fluence, rgb irradiance on n.
void water_effect_lights(vec3 x, vec3 r, float s, vec3 n, out vec3 spec, out vec3 fluence, out vec3 irr)
{
    spec = vec3(0.0);
    fluence = vec3(0.0);
    irr = vec3(0.0);
    for (uint i = 0u; i < u_light_count.x; ++i) {
        WaterLight l = u_lights[i];
        vec3 sf = l.p0_kind.w > 0.5 ? water_line_light(x, r, s, l.p0_kind.xyz, l.p1_hmin.xyz, l.p1_hmin.w, n)
                                    : water_point_light(x, r, s, l.p0_kind.xyz, l.p1_hmin.w, n);
        spec += sf.x * l.color_i.rgb;
        fluence += sf.y * l.color_i.rgb;
        irr += sf.z * l.color_i.rgb;
    }
}

// the surface's reflection lobe (radians; VOLFX_WATER_LIGHT_LOBE in plugin/water/water_lights.h)
#define WATER_LIGHT_LOBE 0.12

// What the effect lights add at the surface point x (normal n): the specular streak through
// Fresnel, and the glow the body scatters as it scatters the sun and the sky (shade.frag
// water_body: albedo x tint x irradiance / pi where it is opaque, 1 - trans of it), through the
// surface (1 - Fresnel). *irr: the lights' irradiance on n (the foam on the surface scatters it).
vec3 water_effect_light_radiance(vec3 x, vec3 r, vec3 n, float fresnel, vec3 trans, vec3 tint, float albedo,
                                 out vec3 irr)
{
    vec3 spec, flu;
    water_effect_lights(x, r, WATER_LIGHT_LOBE, n, spec, flu, irr);
    return fresnel * spec + (1.0 - fresnel) * albedo * 0.3183099 * tint * (vec3(1.0) - trans) * irr;
}
#endif
