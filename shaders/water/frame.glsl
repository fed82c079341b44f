// frame.glsl — the paper method's per-frame constants: one std140 block uploaded once a frame
// (water_frame_block in plugin/water/water_internal.h mirrors it), read by the billboard and
// march passes, so the sample loop sets no loose uniforms for them.
layout(std140, binding = 4) uniform WaterFrame {
    mat4 u_inv_view_proj;
    mat4 u_view_proj;
    vec3 u_eye;
    float u_h;
    float u_T;
    float u_step;
    float u_t_end;        // the farthest a particle's support reaches from the eye (paper march)
    float u_near;
    uint u_max_samples;
    uint u_count;         // particles in the columns, non-finite included
    bool u_has_depth;     // host depth bound at texture unit 1
    int u_frame_pad0;
    ivec2 u_size;
    vec2 u_sizef;
};
