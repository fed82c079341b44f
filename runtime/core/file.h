/* file.h — reading a whole input file with a size cap, for every loader that parses from memory. */
#ifndef RT_FILE_H
#define RT_FILE_H

#include <stddef.h>
#include <stdio.h>
#include <volfx/volfx.h>

/* Fails (VFX_ERR_IO) unless `path` names a regular file, without opening it: "PATH: is a
 * directory", "is a FIFO", "is a character device", ... or "cannot open: <errno text>". */
vfx_result rt_check_regular_file(const char *path, char *err, size_t errlen);

/* Reads `path` into a malloc'd buffer with a NUL after the last byte (*size excludes it).
 * Anything but a regular file is refused before it is opened (rt_check_regular_file), and it is
 * opened non-blocking, so a FIFO swapped in between cannot hang the read. A file above
 * max_bytes, by its size or by what reading it gives (a /proc file reports size 0), is refused
 * with "PATH: N bytes, above the cap of CAP" (CAP = cap_text, VFX_ERR_INVALID_ARGUMENT) before
 * more than max_bytes + 1 are held. Other errors name the path: short read, out of memory. */
vfx_result rt_read_file(const char *path, size_t max_bytes, const char *cap_text, char **out,
                         size_t *size, char *err, size_t errlen);

/* Checks an output path before a run: an existing path must be a regular file we may write or
 * /dev/null (a FIFO, directory, socket or other device is refused, naming what it is); a new
 * name needs an existing writable directory. Messages start with the path. */
vfx_result rt_check_output_path(const char *path, char *err, size_t errlen);

/* Opens an output for writing (`mode` "w" or "wb", truncating) without ever blocking: a FIFO
 * with no reader, or anything but a regular file or /dev/null, gives NULL and a message naming
 * the path, as does any open error. */
FILE *rt_open_output(const char *path, const char *mode, char *err, size_t errlen);

#endif
