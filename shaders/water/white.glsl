// The light the water receives: the sample host's default sun (scene environment.sun_dir,
// normalised, and the irradiance its meshes get, shaders/host/mesh.frag), the sky above (the
// host's cubemap when it gives one, else the procedural sky) and the host's own image as the
// light of the surroundings (u_host_light, shade.frag). Values are irradiance / pi: a white
// Lambertian scatterer's radiance. The plugin's own lights (the beams' lines, heads and impacts)
// are not here: the passes that see them add them from effect_lights.glsl's closed forms
// (WATER_EFFECT_LIGHTS): shade.frag the body's glow, the surface's streak and the foam layer's
// 0.9 x irradiance / pi, diffuse.frag a spray drop's 0.9 x fluence / 4 pi.
const vec3 WATER_SUN = vec3(-0.4653, 0.3619, -0.8079);
const vec3 WATER_SUN_E = vec3(1.0, 0.72, 0.48) * 1.7;

// The sky's irradiance / pi on an upward surface: the zenith and the horizon towards the sun
// (the procedural sky; the cubemap's up and sun-side horizon when the host gives one).
vec3 water_sky_ambient(vec3 zenith, vec3 horizon)
{
    return 0.5 * (zenith + horizon) * 1.5;
}

// What a white scatterer (spray, foam, bubbles) sends back of the sky and the sun: ambient, the
// sun over n (n = 0: half of it, a drop lit from one side); the hue kept at a quarter so that
// white water stays white under a coloured sky. (The plugin's lights: added by the caller.)
vec3 water_white(vec3 ambient, vec3 n)
{
    float ndl = dot(n, n) > 0.0 ? max(dot(n, WATER_SUN), 0.0) : 0.5;
    vec3 light = ambient + WATER_SUN_E * ndl;
    float lum = dot(light, vec3(0.2126, 0.7152, 0.0722));
    return 0.9 * mix(vec3(lum), light, 0.25);
}

// The white light of the procedural sky alone (the diffuse particles' passes, which do not read
// the host's image): the sky's ambient and the sun on a drop.
vec3 water_white_light()
{
    vec3 sun_h = normalize(vec3(WATER_SUN.x, 0.15, WATER_SUN.z));
    vec3 amb = water_sky_ambient(volfx_sky(vec3(0.0, 1.0, 0.0), WATER_SUN), volfx_sky(sun_h, WATER_SUN));
    return water_white(amb, vec3(0.0));
}
