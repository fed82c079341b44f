#!/bin/sh
# The plugin must export vfx_plugin_entry and nothing else of ours.
set -eu
syms=$(nm -D --defined-only "$1" | awk '{print $3}' | grep -v -E '^(_init|_fini|_edata|_end|__bss_start)$' | sort)
if [ "$syms" != "vfx_plugin_entry" ]; then
  echo "unexpected exported symbols in $1:"; echo "$syms"; exit 1
fi
echo "only vfx_plugin_entry exported"
# No GL loader of its own: every GL command comes through the host's gl_get_proc_address, so the
# library needs no GL, EGL, GLX or libepoxy library and calls no such symbol.
needed=$(readelf -d "$1" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p')
if echo "$needed" | grep -q -E 'epoxy|libGL|libEGL|libOpenGL|libGLX|cglm'; then
  echo "$1 needs a GL library or libcglm (cglm is used header-inline):"; echo "$needed"; exit 1
fi
gl=$(nm -D --undefined-only "$1" | awk '{print $2}' | grep -E '^(gl[A-Z]|egl|glX|epoxy)' || true)
if [ -n "$gl" ]; then
  echo "$1 calls GL symbols directly:"; echo "$gl"; exit 1
fi
echo "no GL library or symbol: needs only $(echo $needed | tr '\n' ' ')"
