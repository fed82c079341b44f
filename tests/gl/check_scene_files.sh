#!/bin/sh
# check_scene_files.sh GAME — issue 18: files a scene names (volume.path, a water particle file,
# meshes[].path) that are FIFOs, directories or devices. Each is refused (volume, water: exit 1
# naming the file and what it is) or skipped with a warning (a mesh, as a missing one is),
# never opened: opening a FIFO for reading blocked the game forever. Every run is bounded by
# timeout, so a hang fails the test.
game=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
mkfifo "$dir/v.vtu" "$dir/t.node" "$dir/p.bin" "$dir/m.obj"
mkdir "$dir/d.vtu"
: > "$dir/e.bin"
ln -s /dev/zero "$dir/z.node"
printf 'not a tet' > "$dir/z.ele"
cp "$dir/z.ele" "$dir/t.ele"
fail=0
run() { # run RC NEEDLE JSON
  printf '%s' "$3" > "$dir/s.json"
  out=$(timeout 60 "$game" --headless --frames 1 --size 16x16 --scene "$dir/s.json" 2>&1); rc=$?
  if [ "$rc" != "$1" ] || ! printf '%s' "$out" | grep -qF -- "$2"; then
    echo "FAIL: $3 -> rc $rc (want $1), output lacks '$2':"; printf '%s\n' "$out" | tail -4; fail=1
  else
    echo "ok: rc $rc: $(printf '%s' "$out" | grep -F -- "$2" | head -1)"
  fi
}
run 1 "v.vtu: is a FIFO" '{"volume":{"path":"v.vtu"}}'
run 1 "t.node: is a FIFO" '{"volume":{"path":"t.node"}}'
run 1 "d.vtu: is a directory" '{"volume":{"path":"d.vtu"}}'
run 1 "z.node: is a character device" '{"volume":{"path":"z.node"}}'
run 1 "p.bin: is a FIFO" '{"water":{"source":"file","path":"p.bin"}}'
run 0 "e.bin: the file holds no particles (0 bytes); no water is drawn" '{"water":{"source":"file","path":"e.bin"}}'
run 0 "m.obj: is a FIFO (named pipe), not a regular file, skipped" '{"meshes":[{"path":"m.obj"}]}'
exit $fail
