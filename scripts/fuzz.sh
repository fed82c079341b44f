#!/usr/bin/env bash
# Builds the libFuzzer targets in a separate clang build dir and runs each for a bounded time.
# usage: [FUZZ_TARGETS="vtu tetgen"] scripts/fuzz.sh [seconds per target, default 60]
set -euo pipefail
cd "$(dirname "$0")/.."
secs=${1:-60}
[ -f build-fuzz/build.ninja ] || CC=clang meson setup build-fuzz -Dfuzz=true -Db_lundef=false \
  -Dmetaballs=false -Dbeams=false -Dtetvol=false >/dev/null
targets="${FUZZ_TARGETS:-scene particle_file vtu tetgen assimp}"
ninja -C build-fuzz $(for t in $targets; do printf 'tests/fuzz/fuzz_%s ' "$t"; done)
for t in $targets; do
  work=build-fuzz/corpus-$t; mkdir -p "$work"
  log=build-fuzz/fuzz-$t.log
  # a fresh artifact folder per target and run: crash-*, oom-*, leak-*, timeout-* all count
  art=build-fuzz/artifacts-$t; rm -rf "$art"; mkdir -p "$art"
  set +e
  build-fuzz/tests/fuzz/fuzz_$t -max_total_time="$secs" -max_len=8192 -artifact_prefix="$art/" "$work" "tests/fuzz/corpus/$t" >"$log" 2>&1
  rc=$?
  set -e
  runs=$(grep -o 'Done [0-9]* runs' "$log" | tail -1 || true)
  echo "fuzz_$t: ${runs:-no summary} rc=$rc findings=$(find "$art" -type f | wc -l) (in $art)"
done
