/* volfx_shaders.h — GLSL sources embedded at build time (see shaders/embed.py). Two tables are
 * made: the plugin's (volfx_plugin_shaders, plugin/gpu) and the host's (rt_host_shaders,
 * runtime/gfx); each program is built from one table, so a host file never ships in the plugin. */
#ifndef VOLFX_SHADERS_H
#define VOLFX_SHADERS_H

typedef struct volfx_embedded_shader {
    const char *path;   /* relative to shaders/, e.g. "water/shade.frag" */
    const char *source;
} volfx_embedded_shader;

/* One embedded table: entries[i] for i < count (then a {0,0} entry); index i is also the GLSL
 * source-string number of that file. */
typedef struct volfx_shader_table {
    const volfx_embedded_shader *entries;
    unsigned count;
} volfx_shader_table;

/* The plugin's shaders (plugin/meson.build: shaders/meson.build's shader_files). */
extern const volfx_shader_table volfx_plugin_shaders;
/* The sample host's shaders (runtime/meson.build: shaders/meson.build's host_shader_files);
 * linked into the runtime only, never into libvolfx. */
extern const volfx_shader_table rt_host_shaders;
/* The lab's shaders (plugin/lab/meson.build: shaders/meson.build's lab_shader_files): the
 * baselines and the tests' probes, in the lab library only, reached through ctx->lab. */
extern const volfx_shader_table volfx_lab_shaders;

#endif
