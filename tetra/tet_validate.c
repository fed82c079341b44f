/* tet_validate.c — checks shared by every tet loader. Orientation uses float64 so that the sign of
 * thin but valid cells is not decided by float32 rounding. */
#include "tet_mesh.h"

#include <math.h>
#include <stdio.h>

static double signed_volume6(const float *p, const uint32_t *t)
{
    const float *a = p + 3 * (size_t)t[0], *b = p + 3 * (size_t)t[1];
    const float *c = p + 3 * (size_t)t[2], *d = p + 3 * (size_t)t[3];
    double u[3], v[3], w[3];
    for (int k = 0; k < 3; k++) {
        u[k] = (double)b[k] - a[k];
        v[k] = (double)c[k] - a[k];
        w[k] = (double)d[k] - a[k];
    }
    return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
           u[2] * (v[0] * w[1] - v[1] * w[0]);
}

tet_result tet_validate(tet_mesh *m, char *err, size_t errlen)
{
    if (!m || m->point_count == 0 || m->tet_count == 0 || !m->points || !m->tets) {
        tet_errf(err, errlen, "mesh has no points or no tetrahedra");
        return TET_ERR_FORMAT;
    }
    for (uint32_t i = 0; i < m->point_count; i++)
        for (int k = 0; k < 3; k++)
            if (!isfinite(m->points[3 * (size_t)i + k])) {
                tet_errf(err, errlen, "point %u has a non-finite coordinate", i);
                return TET_ERR_NUMERIC;
            }
    for (uint32_t t = 0; t < m->tet_count; t++)
        for (int k = 0; k < 4; k++)
            if (m->tets[4 * (size_t)t + k] >= m->point_count) {
                tet_errf(err, errlen, "tetrahedron %u vertex %d index %u out of range (%u points)",
                         t, k, m->tets[4 * (size_t)t + k], m->point_count);
                return TET_ERR_FORMAT;
            }
    /* Degenerate: |6V| below a relative epsilon of the bounding box scale cubed. */
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < m->point_count; i++)
        for (int k = 0; k < 3; k++) {
            double x = m->points[3 * (size_t)i + k];
            lo[k] = x < lo[k] ? x : lo[k];
            hi[k] = x > hi[k] ? x : hi[k];
        }
    double ext = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
    double eps = 1e-12 * ext * ext * ext;
    m->inverted_fixed = 0;
    m->degenerate_count = 0;
    for (uint32_t t = 0; t < m->tet_count; t++) {
        uint32_t *q = m->tets + 4 * (size_t)t;
        double v6 = signed_volume6(m->points, q);
        if (fabs(v6) <= eps) {
            m->degenerate_count++;
        } else if (v6 < 0) {
            uint32_t s = q[2];
            q[2] = q[3];
            q[3] = s;
            m->inverted_fixed++;
        }
    }
    if (m->scalar) {
        float mn = INFINITY, mx = -INFINITY;
        for (uint32_t i = 0; i < m->point_count; i++) {
            float s = m->scalar[i];
            if (!isfinite(s)) {
                tet_errf(err, errlen, "scalar '%s' is not finite at point %u", m->scalar_name, i);
                return TET_ERR_NUMERIC;
            }
            mn = s < mn ? s : mn;
            mx = s > mx ? s : mx;
        }
        m->scalar_min = mn;
        m->scalar_max = mx;
    }
    return TET_OK;
}
