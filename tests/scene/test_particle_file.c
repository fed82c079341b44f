/* test_particle_file.c — the particle file: round trip, byte layout, every error names what
 * and where (size, particle index), the count cap refused before reading. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "scene/particle_file.h"

static char dir[] = "/tmp/vfx_particles_XXXXXX";

static const char *tmp(const char *name)
{
    static char buf[256];
    snprintf(buf, sizeof buf, "%s/%s", dir, name);
    return buf;
}

static void write_bytes(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, n, f), n);
    fclose(f);
}

static void test_round_trip_and_layout(void **state)
{
    (void)state;
    const float xyz[9] = {1.0f, -2.5f, 3.25f, 0, 1e-30f, -1e30f, 7, 8, 9};
    char err[256];
    const char *p = tmp("a.bin");
    assert_int_equal(rt_particle_file_save(p, xyz, 3, err, sizeof err), VFX_OK);
    /* byte layout independent of the loader: 1.0f little-endian is 00 00 80 3f */
    unsigned char raw[36];
    FILE *f = fopen(p, "rb");
    assert_int_equal(fread(raw, 1, 36, f), 36);
    assert_int_equal(fgetc(f), EOF);
    fclose(f);
    const unsigned char one[4] = {0x00, 0x00, 0x80, 0x3f}, minus_2_5[4] = {0x00, 0x00, 0x20, 0xc0};
    assert_memory_equal(raw, one, 4);
    assert_memory_equal(raw + 4, minus_2_5, 4);
    float *got = NULL;
    uint32_t n = 0;
    assert_int_equal(rt_particle_file_load(p, &got, &n, err, sizeof err), VFX_OK);
    assert_int_equal(n, 3);
    assert_memory_equal(got, xyz, sizeof xyz);
    free(got);
}

static void test_empty_file(void **state)
{
    (void)state;
    char err[256];
    float *got = (float *)err;
    uint32_t n = 99;
    assert_int_equal(rt_particle_file_save(tmp("e.bin"), NULL, 0, err, sizeof err), VFX_OK);
    assert_int_equal(rt_particle_file_load(tmp("e.bin"), &got, &n, err, sizeof err), VFX_OK);
    assert_int_equal(n, 0);
    assert_null(got);
}

static void test_bad_size(void **state)
{
    (void)state;
    unsigned char bytes[25] = {0};
    write_bytes(tmp("s.bin"), bytes, 25);
    char err[256];
    float *got = NULL;
    uint32_t n = 0;
    assert_int_equal(rt_particle_file_load(tmp("s.bin"), &got, &n, err, sizeof err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "size 25 bytes is not a multiple of 12"));
    assert_non_null(strstr(err, tmp("s.bin")));
    assert_null(got);
    assert_int_equal(rt_particle_file_parse(bytes, 13, &got, &n, err, sizeof err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "size 13 bytes"));
}

static void test_non_finite(void **state)
{
    (void)state;
    float xyz[12] = {0};
    xyz[3 * 2 + 1] = NAN; /* particle 2, y */
    char err[256];
    float *got = NULL;
    uint32_t n = 0;
    assert_int_equal(rt_particle_file_parse(xyz, sizeof xyz, &got, &n, err, sizeof err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "particle 2 has a non-finite y (NaN)"));
    xyz[3 * 2 + 1] = 0;
    xyz[3 * 3 + 2] = -INFINITY;
    assert_int_equal(rt_particle_file_parse(xyz, sizeof xyz, &got, &n, err, sizeof err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "particle 3 has a non-finite z (Inf)"));
    assert_null(got);
    /* save refuses them too, before creating the file */
    assert_int_equal(rt_particle_file_save(tmp("nan.bin"), xyz, 4, err, sizeof err), VFX_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "particle 3"));
    assert_int_equal(access(tmp("nan.bin"), F_OK), -1);
}

static void test_cap_and_io(void **state)
{
    (void)state;
    /* a sparse file one particle above the cap (4,194,305, the scene's cap + 1; it loaded before
     * the caps were unified): refused from its size, nothing read */
    const char *p = tmp("huge.bin");
    int fd = open(p, O_CREAT | O_WRONLY | O_TRUNC, 0600);
    assert_true(fd >= 0);
    assert_int_equal(ftruncate(fd, (off_t)12 * (RT_PARTICLE_FILE_MAX_COUNT + 1ull)), 0);
    close(fd);
    char err[256];
    float *got = NULL;
    uint32_t n = 0;
    assert_int_equal(rt_particle_file_load(p, &got, &n, err, sizeof err), VFX_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "50331660 bytes")); /* 12 x 4,194,305 */
    assert_non_null(strstr(err, "above the cap of 4194304 particles (RT_PARTICLE_FILE_MAX_COUNT)"));
    unlink(p);
    assert_int_equal(rt_particle_file_load(tmp("missing.bin"), &got, &n, err, sizeof err), VFX_ERR_IO);
    assert_non_null(strstr(err, "missing.bin: cannot open"));
    assert_int_equal(rt_particle_file_load(dir, &got, &n, err, sizeof err), VFX_ERR_IO);
    assert_non_null(strstr(err, "is a directory"));
    /* a FIFO is refused before it is opened: opening it for reading would block forever */
    alarm(30);
    const char *fifo = tmp("fifo.bin");
    assert_int_equal(mkfifo(fifo, 0600), 0);
    assert_int_equal(rt_particle_file_load(fifo, &got, &n, err, sizeof err), VFX_ERR_IO);
    assert_non_null(strstr(err, "is a FIFO"));
    unlink(fifo);
    alarm(0);
    assert_int_equal(rt_particle_file_load("/dev/zero", &got, &n, err, sizeof err), VFX_ERR_IO);
    assert_non_null(strstr(err, "is a character device"));
    assert_int_equal(rt_particle_file_save("/nonexistent-dir/x.bin", got, 0, err, sizeof err), VFX_ERR_IO);
    assert_int_equal(rt_particle_file_parse(NULL, 12, &got, &n, err, sizeof err), VFX_ERR_INVALID_ARGUMENT);
}

static int setup(void **state)
{
    (void)state;
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    static const char *names[] = {"a.bin", "e.bin", "s.bin", "nan.bin", "huge.bin"};
    for (size_t i = 0; i < 5; ++i)
        unlink(tmp(names[i]));
    return rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip_and_layout),
        cmocka_unit_test(test_empty_file),
        cmocka_unit_test(test_bad_size),
        cmocka_unit_test(test_non_finite),
        cmocka_unit_test(test_cap_and_io),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
