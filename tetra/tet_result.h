/* tet_result.h — the result codes of the tet library and its message writer. A function that
 * can fail returns a tet_result and takes `char *err, size_t errlen` last (NULL allowed) for a
 * message naming what failed and where. The values equal those of the plugin ABI's tet_result
 * (plugin/include/volfx/volfx.h) so hosts map them with a cast, but the library does not see
 * that header: it sits below the plugin. */
#ifndef TET_RESULT_H
#define TET_RESULT_H

#include <stddef.h>

typedef enum tet_result {
    TET_OK = 0,
    TET_ERR_INVALID_ARGUMENT = 1, /* NULL, NaN, out-of-range value, bad index or count */
    TET_ERR_OUT_OF_MEMORY = 5,
    TET_ERR_FORMAT = 7,           /* mesh filled but malformed */
    TET_ERR_NUMERIC = 9,          /* NaN/Inf in the points or the scalar */
} tet_result;

/* Formats the message into err when err is not NULL and errlen > 0 (always terminated). */
void tet_errf(char *err, size_t errlen, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

#endif
