/* camera.h — the host's perspective camera (eye, target, up in float64 so large worlds keep
 * their precision) and the GL matrices it hands to the renderer and the plugin. cglm-style:
 * rt_camera_<op>(inputs..., dest). GL-free. The convention is reference/camera_ref.h's: the
 * pixel-centre rays of the float64 references go through the same pixels (test camera). */
#ifndef RT_CAMERA_H
#define RT_CAMERA_H

#include <stddef.h>
#include <stdint.h>
#include <volfx/volfx.h>

typedef struct rt_camera {
    double eye[3], target[3], up[3];
    double fov_y; /* radians, vertical */
    uint32_t width, height;
    double near_plane, far_plane;
} rt_camera;

/* VFX_OK when the camera can make matrices (size > 0, 0 < fov_y < pi, 0 < near < far, finite
 * eye/target/up), else VFX_ERR_INVALID_ARGUMENT with a message naming the field in err. */
vfx_result rt_camera_check(const rt_camera *cam, char *err, size_t errlen);
/* Forward (towards the target), right and up: an orthonormal basis, up recomputed. */
void rt_camera_basis(const rt_camera *cam, double fwd[3], double right[3], double up[3]);
/* Column-major GL view matrix (world -> eye), computed in float64 and rounded once. */
void rt_camera_view(const rt_camera *cam, float dest[16]);
/* Column-major GL perspective projection (OpenGL clip space, z in [-w, w]). */
void rt_camera_proj(const rt_camera *cam, float dest[16]);
/* Moves eye and target by d (the camera keeps its direction). */
void rt_camera_translate(rt_camera *cam, const double d[3]);
/* Orbits the eye around the target: yaw radians about +y, then dy added to the eye's height. */
void rt_camera_orbit(rt_camera *cam, double yaw, double dy);

#endif
