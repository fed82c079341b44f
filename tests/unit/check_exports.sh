#!/bin/sh
# The plugin must export vfx_plugin_entry and nothing else of ours.
set -eu
syms=$(nm -D --defined-only "$1" | awk '{print $3}' | grep -v -E '^(_init|_fini|_edata|_end|__bss_start)$' | sort)
if [ "$syms" != "vfx_plugin_entry" ]; then
  echo "unexpected exported symbols in $1:"; echo "$syms"; exit 1
fi
echo "only vfx_plugin_entry exported"
