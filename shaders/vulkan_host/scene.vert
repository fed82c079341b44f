#version 450
// The Vulkan host's opaque scene (tests/integration/vulkan_host.c): vertices arrive in clip space
// (the host multiplies by its OpenGL-convention projection * view on the CPU), so the same file
// draws the same pixels in Vulkan (glslc, SPIR-V embedded at build time) and in the test's GL
// reference (GLSL text embedded at build time).
layout(location = 0) in vec4 clip;
layout(location = 1) in vec3 color;
layout(location = 0) out vec3 v_color;
void main()
{
    gl_Position = clip;
#ifdef VULKAN
    // GL's clip z/w is in [-1, 1] and window depth is (z/w + 1) / 2; Vulkan's window depth is
    // z/w itself. Remapping z here writes the window depth GL would, so the plugin reads the
    // Vulkan depth image as the GL depth it expects. y needs nothing: clip y = -1 lands in memory
    // row 0 in both APIs (GL calls it the bottom row, Vulkan the top).
    gl_Position.z = 0.5 * (clip.z + clip.w);
#endif
    v_color = color;
}
