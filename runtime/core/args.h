/* args.h — strict command-line numbers for the game and the benchmarks: the whole argument must
 * be a number in range ("-5" is not a count, "12abc" is not 12), and the message names the
 * option and the value. */
#ifndef RT_ARGS_H
#define RT_ARGS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* Decimal integer in [lo, hi] (no sign, no trailing text); false with "OPT: ..." in err. */
bool rt_arg_u32(const char *opt, const char *v, uint32_t lo, uint32_t hi, uint32_t *out, char *err,
                size_t errlen);
/* Finite number in [lo, hi]; false with "OPT: ..." in err. */
bool rt_arg_double(const char *opt, const char *v, double lo, double hi, double *out, char *err,
                   size_t errlen);
/* "WxH", each in [1, max]; false with "OPT: ..." in err. */
bool rt_arg_size(const char *opt, const char *v, uint32_t max, uint32_t *w, uint32_t *h, char *err,
                 size_t errlen);
/* True when `path` can be written (rt_check_output_path: an existing regular file we may write
 * or /dev/null, or a new name in an existing writable directory; never a FIFO, directory or
 * other device), checked before a long run so it cannot fail or block at the end;
 * "OPT: PATH ..." in err. */
bool rt_arg_writable(const char *opt, const char *path, char *err, size_t errlen);

#endif
