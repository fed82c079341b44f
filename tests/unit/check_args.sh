#!/bin/sh
# check_args.sh GAME BENCH MPI_EXE — issue 18, defect 10: bad command-line values are refused
# before any frame (exit 2 and a message naming the option), never wrapped around, never found
# out after a whole run; a flat mesh is an error of volfx-bench tetvol, not "inf" in its JSON;
# an unknown --modes entry of volfx-tetvol-mpi is an error. Each run is bounded by timeout: a
# command that runs on (--frames -5 ran forever) fails the test.
game=$1; bench=$2; mpi=$3
fail=0
expect() { # expect RC NEEDLE CMD...
  want=$1; needle=$2; shift 2
  out=$(timeout 60 "$@" 2>&1); rc=$?
  if [ "$rc" != "$want" ] || ! printf '%s' "$out" | grep -qF -- "$needle"; then
    echo "FAIL: $* -> rc $rc (want $want), output lacks '$needle':"; printf '%s\n' "$out" | tail -5
    fail=1
  else
    echo "ok: $* -> rc $rc: $(printf '%s' "$out" | grep -F -- "$needle" | head -1)"
  fi
}
expect 2 "--frames wants a whole number" "$game" --headless --frames -5
expect 2 "--frames wants a whole number" "$game" --headless --frames 12abc
expect 2 "--frames wants a whole number" "$game" --headless --frames 99999999999
expect 2 "--seconds wants a number" "$game" --headless --seconds nan
expect 2 "--size wants WxH" "$game" --headless --size -5x3
expect 2 "--size wants WxH" "$game" --headless --size 64x0
expect 2 "--mem-every wants a whole number" "$game" --headless --mem-every -1
expect 2 "--dump-raw wants water, beams or volume, got 'foo'" "$game" --headless --dump-raw foo x.pfm
expect 2 "cannot create /nonexistent-dir/x.pfm" "$game" --headless --dump-raw beams /nonexistent-dir/x.pfm
expect 2 "with --no-beams: nothing to dump" "$game" --headless --no-beams --dump-raw beams x.pfm
expect 2 "--png: / is a directory" "$game" --headless --png /
expect 2 "--frames wants a whole number" "$bench" frame --frames -5
expect 2 "--size wants WxH" "$bench" frame --size 10
expect 2 "cannot create /nonexistent-dir/x.pfm" "$bench" frame --dump-raw beams /nonexistent-dir/x.pfm
expect 2 "--grid wants a whole number in 1..200, got '-3'" "$bench" tetvol --grid -3
expect 2 "--tau wants a number" "$bench" tetvol --tau inf
dir=$(mktemp -d)
# issue 28: an output naming a FIFO with no reader blocked forever at start, saying nothing
mkfifo "$dir/out.fifo"
for opt in --csv --trace --png; do
  expect 2 "$opt: $dir/out.fifo is a FIFO (named pipe); an output must be a regular file or /dev/null" \
    "$game" --headless --frames 1 --size 16x16 $opt "$dir/out.fifo"
done
expect 2 "--dump-raw: $dir/out.fifo is a FIFO" "$game" --headless --frames 1 --dump-raw beams "$dir/out.fifo"
expect 2 "--dump-raw: $dir/out.fifo is a FIFO" "$bench" frame --frames 1 --dump-raw beams "$dir/out.fifo"
expect 2 "--png: /dev/zero is a character device" "$game" --headless --frames 1 --png /dev/zero
printf '4 3 1 0\n0 0 0 0 1\n1 1 0 0 2\n2 0 1 0 3\n3 1 1 0 4\n' > "$dir/flat.node"
printf '1 4 0\n0 0 1 2 3\n' > "$dir/flat.ele"
expect 1 "is flat (extent 0 along z)" "$bench" tetvol --mesh "$dir/flat.node" --size 8 --reps 1
if timeout 60 "$bench" tetvol --mesh "$dir/flat.node" --size 8 --reps 1 2>/dev/null | grep -qi 'inf\|nan'; then
  echo "FAIL: inf or nan in the JSON of a flat mesh"; fail=1
fi
rm -rf "$dir"
if [ "$mpi" != none ] && command -v mpirun >/dev/null 2>&1; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
  # as tests/tetvol/run-mpi.sh: Open MPI's own allocations show as leaks under ASan
  [ -n "${ASAN_OPTIONS:-}" ] && export ASAN_OPTIONS="${ASAN_OPTIONS}:detect_leaks=0"
  expect 2 "--modes: unknown mode 'bogus'" mpirun --oversubscribe -np 1 "$mpi" --modes ert,bogus --grid 4 --size 16
  expect 2 "--grid wants a whole number" mpirun --oversubscribe -np 1 "$mpi" --grid 0
fi
exit $fail
