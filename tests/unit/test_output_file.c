/* rt_open_output (issue 28): an output path that is, or has become after the up-front check, a
 * FIFO without a reader is refused at once instead of blocking the open forever; a directory
 * or a device other than /dev/null is refused naming what it is; a regular file and /dev/null
 * are written. Each refusal would hang this test (the meson timeout fails it) before the fix. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/file.h"
#include "gfx/image.h"
#include "profile/profiler.h"

static void test_fifo_and_devices_refused(void **state)
{
    (void)state;
    char dir[] = "/tmp/volfx-out-XXXXXX", fifo[64], err[1200];
    assert_non_null(mkdtemp(dir));
    snprintf(fifo, sizeof fifo, "%s/out.fifo", dir);
    assert_int_equal(mkfifo(fifo, 0600), 0);
    assert_int_equal(rt_check_output_path(fifo, err, sizeof err), VFX_ERR_IO);
    assert_non_null(strstr(err, "is a FIFO (named pipe)"));
    /* the writers themselves: a FIFO that appeared after the check */
    assert_null(rt_open_output(fifo, "w", err, sizeof err));
    assert_non_null(strstr(err, "with no reader"));
    float px[4] = {0};
    assert_int_equal(rt_write_pfm(fifo, 1, 1, px, err, sizeof err), VFX_ERR_IO);
    assert_non_null(strstr(err, fifo));
    uint8_t rgba[4] = {0};
    assert_int_equal(rt_write_png(fifo, 1, 1, rgba, err, sizeof err), VFX_ERR_IO);
    rt_profiler *p = rt_profiler_create(16);
    assert_non_null(p);
    assert_int_equal(rt_profiler_write_csv(p, fifo, err, sizeof err), VFX_ERR_IO);
    assert_int_equal(rt_profiler_write_trace(p, fifo, err, sizeof err), VFX_ERR_IO);
    assert_non_null(strstr(err, "is a FIFO"));
    assert_null(rt_open_output(dir, "w", err, sizeof err));
    assert_int_equal(rt_check_output_path(dir, err, sizeof err), VFX_ERR_IO);
    assert_non_null(strstr(err, "is a directory"));
    assert_int_equal(rt_check_output_path("/dev/zero", err, sizeof err), VFX_ERR_IO);
    assert_non_null(strstr(err, "is a character device"));
    assert_null(rt_open_output("/dev/zero", "w", err, sizeof err));
    /* what may be written */
    assert_int_equal(rt_check_output_path("/dev/null", err, sizeof err), VFX_OK);
    FILE *f = rt_open_output("/dev/null", "w", err, sizeof err);
    assert_non_null(f);
    fclose(f);
    char file[64];
    snprintf(file, sizeof file, "%s/out.csv", dir);
    assert_int_equal(rt_check_output_path(file, err, sizeof err), VFX_OK);
    assert_int_equal(rt_profiler_write_csv(p, file, err, sizeof err), VFX_OK);
    struct stat st;
    assert_int_equal(stat(file, &st), 0);
    assert_true(S_ISREG(st.st_mode) && st.st_size > 0);
    rt_profiler_destroy(p);
    unlink(file);
    unlink(fifo);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_fifo_and_devices_refused)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
