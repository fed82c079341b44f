#!/bin/sh
# Regenerates the figures in docs/benchmarks-tetvol.md (generated grid mesh, 8 workers).
set -e
BUILD=${BUILD:-build-tetrender}
ninja -C "$BUILD"
"$BUILD"/sample_game/volfx-bench tetvol --grid "${GRID:-24}" --size "${SIZE:-150}" --workers 8
