/* vfx_shaders.h — GLSL sources embedded at build time (see shaders/embed.py). */
#ifndef VFX_SHADERS_H
#define VFX_SHADERS_H

typedef struct vfx_embedded_shader {
    const char *path;   /* relative to shaders/, e.g. "water/accumulate.frag" */
    const char *source;
} vfx_embedded_shader;

/* Table ending with a {0,0} entry; index i is also the GLSL source-string number. */
extern const vfx_embedded_shader vfx_embedded_shaders[];
extern const unsigned vfx_embedded_shader_count;

#endif
