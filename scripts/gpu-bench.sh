#!/usr/bin/env bash
# One command on a machine with an NVIDIA GPU: unpack the carried GL/EGL debs, build (or take the
# carried build), run the GL tests on the EGL device platform, and write every GPU table as JSON
# within a time budget (default 480 s for the tables):
#   water Table 1 (4,096 / 16,384 / 65,536 particles at 128^2 / 256^2 / 512^2, and 262,144 and
#   1,048,576 at 1920x1080), every water method at 1920x1080 and against the float64 reference,
#   beams 100 and 1,000 at 1920x1080, the default scene at 1920x1080; the fluid solver on the CPU
#   and the GPU side by side (16,384 / 65,536 / 262,144 particles, volfx-bench sim --device gpu),
#   and 1,048,576 particles simulated on the GPU and drawn as water at 1920x1080 in one frame.
# On llvmpipe the test suite runs it with --small (tiny sizes, two GL tests), so it cannot rot.
#
# Usage:
#   scripts/gpu-bench.sh --prepare            on the Debian build machine: fetch the GL debs into
#                                             .gl/, build build-gpu (release), bundle its programs,
#                                             the shared libraries they need and the shared data
#                                             into .gl/bundle (the GPU machine has no -dev packages)
#   scripts/gpu-bench.sh [--out DIR]          on the GPU machine (device tool: carry [".gl"],
#                                             --out "$OUT"); also on any NVIDIA box with the
#                                             project's packages installed (then it builds)
#   options: --small (tiny sizes), --build DIR (default build-gpu), --no-build (use DIR as it is),
#            --budget S (seconds for the tables, default 480); VFX_GPU_BENCH_BUNDLE=1 takes the
#            carried bundle even where the packages are present (to try the bundle here)
# Output in DIR (default /tmp/volfx-gpu-bench): gpu.json (renderer, driver, machine), tests.json,
# water-table1.json, water-methods.json, beams-1080p.json, default-scene-1080p.json (each: command
# lines, rows as the benches print them, configurations that ran out of time), gpu-bench.log and
# benchmarks-gpu.md (scripts/gpu-bench-md.py): copy it to docs/benchmarks-gpu.md, then
# scripts/run-benchmarks.sh --index-only lists it in docs/benchmarks.md ("Figures by area").
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
small=0 prepare=0 nobuild=0 out=/tmp/volfx-gpu-bench build=build-gpu budget=480
while [ $# -gt 0 ]; do
  case $1 in
    --small) small=1 ;;
    --prepare) prepare=1 ;;
    --no-build) nobuild=1 ;;
    --out) out=$2; shift ;;
    --build) build=$2; shift ;;
    --budget) budget=$2; shift ;;
    *) echo "gpu-bench: unknown option $1 (see the header of $0)" >&2; exit 2 ;;
  esac
  shift
done
bundle=$root/.gl/bundle

if [ $prepare = 1 ]; then
  # The recipe of the device tool's README: vendor-neutral GL/EGL loaders as amd64 debs.
  mkdir -p .gl
  grep -qx '/.gl/' .git/info/exclude 2>/dev/null || echo /.gl/ >> "$(git rev-parse --git-path info/exclude)"
  if ! ls .gl/*.deb >/dev/null 2>&1; then
    mkdir -p /tmp/amd64/partial
    o=(-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64)
    apt-get "${o[@]}" update -qq
    (cd .gl && apt-get "${o[@]}" download libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
  fi
  [ -f "$build/build.ninja" ] || meson setup "$build" --buildtype=release >/dev/null
  ninja -C "$build" >/dev/null
  rm -rf "$bundle"
  mkdir -p "$bundle/lib" "$bundle/build"
  # every program and library of the build, at the same place under bundle/build
  (cd "$build" && find . -type f \( -executable -o -name '*.so*' \) ! -path '*/meson-*' ! -path '*.p/*' \
      -exec sh -c 'file -b "$1" | grep -q ELF' _ {} \; -print) | while read -r f; do
    mkdir -p "$bundle/build/$(dirname "$f")"; cp -a "$build/$f" "$bundle/build/$f"
  done
  (cd "$build/plugin" && cp -a libvolfx.so* "$bundle/build/plugin/")
  # their shared libraries, less what every Linux has and the GL loaders (from the debs/driver)
  find "$bundle/build" -type f -exec sh -c 'file -b "$1" | grep -q ELF' _ {} \; -print | xargs ldd 2>/dev/null \
    | awk '/=> \//{print $3}' | sort -u \
    | grep -v -E '/(libc|libm|libdl|libpthread|librt|ld-linux[^/]*|libgcc_s|libstdc\+\+|libEGL[^/]*|libGL[^/]*|libGLX[^/]*|libOpenGL|libGLdispatch|libvolfx)\.so' \
    | while read -r l; do cp -L "$l" "$bundle/lib/"; done
  meson introspect --tests "$build" > "$bundle/tests.json"
  printf '{"build":"%s","source":"%s","shared_data":"%s"}\n' "$(cd "$build" && pwd)" "$root" \
    "$(cd "$root/../shared/data" 2>/dev/null && pwd || echo "")" > "$bundle/paths.json"
  [ -d ../shared/data ] && cp -r ../shared/data "$bundle/data"
  echo "gpu-bench: .gl holds $(ls .gl/*.deb | wc -l) debs and a bundle of $(du -sh "$bundle" | cut -f1);" \
       "on the GPU machine: carry [\".gl\"], run scripts/gpu-bench.sh --out \$OUT"
  exit 0
fi

mkdir -p "$out"
log=$out/gpu-bench.log
: > "$log"
say() { echo "gpu-bench: $*" | tee -a "$log" >&2; }
t_start=$(date +%s)

# 1. GL/EGL loaders from the carried debs, on the GPU machine only (they go into /).
nvidia=0
{ command -v nvidia-smi >/dev/null 2>&1 || [ -d /usr/local/nvidia ]; } && nvidia=1
if [ $nvidia = 1 ] && [ "$(id -u)" = 0 ] && ls .gl/*.deb >/dev/null 2>&1; then
  for f in .gl/*.deb; do dpkg -x "$f" /; done
  ldconfig
  say "unpacked $(ls .gl/*.deb | wc -l) GL/EGL debs"
fi
if [ $nvidia = 1 ]; then
  vendor=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
  [ -f $vendor ] && export __EGL_VENDOR_LIBRARY_FILENAMES=$vendor
  nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader >> "$log" 2>&1 || true
fi

# 2. Programs: build here when the project's packages are present, else the carried bundle.
bin=$root/$build
case $build in /*) bin=$build ;; esac
tests_json=
have_deps() { command -v meson >/dev/null && command -v pkg-config >/dev/null \
              && pkg-config --exists epoxy glfw3 cglm assimp libcjson cmocka expat zlib; }
if [ $nobuild = 1 ]; then
  say "using $bin as it is"
elif [ "${VFX_GPU_BENCH_BUNDLE:-0}" != 1 ] && have_deps; then
  [ -f "$bin/build.ninja" ] || meson setup "$bin" --buildtype=release >> "$log"
  ninja -C "$bin" >> "$log"
  say "built $bin"
elif [ -d "$bundle/build" ]; then
  bin=$bundle/build
  export LD_LIBRARY_PATH="$bundle/lib:$bundle/build/plugin${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  tests_json=$bundle/tests.json
  say "no -dev packages here: using the carried bundle (.gl/bundle, made by --prepare)"
else
  say "neither the project's packages nor a carried bundle: run scripts/gpu-bench.sh --prepare first"
  exit 1
fi
if [ -z "$tests_json" ]; then
  tests_json=$out/.tests.json
  meson introspect --tests "$bin" > "$tests_json"
fi
export VFX_EGL_PLATFORM=device EGL_LOG_LEVEL=fatal

# 3. The GL tests (every test of the GL suites that needs no X server, MPI launcher or install),
#    on the EGL device platform; --small runs two of them.
if [ $small = 1 ]; then only=minimal_host_linked,gl_missing_version; else only=; fi
only=${VFX_GPU_BENCH_TESTS:-$only} # a comma list of test names instead
python3 - "$tests_json" "$bundle/paths.json" "$bin" "$root" "$out/tests.json" "$only" <<'PY' 2>&1 | tee -a "$log" || true
import json, os, subprocess, sys, time
tests, paths_file, bin_dir, root, out, only = sys.argv[1:7]
tests = json.load(open(tests))
old = json.load(open(paths_file)) if os.path.exists(paths_file) and "/.gl/bundle/" in bin_dir + "/" else None
def fix(s):  # the bundle's tests were introspected where they were built
    if old is None or not isinstance(s, str):
        return s
    s = s.replace(old["build"], bin_dir).replace(old["source"], root)
    if old.get("shared_data"):
        s = s.replace(old["shared_data"], os.path.join(os.path.dirname(bin_dir), "data"))
    return s
suites = {"volfx:gl", "volfx:water", "volfx:beams", "volfx:tetvol", "volfx:integration"}
skip = {"game_window": "needs an X server", "install_pkg_config": "needs meson install",
        "assimp_import": "needs assimp-testmodels"}
want = set(only.split(",")) if only else None
res = []
for t in tests:
    name = t["name"]
    if want is not None and name not in want:
        continue
    if not suites & set(t["suite"]):
        continue
    why = skip.get(name) or ("needs mpirun" if "mpi" in name else None)
    if why:
        res.append({"name": name, "result": "skipped", "why": why})
        continue
    env = dict(os.environ)
    env.update({k: fix(v) for k, v in (t.get("env") or {}).items()})
    if "VFX_SOURCE_ROOT" in env and old is not None:
        env["VFX_SOURCE_ROOT"] = root
    cmd = [fix(c) for c in t["cmd"]]
    if cmd[0].endswith("python3"):
        cmd[0] = sys.executable
    t0 = time.time()
    try:
        p = subprocess.run(cmd, cwd=fix(t.get("workdir")) or None, env=env, capture_output=True, text=True,
                           timeout=t.get("timeout") or 300)
        rc, tail = p.returncode, (p.stdout + p.stderr)[-2000:]
    except subprocess.TimeoutExpired:
        rc, tail = "timeout", ""
    except OSError as e:
        rc, tail = "cannot run", str(e)
    r = "ok" if rc == 0 else "skipped" if rc == 77 else "failed"
    res.append({"name": name, "result": r, "rc": rc, "seconds": round(time.time() - t0, 2),
                **({"output_tail": tail} if r != "ok" else {})})
    print("test %-24s %s (%.1f s)" % (name, r, time.time() - t0))
json.dump({"egl_platform": os.environ.get("VFX_EGL_PLATFORM"), "tests": res}, open(out, "w"), indent=1)
fails = [r["name"] for r in res if r["result"] == "failed"]
print("tests: %d ok, %d failed %s, %d skipped" % (sum(r["result"] == "ok" for r in res), len(fails), fails,
                                                  sum(r["result"] == "skipped" for r in res)))
PY

# 4. The tables, each command under what is left of the budget.
bench=$bin/bench/volfx-bench
deadline=$(( $(date +%s) + budget ))
tmp=$out/.rows
mkdir -p "$tmp"
# run TABLE CAP_S volfx-bench-args...: JSON lines into $tmp/TABLE.jsonl, the command into .cmds
run() {
  local table=$1 cap=$2; shift 2
  local left=$(( deadline - $(date +%s) ))
  [ $left -gt $cap ] && left=$cap
  echo "volfx-bench $*" >> "$tmp/$table.cmds"
  if [ $left -le 5 ]; then
    echo "volfx-bench $*" >> "$tmp/$table.late"; say "no time left for: $*"; return 0
  fi
  local t0; t0=$(date +%s)
  if ! timeout "$left" "$bench" "$@" >> "$tmp/$table.jsonl" 2>> "$log"; then
    echo "volfx-bench $*" >> "$tmp/$table.late"; say "ran out of time or failed after $(( $(date +%s) - t0 )) s: $*"
  fi
}
# pool_scene FILE N SETTLE: the default scene's tank and pool (paddle, method TILE) with N particles
# simulated on the GPU (water.simulation.device "gpu"), no beams or volume: simulation and water
pool_scene() {
  cat > "$1" <<JSON
{"version": 1, "name": "gpu-pool-$2",
 "camera": {"eye": [-0.7, 2.5, 3.2], "target": [0.7, 0.15, -0.9], "fov_y_deg": 55, "near": 0.05, "far": 100},
 "environment": {"sky": "dusk", "fog": 0.025},
 "meshes": [{"box": {"min": [-40, -0.2, -40], "max": [40, 0, 40]}, "color": [0.55, 0.5, 0.45]}],
 "water": {"source": "simulation", "simulation": {"tank": {"min": [-1.65, 0, -1.25], "max": [1.65, 1.4, 1.25]},
   "fluid": {"min": [-1.6, 0.02, -1.2], "max": [1.6, 0.34, 1.2]}, "particle_count": $2, "gravity": [0, -9.81, 0],
   "dt": 0.016666667, "solver": "pbf", "device": "gpu", "settle_steps": $3,
   "paddle": {"axis": "x", "amplitude": 0.25, "period_s": 2.5}},
  "threshold": 0.765625, "quality": {"method": "tile"}, "color": [0.15, 0.6, 0.65], "absorption": 3.0, "ior": 1.333}}
JSON
}
# The water methods the bench knows (its own error message lists them), so a new one is included.
methods=$("$bench" metaballs --method '?' 2>&1 | sed -n 's/.*--method \([a-z|_]*\),.*/\1/p' | tr '|' ' ' || true)
[ -n "$methods" ] || methods="paper brute grid"
F="--disable 64" # flat shading, as scripts/bench-water.sh: shading is not what is compared
if [ $small = 1 ]; then
  run water-table1 60 metaballs --method paper --particles 1024 --size 32 --frames 2 $F
  run water-table1 60 metaballs --method paper --particles 1024 --size 48 --height 27 --frames 2 $F
  for m in $methods; do run water-methods 60 metaballs --method "$m" --particles 1024 --size 48 --height 27 --frames 2 --reference $F; done
  run beams-1080p 60 beams --gpu --timing-only --sets 1,10 --size 64x36 --frames 2 --json
  run default-scene-1080p 60 frame --size 64x36 --frames 2 --json
  run sim-device 60 sim --device gpu --sizes 1024 --frames 2 --json
  pool_scene "$tmp/pool.json" 2048 5
  run sim-water-1m-1080p 60 frame --scene "$tmp/pool.json" --size 64x36 --frames 2 --json
else
  run water-table1 120 metaballs --method paper --particles 4096 --particles 16384 --particles 65536 \
      --size 128 --size 256 --size 512 --frames 8 $F
  run water-table1 90 metaballs --method paper --particles 262144 --size 1920 --height 1080 --frames 5 $F
  run water-table1 90 metaballs --method paper --particles 1048576 --size 1920 --height 1080 --frames 3 $F
  for m in $methods; do # same particles, camera and size for every method; then their error
    run water-methods 40 metaballs --method "$m" --particles 65536 --size 1920 --height 1080 --frames 5 $F
    run water-methods 30 metaballs --method "$m" --particles 4096 --size 256 --frames 3 --reference $F
  done
  run beams-1080p 60 beams --gpu --timing-only --sets 100,1000 --size 1920x1080 --frames 20 --json
  run default-scene-1080p 60 frame --size 1920x1080 --frames 30 --json
  # PBF at 5 iterations on the CPU (all cores) and in compute shaders, the same blocks, in turn
  run sim-device 240 sim --device gpu --sizes 16384,65536,262144 --frames 10 --threads 0 --json
  # 1,048,576 particles: settled (120 GPU steps before frame 0), then simulation + water each frame
  pool_scene "$tmp/pool.json" 1048576 120
  run sim-water-1m-1080p 240 frame --scene "$tmp/pool.json" --size 1920x1080 --frames 20 --json
fi

# 5. One JSON file per table, plus the machine.
rc=0
python3 - "$tmp" "$out" "$small" "$(( $(date +%s) - t_start ))" <<'PY' 2>&1 | tee -a "$log" || rc=1
import glob, json, os, platform, subprocess, sys
tmp, out, small, secs = sys.argv[1], sys.argv[2], sys.argv[3] == "1", int(sys.argv[4])
renderer = None
for table in ("water-table1", "water-methods", "beams-1080p", "default-scene-1080p", "sim-device",
              "sim-water-1m-1080p"):
    def lines(ext):
        p = os.path.join(tmp, table + ext)
        return [l.rstrip("\n") for l in open(p)] if os.path.exists(p) else []
    rows = []
    for l in lines(".jsonl"):
        if l.startswith("{"):
            try:
                rows.append(json.loads(l))
            except ValueError:
                pass
    renderer = renderer or next((r.get("gl_renderer") for r in rows if r.get("gl_renderer")), None)
    json.dump({"table": table, "small": small, "commands": lines(".cmds"), "not_finished": lines(".late"),
               "rows": rows}, open(os.path.join(out, table + ".json"), "w"), indent=1)
    print("%-20s %3d rows, %d not finished" % (table, len(rows), len(lines(".late"))))
smi = ""
try:
    smi = subprocess.run(["nvidia-smi", "--query-gpu=name,driver_version,memory.total", "--format=csv,noheader"],
                         capture_output=True, text=True, timeout=20).stdout.strip()
except (OSError, subprocess.SubprocessError):
    pass
json.dump({"gl_renderer": renderer, "nvidia_smi": smi, "cpu": platform.processor() or platform.machine(),
           "cores": os.cpu_count(), "egl_platform": os.environ.get("VFX_EGL_PLATFORM"), "seconds": secs},
          open(os.path.join(out, "gpu.json"), "w"), indent=1)
print("GL_RENDERER %s, %d s in all" % (renderer, secs))
# exit status: 1 when a GL test failed or a table has no row (the JSON is written either way)
tests = json.load(open(os.path.join(out, "tests.json"))) if os.path.exists(os.path.join(out, "tests.json")) else {"tests": []}
bad = [t["name"] for t in tests["tests"] if t["result"] == "failed"]
empty = [t for t in ("water-table1", "water-methods", "beams-1080p", "default-scene-1080p", "sim-device",
                     "sim-water-1m-1080p")
         if not json.load(open(os.path.join(out, t + ".json")))["rows"]]
if bad or empty or not tests["tests"]:
    print("gpu-bench: failed tests %s, tables without rows %s" % (bad, empty))
    sys.exit(1)
PY
python3 scripts/gpu-bench-md.py "$out" > "$out/benchmarks-gpu.md" || rc=1
rm -rf "$tmp" "$out/.tests.json"
exit $rc
