#!/bin/sh
# Installs the build into a DESTDIR and uses it the way an integrator would use any Debian
# library: the minimal host is compiled against the installed tree with pkg-config alone (no
# -I into the source tree), linked with -lvolfx and also loaded by soname with dlopen, and the
# installed game's --plugin finds libvolfx.so.<ABI> through the loader's search path.
# usage: check_install.sh BUILD_DIR SOURCE_DIR PREFIX LIBDIR [SANITIZE]
# SANITIZE (meson's b_sanitize, e.g. address,undefined) is passed to cc: an instrumented
# libvolfx needs an instrumented host.
# Exits 77 when no GL context can be made (the hosts say so).
set -eu
build=$1 src=$2 prefix=$3 libdir=$4 san=${5:-none}
san_flags=
[ "$san" = none ] || san_flags="-fsanitize=$san"
dest=$(mktemp -d "${TMPDIR:-/tmp}/volfx-install.XXXXXX")
trap 'rm -rf "$dest"' EXIT
fail() { echo "check_install: $*" >&2; exit 1; }

meson install -C "$build" --no-rebuild --quiet --destdir "$dest" >/dev/null
case $libdir in /*) lib=$dest$libdir ;; *) lib=$dest$prefix/$libdir ;; esac
abi=$(sed -n 's/^#define VFX_ABI_VERSION \([0-9]*\)u/\1/p' "$src/plugin/include/volfx/volfx.h")
for f in "$lib/libvolfx.so.$abi" "$lib/libvolfx.so" "$lib/pkgconfig/volfx.pc" "$dest$prefix/include/volfx/volfx.h"; do
  [ -e "$f" ] || fail "not installed: ${f#"$dest"}"
done
[ ! -e "$dest$prefix/include/volfx/volfx_lab.h" ] || fail "the lab header is installed"
soname=$(readelf -d "$lib/libvolfx.so.$abi" | sed -n 's/.*Library soname: \[\(.*\)\]/\1/p')
header_soname=$(sed -n 's/^#define VFX_SONAME "\(.*\)"/\1/p' "$dest$prefix/include/volfx/volfx.h")
[ "$soname" = "libvolfx.so.$abi" ] || fail "soname '$soname', ABI version $abi"
[ "$soname" = "$header_soname" ] || fail "soname '$soname', VFX_SONAME '$header_soname'"

# pkg-config sees only the installed tree (the sysroot maps its /usr/local paths into DESTDIR).
export PKG_CONFIG_PATH="$lib/pkgconfig" PKG_CONFIG_SYSROOT_DIR="$dest"
flags=$(pkg-config --cflags --libs volfx) || fail "pkg-config cannot find volfx"
echo "pkg-config --cflags --libs volfx: $flags"
# The host's own GL context comes from libepoxy/EGL: that is the host's business, not ours.
# shellcheck disable=SC2086
cc -std=c11 -D_POSIX_C_SOURCE=200809L $san_flags -o "$dest/minimal_host" "$src/tests/integration/minimal_host.c" \
  $flags $(pkg-config --cflags --libs epoxy) -ldl -lm || fail "minimal host does not build against the installed tree"
# shellcheck disable=SC2086
cc -std=c11 -M $flags $(pkg-config --cflags epoxy) "$src/tests/integration/minimal_host.c" | tr ' ' '\n' \
  | grep -q "^$dest.*/include/volfx/volfx.h$" || fail "volfx.h did not come from the installed tree"
readelf -d "$dest/minimal_host" | grep -q "NEEDED.*\[$soname\]" || fail "minimal host does not need $soname"

# Outside /usr, volfx.pc carries -Wl,-rpath,${libdir}: a host built with it runs, and dlopens the
# plugin by soname, with no LD_LIBRARY_PATH (pkg-config's prefix pointed at the DESTDIR tree, as
# if the prefix were there).
if [ "$prefix" != /usr ]; then
  # shellcheck disable=SC2046
  rflags=$(PKG_CONFIG_SYSROOT_DIR= pkg-config --define-variable=prefix="$dest$prefix" --cflags --libs volfx)
  echo "$rflags" | grep -q -- "-Wl,-rpath,$lib" || fail "volfx.pc gives no rpath to $lib: $rflags"
  # shellcheck disable=SC2086
  cc -std=c11 -D_POSIX_C_SOURCE=200809L $san_flags -o "$dest/rpath_host" "$src/tests/integration/minimal_host.c" \
    $rflags $(pkg-config --cflags --libs epoxy) -ldl -lm || fail "a host does not build with volfx.pc's rpath"
  rc=0; env -u LD_LIBRARY_PATH "$dest/rpath_host" || rc=$?
  [ $rc -eq 77 ] && exit 77
  [ $rc -eq 0 ] || fail "a host built with volfx.pc failed without LD_LIBRARY_PATH ($rc)"
  env -u LD_LIBRARY_PATH "$dest/rpath_host" "$soname" || fail "a host built with volfx.pc cannot dlopen $soname without LD_LIBRARY_PATH"
  echo "no LD_LIBRARY_PATH needed: rpath $lib"
fi

export LD_LIBRARY_PATH="$lib"
rc=0; "$dest/minimal_host" || rc=$?
[ $rc -eq 77 ] && exit 77
[ $rc -eq 0 ] || fail "linked minimal host failed ($rc)"
"$dest/minimal_host" "$soname" || fail "minimal host cannot dlopen $soname"

# The installed game, its plugin found by soname, reports where the loader found it.
out=$("$dest$prefix/bin/volfx-game" --headless --frames 2 --size 64x36 --no-volume --png "$dest/g.png" \
      --plugin "$soname" 2>&1) || { echo "$out"; fail "installed volfx-game --plugin $soname failed"; }
echo "$out" | grep "loaded from" || { echo "$out"; fail "the game did not report the plugin's path"; }
echo "$out" | grep -q "loaded from $lib/libvolfx.so.$abi" || fail "plugin not loaded from the DESTDIR"
# The installed game with the source tree gone: the default scene (its dome mesh is a relative
# path in the scene) must come from the installed share/volfx/scenes. The source tree is hidden
# under an empty tmpfs in a private mount namespace where unshare can make one (root); elsewhere
# the log must still name the installed file.
scenes=$dest$prefix/share/volfx/scenes
[ -f "$scenes/data/dome.vtu" ] && [ -f "$scenes/default.json" ] || fail "scenes not installed under share/volfx/scenes"
game="$dest$prefix/bin/volfx-game --headless --frames 1 --size 64x36 --progress 0 --png $dest/d.png"
if unshare -m true 2>/dev/null; then
  hidden="with $src hidden"
  # shellcheck disable=SC2086
  out=$(unshare -m sh -c "mount -t tmpfs none '$src' && exec $game" 2>&1) || { echo "$out"; fail "installed volfx-game failed $hidden"; }
else
  hidden="(unshare -m refused: source tree present)"
  # shellcheck disable=SC2086
  out=$($game 2>&1) || { echo "$out"; fail "installed volfx-game failed"; }
fi
echo "$out" | grep "scene volume" || { echo "$out"; fail "no volume loaded by the default scene"; }
echo "$out" | grep -q "scene volume $scenes/data/dome.vtu:" || fail "the default scene's dome did not come from $scenes"
[ -s "$dest/d.png" ] || fail "no image written"
echo "installed game rendered the default scene $hidden"
# A shipped scene by bare name, found in the installed scenes folder.
# shellcheck disable=SC2086
$game --scene beams-only.json >/dev/null 2>&1 || fail "installed volfx-game --scene beams-only.json failed"
echo "install ok"
