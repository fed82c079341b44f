// Ray distance from the eye to the nearest opaque thing per pixel, for the CPU volume renderer's
// clip: the host's depth turned into view depth by the projection, times the length of the
// pixel's ray (dx, dy, -1) (the renderer's own ray model), then the water's distance if nearer.
// No opaque thing: +infinity.
layout(std140, binding = 0) uniform VolumeDist {
    vec4 u_proj;   // P[0], P[5], P[8], P[9]
    vec4 u_depth;  // P[10], P[14], has_water
    vec4 u_size;   // width, height
};
layout(binding = 0) uniform sampler2D u_scene_depth;
layout(binding = 1) uniform sampler2D u_water_dist;
out float o_dist;

void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy);
    float dist = uintBitsToFloat(0x7f800000u);
    float d = texelFetch(u_scene_depth, p, 0).r;
    if (d < 1.0) {
        vec2 ndc = (vec2(p) + 0.5) / u_size.xy * 2.0 - 1.0;
        vec2 dxy = (ndc + u_proj.zw) / u_proj.xy;
        float t = u_depth.y / ((2.0 * d - 1.0) + u_depth.x);
        dist = t * sqrt(dot(dxy, dxy) + 1.0);
    }
    if (u_depth.z > 0.0) {
        float w = texelFetch(u_water_dist, p, 0).r;
        if (w >= 0.0 && w < dist)
            dist = w;
    }
    o_dist = dist;
}
