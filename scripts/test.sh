#!/usr/bin/env bash
# README command 2: installs what is missing, builds, runs every test, and ends with the line
# "N passed, N failed, N skipped" taken from meson's testlog.json.
# Environment: VFX_BUILD_DIR (default build), VFX_MESON_OPTS (extra meson setup options),
# VFX_TEST_ARGS (extra meson test arguments, e.g. "--suite ecs").
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
build=${VFX_BUILD_DIR:-build}
if [ ! -f "$build/build.ninja" ]; then
  # shellcheck disable=SC2086
  meson setup "$build" ${VFX_MESON_OPTS:-}
fi
ninja -C "$build"
set +e
# shellcheck disable=SC2086
meson test -C "$build" --print-errorlogs --num-processes "$(nproc)" ${VFX_TEST_ARGS:-}
rc=$?
set -e
# the closing line CI reads
python3 scripts/testlog-count.py "$build/meson-logs/testlog.json" || true
exit $rc
