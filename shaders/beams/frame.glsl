// frame.glsl — the beams' own uniform block, uploaded once per frame (beams_block in
// plugin/beams/beams_effect.c mirrors it, std140). The camera is not here: it is the frame
// gate's VolfxFrame block (shaders/common/frame.glsl).
layout(std140, binding = 3) uniform BeamsFrame {
    float u_far;              // integrate to here where no surface
    float u_c;                // saturate_c
    int u_tile_px;
    int u_tiles_x;
    int u_has_water;
    int u_smooth_saturation;  // thesis ramp: 1 - exp(-H/c) instead of min(H/c, 1)
    int u_bloom;              // composite adds the bloom chain
    float u_bloom_gain;       // strength / levels
};
