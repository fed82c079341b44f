/* error.h — the runtime's one error convention: a function that can fail returns a vfx_result
 * and takes `char *err, size_t errlen` last (NULL or 0 allowed) for a message naming what failed
 * and where. No object keeps a message of its own for later (the ECS world's
 * rt_world_last_error is the one context-style exception, as the plugin's volfx_fail is). */
#ifndef RT_CORE_ERROR_H
#define RT_CORE_ERROR_H

#include <stddef.h>
#include <volfx/volfx.h>

/* Formats the message into err (when err is not NULL and errlen > 0, always terminated) and
 * returns r, so a failure reads `return rt_errf(err, errlen, VFX_ERR_..., "...", ...);`. */
vfx_result rt_errf(char *err, size_t errlen, vfx_result r, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

#endif
