#!/usr/bin/env bash
# The whole suite again under AddressSanitizer + UndefinedBehaviorSanitizer + LeakSanitizer
# (build-asan). GL suites keep Mesa's driver loaded (VFX_EGL_KEEP_DRIVER) so the driver's own
# process-lifetime allocations can be named and suppressed (tests/lsan-gl.supp, driver
# libraries only); leaks in volfx code are reported and fail the run.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
build=${VFX_ASAN_BUILD_DIR:-build-asan}
[ -f "$build/build.ninja" ] || meson setup "$build" -Db_sanitize=address,undefined -Db_lundef=false
ninja -C "$build"
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
export ASAN_OPTIONS=detect_leaks=1
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan-gl.supp:print_suppressions=0"
export VFX_EGL_KEEP_DRIVER=1
set +e
# shellcheck disable=SC2086
meson test -C "$build" --print-errorlogs --num-processes "$(nproc)" --timeout-multiplier 3 ${VFX_TEST_ARGS:-}
rc=$?
set -e
python3 scripts/testlog-count.py "$build/meson-logs/testlog.json" || true
exit $rc
