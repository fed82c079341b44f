/* A shared library that is not a volfx plugin: it lacks vfx_plugin_entry. */
int vfx_not_the_entry(void);
int vfx_not_the_entry(void) { return 42; }
