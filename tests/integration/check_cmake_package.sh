#!/bin/sh
# The CMake package of a meson install (DESTDIR): a tiny host (the minimal host's source) is
# configured with find_package(volfx 0.1 CONFIG REQUIRED) and nothing else of ours, built against
# volfx::volfx and run; a version of another major (1) must not be found.
# usage: check_cmake_package.sh BUILD_DIR SOURCE_DIR PREFIX LIBDIR [SANITIZE]
# Exits 77 when cmake is missing or no GL context can be made (the host says so).
set -eu
build=$1 src=$2 prefix=$3 libdir=$4 san=${5:-none}
command -v cmake >/dev/null 2>&1 || { echo "cmake absent (scripts/install-deps.sh installs it): skipping"; exit 77; }
san_flags=
[ "$san" = none ] || san_flags="-fsanitize=$san"
dest=$(mktemp -d "${TMPDIR:-/tmp}/volfx-cmake.XXXXXX")
trap 'rm -rf "$dest"' EXIT
fail() { echo "check_cmake_package: $*" >&2; exit 1; }

meson install -C "$build" --no-rebuild --quiet --destdir "$dest/root" >/dev/null
case $libdir in /*) lib=$dest/root$libdir ;; *) lib=$dest/root$prefix/$libdir ;; esac
for f in volfxConfig.cmake volfxConfigVersion.cmake volfxTargets.cmake; do
  [ -f "$lib/cmake/volfx/$f" ] || fail "not installed: $lib/cmake/volfx/$f"
done
[ -f "$lib/pkgconfig/volfx.pc" ] || fail "volfx.pc not beside the CMake package"

mkdir -p "$dest/host"
cp "$src/tests/integration/minimal_host.c" "$dest/host/"
cat > "$dest/host/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.16)
project(tiny_host C)
find_package(volfx 0.1 CONFIG REQUIRED)
message(STATUS "volfx ${volfx_VERSION} (ABI ${volfx_ABI_VERSION}) from ${volfx_DIR}")
find_package(PkgConfig REQUIRED)
pkg_check_modules(EPOXY REQUIRED IMPORTED_TARGET epoxy) # the host's own GL context
add_executable(tiny_host minimal_host.c)
set_property(TARGET tiny_host PROPERTY C_STANDARD 11)
target_compile_definitions(tiny_host PRIVATE _POSIX_C_SOURCE=200809L)
target_link_libraries(tiny_host PRIVATE volfx::volfx PkgConfig::EPOXY ${CMAKE_DL_LIBS} m)
CMAKE
cmake -S "$dest/host" -B "$dest/host/build" -DCMAKE_PREFIX_PATH="$dest/root$prefix" \
  -DCMAKE_C_FLAGS="$san_flags" -DCMAKE_EXE_LINKER_FLAGS="$san_flags" >"$dest/configure.log" 2>&1 \
  || { cat "$dest/configure.log"; fail "cmake cannot configure a host with find_package(volfx CONFIG)"; }
grep "volfx .* from $lib/cmake/volfx" "$dest/configure.log" || { cat "$dest/configure.log"; fail "volfx not found in the DESTDIR"; }
cmake --build "$dest/host/build" >"$dest/build.log" 2>&1 || { cat "$dest/build.log"; fail "the host does not build against volfx::volfx"; }
exe=$dest/host/build/tiny_host
soname=$(sed -n 's/^#define VFX_SONAME "\(.*\)"/\1/p' "$dest/root$prefix/include/volfx/volfx.h")
readelf -d "$exe" | grep -q "NEEDED.*\[$soname\]" || fail "the host does not need $soname"
grep -rq -- "-I$dest/root$prefix/include\|isystem $dest/root$prefix/include" "$dest/host/build/CMakeFiles" \
  || fail "volfx.h's include directory is not the installed one"

# no LD_LIBRARY_PATH: CMake puts the imported library's folder in the build tree's RUNPATH
rc=0; env -u LD_LIBRARY_PATH "$exe" || rc=$?
[ $rc -eq 77 ] && exit 77
[ $rc -eq 0 ] || fail "the CMake-built host failed ($rc)"

# Another major version is refused (volfxConfigVersion.cmake, SameMajorVersion).
mkdir -p "$dest/v1"
printf 'cmake_minimum_required(VERSION 3.16)\nproject(v1 NONE)\nfind_package(volfx 1 CONFIG QUIET)\nif(volfx_FOUND)\n  message(FATAL_ERROR "volfx 1 found")\nendif()\n' \
  > "$dest/v1/CMakeLists.txt"
cmake -S "$dest/v1" -B "$dest/v1/build" -DCMAKE_PREFIX_PATH="$dest/root$prefix" >/dev/null 2>&1 || fail "find_package(volfx 1) accepted version 0.1"
echo "cmake package ok"
