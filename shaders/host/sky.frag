// Host background: the procedural sky along each pixel's view ray, drawn before the meshes.
#include "common/sky.glsl"
uniform mat4 u_inv_view_proj;
uniform vec3 u_sun_dir;
in vec2 v_ndc;
out vec4 o_color;
void main()
{
    vec4 a = u_inv_view_proj * vec4(v_ndc, -1.0, 1.0);
    vec4 b = u_inv_view_proj * vec4(v_ndc, 1.0, 1.0);
    vec3 d = b.xyz / b.w - a.xyz / a.w;
    o_color = vec4(volfx_sky(d, u_sun_dir), 1.0);
}
