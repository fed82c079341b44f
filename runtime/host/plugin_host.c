/* plugin_host.c — dlopen/dlsym, version handshake, table validation. */
#define _GNU_SOURCE /* dladdr: which file the loader picked for a bare soname */
#include "host/plugin_host.h"
#include "core/file.h"

#include <dlfcn.h>
#include <stdlib.h>
#include <string.h>

struct rt_plugin_host {
    void *handle; /* NULL for a static plugin */
    vfx_plugin_api api;
};

/* Calls the entry and checks what came back, so a broken plugin never reaches the game. */
static vfx_result handshake(vfx_plugin_entry_fn entry, uint32_t abi, const vfx_context_desc *host,
                            const rt_logger *log, rt_plugin_host *h, const char *where)
{
    memset(&h->api, 0, sizeof h->api);
    vfx_plugin_api *api = &h->api;
    api->type = VFX_TYPE_PLUGIN_API;
    vfx_result r = entry(abi, host, api);
    if (r != VFX_OK) {
        rt_logf(log, VFX_LOG_ERROR, "plugin %s refused the host (host ABI %u): %s", where, abi,
                 vfx_result_name(r));
        return r;
    }
    if (api->type != VFX_TYPE_PLUGIN_API || !api->create || !api->destroy || !api->resize || !api->update
        || !api->render || !api->warm_up || !api->set_program_cache || !api->get_stats || !api->get_lights
        || !api->last_error || !api->read_raw || !api->resolve_defaults) {
        rt_logf(log, VFX_LOG_ERROR, "plugin %s: function table of type %u has NULL entries", where,
                (unsigned)api->type);
        return VFX_ERR_ABI;
    }
    return VFX_OK;
}

vfx_result rt_plugin_host_load_as(const char *path, uint32_t abi, const vfx_context_desc *host,
                                   const rt_logger *log, rt_plugin_host **out)
{
    if (!path || !out)
        return VFX_ERR_INVALID_ARGUMENT;
    *out = NULL;
    /* A path (not a soname the loader searches) is checked first: dlopen of a FIFO blocks
     * forever in open(), a directory gives only "cannot read file data". */
    /* dlopen("") is the main program, whose missing entry symbol would be blamed instead */
    if (!path[0]) {
        rt_logf(log, VFX_LOG_ERROR, "plugin path is empty: name the plugin's file (a path with '/') "
                "or a soname the loader searches");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    char why[512];
    if (strchr(path, '/') && rt_check_regular_file(path, why, sizeof why)) {
        rt_logf(log, VFX_LOG_ERROR, "plugin %s", why);
        return VFX_ERR_IO;
    }
    void *handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
        rt_logf(log, VFX_LOG_ERROR, "plugin '%s' cannot be loaded: %s", path, dlerror());
        return VFX_ERR_IO;
    }
    vfx_plugin_entry_fn entry;
    void *sym = dlsym(handle, VFX_ENTRY_SYMBOL);
    memcpy(&entry, &sym, sizeof entry); /* object-to-function pointer, as POSIX allows */
    if (!entry) {
        rt_logf(log, VFX_LOG_ERROR, "plugin '%s' has no '%s' symbol", path, VFX_ENTRY_SYMBOL);
        dlclose(handle);
        return VFX_ERR_NOT_FOUND;
    }
    rt_plugin_host *h = calloc(1, sizeof *h);
    if (!h) {
        dlclose(handle);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    h->handle = handle;
    Dl_info where;
    if (dladdr(sym, &where) && where.dli_fname)
        rt_logf(log, VFX_LOG_INFO, "plugin '%s' loaded from %s", path, where.dli_fname);
    vfx_result r = handshake(entry, abi, host, log, h, path);
    if (r != VFX_OK) {
        rt_plugin_host_unload(h);
        return r;
    }
    *out = h;
    return VFX_OK;
}

vfx_result rt_plugin_host_load(const char *path, const vfx_context_desc *host, const rt_logger *log,
                                rt_plugin_host **out)
{
    return rt_plugin_host_load_as(path, VFX_ABI_VERSION, host, log, out);
}

vfx_result rt_plugin_host_load_static(vfx_plugin_entry_fn entry, const vfx_context_desc *host,
                                       const rt_logger *log, rt_plugin_host **out)
{
    if (!entry || !out)
        return VFX_ERR_INVALID_ARGUMENT;
    *out = NULL;
    rt_plugin_host *h = calloc(1, sizeof *h);
    if (!h)
        return VFX_ERR_OUT_OF_MEMORY;
    vfx_result r = handshake(entry, VFX_ABI_VERSION, host, log, h, "(static)");
    if (r != VFX_OK) {
        free(h);
        return r;
    }
    *out = h;
    return VFX_OK;
}

const vfx_plugin_api *rt_plugin_host_api(const rt_plugin_host *h) { return h ? &h->api : NULL; }

void rt_plugin_host_unload(rt_plugin_host *h)
{
    if (!h)
        return;
    if (h->handle)
        dlclose(h->handle);
    free(h);
}
