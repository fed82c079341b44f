/* file.h — reading a whole input file with a size cap, for every loader that parses from memory. */
#ifndef RT_FILE_H
#define RT_FILE_H

#include <stddef.h>
#include <volfx/volfx.h>

/* Reads `path` into a malloc'd buffer with a NUL after the last byte (*size excludes it). A file
 * above max_bytes is refused before anything is allocated for it, with "PATH: N bytes, above the
 * cap of CAP" (CAP = cap_text). Errors name the path: cannot open (VFX_ERR_IO), not a regular
 * file, short read, out of memory. */
vfx_result rt_read_file(const char *path, size_t max_bytes, const char *cap_text, char **out,
                         size_t *size, char *err, size_t errlen);

#endif
