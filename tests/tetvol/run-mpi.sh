#!/bin/sh
# run-mpi.sh NP EXE [ARGS...] — runs an MPI test under mpirun with NP ranks (oversubscribed: CI
# machines have 2 cores). Exits 77 (meson's skip) when the MPI backend was not built (EXE is
# "none") or mpirun is missing. Under AddressSanitizer, leak checking is off (see below).
np=$1; exe=$2; shift 2
[ "$exe" = none ] && { echo "MPI backend not built (-Dmpi=disabled or no Open MPI)"; exit 77; }
command -v mpirun >/dev/null 2>&1 || { echo "mpirun not found"; exit 77; }
# running as root (containers, CI) needs Open MPI's explicit consent
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
if [ -n "${ASAN_OPTIONS:-}" ] || [ -n "${LSAN_OPTIONS:-}" ]; then
  # Under ASan: memory errors and UBSan stay on, leak checking is off for these tests. Open
  # MPI 4 dlcloses the components it does not keep (during MPI_Init and MPI_Finalize), and
  # their process-lifetime allocations then show as "<unknown module>", which no suppression
  # can name (tried: by library name, and a leak check before MPI_Finalize).
  export ASAN_OPTIONS="${ASAN_OPTIONS}:detect_leaks=0"
fi
exec mpirun --oversubscribe -np "$np" "$exe" "$@"
