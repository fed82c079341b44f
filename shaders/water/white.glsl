// The light white water scatters back (spray, foam, bubbles): the sample host's default sun
// (scene environment.sun_dir, normalised), the sky above, the horizon towards the sun and the
// sun, as their luminance with a quarter of their hue: white water stays white under the dusk sky.
const vec3 WATER_SUN = vec3(-0.4653, 0.3619, -0.8079);
vec3 water_white_light()
{
    vec3 sun_h = normalize(vec3(WATER_SUN.x, 0.15, WATER_SUN.z));
    vec3 light = 0.5 * (volfx_sky(vec3(0.0, 1.0, 0.0), WATER_SUN) + volfx_sky(sun_h, WATER_SUN))
               + 0.35 * vec3(1.0, 0.62, 0.32);
    float lum = dot(light, vec3(0.2126, 0.7152, 0.0722));
    return 1.2 * mix(vec3(lum), light, 0.25);
}
