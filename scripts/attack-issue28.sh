#!/usr/bin/env bash
# A small fresh attack of issue 28's kind: ~60 bad inputs (mesh files, scene values at and past
# their documented ranges, command-line outputs and numbers) through volfx-game and volfx-bench,
# each bounded in time (60 s) and watched for peak RSS. A case fails when the program dies of a
# signal, runs out of time, peaks above 2 GiB, or when its exit disagrees with what the case
# expects: "refuse" (exit 1 or 2 with a message naming KEY), "skip" (exit 0 with a warning naming
# KEY: a mesh file that is missing or not a regular file is left out, as docs/robustness.md says),
# "draw" (exit 0, no error line, no pixel left undecided).
# usage: scripts/attack-issue28.sh [BUILD_DIR] ; prints one line a case and a summary, exits 1
# when any case failed. Not a CI test (about 4 minutes on llvmpipe); the classes it covers are
# tests already (docs/robustness.md).
set -u
cd "$(dirname "$0")/.."
build=${1:-build}
game=$build/sample_game/volfx-game
bench=$build/bench/volfx-bench
[ -x "$game" ] && [ -x "$bench" ] || { echo "build $build first (ninja -C $build)"; exit 2; }
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
pass=0; fail=0

# run NAME EXPECT KEY CMD...: EXPECT refuse|skip|draw; KEY a text the message must contain
run() {
    local name=$1 expect=$2 key=$3; shift 3
    local out=$dir/out.txt
    /usr/bin/time -f "%M" -o "$dir/rss" timeout -k 5 60 "$@" >"$out" 2>&1
    local rc=$? rss why=""
    rss=$(tail -1 "$dir/rss" 2>/dev/null | grep -o '^[0-9]*'); rss=${rss:-0}
    if [ $rc -eq 124 ] || [ $rc -eq 137 ]; then why="hang (60 s)"
    elif [ $rc -gt 128 ]; then why="signal $((rc - 128))"
    elif [ "$rss" -gt 2097152 ]; then why="peak RSS $((rss / 1024)) MiB"
    elif [ "$expect" = refuse ] && { [ $rc -eq 0 ] || ! grep -qF -- "$key" "$out"; }; then why="not refused naming '$key' (exit $rc)"
    elif [ "$expect" = skip ] && { [ $rc -ne 0 ] || ! grep -qF -- "$key" "$out"; }; then why="not skipped naming '$key' (exit $rc)"
    elif [ "$expect" = draw ] && { [ $rc -ne 0 ] || grep -q '\[volfx error\]' "$out"; }; then why="did not draw (exit $rc)"
    elif [ "$expect" = draw ] && grep -q 'undecided (not drawn)' "$out"; then why="drawn with pixels left undecided"
    fi
    local msg
    msg=$(grep -E 'error|refus|warn|not |outside|must|cannot|claims|is a ' "$out" | tail -1 | cut -c1-150)
    if [ -z "$why" ]; then pass=$((pass + 1)); printf 'ok    %-28s exit %d, %5d MiB: %s\n' "$name" $rc $((rss / 1024)) "$msg"
    else fail=$((fail + 1)); printf 'FAIL  %-28s %s: %s\n' "$name" "$why" "$(tail -2 "$out" | tr '\n' ' ' | cut -c1-200)"; fi
}

# the base scene: a floor, 1,000 water particles (TILE), one beam; tiny frames
scene() { # scene NAME PYTHON-EXPRESSION-ON-s
    python3 - "$dir/$1.json" "$2" <<'EOF'
import json, sys
s = {"version": 1, "camera": {"eye": [0, 1.5, 4], "target": [0, 0.3, 0], "fov_y_deg": 50, "width": 32, "height": 24},
     "meshes": [{"box": {"min": [-3, -0.2, -3], "max": [3, 0, 3]}}],
     "water": {"source": "generator", "generator": {"kind": "layers", "count": 1000, "origin": [-0.5, 0.05, -0.5],
               "spacing": 0.1, "layer_side": 10}, "quality": {"method": "tile"}},
     "beam_settings": {"c": 1.0},
     "beams": [{"head": [-1, 1, 0], "dir": [1, 0, 0], "length": 2, "radius": 0.4}]}
exec(sys.argv[2])
json.dump(s, open(sys.argv[1], "w"))
EOF
    echo "$dir/$1.json"
}
g() { run "$1" "$2" "$3" "$game" --headless --frames 2 --size 32x24 --png "$dir/o.png" --scene "$4"; }

# --- mesh files (meshes[0].path): a bad mesh is skipped with a warning naming it, the game draws on
mesh() { # mesh NAME FILE EXPECT-TEXT [EXPECT]: the message must name the file's problem
    local sc
    sc=$(scene "mesh-$1" "s['meshes'].append({'path': '$2'})")
    run "mesh-$1" "${4:-refuse}" "$3" "$game" --headless --frames 1 --size 32x24 --png "$dir/o.png" --scene "$sc"
}
printf 'ply\nformat binary_little_endian 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\nend_header\n0123456789012345678' >"$dir/trunc.ply"
printf 'ply\nformat binary_little_endian 1.0\nelement vertex 2000000000\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\0\0\0\0' >"$dir/huge.ply"
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 nan\n0 1 0\n3 0 1 2\n' >"$dir/nan.ply"
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n' >"$dir/badidx.ply"
python3 -c "import struct,sys; sys.stdout.buffer.write(b'glTF'+struct.pack('<II',2,0xFFFFFFF0)+struct.pack('<II',0xFFFFFFE0,0x4E4F534A)+b'{}')" >"$dir/huge.glb"
python3 -c "import struct,sys; sys.stdout.buffer.write(b'\0'*80+struct.pack('<I',2**31+1)+b'\0'*50)" >"$dir/wrap.stl"
printf 'solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0\n' >"$dir/trunc-ascii.stl"
printf '{"asset":{"version":"2.0"},"buffers":[{"uri":"/dev/zero","byteLength":4000000000}],"meshes":[]}' >"$dir/zero.gltf"
printf '{"asset":{"version":"2.0"},"buffers":[{"uri":"data:application/octet-stream;base64,AAAA","byteLength":4000000000}],"bufferViews":[{"buffer":0,"byteLength":4000000000}],"accessors":[{"bufferView":0,"componentType":5126,"count":333333333,"type":"VEC3"}],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}]}' >"$dir/lie.gltf"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999\n' >"$dir/badidx.obj"
printf 'v 1e39 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$dir/inf.obj"
: >"$dir/empty.obj"
head -c 4096 /dev/urandom >"$dir/noise.ply"
cp "$dir/trunc.ply" "$dir/mesh.fbx"
mkdir "$dir/adir.obj"; mkfifo "$dir/fifo.obj"
mesh trunc-ply "$dir/trunc.ply" "trunc.ply"
mesh ply-2e9-vertices "$dir/huge.ply" "2000000000"
mesh ply-nan-vertex "$dir/nan.ply" "nan.ply"
mesh ply-bad-index "$dir/badidx.ply" "badidx.ply"
mesh glb-4gb-chunk "$dir/huge.glb" "huge.glb"
mesh stl-count-wrap "$dir/wrap.stl" "2147483649"
mesh stl-ascii-truncated "$dir/trunc-ascii.stl" "trunc-ascii.stl"
mesh gltf-dev-zero-buffer "$dir/zero.gltf" "zero.gltf"
mesh gltf-lying-accessor "$dir/lie.gltf" "lie.gltf"
mesh obj-bad-index "$dir/badidx.obj" "badidx.obj"
mesh obj-inf-vertex "$dir/inf.obj" "inf.obj"
mesh obj-empty "$dir/empty.obj" "empty.obj"
mesh ply-random-bytes "$dir/noise.ply" "noise.ply"
mesh fbx-disabled "$dir/mesh.fbx" "not a mesh format"
mesh directory "$dir/adir.obj" "is a directory" skip
mesh fifo "$dir/fifo.obj" "FIFO" skip
mesh missing "$dir/none.obj" "none.obj" skip

# --- scene values past their documented range: refused naming the key
bad() { g "$1" refuse "$2" "$(scene "$1" "$3")"; }
bad step-1e-4 step "s['water']['quality']['step'] = 1e-4"
bad step-5 step "s['water']['quality']['step'] = 5"
bad refine-65 refine_iters "s['water']['quality']['refine_iters'] = 65"
bad max-samples-4097 max_samples "s['water']['quality']['max_samples'] = 4097"
bad h-negative water.h "s['water']['h'] = -1"
bad threshold-zero threshold "s['water']['threshold'] = 0"
bad ior-3.5 ior "s['water']['ior'] = 3.5"
bad color-2 color "s['water']['color'] = [2, 0, 0]"
bad absorption-1e4 absorption "s['water']['absorption'] = 1e4"
bad method-bogus method "s['water']['quality']['method'] = 'bogus'"
bad exposure-65 exposure "s['beams'][0]['exposure'] = 65"
bad radius-0 radius "s['beams'][0]['radius'] = 0"
bad radius-1e7 radius "s['beams'][0]['radius'] = 1e7"
bad intensity-neg intensity "s['beams'][0]['intensity'] = -1"
bad beam-color-nan color "s['beams'][0]['color'] = [1, 1, 1e999, 1]"
bad c-zero beam_settings.c "s['beam_settings']['c'] = 0"
bad march-4097 march_samples "s['beam_settings']['march_samples'] = 4097"
bad bloom-levels-9 bloom_levels "s['beam_settings']['bloom_levels'] = 9"
bad particles-5e6 count "s['water']['generator']['count'] = 5000000"
bad workers-257 workers "s['volume'] = {'generator': {'cells': 2, 'min': [0, 0, 0], 'max': [1, 1, 1]}, 'workers': 257}"
bad tiles-1025 tiles "s['volume'] = {'generator': {'cells': 2, 'min': [0, 0, 0], 'max': [1, 1, 1]}, 'tiles': 1025}"
bad ert-1.5 ert_threshold "s['volume'] = {'generator': {'cells': 2, 'min': [0, 0, 0], 'max': [1, 1, 1]}, 'ert_threshold': 1.5}"

# --- scene values at the documented edges: drawn
ok() { g "$1" draw "" "$(scene "$1" "$2")"; }
ok exposure-64 "s['beams'][0]['exposure'] = 64"
ok exposure-minus-64 "s['beams'][0]['exposure'] = -64"
ok c-1e-30 "s['beam_settings']['c'] = 1e-30"
ok c-1e6 "s['beam_settings']['c'] = 1e6"
ok refine-64 "s['water']['quality']['refine_iters'] = 64"
ok step-h "s['water']['h'] = 0.2; s['water']['quality']['step'] = 0.2"
ok step-h-over-1024-iso "s['water']['h'] = 0.2; s['water']['quality']['step'] = 0.2 / 1024; s['water']['quality']['kernel'] = 'isotropic'"
ok step-h-over-256-aniso "s['water']['h'] = 0.2; s['water']['quality']['step'] = 0.2 / 256"
# open (2026-12-03): the anisotropic kernel (TILE's default) below h/256 spends llvmpipe's loop
# budget on most water pixels (48 undecided, warned, at h/1024; 8 at h/512; 0 at h/256)
ok step-h-over-1024-aniso "s['water']['h'] = 0.2; s['water']['quality']['step'] = 0.2 / 1024"
ok workers-256 "s['volume'] = {'generator': {'cells': 2, 'min': [0, 0, 0], 'max': [1, 1, 1]}, 'workers': 256}"
ok spacing-1e-6 "s['water']['generator']['spacing'] = 1e-6"
bad spacing-0 spacing "s['water']['generator']['spacing'] = 0"

# --- command line and outputs
mkfifo "$dir/out.fifo"; mkdir "$dir/outdir"
sc=$(scene base "pass")
run csv-fifo refuse "FIFO" "$game" --headless --frames 1 --size 16x16 --scene "$sc" --csv "$dir/out.fifo"
run trace-dir refuse "directory" "$game" --headless --frames 1 --size 16x16 --scene "$sc" --trace "$dir/outdir"
run png-dev-full refuse "device" "$game" --headless --frames 1 --size 16x16 --scene "$sc" --png /dev/full
run dump-raw-fifo refuse "FIFO" "$game" --headless --frames 1 --size 16x16 --scene "$sc" --dump-raw water "$dir/out.fifo"
run size-0 refuse "--size" "$game" --headless --frames 1 --size 0x0 --scene "$sc"
run size-16385 refuse "--size" "$game" --headless --frames 1 --size 16385x16 --scene "$sc"
run frames-negative refuse "--frames" "$game" --headless --frames -1 --scene "$sc"
run plugin-empty refuse "plugin path is empty" "$game" --headless --frames 1 --size 16x16 --scene "$sc" --plugin ""
run plugin-dev-zero refuse "/dev/zero" "$game" --headless --frames 1 --size 16x16 --scene "$sc" --plugin /dev/zero
run scene-fifo refuse "FIFO" "$game" --headless --frames 1 --size 16x16 --scene "$dir/out.fifo"
run scene-directory refuse "directory" "$game" --headless --frames 1 --size 16x16 --scene "$dir/outdir"
run bench-frame-size refuse "--size" "$bench" frame --size 10
run bench-dump-fifo refuse "FIFO" "$bench" frame --frames 1 --size 16x16 --dump-raw beams "$dir/out.fifo"
run bench-tetvol-grid-0 refuse "--grid" "$bench" tetvol --grid 0
run bench-metaballs-method refuse "--method" "$bench" metaballs --method nope

renderer=$("$game" --headless --frames 1 --size 16x16 --png "$dir/o.png" --scene "$sc" 2>&1 | grep -m1 -o 'GL context: [^,]*')
echo "attack-issue28: $pass passed, $fail failed ($((pass + fail)) cases; $renderer)"
[ $fail -eq 0 ]
