// frame.glsl — the frame gate's one std140 block: the camera of this frame, computed once by
// plugin/frame_check.c from the checked frame view and uploaded once a frame, bound at uniform
// block binding 6 (VOLFX_FRAME_BINDING in plugin/effect.h, whose volfx_frame_block mirrors it)
// before any effect renders. Effects read the camera here, never multiply or invert it.
// Positions are relative to the frame's origin (vfx_origin_hdr.xyz); "cam" matrices are
// camera-relative: the view without its translation, so the eye is at 0.
layout(std140, binding = 6) uniform VolfxFrame {
    mat4 vfx_view_proj;         // proj * view
    mat4 vfx_inv_view_proj;     // window NDC -> position
    mat4 vfx_cam_view_proj;     // proj * view with the translation removed (eye at 0)
    mat4 vfx_inv_cam_view_proj; // window NDC -> direction from the eye
    mat4 vfx_view;              // the host's, checked
    mat4 vfx_proj;
    mat4 vfx_inv_view;          // eye space -> position
    vec4 vfx_eye_fov;           // xyz the host's eye, w fov_y [rad]
    vec4 vfx_planes_size;       // x near, y far (FLT_MAX for an infinite projection), zw width, height
    vec4 vfx_origin_hdr;        // xyz origin (float of the host's double), w 1 when colour is HDR
    uvec4 vfx_frame_flags;      // x environment cubemap given, y view id, z effects drawn (mask), w 0
};
