/* core/sandbox.c with children that misbehave on purpose: each ends as an error saying what
 * happened, in about the time its limit allows, and the parent's memory stays small. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include "core/sandbox.h"

static double wall_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static vfx_result child_ok(void *arg, int fd)
{
    (void)arg;
    uint32_t v = 42;
    return write(fd, &v, 4) == 4 ? VFX_OK : VFX_ERR_IO;
}

static vfx_result child_segv(void *arg, int fd)
{
    (void)arg, (void)fd;
    raise(SIGSEGV);
    return VFX_OK;
}

static vfx_result child_spin(void *arg, int fd)
{
    (void)arg, (void)fd;
    for (volatile unsigned long i = 0;; ++i) {
    }
    return VFX_OK;
}

static vfx_result child_sleep(void *arg, int fd)
{
    (void)arg, (void)fd;
    for (;;)
        pause();
    return VFX_OK;
}

/* Touches memory until refused: RLIMIT_AS makes malloc fail (the child ends with an error), or,
 * under AddressSanitizer, the parent's watchdog stops it. */
static vfx_result child_eat(void *arg, int fd)
{
    (void)arg, (void)fd;
    for (size_t total = 0; total < (8ull << 30); total += 16u << 20) {
        char *p = malloc(16u << 20);
        if (!p)
            return VFX_ERR_OUT_OF_MEMORY;
        memset(p, 1, 16u << 20);
    }
    return VFX_OK;
}

static vfx_result child_flood(void *arg, int fd)
{
    (void)arg;
    static char junk[65536];
    for (;;)
        if (write(fd, junk, sizeof junk) <= 0)
            return VFX_ERR_IO;
}

/* Reads one uint32 that must be 42. */
static vfx_result reader_42(void *arg, rt_sandbox_stream *s, char *err, size_t errlen)
{
    (void)arg;
    uint32_t v = 0;
    if (rt_sandbox_read(s, &v, 4))
        return VFX_ERR_FORMAT;
    if (v != 42) {
        snprintf(err, errlen, "test: answered %u, not 42", v);
        return VFX_ERR_FORMAT;
    }
    return VFX_OK;
}

/* 1 s of CPU, 64 MiB; the wall-clock limit long enough that a loaded machine (2 cores shared
 * by many jobs gave a child a tenth of one) reaches the CPU limit first */
static const rt_sandbox_limits tight = {.cpu_s = 1, .wall_s = 40, .memory_bytes = 64u << 20, .stack_bytes = 8u << 20};

/* Runs `child` under `lim`, expects `want` and an error holding `needle`, within `max_s` of
 * wall clock. */
static void expect_in(const rt_sandbox_limits *lim, rt_sandbox_child_fn child, vfx_result want, const char *needle,
                      double max_s)
{
    char err[512] = "";
    double t0 = wall_s();
    vfx_result r = rt_sandbox_run(lim, "test", child, NULL, reader_42, NULL, err, sizeof err);
    double dt = wall_s() - t0;
    printf("%s -> %d \"%s\" in %.2f s\n", needle, r, err, dt);
    assert_int_equal(r, want);
    if (needle[0])
        assert_non_null(strstr(err, needle));
    assert_true(dt < max_s);
}

static void test_children(void **state)
{
    (void)state;
    const rt_sandbox_limits one_s = {.cpu_s = 30, .wall_s = 1, .memory_bytes = 64u << 20, .stack_bytes = 8u << 20};
    expect_in(&tight, child_ok, VFX_OK, "", 20);
    expect_in(&tight, child_segv, VFX_ERR_FORMAT, "test: the reader crashed (SIGSEGV", 20);
    expect_in(&tight, child_spin, VFX_ERR_FORMAT, "test: stopped after 1 s of CPU time", 39);
    expect_in(&one_s, child_sleep, VFX_ERR_FORMAT, "test: stopped after 1 s, the wall-clock limit", 3);
    expect_in(&tight, child_flood, VFX_ERR_FORMAT, "test: answered 0, not 42", 20); /* 4 bytes taken, then stopped */
    char err[512] = "";
    double t0 = wall_s();
    assert_int_equal(rt_sandbox_run(&tight, "test", child_eat, NULL, reader_42, NULL, err, sizeof err), VFX_ERR_FORMAT);
    printf("eat -> \"%s\" in %.2f s (AddressSanitizer: %d)\n", err, wall_s() - t0, rt_sandbox_under_asan());
    if (rt_sandbox_under_asan())
        assert_non_null(strstr(err, "test: stopped at"));
    else
        assert_non_null(strstr(err, "test: the process that reads it exited with status 1"));
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    assert_true(ru.ru_maxrss < 128 * 1024); /* the child's gigabytes never were the parent's */
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_children)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
