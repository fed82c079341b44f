#!/usr/bin/env bash
# README command 1: installs what is missing, builds, and runs the sample game on its
# built-in default scene. With no display it runs headless (EGL) for 30 frames, prints fps and
# frame-time statistics and writes volfx-game.png. Extra arguments go to volfx-game.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
build=${VFX_BUILD_DIR:-build}
[ -f "$build/build.ninja" ] || meson setup "$build" --buildtype=release
ninja -C "$build"
exec "$build/sample_game/volfx-game" "$@"
