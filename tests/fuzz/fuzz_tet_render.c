/* fuzz_tet_render.c — libFuzzer target: the tet renderer on what a host may hand the volume
 * effect (points, tets, scalars, a transfer-function table, the options) from raw bytes, so
 * NaN, Inf, huge, coincident and out-of-range values all occur. The camera is a fixed valid
 * perspective one (the ABI checks the frame view before the renderer sees it). The renderer
 * must return TET_OK or an error with its text, never crash, and leave the image finite. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "tet_render.h"

typedef struct reader { const uint8_t *p; size_t n; } reader;

static uint8_t byte(reader *r)
{
    if (!r->n) return 0;
    r->n--;
    return *r->p++;
}

static float num(reader *r)
{
    /* one byte in four picks a special value; the rest is a float32 of the next bytes */
    uint8_t k = byte(r);
    switch (k & 7) {
    case 0: return NAN;
    case 1: return (k & 8) ? INFINITY : -INFINITY;
    case 2: return (float)(k >> 4) * 0.25f; /* small exact values: coincident points */
    default: {
        uint32_t u = (uint32_t)byte(r) | (uint32_t)byte(r) << 8 | (uint32_t)byte(r) << 16 | (uint32_t)byte(r) << 24;
        float f;
        memcpy(&f, &u, sizeof f);
        return f;
    }
    }
}

#define W 12
#define H 10

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader r = {data, size};
    uint32_t np = 1 + byte(&r) % 8, nt = 1 + byte(&r) % 6, ntf = byte(&r) % 6;
    uint8_t flags = byte(&r);
    float pts[24], sc[8];
    uint32_t tets[24];
    for (uint32_t i = 0; i < 3 * np; ++i) pts[i] = num(&r);
    for (uint32_t i = 0; i < np; ++i) sc[i] = num(&r);
    for (uint32_t i = 0; i < 4 * nt; ++i) tets[i] = byte(&r) % (np + 1); /* np: one past the end */
    tet_tf_point tp[5];
    for (uint32_t i = 0; i < ntf; ++i) {
        tp[i].s = num(&r);
        for (int k = 0; k < 3; ++k) tp[i].rgb[k] = num(&r);
        tp[i].tau = num(&r);
    }
    tet_mesh m = {.point_count = np, .tet_count = nt, .points = pts, .tets = tets, .scalar = sc};
    tet_tf tf = {.smin = num(&r), .smax = num(&r), .tau_lo = num(&r), .tau_hi = num(&r),
                 .color_lo = {1, 1, 1}, .color_hi = {1, 0.5f, 0}, .points = ntf >= 2 ? tp : NULL,
                 .count = ntf >= 2 ? (int)ntf : 0, .method = (flags >> 4) % 4, .pre_size = (flags >> 6) * 8};
    /* camera at z = 3 looking down -z, 60 degrees, near 0.1 far 100 (GL convention) */
    tet_camera cam = {.view = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -3, 1}, .width = W, .height = H};
    const float f = 1.7320508f, n = 0.1f, fa = 100.f;
    float proj[16] = {f * H / W, 0, 0, 0, 0, f, 0, 0, 0, 0, -(fa + n) / (fa - n), -1, 0, 0, -2 * fa * n / (fa - n), 0};
    memcpy(cam.proj, proj, sizeof proj);
    tet_options o;
    tet_options_default(&o);
    o.ert = flags & 1, o.partial_composite = (flags >> 1) & 1;
    o.tiles_d = 1 + byte(&r) % 32, o.update_c = 1 + byte(&r) % 200;
    o.ert_threshold = (float)(byte(&r) % 101) / 100.0f;
    static float rgba[W * H * 4];
    char err[256] = "";
    tet_counters c;
    int rc = tet_render(&m, &cam, &tf, &o, rgba, &c, err, sizeof err);
    if (rc != TET_OK && !err[0])
        abort(); /* an error without its text */
    if (rc == TET_OK)
        for (int i = 0; i < W * H * 4; ++i)
            if (!isfinite(rgba[i]))
                abort(); /* a non-finite pixel returned as success */
    return 0;
}
