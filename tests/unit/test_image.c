/* PNG and PFM writers: PFM round trip (bottom-row-first storage), PNG checked by zlib. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "gfx/image.h"
#include "shader_text.h"

static void test_pfm_roundtrip(void **state)
{
    (void)state;
    float data[6] = {1, 2, 3, 4, 5, 6}; /* 3x2, top row 1 2 3 */
    char err[128];
    assert_int_equal(rt_write_pfm("t.pfm", 3, 2, data, err, sizeof err), VFX_OK);
    FILE *f = fopen("t.pfm", "rb");
    char hdr[32];
    assert_non_null(fgets(hdr, sizeof hdr, f));
    assert_string_equal(hdr, "Pf\n");
    assert_non_null(fgets(hdr, sizeof hdr, f));
    assert_non_null(fgets(hdr, sizeof hdr, f));
    float first;
    assert_int_equal(fread(&first, 4, 1, f), 1);
    assert_true(first == 4.f); /* the file starts with the bottom row */
    fclose(f);
    uint32_t w, h;
    float *back;
    assert_int_equal(rt_read_pfm("t.pfm", &w, &h, &back, err, sizeof err), VFX_OK);
    assert_int_equal(w, 3);
    assert_int_equal(h, 2);
    assert_memory_equal(back, data, sizeof data);
    free(back);
    f = fopen("bad.pfm", "wb");
    fputs("P6\n1 1\n255\n", f);
    fclose(f);
    assert_int_equal(rt_read_pfm("bad.pfm", &w, &h, &back, err, sizeof err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "bad.pfm"));
}

static void test_png_valid(void **state)
{
    (void)state;
    uint8_t rgba[4 * 4 * 4];
    for (int i = 0; i < 64; ++i)
        rgba[i] = (uint8_t)(i * 3);
    char err[128];
    assert_int_equal(rt_write_png("t.png", 4, 4, rgba, err, sizeof err), VFX_OK);
    FILE *f = fopen("t.png", "rb");
    uint8_t buf[4096];
    size_t n = fread(buf, 1, sizeof buf, f);
    fclose(f);
    assert_true(n > 57);
    assert_memory_equal(buf, "\x89PNG\r\n\x1a\n", 8);
    /* IHDR crc, then inflate IDAT and compare the pixels */
    uint32_t len = (uint32_t)buf[33] << 24 | (uint32_t)buf[34] << 16 | (uint32_t)buf[35] << 8 | buf[36];
    assert_memory_equal(buf + 37, "IDAT", 4);
    uint8_t raw[4 * (16 + 1)];
    uLongf rawlen = sizeof raw;
    assert_int_equal(uncompress(raw, &rawlen, buf + 41, len), Z_OK);
    assert_int_equal(rawlen, sizeof raw);
    for (int y = 0; y < 4; ++y) {
        assert_int_equal(raw[y * 17], 0);
        assert_memory_equal(raw + y * 17 + 1, rgba + y * 16, 16);
    }
    assert_int_equal(rt_write_png("/nonexistent/dir/x.png", 4, 4, rgba, err, sizeof err), VFX_ERR_IO);
    assert_non_null(strstr(err, "/nonexistent/dir/x.png"));
}

static void test_shader_log_rewrite(void **state)
{
    (void)state;
    int idx = volfx_shader_index(&rt_host_shaders, "common/fullscreen.vert");
    assert_true(idx >= 0);
    char log[128], out[256];
    /* Mesa's and NVIDIA's formats both come back as file:line */
    snprintf(log, sizeof log, "%d:7(12): error: syntax error\n", idx);
    volfx_shader_rewrite_log(&rt_host_shaders, log, out, sizeof out, "x");
    assert_non_null(strstr(out, "common/fullscreen.vert:7: error: syntax error"));
    snprintf(log, sizeof log, "%d(9) : error C0000: bad\n", idx);
    volfx_shader_rewrite_log(&rt_host_shaders, log, out, sizeof out, "x");
    assert_non_null(strstr(out, "common/fullscreen.vert:9:"));
    /* Mesa prints source string 0 whatever #line said: the file comes from the line number */
    snprintf(log, sizeof log, "0:%ld(3): error: x\n", volfx_shader_line_base(idx) + 42);
    volfx_shader_rewrite_log(&rt_host_shaders, log, out, sizeof out, "x");
    assert_non_null(strstr(out, "common/fullscreen.vert:42: error: x"));
    char err[128];
    assert_null(volfx_shader_expand(&rt_host_shaders, "nope/missing.frag", NULL, err, sizeof err));
    assert_non_null(strstr(err, "nope/missing.frag"));
    char *src = volfx_shader_expand(&rt_host_shaders, "common/fullscreen.vert", "#define X 1", err, sizeof err);
    assert_non_null(src);
    assert_true(strncmp(src, "#version 450 core\n#define X 1\n", 30) == 0);
    free(src);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pfm_roundtrip),
        cmocka_unit_test(test_png_valid),
        cmocka_unit_test(test_shader_log_rewrite),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
