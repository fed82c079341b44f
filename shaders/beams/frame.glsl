// frame.glsl — the beams' one uniform block, uploaded once per frame (beams_block in
// plugin/beams/beams_effect.c mirrors it, std140).
layout(std140, binding = 3) uniform BeamsFrame {
    mat4 u_inv_rot_view_proj; // inverse(proj * view without translation): eye at 0
    float u_far;              // integrate to here where no surface
    float u_c;                // saturate_c
    int u_tile_px;
    int u_tiles_x;
    int u_samples;            // ray-marching baseline samples
    int u_has_water;
    int u_smooth_saturation;  // thesis ramp: 1 - exp(-H/c) instead of min(H/c, 1)
    int u_bloom;              // composite adds the bloom chain
    float u_bloom_gain;       // strength / levels
};
