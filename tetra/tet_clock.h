/* tet_clock.h — the millisecond clocks the tet renderer, its MPI backend and the tetvol bench
 * time themselves with (header-only, static inline: no state, nothing to link). The includer
 * defines _POSIX_C_SOURCE >= 199309L before any system header, for clock_gettime. */
#ifndef TET_CLOCK_H
#define TET_CLOCK_H

#include <time.h>

/* Milliseconds on clock id; 0 when the clock cannot be read. */
static inline double tet_clock_ms(clockid_t id)
{
    struct timespec ts;
    if (clock_gettime(id, &ts) != 0)
        return 0;
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/* Wall time: the monotonic clock in ms. */
static inline double tet_now_ms(void)
{
    return tet_clock_ms(CLOCK_MONOTONIC);
}

/* CPU time of the calling thread in ms: on a loaded machine wall time mostly measures the
 * scheduler. */
static inline double tet_thread_cpu_ms(void)
{
    return tet_clock_ms(CLOCK_THREAD_CPUTIME_ID);
}

#endif
