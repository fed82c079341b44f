/* test_camera.h — tests that drive the sample host keep the float64 reference's camera
 * (reference/camera_ref.h, the oracle's rays and matrices) and hand the same numbers to the
 * host's runtime camera (runtime/gfx/camera.h). */
#ifndef TEST_CAMERA_H
#define TEST_CAMERA_H

#include "camera_ref.h"
#include "gfx/camera.h"

/* The runtime camera with the reference camera's eye, target, up, fov, size and planes. */
static inline rt_camera test_rt_camera(const ref_camera *c)
{
    return (rt_camera){{c->eye[0], c->eye[1], c->eye[2]}, {c->target[0], c->target[1], c->target[2]},
                       {c->up[0], c->up[1], c->up[2]}, c->fov_y, c->width, c->height,
                       c->near_plane, c->far_plane};
}

#endif
