/* fuzz_scene.c — libFuzzer target: scene JSON parsing plus the beam animation of what loads. */
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
    if (rt_scene_load_mem((const char *)data, size, "/base", &lg, &s, err, sizeof err) == VFX_OK) {
        vfx_beam b[8];
        rt_scene_beams_at(s, 0.37, b, 8);
        rt_scene_beams_at(s, 1e6, b, 8);
        rt_scene_free(s);
    }
    return 0;
}
