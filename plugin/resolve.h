/* resolve.h — the plugin api's resolve_defaults: what a zero field of a typed host struct
 * resolves to (docs/abi.md "Resolved defaults"). */
#ifndef VOLFX_RESOLVE_H
#define VOLFX_RESOLVE_H

#include "context.h"

/* Fills every zero field of the typed struct at inout with its default (by its type); ctx may be
 * NULL. VFX_ERR_INVALID_ARGUMENT for NULL, VFX_ERR_UNSUPPORTED for a type it does not resolve. */
vfx_result volfx_resolve_defaults(vfx_context *ctx, void *inout);

#endif
