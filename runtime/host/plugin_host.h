/* plugin_host.h — loads the volfx plugin (dlopen, or the statically linked entry), checks
 * its ABI, and owns the resulting function table. */
#ifndef RT_PLUGIN_HOST_H
#define RT_PLUGIN_HOST_H

#include <volfx/volfx.h>
#include "core/log.h"

typedef struct rt_plugin_host rt_plugin_host;

/* Loads the shared plugin at `path` (a bare soname such as VFX_SONAME goes through the loader's
 * search path; the file found is logged) and calls its entry with VFX_ABI_VERSION. Fails with
 * VFX_ERR_IO (cannot open: dlerror text), VFX_ERR_NOT_FOUND (no vfx_plugin_entry symbol),
 * VFX_ERR_ABI (versions differ: the message names both), VFX_ERR_INVALID_ARGUMENT (an empty
 * path: dlopen("") would open the program itself). */
vfx_result rt_plugin_host_load(const char *path, const vfx_context_desc *host, const rt_logger *log,
                                rt_plugin_host **out);
/* Same, with an entry function linked into the executable (static plugin). */
vfx_result rt_plugin_host_load_static(vfx_plugin_entry_fn entry, const vfx_context_desc *host,
                                       const rt_logger *log, rt_plugin_host **out);
/* Like load, but passes `abi_version` instead of ours (tests of the refusal path). */
vfx_result rt_plugin_host_load_as(const char *path, uint32_t abi_version, const vfx_context_desc *host,
                                   const rt_logger *log, rt_plugin_host **out);
/* The plugin's function table (valid until unload). */
const vfx_plugin_api *rt_plugin_host_api(const rt_plugin_host *h);
/* Unloads (dlclose) the plugin. Destroy every context first. NULL allowed. */
void rt_plugin_host_unload(rt_plugin_host *h);

#endif
