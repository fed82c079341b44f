#!/bin/sh
# The GLFW window path (GL 4.5 core window under Xvfb): the game runs 3 frames and writes a PNG.
# Exits 77 when xvfb-run is absent. X11's own allocations are not ours: leak checking off here.
set -eu
command -v xvfb-run >/dev/null 2>&1 || { echo "xvfb-run absent: skipping"; exit 77; }
out=${TMPDIR:-/tmp}/volfx-window-$$.png
ASAN_OPTIONS=detect_leaks=0 xvfb-run -a "$1" --window --frames 3 --size 160x90 --no-water --png "$out" | tee /dev/stderr | grep -q ", window, "
test -s "$out"
rm -f "$out"
echo "window mode ok"
