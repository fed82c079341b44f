/* camera.c — the host camera's basis and GL matrices in float64, rounded to float once. */
#include "gfx/camera.h"

#include <math.h>
#include <string.h>

#include "core/error.h"

vfx_result rt_camera_check(const rt_camera *c, char *err, size_t errlen)
{
    if (!c)
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT, "camera: NULL");
    for (int k = 0; k < 3; ++k)
        if (!isfinite(c->eye[k]) || !isfinite(c->target[k]) || !isfinite(c->up[k]))
            return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT,
                           "camera: eye, target and up must be finite");
    if (c->width == 0 || c->height == 0)
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT,
                       "camera: size %ux%u, need both > 0", c->width, c->height);
    if (!(c->fov_y > 0 && c->fov_y < M_PI))
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT,
                       "camera: fov_y %g rad, need 0 < fov_y < pi", c->fov_y);
    if (!(c->near_plane > 0) || !(c->far_plane > c->near_plane))
        return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT,
                       "camera: near %g far %g, need 0 < near < far", c->near_plane, c->far_plane);
    return VFX_OK;
}

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* v / |v|; a zero vector stays zero (up parallel to the view direction gives a zero right
 * axis, as in the reference) */
static void unit3(double v[3])
{
    double l = sqrt(dot3(v, v));
    if (l > 0)
        v[0] /= l, v[1] /= l, v[2] /= l;
}

static void cross3(const double a[3], const double b[3], double dest[3])
{
    double o[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    memcpy(dest, o, sizeof o);
}

void rt_camera_basis(const rt_camera *c, double fwd[3], double right[3], double up[3])
{
    for (int k = 0; k < 3; ++k)
        fwd[k] = c->target[k] - c->eye[k];
    unit3(fwd);
    cross3(fwd, c->up, right);
    unit3(right);
    cross3(right, fwd, up);
}

void rt_camera_view(const rt_camera *c, float dest[16])
{
    double f[3], r[3], u[3];
    rt_camera_basis(c, f, r, u);
    /* rows right, up, -forward; translation -R * eye, all in float64 before the one rounding */
    const double m[16] = {r[0], u[0], -f[0], 0, r[1], u[1], -f[1], 0, r[2], u[2], -f[2], 0,
                          -dot3(r, c->eye), -dot3(u, c->eye), dot3(f, c->eye), 1};
    for (int i = 0; i < 16; ++i)
        dest[i] = (float)m[i];
}

void rt_camera_proj(const rt_camera *c, float dest[16])
{
    double t = tan(c->fov_y * 0.5), aspect = (double)c->width / c->height;
    double n = c->near_plane, fa = c->far_plane;
    memset(dest, 0, 16 * sizeof *dest);
    dest[0] = (float)(1.0 / (t * aspect));
    dest[5] = (float)(1.0 / t);
    dest[10] = (float)(-(fa + n) / (fa - n));
    dest[11] = -1.f;
    dest[14] = (float)(-2.0 * fa * n / (fa - n));
}

void rt_camera_translate(rt_camera *c, const double d[3])
{
    for (int k = 0; k < 3; ++k) {
        c->eye[k] += d[k];
        c->target[k] += d[k];
    }
}

void rt_camera_orbit(rt_camera *c, double yaw, double dy)
{
    double off[3];
    for (int k = 0; k < 3; ++k)
        off[k] = c->eye[k] - c->target[k];
    double cy = cos(yaw), sy = sin(yaw);
    double x = off[0] * cy - off[2] * sy, z = off[0] * sy + off[2] * cy;
    off[0] = x, off[2] = z;
    off[1] += dy;
    for (int k = 0; k < 3; ++k)
        c->eye[k] = c->target[k] + off[k];
}
