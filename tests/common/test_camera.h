/* test_camera.h — tests that drive the sample host keep the float64 reference's camera
 * (reference/camera_ref.h, the oracle's rays and matrices) and hand the same numbers to the
 * host's runtime camera (runtime/gfx/camera.h). */
#ifndef TEST_CAMERA_H
#define TEST_CAMERA_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app.h"
#include "camera_ref.h"
#include "gfx/camera.h"
#include "test_util.h"

/* The runtime camera with the reference camera's eye, target, up, fov, size and planes. */
static inline rt_camera test_rt_camera(const ref_camera *c)
{
    return (rt_camera){{c->eye[0], c->eye[1], c->eye[2]}, {c->target[0], c->target[1], c->target[2]},
                       {c->up[0], c->up[1], c->up[2]}, c->fov_y, c->width, c->height,
                       c->near_plane, c->far_plane};
}

/* The reference camera with a runtime camera's numbers (the oracle's rays for what a host drew). */
static inline ref_camera test_ref_camera(const rt_camera *c)
{
    return (ref_camera){{c->eye[0], c->eye[1], c->eye[2]}, {c->target[0], c->target[1], c->target[2]},
                        {c->up[0], c->up[1], c->up[2]}, c->fov_y, c->width, c->height,
                        c->near_plane, c->far_plane};
}

/* The sample host, headless, at the camera's size and rendering with its numbers; its log
 * recorded into *log (cleared first) when log is not NULL. Exits 77 (skip) without a GL
 * context. */
static inline game_app *test_app_with_camera(const ref_camera *c, test_log *log)
{
    game_app_desc d = {.mode = RT_GL_HEADLESS, .width = c->width, .height = c->height};
    if (log) {
        memset(log, 0, sizeof *log);
        d.logger = (rt_logger){test_log_fn, log};
    }
    game_app *app;
    if (game_app_create(&d, &app) != VFX_OK)
        exit(VFX_TEST_SKIP);
    rt_camera cam = test_rt_camera(c);
    if (game_app_set_camera(app, &cam) != VFX_OK) {
        fprintf(stderr, "test camera refused\n");
        exit(1);
    }
    return app;
}

#endif
