/* A plugin built against a future ABI: its function table claims version 99. */
#include <string.h>
#include <volfx/volfx.h>

VFX_EXPORT vfx_result vfx_plugin_entry(uint32_t abi_version, const vfx_host_api *host, vfx_plugin_api *out)
{
    (void)abi_version, (void)host;
    memset(out, 0, sizeof *out);
    out->size = sizeof *out;
    out->version = 99;
    return VFX_OK;
}
