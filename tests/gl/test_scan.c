/* The plugin's GPU prefix sum (plugin/gpu/scan.h, shaders/common/scan.comp) against a CPU
 * exclusive prefix sum at the sizes where the two levels meet (1, one thread's 4 short, a
 * block of 1024 and one past it, a block of blocks and past it, the 2^20 limit), on counts up
 * to 1000 (sums below 2^32 at every size); and its refusal of one entry past the limit. The
 * sums are of integers: the GPU result must equal the CPU's exactly. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <epoxy/gl.h>
#include <stdlib.h>
#include <string.h>

#include "debug.h"
#include "gpu/scan.h"
#include "test_plugin.h"

static vfx_context *g_ctx;
static const vfx_plugin_api *g_api;

/* Scans n pseudo-random counts on the GPU; returns how many entries differ from the CPU's sum.
 * The starts buffer is pre-filled with a marker so an entry the scan misses shows. */
static uint32_t scan_mismatches(uint32_t n)
{
    uint32_t *counts = malloc((size_t)n * 4), *got = malloc((size_t)n * 4), *marker = malloc((size_t)n * 4);
    unsigned st = 7u + n;
    for (uint32_t i = 0; i < n; ++i) {
        st = st * 1664525u + 1013904223u;
        counts[i] = (st >> 8) % 1001u;
        marker[i] = 0xdeadbeefu;
    }
    GLuint buf[2];
    glCreateBuffers(2, buf);
    glNamedBufferStorage(buf[0], (GLsizeiptr)n * 4, counts, 0);
    glNamedBufferStorage(buf[1], (GLsizeiptr)n * 4, marker, GL_MAP_READ_BIT);
    assert_int_equal(volfx_gpu_scan(g_ctx, buf[0], buf[1], n, "test"), VFX_OK);
    glGetNamedBufferSubData(buf[1], 0, (GLsizeiptr)n * 4, got);
    glDeleteBuffers(2, buf);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    uint32_t bad = 0, run = 0;
    for (uint32_t i = 0; i < n; ++i) {
        if (got[i] != run && bad++ < 4)
            print_message("n %u: starts[%u] = %u, CPU %u\n", n, i, got[i], run);
        run += counts[i];
    }
    free(counts);
    free(got);
    free(marker);
    return bad;
}

static void test_matches_cpu(void **state)
{
    (void)state;
    const uint32_t sizes[] = {1, 3, 255, 256, 257, 1023, 1024, 1025, 65537, VOLFX_SCAN_MAX - 1, VOLFX_SCAN_MAX};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; ++k)
        assert_int_equal(scan_mismatches(sizes[k]), 0);
}

/* One past the limit: refused with VFX_ERR_UNSUPPORTED naming the caller and the size, and the
 * output untouched (nothing ran). */
static void test_refuses_past_limit(void **state)
{
    (void)state;
    GLuint buf[2];
    glCreateBuffers(2, buf);
    const uint32_t marker = 0x5eedu;
    glNamedBufferStorage(buf[0], 16, NULL, 0);
    glNamedBufferStorage(buf[1], 4, &marker, GL_MAP_READ_BIT);
    assert_int_equal(volfx_gpu_scan(g_ctx, buf[0], buf[1], VOLFX_SCAN_MAX + 1, "the test's bins"), VFX_ERR_UNSUPPORTED);
    assert_true(test_last_error_is(g_api, g_ctx, VFX_LOG_ID_API_ARGUMENT, "the test's bins"));
    assert_true(test_last_error_is(g_api, g_ctx, VFX_LOG_ID_API_ARGUMENT, "1048577"));
    uint32_t got = 0;
    glGetNamedBufferSubData(buf[1], 0, 4, &got);
    assert_int_equal(got, marker);
    assert_int_equal(volfx_gpu_scan(g_ctx, buf[0], buf[1], 0, "empty"), VFX_OK); /* nothing to do */
    glDeleteBuffers(2, buf);
    assert_int_equal(glGetError(), GL_NO_ERROR);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matches_cpu),
        cmocka_unit_test(test_refuses_past_limit),
    };
    return test_plugin_run_group(tests, &g_ctx, &g_api);
}
