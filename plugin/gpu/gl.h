/* gl.h — the GL the plugin calls. Inside the plugin (VOLFX_GL_TABLE, set for its sources only)
 * every GL command is a field of a table generated at build time from Khronos' gl.xml for exactly
 * the commands the plugin's sources use (gen_gl.py -> volfx_gl.h/.c) and filled at create through
 * the host's vfx_context_desc.gl_get_proc_address; the plugin links no GL loader of its own.
 *
 * `glFoo(...)` expands to `volfx_gl_current->Foo(...)`: a per-thread pointer to the table of the
 * context whose API call is running, set on entry to every call (volfx_gl_bind). Why a
 * thread-local instead of passing the table: GL itself keeps a per-thread current context and the
 * plugin may only be called where the host's context is current, so the table follows the same
 * rule, and the effects' GL code (helpers without a context parameter among them) stays plain GL
 * instead of threading a table through every call. It is the plugin's one piece of state outside
 * a context: it holds no data, is rebound by every call, and two contexts on two threads (or one
 * after another on one thread) each see their own.
 *
 * Tests and benches that include plugin internals compile without VOLFX_GL_TABLE and get libepoxy's
 * declarations of the same functions (they link it for their own GL). */
#ifndef VOLFX_GPU_GL_H
#define VOLFX_GPU_GL_H

#ifdef VOLFX_GL_TABLE
#include "volfx_gl.h"
#else
#include <epoxy/gl.h>
#endif

#endif
