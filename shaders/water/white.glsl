// The light the water receives: the sample host's default sun (scene environment.sun_dir,
// normalised, and the irradiance its meshes get, shaders/host/mesh.frag), the sky above (the
// host's cubemap when it gives one, else the procedural sky), the host's own image as the light
// of the surroundings (u_host_light, shade.frag), and the plugin's own lights (water_fx_lights).
// Values are irradiance / pi: a white Lambertian scatterer's radiance.
const vec3 WATER_SUN = vec3(-0.4653, 0.3619, -0.8079);
const vec3 WATER_SUN_E = vec3(1.0, 0.72, 0.48) * 1.7;

// The plugin's own lights (beams' line lights, heads, impacts) at p with normal n (n = 0: a
// droplet lit from every side), irradiance / pi. The hook the beams' light access fills; none
// yet: the water sees the beams through the host image only.
vec3 water_fx_lights(vec3 p, vec3 n)
{
    return vec3(0.0);
}

// The sky's irradiance / pi on an upward surface: the zenith and the horizon towards the sun
// (the procedural sky; the cubemap's up and sun-side horizon when the host gives one).
vec3 water_sky_ambient(vec3 zenith, vec3 horizon)
{
    return 0.5 * (zenith + horizon) * 1.5;
}

// What a white scatterer (spray, foam, bubbles) sends back: ambient, the sun over n (n = 0:
// half of it, a drop lit from one side), the plugin's lights; the hue kept at a quarter so that
// white water stays white under a coloured sky.
vec3 water_white(vec3 ambient, vec3 p, vec3 n)
{
    float ndl = dot(n, n) > 0.0 ? max(dot(n, WATER_SUN), 0.0) : 0.5;
    vec3 light = ambient + WATER_SUN_E * ndl + water_fx_lights(p, n);
    float lum = dot(light, vec3(0.2126, 0.7152, 0.0722));
    return 0.9 * mix(vec3(lum), light, 0.25);
}

// The white light of the procedural sky alone (the diffuse particles' passes, which do not read
// the host's image): the sky's ambient and the sun on a drop.
vec3 water_white_light()
{
    vec3 sun_h = normalize(vec3(WATER_SUN.x, 0.15, WATER_SUN.z));
    vec3 amb = water_sky_ambient(volfx_sky(vec3(0.0, 1.0, 0.0), WATER_SUN), volfx_sky(sun_h, WATER_SUN));
    return water_white(amb, vec3(0.0), vec3(0.0));
}
