// Procedural dusk sky, shared by the host's background and the water's reflections so that what
// the water mirrors is what the player sees behind it. Radiance in the host's units (display
// white = 1): the sun's disc is far above 1 and blooms in an HDR host.
vec3 volfx_sky(vec3 d, vec3 sun_dir)
{
    d = normalize(d);
    vec3 sun = normalize(sun_dir);
    vec3 zenith = vec3(0.045, 0.075, 0.19);
    vec3 horizon = vec3(0.62, 0.36, 0.24);
    vec3 ground = vec3(0.07, 0.06, 0.06);
    float up = d.y;
    vec3 c = up >= 0.0 ? mix(horizon, zenith, pow(clamp(up, 0.0, 1.0), 0.45))
                       : mix(horizon, ground, smoothstep(0.0, 0.35, -up));
    // the horizon glows warmer on the sun's side
    float side = max(dot(normalize(vec3(d.x, 0.0, d.z) + 1e-6), normalize(vec3(sun.x, 0.0, sun.z) + 1e-6)), 0.0);
    c += vec3(0.35, 0.14, 0.04) * pow(side, 3.0) * exp(-abs(up) * 6.0);
    float s = max(dot(d, sun), 0.0);
    c += vec3(1.0, 0.62, 0.32) * (0.22 * pow(s, 12.0) + 14.0 * pow(s, 2400.0));
    return c;
}
