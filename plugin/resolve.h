/* resolve.h — the plugin api's resolve_defaults: what a zero field of a typed host struct
 * resolves to (docs/abi.md "Resolved defaults"). */
#ifndef VOLFX_RESOLVE_H
#define VOLFX_RESOLVE_H

#include "context.h"

/* Fills every zero field of the typed struct at inout with its default (by its type; docs/abi.md
 * "Resolved defaults"); ctx may be NULL. VFX_ERR_INVALID_ARGUMENT for NULL or a type without
 * defaults, or the error update() would give for a value out of range. */
vfx_result volfx_resolve_defaults(vfx_context *ctx, void *inout);

#endif
