/* debug.h — the one door through which tests and benchmarks reach inside the plugin: the
 * context (debug knobs, effect states, counters), the effect table and the GPU helpers. Hosts
 * never include it; the runtime and the game cannot (their include path is plugin/include). */
#ifndef VOLFX_DEBUG_H
#define VOLFX_DEBUG_H

#include "context.h"
#include "effect.h"
#include "gpu/gpu.h"

#endif
