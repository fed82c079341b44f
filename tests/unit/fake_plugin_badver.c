/* A broken plugin: its entry answers OK but fills a table of another type (99) with no functions. */
#include <string.h>
#include <volfx/volfx.h>

VFX_EXPORT vfx_result vfx_plugin_entry(uint32_t abi_version, const vfx_context_desc *host, vfx_plugin_api *out)
{
    (void)abi_version, (void)host;
    memset(out, 0, sizeof *out);
    out->type = (vfx_struct_type)99;
    return VFX_OK;
}
