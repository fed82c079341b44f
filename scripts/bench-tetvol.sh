#!/bin/sh
# Regenerates docs/benchmarks-tetvol.md: volfx-bench tetvol on the pipe mesh (|Velocity|) and on
# a generated >= 300k-tet mesh (scripts/make-tet-mesh.sh), both from the across and axis views
# (Table 1, ERT thresholds, D and C sweeps, Table 2), then scripts/compare-vtk.py against VTK's
# three unstructured-grid mappers when python3-vtk9 and xvfb-run are present.
# Usage: scripts/bench-tetvol.sh [build-dir]   (default $VFX_BUILD_DIR, else build)
# Env: REPS (5; runs per figure after one dropped warm-up), TORUS_REPS (3), PIPE (the .vtu),
#      REUSE=1 keeps JSON already in build-dir/bench-tetvol (to regenerate the doc only).
set -e
B=${1:-${VFX_BUILD_DIR:-build}}
OUT=$B/bench-tetvol
PIPE=${PIPE:-${VFX_SHARED_DATA:-../shared/data}/tets/pipe_RCR_init_flow.vtu}
REPS=${REPS:-5}
TORUS_REPS=${TORUS_REPS:-3}
ninja -C "$B" bench/volfx-bench >/dev/null
mkdir -p "$OUT"
[ -f "$B/tetmesh/torus.ele" ] || scripts/make-tet-mesh.sh "$B/tetmesh/torus" >/dev/null
{
    echo "date=$(date -u +%Y-%m-%dT%H:%MZ)"
    echo "cores=$(nproc)"
    echo "cpu=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
    echo "load_start=$(cut -d' ' -f1-3 /proc/loadavg)"
    echo "reps=$REPS torus_reps=$TORUS_REPS"
} > "$OUT/machine.txt"
run() {
    name=$1
    shift
    if [ -n "$REUSE" ] && [ -s "$OUT/$name.jsonl" ]; then return 0; fi
    "$@" > "$OUT/$name.jsonl.tmp"
    mv "$OUT/$name.jsonl.tmp" "$OUT/$name.jsonl"
}
BENCH=$B/bench/volfx-bench
HAVE_VTK=
if command -v xvfb-run >/dev/null && /usr/bin/python3 -c 'import vtk, numpy' 2>/dev/null; then
    HAVE_VTK=1
fi
# two streams at once (one per core): the pipe, then the generated mesh (partial-off C sweep to
# C = 10 only: at 400k tets each point takes minutes), each followed by its VTK comparison
(
    run pipe "$BENCH" tetvol --mesh "$PIPE" --reps "$REPS" --json
    # an opaque transfer function (4x the extinction): where ERT has something to terminate
    run pipe_opaque "$BENCH" tetvol --mesh "$PIPE" --tau 16 --view axis --only table1,ert,D \
        --reps "$REPS" --json
    [ -z "$HAVE_VTK" ] || run vtk_pipe xvfb-run -a -s '-screen 0 640x480x24' /usr/bin/python3 \
        scripts/compare-vtk.py --bench "$BENCH" --mesh "$PIPE" --reps "$REPS" --truth-steps 400 \
        --tmp "$OUT/vtk_pipe"
) &
(
    run torus "$BENCH" tetvol --mesh "$B/tetmesh/torus" --reps "$TORUS_REPS" --c-nopartial-max 10 --json
    [ -z "$HAVE_VTK" ] || run vtk_torus xvfb-run -a -s '-screen 0 640x480x24' /usr/bin/python3 \
        scripts/compare-vtk.py --bench "$BENCH" --mesh "$B/tetmesh/torus" --reps "$TORUS_REPS" \
        --truth-steps 300 --tmp "$OUT/vtk_torus"
) &
wait
echo "load_end=$(cut -d' ' -f1-3 /proc/loadavg)" >> "$OUT/machine.txt"
/usr/bin/python3 scripts/bench-tetvol-md.py "$OUT" > docs/benchmarks-tetvol.md
echo "wrote docs/benchmarks-tetvol.md from $OUT"
