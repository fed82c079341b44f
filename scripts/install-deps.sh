#!/usr/bin/env bash
# Installs what volfx needs on Debian 12, idempotently: packages already present are not
# fetched again, and apt-get update runs only when something is missing.
# Usage: scripts/install-deps.sh [extra-package ...]
set -euo pipefail
# python3: the shader/scene embedders, tests/gl/check_bench_dump.sh, scripts/testlog-count.py and
# scripts/make-tet-mesh.sh call it directly (meson pulls it in too). Checked on a debootstrap
# minbase bookworm by scripts/check-fresh-debian.sh (docs/robustness-testing.md, "Fresh machine").
pkgs=(
  build-essential meson ninja-build pkg-config python3
  libglfw3-dev libepoxy-dev libegl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri
  libcglm-dev libassimp-dev libcjson-dev zlib1g-dev libexpat1-dev libcmocka-dev
  libopenmpi-dev openmpi-bin
  assimp-testmodels tetgen
  xvfb xauth
  libsdl2-dev          # tests/integration/sdl_host.c, the second host
  libogre-1.12-dev     # tests/integration/ogre_host.cpp: an OGRE 1.12 application (GL3Plus on GLX: xvfb above)
  khronos-api          # gl.xml: the plugin's GL loader is generated from it (plugin/gpu/gen_gl.py)
  glslang-tools        # glslangValidator: every shader variant validated at build time
  libvulkan-dev mesa-vulkan-drivers glslc vulkan-validationlayers  # tests/integration/vulkan_host.c: Vulkan (lavapipe), its SPIR-V, validation
  cmake                # tests/integration/check_cmake_package.sh: find_package(volfx CONFIG)
  python3-matplotlib   # scripts/bench-water.sh plots with /usr/bin/python3
  clang libclang-rt-14-dev  # scripts/fuzz.sh (CI's third step): libFuzzer and the sanitizer runtimes
  "$@"
)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#pkgs[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then SUDO=sudo; else SUDO=; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
