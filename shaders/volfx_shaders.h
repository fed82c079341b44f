/* volfx_shaders.h — GLSL sources embedded at build time (see shaders/embed.py). */
#ifndef VOLFX_SHADERS_H
#define VOLFX_SHADERS_H

typedef struct volfx_embedded_shader {
    const char *path;   /* relative to shaders/, e.g. "water/accumulate.frag" */
    const char *source;
} volfx_embedded_shader;

/* Table ending with a {0,0} entry; index i is also the GLSL source-string number. */
extern const volfx_embedded_shader volfx_embedded_shaders[];
extern const unsigned volfx_embedded_shader_count;

#endif
