/* sandbox.c — see sandbox.h. The child is a fork of the host, so it starts with the host's
 * address space and resident pages: its limits are what it may add to them. fork in a host
 * with other threads leaves the child only the calling one; a lock another thread held at the
 * fork stays held in the child, which then waits until the wall-clock limit stops it. */
#include "core/sandbox.h"

#include <errno.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define RT_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) && !defined(RT_ASAN)
#define RT_ASAN 1
#endif
#ifdef RT_ASAN
#include <sanitizer/common_interface_defs.h>
#endif

enum { STOP_NONE, STOP_WALL, STOP_MEMORY };

struct rt_sandbox_stream {
    int fd;
    pid_t pid;
    double deadline, next_rss_check;
    uint64_t rss_limit; /* bytes of resident memory at which the child is stopped */
    uint64_t rss_seen;
    int stopped; /* STOP_* */
    int ended;   /* the child's answer ended before a read was complete */
};

int rt_sandbox_under_asan(void)
{
#ifdef RT_ASAN
    return 1;
#else
    return 0;
#endif
}

rt_sandbox_limits rt_sandbox_default_limits(void)
{
    return (rt_sandbox_limits){.cpu_s = 30, .wall_s = 60, .memory_bytes = 2ull << 30, .stack_bytes = 8ull << 20};
}

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Field `k` of /proc/<pid>/statm (0: size, 1: resident) in bytes; 0 when unreadable. */
static uint64_t statm_bytes(pid_t pid, int k)
{
    char path[64];
    if (pid)
        snprintf(path, sizeof path, "/proc/%ld/statm", (long)pid);
    else
        snprintf(path, sizeof path, "/proc/self/statm");
    FILE *f = fopen(path, "r");
    unsigned long long v[2] = {0, 0};
    if (f) {
        if (fscanf(f, "%llu %llu", &v[0], &v[1]) != 2)
            v[0] = v[1] = 0;
        fclose(f);
    }
    return v[k] * (uint64_t)sysconf(_SC_PAGESIZE);
}

static void stop(rt_sandbox_stream *s, int why)
{
    if (!s->stopped)
        s->stopped = why;
    kill(s->pid, SIGKILL);
}

/* Past the deadline or the memory limit: stops the child; 1 when it was stopped. */
static int watch(rt_sandbox_stream *s)
{
    double t = now_s();
    if (t >= s->deadline) {
        stop(s, STOP_WALL);
        return 1;
    }
    if (t >= s->next_rss_check) {
        s->next_rss_check = t + 0.02;
        uint64_t rss = statm_bytes(s->pid, 1);
        if (rss > s->rss_seen)
            s->rss_seen = rss;
        if (rss > s->rss_limit) {
            stop(s, STOP_MEMORY);
            return 1;
        }
    }
    return 0;
}

vfx_result rt_sandbox_read(rt_sandbox_stream *s, void *buf, size_t n)
{
    unsigned char *p = buf;
    while (n > 0) {
        if (s->stopped || s->ended || watch(s)) {
            s->ended = 1;
            return VFX_ERR_FORMAT;
        }
        struct pollfd pfd = {.fd = s->fd, .events = POLLIN};
        int ready = poll(&pfd, 1, 20);
        if (ready < 0 && errno != EINTR) {
            s->ended = 1;
            return VFX_ERR_FORMAT;
        }
        if (ready <= 0)
            continue;
        ssize_t got = read(s->fd, p, n);
        if (got < 0 && (errno == EINTR || errno == EAGAIN))
            continue;
        if (got <= 0) {
            s->ended = 1;
            return VFX_ERR_FORMAT;
        }
        p += got, n -= (size_t)got;
    }
    return VFX_OK;
}

/* The child's side: default crash actions, limits, the work, _exit (no atexit handler, no
 * stdio buffer of the host's flushed twice). */
static void run_child(const rt_sandbox_limits *lim, int fd, rt_sandbox_child_fn child, void *arg)
{
    static const int crash[] = {SIGSEGV, SIGBUS, SIGABRT, SIGILL, SIGFPE, SIGXCPU, SIGTRAP, SIGPIPE, SIGSYS, SIGXFSZ};
    for (size_t i = 0; i < sizeof crash / sizeof crash[0]; ++i)
        signal(crash[i], SIG_DFL);
    sigset_t all;
    sigemptyset(&all);
    sigprocmask(SIG_SETMASK, &all, NULL);
#ifdef RT_ASAN
    /* a fuzzer's death callback would write the input as its own crash */
    __sanitizer_set_death_callback(NULL);
#endif
    struct rlimit r = {0, 0};
    setrlimit(RLIMIT_CORE, &r);
    rlim_t cpu = (rlim_t)ceil(lim->cpu_s < 1 ? 1 : lim->cpu_s);
    r = (struct rlimit){cpu, cpu + 1}; /* SIGXCPU at the soft limit, SIGKILL a second later */
    setrlimit(RLIMIT_CPU, &r);
    if (getrlimit(RLIMIT_STACK, &r) == 0) {
        rlim_t want = (rlim_t)lim->stack_bytes;
        if (r.rlim_max != RLIM_INFINITY && r.rlim_max < want)
            want = r.rlim_max;
        r.rlim_cur = want;
        setrlimit(RLIMIT_STACK, &r);
    }
#ifndef RT_ASAN
    uint64_t vm = statm_bytes(0, 0);
    r = (struct rlimit){(rlim_t)(vm + lim->memory_bytes), (rlim_t)(vm + lim->memory_bytes)};
    setrlimit(RLIMIT_AS, &r);
#endif
    vfx_result res = child(arg, fd);
    close(fd);
    _exit(res == VFX_OK ? 0 : 1);
}

static void describe(const rt_sandbox_limits *lim, const rt_sandbox_stream *s, int status, const char *what,
                     char *err, size_t errlen)
{
    if (s->stopped == STOP_WALL)
        snprintf(err, errlen, "%s: stopped after %.0f s, the wall-clock limit of the process that reads it", what,
                 lim->wall_s);
    else if (s->stopped == STOP_MEMORY)
        snprintf(err, errlen, "%s: stopped at %llu MiB more resident memory than the host had, above the limit of "
                 "%llu MiB of the process that reads it", what,
                 (unsigned long long)((s->rss_seen - (s->rss_limit - lim->memory_bytes)) >> 20),
                 (unsigned long long)(lim->memory_bytes >> 20));
    else if (WIFSIGNALED(status) && WTERMSIG(status) == SIGXCPU)
        snprintf(err, errlen, "%s: stopped after %.0f s of CPU time, the limit of the process that reads it", what,
                 ceil(lim->cpu_s < 1 ? 1 : lim->cpu_s));
    else if (WIFSIGNALED(status) && WTERMSIG(status) == SIGSEGV)
        snprintf(err, errlen, "%s: the reader crashed (SIGSEGV: a memory fault, or a stack overflow such as a "
                 "recursion too deep) in the process that reads it", what);
    else if (WIFSIGNALED(status) && WTERMSIG(status) == SIGABRT)
        snprintf(err, errlen, "%s: the reader aborted (SIGABRT: a failed assertion or an uncaught exception, such "
                 "as memory refused at the limit of %llu MiB) in the process that reads it", what,
                 (unsigned long long)(lim->memory_bytes >> 20));
    else if (WIFSIGNALED(status))
        snprintf(err, errlen, "%s: the process that reads it was killed by signal %d (%s)", what, WTERMSIG(status),
                 strsignal(WTERMSIG(status)));
    else
        snprintf(err, errlen, "%s: the process that reads it exited with status %d before its answer was whole%s",
                 what, WEXITSTATUS(status),
                 rt_sandbox_under_asan() ? " (a sanitizer's report, if any, is on stderr)" : "");
}

/* Waits for the child until the deadline, then kills it; its wait status. */
static int reap(rt_sandbox_stream *s)
{
    int status = 0;
    for (;;) {
        pid_t got = waitpid(s->pid, &status, WNOHANG);
        if (got == s->pid || (got < 0 && errno != EINTR))
            return status;
        if (got == 0 && watch(s)) {
            while (waitpid(s->pid, &status, 0) < 0 && errno == EINTR) {
            }
            return status;
        }
        struct timespec t = {0, 1000000};
        nanosleep(&t, NULL);
    }
}

vfx_result rt_sandbox_run(const rt_sandbox_limits *lim, const char *what, rt_sandbox_child_fn child,
                          void *child_arg, rt_sandbox_reader_fn reader, void *reader_arg, char *err,
                          size_t errlen)
{
    int p[2];
    if (pipe(p) != 0) {
        snprintf(err, errlen, "%s: cannot make a pipe for the process that reads it: %s", what, strerror(errno));
        return VFX_ERR_IO;
    }
    uint64_t rss0 = statm_bytes(0, 1);
    fflush(NULL); /* nothing the host buffered is written twice */
    pid_t pid = fork();
    if (pid < 0) {
        snprintf(err, errlen, "%s: cannot start the process that reads it: %s", what, strerror(errno));
        close(p[0]), close(p[1]);
        return VFX_ERR_IO;
    }
    if (pid == 0) {
        close(p[0]);
        run_child(lim, p[1], child, child_arg);
    }
    close(p[1]);
    double t0 = now_s();
    rt_sandbox_stream s = {.fd = p[0], .pid = pid, .deadline = t0 + lim->wall_s, .next_rss_check = t0,
                           .rss_limit = rss0 + lim->memory_bytes};
    char rmsg[1024] = "";
    vfx_result r = reader(reader_arg, &s, rmsg, sizeof rmsg);
    close(p[0]); /* a child still writing gets EPIPE and ends */
    if (r != VFX_OK && !s.ended)
        stop(&s, STOP_NONE); /* the reader refused the answer: the rest is not wanted */
    int status = reap(&s);
    if (r != VFX_OK && !s.ended) { /* the child's own error, or an answer the reader refused */
        snprintf(err, errlen, "%s", rmsg);
        return r;
    }
    if (s.stopped || s.ended || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        describe(lim, &s, status, what, err, errlen);
        return VFX_ERR_FORMAT;
    }
    return VFX_OK;
}
