/* beam_field.c — what the effect calls of the beam field at run time: a host beam's validation
 * and normalisation, its polyline joints, its culling radius. The closed form the effect runs is
 * the shader, shaders/beams/beam_field.glsl; the C closed form (the tests' float64 reference and
 * the benches' float32 instance) and the density are the lab's (plugin/lab/beam_field_d.h). */
#include "beams/beam_field.h"

#include <math.h>
#include <stdio.h>

vfx_result volfx_beam_validate(const vfx_beam *in, volfx_beam_d *out, char *err, size_t errlen)
{
    const float *f = &in->head[0];
    static const char *names[] = {"head.x", "head.y", "head.z", "length", "dir.x", "dir.y",
                                  "dir.z", "radius", "a", "b", "eps"};
    for (int i = 0; i < 11; ++i)
        if (!isfinite(f[i])) {
            snprintf(err, errlen, "beam %s is not finite", names[i]);
            return VFX_ERR_INVALID_ARGUMENT;
        }
    double d2 = (double)in->dir[0] * in->dir[0] + (double)in->dir[1] * in->dir[1] + (double)in->dir[2] * in->dir[2];
    if (!(d2 > 0)) {
        snprintf(err, errlen, "beam dir is the zero vector");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    if (in->length < 0 || !(in->radius > 0) || in->a < 0 || in->b < 0 || in->eps < 0) {
        snprintf(err, errlen, "beam needs length >= 0, radius > 0, a, b, eps >= 0 (got L %g, R %g, a %g, b %g, eps %g)",
                 (double)in->length, (double)in->radius, (double)in->a, (double)in->b, (double)in->eps);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    double n = sqrt(d2);
    for (int k = 0; k < 3; ++k) {
        out->head[k] = in->head[k];
        out->dir[k] = in->dir[k] / n;
    }
    out->length = in->length;
    out->radius = in->radius;
    out->a = in->a;
    out->b = in->b;
    out->eps = in->eps;
    out->smooth = 0;      /* hard support here; the effect sets the falloff */
    out->joint_count = 0; /* straight; volfx_beam_set_joints makes it a polyline */
    out->head_radius = out->orb_radius = out->orb_a = 0; /* no anatomy: the effect sets it */
    out->taper = out->surge = out->surge_inv_wl = out->surge_phase = 0;
    return VFX_OK;
}

double volfx_beam_max_radius(const volfx_beam_d *bm)
{
    double r = bm->radius * (bm->joint_count >= 2 ? 1.0 : 1.0 + bm->surge);
    r = fmax(r, bm->head_radius);
    return bm->orb_a > 0 ? fmax(r, bm->orb_radius) : r;
}

vfx_result volfx_beam_set_joints(volfx_beam_d *bm, const float *xyz, uint32_t count, char *err, size_t errlen)
{
    if (count == 0) {
        bm->joint_count = 0;
        return VFX_OK;
    }
    if (count < 2 || count > VOLFX_BEAM_MAX_JOINTS || !xyz) {
        snprintf(err, errlen, "beam joint_count %u (0, or 2 to %d, with joints)", count, VOLFX_BEAM_MAX_JOINTS);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    for (uint32_t k = 0; k < count; ++k)
        for (int i = 0; i < 3; ++i) {
            if (!isfinite(xyz[3 * k + i])) {
                snprintf(err, errlen, "beam joint %u is not finite", k);
                return VFX_ERR_INVALID_ARGUMENT;
            }
            bm->joints[k][i] = xyz[3 * k + i];
        }
    bm->joint_count = (int)count;
    /* the head is J0; dir and length describe the first segment (tile bounds use the joints) */
    double d[3], n = 0;
    for (int i = 0; i < 3; ++i) {
        bm->head[i] = bm->joints[0][i];
        d[i] = bm->joints[1][i] - bm->joints[0][i];
        n += d[i] * d[i];
    }
    n = sqrt(n);
    if (n > 0)
        for (int i = 0; i < 3; ++i)
            bm->dir[i] = d[i] / n;
    bm->length = n;
    return VFX_OK;
}
