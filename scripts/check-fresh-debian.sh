#!/usr/bin/env bash
# Checks the README's two set-up commands on a fresh Debian 12 (not a CI test; needs root and
# Debian's mirror): debootstraps a minbase bookworm into ROOTDIR (unless one is already there),
# copies a clean export of this repository's HEAD to ROOTDIR/root/volfx and SHARED to
# ROOTDIR/root/shared (so ../shared/data is where the build expects it), then runs, in the
# chroot as root with an empty environment, scripts/run-game.sh and scripts/test.sh, timing each.
# Passes when the game prints fps and writes a non-empty PNG and test.sh exits 0 with "0 failed".
# Usage: scripts/check-fresh-debian.sh [ROOTDIR] [SHARED]
#   ROOTDIR default /var/tmp/deb12. Give a new folder for a truly fresh machine: a reused one
#   already has the packages from the previous check installed.
#   SHARED  default ../shared next to the repository.
#   VFX_CHECK_TEST_FIRST=1 runs scripts/test.sh before scripts/run-game.sh, so that test.sh is the
#   one that installs and builds (each README command must set up on its own).
# Logs: ROOTDIR/root/run-game.log, ROOTDIR/root/test.log.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
root=${1:-/var/tmp/deb12}
shared=${2:-$repo/../shared}
[ "$(id -u)" -eq 0 ] || { echo "check-fresh-debian: must run as root (debootstrap, chroot, mount)" >&2; exit 2; }
[ -d "$shared/data" ] || { echo "check-fresh-debian: $shared/data not found (pass SHARED)" >&2; exit 2; }
case "$root" in "$repo"|"$repo"/*) echo "check-fresh-debian: ROOTDIR must be outside the repository" >&2; exit 2;; esac

if [ ! -f "$root/etc/debian_version" ]; then
  command -v debootstrap >/dev/null || { apt-get update -qq; apt-get install -y -qq debootstrap; }
  mkdir -p "$root"
  echo "check-fresh-debian: debootstrap minbase bookworm into $root"
  t0=$(date +%s)
  debootstrap --variant=minbase bookworm "$root" http://deb.debian.org/debian
  fresh="yes (debootstrap $(( $(date +%s) - t0 )) s)"
else
  echo "check-fresh-debian: reusing the system already in $root (not fresh: packages may be installed)"
  fresh=no
fi

# Mounts for apt and for Mesa's EGL (llvmpipe needs /dev/shm and /proc; no GPU device needed).
mounted=()
mnt() { # mnt TARGET mount-args...
  local t="$root/$1"; shift
  mkdir -p "$t"
  mountpoint -q "$t" || { mount "$@" "$t"; mounted=("$t" "${mounted[@]}"); }
}
cleanup() { for t in "${mounted[@]}"; do umount -l "$t" || true; done; }
trap cleanup EXIT
mnt proc -t proc proc
mnt sys -t sysfs sysfs
mnt dev --bind /dev
mnt dev/pts --bind /dev/pts
mnt dev/shm -t tmpfs tmpfs
cp -L /etc/resolv.conf "$root/etc/resolv.conf" 2>/dev/null || true

rm -rf "$root/root/volfx" "$root/root/shared"
mkdir -p "$root/root/volfx"
git -C "$repo" archive HEAD | tar -x -C "$root/root/volfx"
cp -a "$shared" "$root/root/shared"
echo "check-fresh-debian: copied $(git -C "$repo" rev-parse --short HEAD) and $shared"

run() { # run NAME: runs scripts/NAME.sh in the chroot with an empty environment; sets secs, rc
  local t0 t1
  t0=$(date +%s)
  set +e
  chroot "$root" /usr/bin/env -i HOME=/root PATH=/usr/sbin:/usr/bin:/sbin:/bin \
    /bin/bash -c "cd /root/volfx && scripts/$1.sh" > "$root/root/$1.log" 2>&1
  rc=$?
  set -e
  t1=$(date +%s)
  secs=$((t1 - t0))
}

game() {
  run run-game
  game_rc=$rc game_s=$secs
  fps=$(grep -m1 -o '[0-9.]* fps' "$root/root/run-game.log" || true)
  png=no; [ -s "$root/root/volfx/volfx-game.png" ] && png=yes
}
tests() {
  run test
  test_rc=$rc test_s=$secs
  count=$(tail -n 1 "$root/root/test.log")
}
if [ "${VFX_CHECK_TEST_FIRST:-0}" = 1 ]; then tests; game; else game; tests; fi

echo "check-fresh-debian: fresh root: $fresh"
echo "  scripts/run-game.sh: exit $game_rc, ${game_s} s, fps '${fps}', volfx-game.png written: $png"
echo "  scripts/test.sh:     exit $test_rc, ${test_s} s, '$count'"
ok=1
if ! { [ "$game_rc" -eq 0 ] && [ -n "$fps" ] && [ "$png" = yes ]; }; then
  ok=0; echo "  run-game FAILED: see $root/root/run-game.log"
fi
if ! { [ "$test_rc" -eq 0 ] && [[ "$count" =~ ^[0-9]+\ passed,\ 0\ failed ]]; }; then
  ok=0; echo "  test.sh FAILED: see $root/root/test.log"
fi
if [ $ok -eq 1 ]; then echo "check-fresh-debian: PASS"; else echo "check-fresh-debian: FAIL"; exit 1; fi
