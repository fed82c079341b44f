/* resolve.c — see resolve.h. */
#include "resolve.h"

vfx_result volfx_resolve_defaults(vfx_context *ctx, void *inout)
{
    if (!inout)
        return VFX_ERR_INVALID_ARGUMENT;
    (void)ctx;
    return VFX_ERR_UNSUPPORTED;
}
