#!/bin/sh
# The SDL2 host (its own window, GL context and SDL_GL_GetProcAddress) under Xvfb: the plugin
# loaded with dlopen, 8 frames, each effect seen where the game put it; the last frame kept
# as a PPM when VFX_SDL_PPM names a file. Exits 77 when xvfb-run is absent. X11's and SDL's own
# allocations are not ours: leak checking off here.
set -eu
command -v xvfb-run >/dev/null 2>&1 || { echo "xvfb-run absent: skipping"; exit 77; }
ppm=${VFX_SDL_PPM:-${TMPDIR:-/tmp}/volfx-sdl-$$.ppm}
rc=0
ASAN_OPTIONS=detect_leaks=0 SDL_VIDEODRIVER=x11 xvfb-run -a -s "-screen 0 640x480x24" "$1" "$2" --ppm "$ppm" || rc=$?
[ -n "${VFX_SDL_PPM:-}" ] || rm -f "$ppm"
exit $rc
