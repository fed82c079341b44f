#!/bin/sh
# bench-tetvol-mpi.sh [OUT.jsonl] — the figures of docs/tetvol-mpi.md: volfx-tetvol-mpi on the
# pipe mesh (|Velocity|) for 1, 2, 4 and 8 ranks (oversubscribed: the bench machine has 2
# cores), every configuration (base, dlb, ert, ert_share, ert_dlb, ert_share_dlb), median of
# REPEAT renders; then the table (scripts/tetvol-mpi-table.py). Falls back to a generated grid
# when the pipe mesh is absent. Env: BUILD, VIEW (Z|A|B), TAU, SIZE, REPEAT, NPS, MPIRUN_ARGS
# (default "--mca mpi_yield_when_idle 0": Open MPI otherwise yields the core at every test when
# oversubscribed, see docs/tetvol-mpi.md; MPIRUN_ARGS= gives Open MPI's default).
set -eu
cd "$(dirname "$0")/.."
BUILD=${BUILD:-${VFX_BUILD_DIR:-build}}
out=${1:-$BUILD/bench-tetvol-mpi.jsonl}
ninja -C "$BUILD" bench/volfx-tetvol-mpi
pipe=${VFX_SHARED_DATA:-../shared/data}/tets/pipe_RCR_init_flow.vtu
if [ -f "$pipe" ]; then mesh="--vtu $pipe --field Velocity"; else mesh="--grid 40"; fi
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
: > "$out"
for np in ${NPS:-1 2 4 8}; do
  # shellcheck disable=SC2086
  mpirun --oversubscribe ${MPIRUN_ARGS---mca mpi_yield_when_idle 0} -np "$np" "$BUILD/bench/volfx-tetvol-mpi" \
    $mesh --size "${SIZE:-300}" --view "${VIEW:-Z}" --tau "${TAU:-200}" --repeat "${REPEAT:-3}" \
    >> "$out"
done
python3 scripts/tetvol-mpi-table.py "$out"
