#version 450
// The Vulkan host's opaque scene: flat vertex colours (see scene.vert).
layout(location = 0) in vec3 v_color;
layout(location = 0) out vec4 frag;
void main()
{
    frag = vec4(v_color, 1.0);
}
