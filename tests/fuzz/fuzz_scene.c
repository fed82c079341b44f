/* fuzz_scene.c — libFuzzer target: scene JSON parsing, then what a host does with what loads:
 * the beam animation, the water's initial particles (generators and the simulation's fluid
 * block; never a file: the fuzzer must not read the machine's files), the transfer function
 * and a small generated volume. */
#include <stdint.h>
#include <stdlib.h>

#include "scene/scene.h"

static void quiet(void *user, vfx_log_level level, const char *message)
{
    (void)user, (void)level, (void)message;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rt_logger lg = {quiet, NULL};
    rt_scene *s = NULL;
    char err[256];
    if (rt_scene_load_mem((const char *)data, size, "/base", &lg, &s, err, sizeof err) != VFX_OK)
        return 0;
    vfx_beam b[8];
    rt_scene_beams_at(s, 0.37, b, 8, NULL, 0, NULL);
    rt_scene_beams_at(s, 1e6, b, 8, NULL, 0, NULL);
    /* counts up to 65,536 keep the run fast; the code paths above that are the same */
    if (s->has_water && s->water.source != RT_SCENE_WATER_FILE && s->water.count <= 65536) {
        float *xyz = NULL;
        uint32_t n = 0;
        if (rt_scene_water_particles(&s->water, &xyz, &n, err, sizeof err) == VFX_OK && n != s->water.count)
            abort(); /* a generator that returns fewer particles than asked without an error */
        free(xyz);
    }
    if (s->has_volume) {
        float rgba[4 * 16], smin, smax;
        rt_scene_transfer_sample(&s->volume, 16, rgba, &smin, &smax);
        if (s->volume.generated && s->volume.gen_cells <= 8) {
            float *pts = NULL, *sc = NULL;
            uint32_t *tets = NULL, np = 0, nt = 0;
            rt_scene_volume_generate(&s->volume, &pts, &np, &tets, &nt, &sc, err, sizeof err);
            free(pts), free(tets), free(sc);
        }
    }
    rt_scene_free(s);
    return 0;
}
