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
/usr/bin/python3 - "$build/meson-logs/testlog.json" <<'PY'
import json, sys
passed = failed = skipped = 0
with open(sys.argv[1]) as f:
    for line in f:
        line = line.strip()
        if not line:
            continue
        r = json.loads(line).get("result")
        if r in ("OK", "EXPECTEDFAIL"):
            passed += 1
        elif r == "SKIP":
            skipped += 1
        else:
            failed += 1
print(f"{passed} passed, {failed} failed, {skipped} skipped")
PY
exit $rc
