/* tet_testmesh.c — see tet_testmesh.h. */
#include "tet_testmesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
