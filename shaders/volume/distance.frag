// Ray distance from the eye to the nearest opaque thing per pixel, for the CPU volume renderer's
// clip: the host's depth turned into view depth by the projection, times the length of the
// pixel's ray (dx, dy, -1) (the renderer's own ray model), then the water's distance if nearer.
// No opaque thing: +infinity.
// The camera from the frame gate's block (projection, frame size); the effect's own block says
// only whether the water's distance is bound.
#include "common/frame.glsl"
layout(std140, binding = 0) uniform VolumeDist {
    vec4 u_water;  // x: 1 when the water's distance is bound
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
        vec2 ndc = (vec2(p) + 0.5) / vfx_planes_size.zw * 2.0 - 1.0;
        vec2 dxy = (ndc + vec2(vfx_proj[2][0], vfx_proj[2][1])) / vec2(vfx_proj[0][0], vfx_proj[1][1]);
        float t = vfx_proj[3][2] / ((2.0 * d - 1.0) + vfx_proj[2][2]);
        dist = t * sqrt(dot(dxy, dxy) + 1.0);
    }
    if (u_water.x > 0.0) {
        float w = texelFetch(u_water_dist, p, 0).r;
        if (w >= 0.0 && w < dist)
            dist = w;
    }
    o_dist = dist;
}
