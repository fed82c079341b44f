/* reference.c — camera basis and pixel rays in float64. */
#include "camera_ref.h"

#include <math.h>
#include <string.h>

static void normalize3(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0)
        v[0] /= l, v[1] /= l, v[2] /= l;
}

static void cross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

void ref_camera_basis(const ref_camera *c, double f[3], double r[3], double u[3])
{
    for (int k = 0; k < 3; ++k)
        f[k] = c->target[k] - c->eye[k];
    normalize3(f);
    cross3(f, c->up, r);
    normalize3(r);
    cross3(r, f, u);
}

void ref_pixel_ray(const ref_camera *c, uint32_t i, uint32_t j, double d[3])
{
    double f[3], r[3], u[3];
    ref_camera_basis(c, f, r, u);
    double t = tan(c->fov_y * 0.5);
    double x = (2.0 * (i + 0.5) / c->width - 1.0) * t * (double)c->width / c->height;
    double y = (1.0 - 2.0 * (j + 0.5) / c->height) * t;
    for (int k = 0; k < 3; ++k)
        d[k] = f[k] + x * r[k] + y * u[k];
    normalize3(d);
}

void ref_camera_matrices(const ref_camera *c, float view[16], float proj[16])
{
    double f[3], r[3], u[3];
    ref_camera_basis(c, f, r, u);
    memset(view, 0, 16 * sizeof(float));
    for (int k = 0; k < 3; ++k) {
        view[k * 4 + 0] = (float)r[k];
        view[k * 4 + 1] = (float)u[k];
        view[k * 4 + 2] = (float)-f[k];
    }
    view[12] = (float)-(r[0] * c->eye[0] + r[1] * c->eye[1] + r[2] * c->eye[2]);
    view[13] = (float)-(u[0] * c->eye[0] + u[1] * c->eye[1] + u[2] * c->eye[2]);
    view[14] = (float)(f[0] * c->eye[0] + f[1] * c->eye[1] + f[2] * c->eye[2]);
    view[15] = 1.f;
    double t = tan(c->fov_y * 0.5), aspect = (double)c->width / c->height;
    double n = c->near_plane, fa = c->far_plane;
    memset(proj, 0, 16 * sizeof(float));
    proj[0] = (float)(1.0 / (t * aspect));
    proj[5] = (float)(1.0 / t);
    proj[10] = (float)(-(fa + n) / (fa - n));
    proj[11] = -1.f;
    proj[14] = (float)(-2.0 * fa * n / (fa - n));
}
