/* tet_testmesh.c — see tet_testmesh.h. */
#include "tet_testmesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

double ref_testmesh_tet_scalar(const tet_mesh *m, const uint32_t tt[4], const double p[3])
{
    double v[4][3];
    for (int j = 0; j < 4; j++)
        for (int r = 0; r < 3; r++)
            v[j][r] = m->points[3 * tt[j] + r];
    double lam[4], vol = 0;
    for (int j = 0; j < 4; j++) { /* barycentric by signed volumes */
        double q4[4][3];
        memcpy(q4, v, sizeof q4);
        memcpy(q4[j], p, sizeof q4[j]);
        double a[3], b[3], e[3];
        for (int r = 0; r < 3; r++) {
            a[r] = q4[1][r] - q4[0][r];
            b[r] = q4[2][r] - q4[0][r];
            e[r] = q4[3][r] - q4[0][r];
        }
        lam[j] = a[0] * (b[1] * e[2] - b[2] * e[1]) - a[1] * (b[0] * e[2] - b[2] * e[0]) +
                 a[2] * (b[0] * e[1] - b[1] * e[0]);
        vol += lam[j];
    }
    for (int j = 0; j < 4; j++)
        if (lam[j] / vol < -1e-12)
            return NAN;
    double s = 0;
    for (int j = 0; j < 4; j++)
        s += lam[j] / vol * m->scalar[tt[j]];
    return s;
}

/* one cube's 5 tets over the corners numbered x + 2y + 4z */
static const uint32_t cube5[20] = {0, 1, 3, 4, 1, 2, 3, 6, 1, 4, 5, 6, 3, 4, 6, 7, 1, 3, 4, 6};

int ref_testmesh_grid(int n, tet_mesh *m)
{
    uint32_t np = (uint32_t)((n + 1) * (n + 1) * (n + 1)), nt = (uint32_t)(n * n * n * 5);
    memset(m, 0, sizeof *m);
    m->points = malloc((size_t)np * 3 * sizeof(float));
    m->scalar = malloc((size_t)np * sizeof(float));
    m->tets = malloc((size_t)nt * 4 * sizeof(uint32_t));
    if (!m->points || !m->scalar || !m->tets)
        return -1;
    for (int k = 0, i = 0; k <= n; k++)
        for (int j = 0; j <= n; j++)
            for (int l = 0; l <= n; l++, i++) {
                float x = -1 + 2.0f * l / n, y = -1 + 2.0f * j / n, z = -1 + 2.0f * k / n;
                m->points[3 * i] = x;
                m->points[3 * i + 1] = y;
                m->points[3 * i + 2] = z;
                m->scalar[i] = 0.5f + 0.5f * sinf(3 * x) * cosf(2 * y) * cosf(1.5f * z);
            }
    uint32_t t = 0;
    for (int k = 0; k < n; k++)
        for (int j = 0; j < n; j++)
            for (int l = 0; l < n; l++) {
                uint32_t c[8];
                for (int q = 0; q < 8; q++)
                    c[q] = (uint32_t)((k + (q >> 2 & 1)) * (n + 1) * (n + 1) +
                                      (j + (q >> 1 & 1)) * (n + 1) + l + (q & 1));
                uint32_t o8[8] = {c[0], c[1], c[3], c[2], c[4], c[5], c[7], c[6]};
                static const uint32_t mirror[8] = {1, 0, 3, 2, 5, 4, 7, 6};
                int flip = (l + j + k) & 1;
                for (int q = 0; q < 20; q++)
                    m->tets[(size_t)t * 4 + q] = o8[flip ? mirror[cube5[q]] : cube5[q]];
                t += 5;
            }
    m->point_count = np;
    m->tet_count = nt;
    m->scalar_min = 0;
    m->scalar_max = 1;
    snprintf(m->scalar_name, sizeof m->scalar_name, "grid");
    return 0;
}

void ref_testmesh_orbit(tet_camera *c, int w, int h, float yaw, float pitch, float f,
                            float nearp, float farp)
{
    memset(c, 0, sizeof *c);
    c->width = w;
    c->height = h;
    float cy = cosf(yaw), sy = sinf(yaw), cp = cosf(pitch), sp = sinf(pitch);
    float R[9] = {cy, sp * sy, -cp * sy, 0, cp, sp, sy, -sp * cy, cp * cy};
    for (int col = 0; col < 3; col++)
        for (int r = 0; r < 3; r++)
            c->view[col * 4 + r] = R[col * 3 + r];
    c->view[15] = 1;
    c->proj[0] = f * h / (float)w;
    c->proj[5] = f;
    c->proj[10] = (farp + nearp) / (nearp - farp);
    c->proj[11] = -1;
    c->proj[14] = 2 * farp * nearp / (nearp - farp);
}

void ref_tf_eval(const tet_tf *tf, double s, double *tau, double rgb[3])
{
    double s0, s1, t0, t1;
    const float *c0, *c1;
    if (tf->count >= 2) {
        int k = 0;
        while (k + 2 < tf->count && s >= tf->points[k + 1].s)
            k++;
        s0 = tf->points[k].s, s1 = tf->points[k + 1].s;
        t0 = tf->points[k].tau, t1 = tf->points[k + 1].tau;
        c0 = tf->points[k].rgb, c1 = tf->points[k + 1].rgb;
    } else {
        s0 = tf->smin, s1 = tf->smax, t0 = tf->tau_lo, t1 = tf->tau_hi;
        c0 = tf->color_lo, c1 = tf->color_hi;
    }
    double u = s1 > s0 ? (s - s0) / (s1 - s0) : 0;
    u = u < 0 ? 0 : u > 1 ? 1 : u;
    *tau = t0 + (t1 - t0) * u;
    for (int r = 0; r < 3; r++)
        rgb[r] = c0[r] + ((double)c1[r] - c0[r]) * u;
}

/* the scalar at world point p of the grid (NAN outside) */
static double grid_scalar(int n, const tet_mesh *m, const double p[3])
{
    int cell[3];
    for (int r = 0; r < 3; r++) {
        double f = (p[r] + 1) * 0.5 * n;
        if (!(f >= 0 && f <= n))
            return NAN;
        cell[r] = f >= n ? n - 1 : (int)f;
    }
    const uint32_t *tt = &m->tets[(size_t)5 * 4 * ((cell[2] * n + cell[1]) * n + cell[0])];
    for (int q = 0; q < 5; q++, tt += 4) {
        double s = ref_testmesh_tet_scalar(m, tt, p);
        if (!isnan(s))
            return s;
    }
    return NAN;
}

void ref_testmesh_raymarch(int n, const tet_mesh *m, const tet_camera *c, const tet_tf *tf,
                           int steps, double *out)
{
    const int W = c->width, H = c->height;
    const float *V = c->view, *P = c->proj;
    /* the eye and the ray directions in world space: view = [R | T], world = R^T (v - T) */
    double eye[3], R[3][3];
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++)
            R[r][k] = V[k * 4 + r];
    for (int k = 0; k < 3; k++)
        eye[k] = -(R[0][k] * V[12] + R[1][k] * V[13] + R[2][k] * V[14]);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double dv[3] = {(((x + 0.5) / W) * 2 - 1 + P[8]) / P[0], (((y + 0.5) / H) * 2 - 1 + P[9]) / P[5], -1};
            double d[3], len = sqrt(dv[0] * dv[0] + dv[1] * dv[1] + 1);
            for (int k = 0; k < 3; k++)
                d[k] = (R[0][k] * dv[0] + R[1][k] * dv[1] + R[2][k] * dv[2]) / len;
            double t0 = 0, t1 = INFINITY; /* slabs of [-1,1]^3 */
            for (int k = 0; k < 3; k++) {
                if (d[k] == 0) {
                    if (fabs(eye[k]) > 1) t1 = -1;
                    continue;
                }
                double a = (-1 - eye[k]) / d[k], b = (1 - eye[k]) / d[k];
                if (a > b) { double tmp = a; a = b; b = tmp; }
                if (a > t0) t0 = a;
                if (b < t1) t1 = b;
            }
            double T = 1, col[3] = {0, 0, 0};
            if (t1 > t0) {
                double h = (t1 - t0) / steps;
                for (int i = 0; i < steps; i++) {
                    double t = t0 + (i + 0.5) * h, p[3];
                    for (int k = 0; k < 3; k++)
                        p[k] = eye[k] + d[k] * t;
                    double s = grid_scalar(n, m, p);
                    if (isnan(s))
                        continue;
                    double tau, rgb[3];
                    ref_tf_eval(tf, s, &tau, rgb);
                    double a = 1 - exp(-tau * h);
                    for (int r = 0; r < 3; r++)
                        col[r] += T * a * rgb[r];
                    T *= 1 - a;
                }
            }
            for (int r = 0; r < 3; r++)
                out[4 * ((size_t)y * W + x) + r] = col[r];
            out[4 * ((size_t)y * W + x) + 3] = 1 - T;
        }
}
