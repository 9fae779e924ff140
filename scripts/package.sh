#!/usr/bin/env bash
# Builds the Debian packages caracarad and caracara-sim with dpkg-buildpackage, then runs
# lintian on them (an error fails the script).
#
#   scripts/package.sh [amd64|arm64|native] [OUTDIR]
#
# amd64 (or whatever this machine is) is a native build that runs the test suite (less the
# system and kernel tests) unless DEB_BUILD_OPTIONS has nocheck. arm64 is a cross build with
# Debian's multiarch (dpkg --add-architecture arm64, crossbuild-essential-arm64, the :arm64
# -dev packages), always nocheck (scripts/cross_test.sh runs the arm64 tests under qemu-user).
# The .debs, the .changes, the build log and lintian's report land in OUTDIR (default
# build-deb/ in the repository). Installs what it lacks with apt-get, and only then.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
native=$(dpkg --print-architecture)
arch=${1:-native}
[ "$arch" != native ] || arch=$native
out=${2:-$top/build-deb}
mkdir -p "$out"
out=$(cd "$out" && pwd)
say() { echo "package: $*"; }
t0=$(date +%s)

sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
apt_updated=0
apt_install() {
  if [ "$apt_updated" -eq 0 ]; then
    $sudo apt-get update -qq
    apt_updated=1
  fi
  say "installing $*"
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "$@" >/dev/null
}
installed() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }

opts=${DEB_BUILD_OPTIONS:-}
cross=()
if [ "$arch" != "$native" ]; then
  [ "$arch" = arm64 ] || { echo "package: only $native and arm64 are supported, not $arch" >&2; exit 2; }
  if ! dpkg --print-foreign-architectures | grep -qx arm64; then
    say "dpkg --add-architecture arm64"
    $sudo dpkg --add-architecture arm64
    apt_updated=0
  fi
  cross=(-a arm64)
  # Nothing runs arm64 code during a package build (no emulator there): no tests.
  opts="nocheck${opts:+ $opts}"
fi
profiles=()
case " $opts " in *" nocheck "*) profiles=(-Pnocheck) ;; esac
opts="${opts:+$opts }parallel=$(nproc)"

# --- the tools, then the build dependencies (as debian/control lists them) --------------------
need=()
for p in dpkg-dev debhelper lintian; do installed "$p" || need+=("$p"); done
[ "$arch" = arm64 ] && { installed crossbuild-essential-arm64 || need+=(crossbuild-essential-arm64); }
((${#need[@]} == 0)) || apt_install "${need[@]}"
if ! (cd "$top" && dpkg-checkbuilddeps "${cross[@]}" "${profiles[@]}" >/dev/null 2>&1); then
  [ "$apt_updated" -eq 1 ] || { $sudo apt-get update -qq; apt_updated=1; }
  say "installing the build dependencies (apt-get build-dep ${cross[*]} ${profiles[*]})"
  # apt resolves them for the host architecture (libsystemd-dev:arm64, pkgconf:arm64, ...).
  (cd "$top" && DEBIAN_FRONTEND=noninteractive $sudo apt-get build-dep -y -qq --no-install-recommends \
     "${cross[@]}" "${profiles[@]/-P/--build-profiles=}" ./ >/dev/null)
fi

# --- a clean copy of the sources: the checkout's own build trees stay out of it ---------------
version=$(dpkg-parsechangelog -l "$top/debian/changelog" -S Version)
work=$out/src-$arch
rm -rf "$work"
mkdir -p "$work/caracarad-$version"
if git -C "$top" rev-parse --git-dir >/dev/null 2>&1; then
  (cd "$top" && git ls-files -z --cached --others --exclude-standard | \
     tar --null --ignore-failed-read -T - -cf - 2>/dev/null) | tar -C "$work/caracarad-$version" -xf -
else
  tar -C "$top" --exclude='./build*' --exclude='./obj-*' -cf - . | tar -C "$work/caracarad-$version" -xf -
fi
[ -f "$work/caracarad-$version/debian/rules" ] || { echo "package: no debian/ in the copy" >&2; exit 1; }

# --- build ------------------------------------------------------------------------------------
# Through ccache when present: the copy is made at the same path each time, so the next run's
# package build (same sources, same dpkg-buildflags) compiles only what changed.
. "$top/scripts/ccache.sh" "$work/caracarad-$version"
log=$out/build-$arch.log
say "dpkg-buildpackage -b ${cross[*]} ${profiles[*]} (DEB_BUILD_OPTIONS='$opts'), log in $log"
t1=$(date +%s)
if ! (cd "$work/caracarad-$version" && DEB_BUILD_OPTIONS="$opts" \
        dpkg-buildpackage -b -us -uc "${cross[@]}" "${profiles[@]}") >"$log" 2>&1; then
  tail -n 60 "$log" >&2
  echo "package: dpkg-buildpackage failed (log: $log)" >&2
  exit 1
fi
grep -E '^[0-9]+% tests passed|^Total Test time' "$log" || true
say "built in $(($(date +%s) - t1)) s"
changes=caracarad_${version}_$arch.changes
# Only this build's packages for this architecture in OUTDIR (run.sh --debs takes the newest).
rm -f "$out"/caracara{d,-sim,-ros}{,-dbgsym}_*_"$arch".deb "$out"/caracarad_*_"$arch".{changes,buildinfo}
for f in "$work"/*_"$version"_"$arch".*; do
  mv -f "$f" "$out/"
done
rm -rf "$work"

# --- lintian ----------------------------------------------------------------------------------
say "lintian $changes"
set +e
lintian --fail-on error --display-info "$out/$changes" >"$out/lintian-$arch.txt" 2>&1
lrc=$?
set -e
cat "$out/lintian-$arch.txt"
[ "$lrc" -eq 0 ] || { echo "package: lintian reports errors" >&2; exit 1; }
ls -l "$out"/*_"$version"_"$arch".deb
say "done in $(($(date +%s) - t0)) s"
