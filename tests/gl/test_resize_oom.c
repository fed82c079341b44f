/* A resize that runs out of memory (issue 37): in a child process whose address space may grow
 * by only 1 GiB past what it holds once the host and plugin run, the volume-showcase scene (a
 * volume and beams) at 96x54 is resized to 8192x8192 (the volume's targets alone take 64 bytes a
 * pixel, 4.3 GB). The resize fails with VFX_ERR_OUT_OF_MEMORY naming both sizes, the context stays
 * at 96x54, the next frames render the same pixels as before (it crashed in volume_render, and
 * resizing back failed), and the failed size is not recorded. AddressSanitizer needs terabytes
 * of address space for its shadow, so under it the test skips (77). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/sandbox.h"
#include "demo_scene.h"
#include "debug.h"
#include "test_util.h"

#define W 96
#define H 54

static uint64_t vm_bytes(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    unsigned long long pages = 0;
    if (f) {
        if (fscanf(f, "%llu", &pages) != 1)
            pages = 0;
        fclose(f);
    }
    return pages * (uint64_t)sysconf(_SC_PAGESIZE);
}

static void frame_pixels(game_app *app, game_demo *demo, float *volume)
{
    for (int i = 0; i < 2; ++i) { /* the volume clips with the previous frame's distances */
        game_demo_animate(app, demo, 0.f);
        assert_int_equal(game_app_frame(app, 0.f), VFX_OK);
    }
    assert_int_equal(app->api->read_raw(app->ctx, VFX_EFFECT_VOLUME, volume, W * H), VFX_OK);
}

static void body(void)
{
    char path[1024];
    const char *root = getenv("VFX_SOURCE_ROOT");
    snprintf(path, sizeof path, "%s/sample_game/scenes/volume-showcase.json", root ? root : ".");
    test_log log = {0};
    game_app_desc d = {.mode = RT_GL_HEADLESS, .width = W, .height = H, .logger = {test_log_fn, &log}};
    game_app *app;
    if (game_app_create(&d, &app) != VFX_OK)
        exit(VFX_TEST_SKIP);
    game_demo demo;
    assert_int_equal(game_demo_load(app, &demo, path, 0), VFX_OK);
    float *before = calloc(4 * W * H, sizeof(float)), *after = calloc(4 * W * H, sizeof(float));
    assert_non_null(before);
    assert_non_null(after);
    frame_pixels(app, &demo, before);
    assert_non_null(app->ctx->effect_state[VFX_EFFECT_VOLUME]);
    uint64_t vm = vm_bytes();
    struct rlimit r = {(rlim_t)(vm + (1ull << 30)), (rlim_t)(vm + (1ull << 30))};
    assert_int_equal(setrlimit(RLIMIT_AS, &r), 0);
    vfx_result res = app->api->resize(app->ctx, 8192, 8192);
    printf("resize 8192x8192 under %.2f GB of address space: %s: %s\n", (double)r.rlim_cur / 1e9, vfx_result_name(res),
           app->api->last_error(app->ctx, NULL));
    assert_int_equal(res, VFX_ERR_OUT_OF_MEMORY);
    vfx_log_id id = VFX_LOG_ID_NONE; /* the cause's id: host memory or GL memory ran out */
    assert_non_null(strstr(app->api->last_error(app->ctx, &id), "resize to 8192x8192 failed, the context stays at 96x54"));
    assert_true(id == VFX_LOG_ID_OUT_OF_MEMORY || id == VFX_LOG_ID_GPU_OUT_OF_MEMORY);
    assert_int_equal(app->ctx->width, W); /* the failed size is not recorded */
    assert_int_equal(app->ctx->height, H);
    frame_pixels(app, &demo, after);
    double diff = 0, sum = 0;
    for (int i = 0; i < 4 * W * H; ++i) {
        assert_true(isfinite(after[i]));
        diff = fmax(diff, fabs((double)after[i] - before[i]));
        sum += after[i];
    }
    printf("frames after the failure: volume sum %.3f, largest difference from before %.3g\n", sum, diff);
    assert_true(sum > 0);   /* the volume still draws */
    assert_true(diff < 1e-4); /* as before: same scene, same time, same size */
    assert_int_equal(app->api->resize(app->ctx, 100, 60), VFX_OK); /* and resizes again */
    free(before);
    free(after);
    game_app_destroy(app);
}

static void test_resize_out_of_memory(void **state)
{
    (void)state;
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        body();
        fflush(NULL);
        _exit(0);
    }
    int status = 0;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    if (WIFEXITED(status) && WEXITSTATUS(status) == VFX_TEST_SKIP)
        exit(VFX_TEST_SKIP);
    printf("child: %s %d\n", WIFEXITED(status) ? "exit" : "signal", WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status));
    assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

int main(void)
{
    if (rt_sandbox_under_asan()) {
        printf("AddressSanitizer reserves terabytes of address space: no RLIMIT_AS test under it; skipping\n");
        return VFX_TEST_SKIP;
    }
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_resize_out_of_memory)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
