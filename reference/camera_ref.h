/* reference.h — the camera convention every float64 reference renderer and every raw dump
 * uses (issue 7): pixel (i, j), column i from the left and row j from the top, has its ray
 * through the pixel centre:
 *   x = (2(i+0.5)/W - 1) * tan(fov_y/2) * W/H,  y = (1 - 2(j+0.5)/H) * tan(fov_y/2),
 *   dir = normalize(forward + x*right + y*up), forward = normalize(target - eye),
 *   right = normalize(forward x up), up recomputed as right x forward.
 * ref_camera_matrices gives the GL view/projection that puts exactly these rays through
 * the pixel centres, so GPU and reference images line up pixel for pixel. */
#ifndef REF_REFERENCE_H
#define REF_REFERENCE_H

#include <stdint.h>

typedef struct ref_camera {
    double eye[3], target[3], up[3];
    double fov_y;          /* radians */
    uint32_t width, height;
    double near_plane, far_plane;
} ref_camera;

/* Orthonormal basis of the camera (forward, right, up). */
void ref_camera_basis(const ref_camera *cam, double fwd[3], double right[3], double up[3]);
/* Unit direction of the ray through the centre of pixel (i, j). */
void ref_pixel_ray(const ref_camera *cam, uint32_t i, uint32_t j, double dir[3]);
/* Column-major GL view and projection matrices of the camera. */
void ref_camera_matrices(const ref_camera *cam, float view[16], float proj[16]);

#endif
