/* shader_text.h — embedded GLSL: lookup, #include expansion, error-log rewriting. */
#ifndef VOLFX_SHADER_TEXT_H
#define VOLFX_SHADER_TEXT_H

#include <stddef.h>

#include "volfx_shaders.h"

/* Drivers disagree on reporting #line's source-string number (Mesa always prints 0), so the file
 * is encoded in the line number itself: line (index + 1) * STRIDE + n is line n of file index. */
#define VOLFX_SHADER_LINE_STRIDE 100000L
/* First encoded line number of embedded shader `index` (line n is base + n). */
long volfx_shader_line_base(int index);
/* Index of an embedded shader of table t by path relative to shaders/ (-1 when absent). */
int volfx_shader_index(const volfx_shader_table *t, const char *path);
/* Full source ready for glShaderSource: "#version 450 core", `defines`, then the file of table t
 * with one level of #include "x" (from t too) expanded and #line markers encoding file and line.
 * malloc'd; NULL on error (message in err). */
char *volfx_shader_expand(const volfx_shader_table *t, const char *path, const char *defines, char *err,
                          size_t errlen);
/* Rewrites a driver info log ("0:L(3): error" Mesa, "0(L) : error" NVIDIA) into "file:n: error"
 * lines, decoding the line numbers of volfx_shader_expand over table t (or a driver's source
 * number when L is small). */
void volfx_shader_rewrite_log(const volfx_shader_table *t, const char *log, char *out, size_t cap,
                              const char *fallback);

#endif
