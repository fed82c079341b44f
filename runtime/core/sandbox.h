/* sandbox.h — running a parser of untrusted bytes in a child process (fork) with limits on its
 * CPU time, address space, stack, core dumps and wall-clock time, its output read back over a
 * pipe by the caller's reader with hard caps. A crash, hang or blow-up in the child becomes an
 * error that says which; the parent's memory holds only what the reader accepts. POSIX (Linux:
 * /proc for the memory watchdog). */
#ifndef RT_SANDBOX_H
#define RT_SANDBOX_H

#include <stddef.h>
#include <stdint.h>
#include <volfx/volfx.h>

typedef struct rt_sandbox_limits {
    double cpu_s;          /* RLIMIT_CPU of the child (whole seconds, at least 1) */
    double wall_s;         /* the child is killed after this long, whatever it does */
    uint64_t memory_bytes; /* address space the child may add to what it had at fork (RLIMIT_AS;
                              not under AddressSanitizer, whose shadow needs terabytes of it), and
                              resident memory it may add (the parent's watchdog, always) */
    uint64_t stack_bytes;  /* RLIMIT_STACK of the child */
} rt_sandbox_limits;

/* Runs in the child: writes its answer to fd. Its result is the child's exit status (0: OK). */
typedef vfx_result (*rt_sandbox_child_fn)(void *arg, int fd);

typedef struct rt_sandbox_stream rt_sandbox_stream;

/* Runs in the parent: reads the child's answer with rt_sandbox_read and checks it; on failure
 * writes why into err (the sandbox adds what happened to the child). */
typedef vfx_result (*rt_sandbox_reader_fn)(void *arg, rt_sandbox_stream *s, char *err, size_t errlen);

/* Exactly n bytes from the child, waiting at most until the wall-clock limit and stopping the
 * child when its resident memory passes the limit: VFX_OK, or VFX_ERR_FORMAT when the child
 * ended (or was stopped) first. */
vfx_result rt_sandbox_read(rt_sandbox_stream *s, void *buf, size_t n);

/* The defaults of mesh import: 30 s CPU, 60 s wall clock, 2 GiB, 8 MiB of stack. */
rt_sandbox_limits rt_sandbox_default_limits(void);

/* Forks; the child resets the crash signals to their default action (a crash kills it, no
 * handler of the host's or a fuzzer's runs), sets its limits, runs child(child_arg, fd) and
 * exits with its result. The parent runs reader(reader_arg, stream), then reaps the child.
 * VFX_OK only when the reader accepted and the child exited 0; otherwise err says "what: ..."
 * with the first of: stopped at the wall-clock or memory limit, killed by a signal (SIGXCPU:
 * the CPU limit), a non-zero exit, the reader's own message. */
vfx_result rt_sandbox_run(const rt_sandbox_limits *lim, const char *what, rt_sandbox_child_fn child,
                          void *child_arg, rt_sandbox_reader_fn reader, void *reader_arg, char *err,
                          size_t errlen);

/* 1 when built with AddressSanitizer (no address-space limit in the child then). */
int rt_sandbox_under_asan(void);

#endif
