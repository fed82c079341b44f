// The frame gate's depth conversion (plugin/frame_check.c): the host's window depth, written
// with its own projection and clip control (reversed-Z, GL_ZERO_TO_ONE, an infinite far plane),
// rewritten as the window depth of the standard projection the effects receive (the same camera,
// GL_NEGATIVE_ONE_TO_ONE, depth growing away from the eye, far plane at 1). In double: the
// host's depth is at most float32, so the result is its float32 rounding.
layout(binding = 0) uniform sampler2D u_depth;
uniform dvec4 u_host;    // x proj[10], y proj[14] of the host, z 1 for GL_ZERO_TO_ONE, w 1 perspective
uniform dvec2 u_std;     // proj[10], proj[14] of the standard projection

void main()
{
    double h = double(texelFetch(u_depth, ivec2(gl_FragCoord.xy), 0).r);
    double a = u_host.z > 0.5 ? h : 2.0 * h - 1.0; // the host's NDC z
    double ndc;
    if (u_host.w > 0.5) {
        // perspective: NDC z = -p10 + p14 / D for view depth D; the standard one of the same D
        // (D = inf, the far plane of an infinite projection, gives -s10 exactly)
        ndc = -u_std.x + u_std.y * (a + u_host.x) / u_host.y;
    } else {
        // orthographic: NDC z = -p10 D + p14
        double D = (u_host.y - a) / u_host.x;
        ndc = -u_std.x * D + u_std.y;
    }
    gl_FragDepth = float(clamp(0.5 * ndc + 0.5, 0.0, 1.0));
}
