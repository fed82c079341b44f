#!/bin/sh
# The OGRE 1.12 host (tests/integration/ogre_host.cpp) under Xvfb: OGRE's GL3Plus makes its
# context through GLX, so it needs an X server. Three checks (docs/ogre.md):
#   1. every effect is drawn where OGRE's depth lets it be (the host checks it after frame 30);
#   2. OGRE's own render target after frame 30 is byte-equal to a run without volfx, and a run
#      with the plugin's restore skipped (vfx_gl_state_desc.skip_restore) differs from its
#      volfx-free twin: OGRE's state cache then draws into the plugin's framebuffer and its
#      target stays at frame 0, so the comparison can fail;
#   3. the host does no GL state save or restore: it names no GL function but the loader's
#      glXGetProcAddressARB, and no OGRE state-cache call.
# usage: check_ogre_host.sh OGRE_HOST OGRE_HOST_SOURCE. Exits 77 when xvfb-run is absent or the
# host finds no display or GL context; keeps its images in $VFX_OGRE_DIR when that is set.
set -eu
host=$1 src=$2
# 3: by construction, checked on the source
[ -f "$src" ] || { echo "FAIL: no source $src"; exit 1; }
calls=$(grep -o -E '\bgl[A-Z][A-Za-z0-9]*|StateCache|PushAttrib|PopAttrib' "$src" | grep -v -x glXGetProcAddressARB | sort -u)
if [ -n "$calls" ]; then
    echo "FAIL: the OGRE host calls GL or OGRE's state cache itself: $calls"
    exit 1
fi
command -v xvfb-run >/dev/null 2>&1 || { echo "xvfb-run absent: skipping"; exit 77; }
dir=${VFX_OGRE_DIR:-${TMPDIR:-/tmp}/volfx-ogre-$$}
mkdir -p "$dir"
# X11's, Mesa's and OGRE's own allocations are not ours: leak checking off here.
rc=0
ASAN_OPTIONS=detect_leaks=0 xvfb-run -a -s "-screen 0 640x480x24" sh -c '
  set -e
  "$1" --no-volfx --target "$2/plain.ppm"
  "$1" --target "$2/target.ppm" --output "$2/output.ppm"
  "$1" --no-volfx --frames 3 --target "$2/plain3.ppm"
  "$1" --skip-restore --no-depth-check --frames 3 --target "$2/skip3.ppm"
' sh "$host" "$dir" || rc=$?
if [ $rc -eq 0 ]; then
    if ! cmp -s "$dir/plain.ppm" "$dir/target.ppm"; then
        echo "FAIL: OGRE's render target after frame 30 differs from the run without volfx ($dir)"
        rc=1
    elif cmp -s "$dir/plain3.ppm" "$dir/skip3.ppm"; then
        echo "FAIL: with the plugin's restore skipped OGRE's target is still right: the comparison cannot fail"
        rc=1
    else
        echo "OGRE's render target after frame 30 equals the run without volfx; with the restore skipped it differs"
    fi
fi
[ -n "${VFX_OGRE_DIR:-}" ] || rm -rf "$dir"
exit $rc
