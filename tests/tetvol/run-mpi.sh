#!/bin/sh
# run-mpi.sh NP EXE [ARGS...] — runs an MPI test under mpirun with NP ranks (oversubscribed: CI
# machines have 2 cores). Exits 77 (meson's skip) when the MPI backend was not built (EXE is
# "none") or mpirun is missing. Under AddressSanitizer, Open MPI's own process-lifetime
# allocations are suppressed by name (tests/lsan-mpi.supp, Open MPI libraries only).
np=$1; exe=$2; shift 2
[ "$exe" = none ] && { echo "MPI backend not built (-Dmpi=disabled or no Open MPI)"; exit 77; }
command -v mpirun >/dev/null 2>&1 || { echo "mpirun not found"; exit 77; }
# running as root (containers, CI) needs Open MPI's explicit consent
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
here=$(cd "$(dirname "$0")" && pwd)
if [ -n "${ASAN_OPTIONS:-}" ] || [ -n "${LSAN_OPTIONS:-}" ]; then
  export LSAN_OPTIONS="suppressions=$here/../lsan-mpi.supp:print_suppressions=0"
fi
exec mpirun --oversubscribe -np "$np" "$exe" "$@"
