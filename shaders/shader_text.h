/* shader_text.h — embedded GLSL: lookup, #include expansion, error-log rewriting. */
#ifndef VFX_SHADER_TEXT_H
#define VFX_SHADER_TEXT_H

#include <stddef.h>

/* Index of an embedded shader by path relative to shaders/ (-1 when absent). */
int vfx_shader_index(const char *path);
/* Full source ready for glShaderSource: "#version 450 core", `defines`, then the file with one
 * level of #include "x" expanded and #line <n> <file-index> markers. malloc'd; NULL on error
 * (message in err). */
char *vfx_shader_expand(const char *path, const char *defines, char *err, size_t errlen);
/* Rewrites a driver info log ("0:12(3): error" Mesa, "0(12) : error" NVIDIA) into
 * "file:12: error" lines using the source-string numbers set by vfx_shader_expand. */
void vfx_shader_rewrite_log(const char *log, char *out, size_t cap, const char *fallback);

#endif
