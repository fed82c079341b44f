/* bench_ecs.c — `volfx-bench ecs`: ECS iteration cost per entity over 1,000,000 particle
 * entities (query + column walk), and column upload bandwidth to GL (one glNamedBufferSubData
 * per column, straight from the ECS storage). Medians of repeated runs. */
#include <epoxy/gl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ecs/particles.h"
#include "gfx/gl_context.h"
#include "profile/profiler.h"

int bench_ecs(int argc, char **argv);

int bench_ecs(int argc, char **argv)
{
    uint32_t n = 1000000;
    int reps = 15;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--entities") && i + 1 < argc) n = (uint32_t)strtoul(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "--reps") && i + 1 < argc) reps = atoi(argv[++i]);
        else if (strcmp(argv[i], "--json") != 0) { fprintf(stderr, "volfx-bench ecs: unknown option '%s'\n", argv[i]); return 2; }
    }
    if (reps < 1 || reps > 1000 || n == 0) {
        fprintf(stderr, "volfx-bench ecs: need 1..1000 reps and entities > 0\n");
        return 2;
    }
    rt_world *w = rt_world_create(NULL);
    rt_particle_components pc;
    if (!w || rt_particles_register(w, &pc) || rt_particles_spawn(w, &pc, n, NULL, NULL, NULL, false))
        return 1;
    double *t = malloc((size_t)reps * sizeof *t);
    volatile float sink = 0;
    rt_component terms[2] = {pc.position, pc.velocity};
    for (int r = 0; r < reps; ++r) {
        double t0 = rt_now_ms();
        rt_query_iter it = rt_query_begin(w, terms, 2);
        while (rt_query_next(&it)) {
            float *x = rt_query_column(&it, pc.position, 0), *vx = rt_query_column(&it, pc.velocity, 0);
            float *y = rt_query_column(&it, pc.position, 1), *vy = rt_query_column(&it, pc.velocity, 1);
            float *z = rt_query_column(&it, pc.position, 2), *vz = rt_query_column(&it, pc.velocity, 2);
            for (uint32_t i = 0; i < it.rows; ++i) { /* a typical system: integrate positions */
                x[i] += vx[i] * 0.016f + 1e-6f;
                y[i] += vy[i] * 0.016f;
                z[i] += vz[i] * 0.016f;
            }
            sink += x[it.rows - 1];
        }
        t[r] = rt_now_ms() - t0;
    }
    double iter_ns = rt_median(t, (uint32_t)reps) * 1e6 / n;
    rt_gl_context *gl = NULL;
    rt_gl_context_desc gd = {.mode = RT_GL_HEADLESS};
    double upload_mbs = NAN;
    const char *renderer = "none";
    if (rt_gl_context_create(&gd, &gl) == VFX_OK) {
        renderer = rt_gl_context_renderer(gl);
        GLuint buf;
        size_t bytes = (size_t)n * sizeof(float);
        glCreateBuffers(1, &buf);
        glNamedBufferStorage(buf, (GLsizeiptr)(3 * bytes), NULL, GL_DYNAMIC_STORAGE_BIT);
        for (int r = 0; r < reps; ++r) {
            double t0 = rt_now_ms();
            rt_query_iter it = rt_query_begin(w, &pc.position, 1);
            while (rt_query_next(&it))
                for (uint32_t k = 0; k < 3; ++k)
                    glNamedBufferSubData(buf, (GLintptr)(k * bytes), (GLsizeiptr)(it.rows * sizeof(float)),
                                         rt_query_column(&it, pc.position, k));
            glFinish();
            t[r] = rt_now_ms() - t0;
        }
        upload_mbs = 3.0 * bytes / (rt_median(t, (uint32_t)reps) * 1e-3) / 1e6;
        glDeleteBuffers(1, &buf);
    }
    printf("{\"effect\":\"ecs\",\"entities\":%u,\"reps\":%d,\"iterate_ns_per_entity\":%.4f,"
           "\"column_upload_MBps\":%.1f,\"gl_renderer\":\"%s\"}\n", n, reps, iter_ns, upload_mbs, renderer);
    (void)sink;
    rt_gl_context_destroy(gl);
    rt_world_destroy(w);
    free(t);
    return 0;
}
