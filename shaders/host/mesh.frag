// Simple lit surface with a checker so motion and refraction read well in screenshots.
in vec3 v_normal;
in vec3 v_world;
uniform vec3 u_color;
uniform vec3 u_light_dir;
out vec4 o_color;
void main()
{
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing)
        n = -n;
    float diffuse = max(dot(n, normalize(u_light_dir)), 0.0);
    vec3 c = floor(v_world * 2.0);
    float checker = mod(c.x + c.y + c.z, 2.0) * 0.15 + 0.85;
    o_color = vec4(u_color * checker * (0.25 + 0.75 * diffuse), 1.0);
}
