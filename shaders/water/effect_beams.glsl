// effect_beams.glsl — the beams seen in the water (docs/water-look.md "Beams in the water"). The
// beams' prepare step (plugin/beams/beams_effect.c) split each pixel's ray at this water's surface: the
// light in front of the surface (composited over the water afterwards: the water never sees it
// at its own pixel) and the light behind it. The refracted ray sees the light behind the surface
// where it leaves the water, like the host colour there (so it is absorbed like it); the
// reflected ray (SSR) sees all the beams' light at the pixel where it meets the host's scene, as
// an SSR of the finished frame would. Only in the program built with WATER_BEAMS (a frame with
// beams and water).
#ifdef WATER_BEAMS
layout(binding = 7) uniform sampler2D u_beams_light;   // in front of the water (a: white cores)
layout(binding = 8) uniform sampler2D u_beams_behind;  // behind its surface (a: white cores)

vec3 water_beams_behind(ivec2 p)
{
    vec4 b = texelFetch(u_beams_behind, p, 0);
    return b.rgb + vec3(b.a);
}

vec3 water_beams_seen(ivec2 p)
{
    vec4 f = texelFetch(u_beams_light, p, 0);
    return f.rgb + vec3(f.a) + water_beams_behind(p);
}
#endif
