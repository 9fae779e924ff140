#!/usr/bin/env bash
# The Debian 13 (trixie) test: this source tree built and tested on Debian 13's own toolchain and
# libraries (GCC 14, libgpiod 2 and its C++ binding, Catch2 3, toml++ 3.4, systemd 257, Python
# 3.13), then run under Debian 13's systemd and dbus and on a real kernel's GPIO chip.
#
#   tests/system/debian13.sh SOURCE_DIR
#
# 1. A minbase trixie root with the build and test dependencies is made with debootstrap once
#    and cached as a tarball under /var/cache/caracara-systest/ (CARACARA_SYSTEST_CACHE), keyed
#    by the package list, so later runs unpack it in seconds and install nothing.
# 2. The root is unpacked under /var/tmp. systemd-nspawn runs there, with SOURCE_DIR bound
#    read-only and a build tree (kept between runs under the cache directory, one per source
#    directory) bound writable, both at their host paths: scripts/build.sh with warnings as
#    errors (-j2), then ctest without the tests labelled system or kernel (they boot a
#    container or a VM of their own; both are run next, from the host), then the Debian
#    packages with scripts/package.sh (nocheck, lintian) into a directory beside the build.
# 3. tests/system/run.sh --debs with CARACARA_SYSTEST_SUITE=trixie: the system test's checks
#    (check.sh, check-debs.sh) in a booted Debian 13 container that installs those packages
#    with apt-get, upgrades them while the thrusters run, and purges them.
# 4. tests/kernel/run.sh with CARACARA_KERNEL_ROOT set to the Debian 13 root and
#    CARACARA_KERNEL_SUITE=trixie: the kernel test's scenarios under QEMU on Debian 13's own
#    kernel (its 6.12 linux-image, the test module built against its linux-headers with the
#    root's GCC 14), caracarad's libgpiod 2 backend on the test module's GPIO chip, with
#    caracarad and caracara-sim built with --coverage in the root (GCC 14; its gcov reads them).
#    CARACARA_DEBIAN13_KERNEL=0 leaves this step out, and says so ("kernel: not run (...)");
#    under CI that fails.
#
# Needs root. Exit status 77 (skipped) when not root or when CARACARA_SKIP_DEBIAN13=1; under CI
# (CI=true) a run that cannot happen fails with its reason instead. 0 when every step passed.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
src=$(cd "${1:?usage: debian13.sh SOURCE_DIR}" && pwd)
suite=trixie
arch=$(dpkg --print-architecture)
cache_dir=${CARACARA_SYSTEST_CACHE:-/var/cache/caracara-systest}
# A guard against a hang, not a goal: on a fresh machine the root's three compiles (build,
# packages, kernel coverage) share the 2 cores with the host's tests and, on a fresh machine,
# with nothing cached. A run from a clone at a new path (a new build tree here, 30% ccache
# hits) with other compiles beside it was stopped at 1,500 s, 73% into the build (2026-12-05).
build_timeout_s=${CARACARA_DEBIAN13_BUILD_TIMEOUT:-2400}
# Build and test dependencies (scripts/deps.sh's, by their Debian 13 names), scripts/package.sh's
# tools, and what the kernel test's guest runs in this root: insmod, i2c-tools. The ros tests'
# (tests/ros): Debian 13's Fast DDS 3.1 and fastddsgen 4 for the peer, node for the reference
# codec (its npm packages are installed from the host, below), iproute2 for the namespace; udev
# for the kernel test's devices_for_the_daemon_alone (the shipped rules applied by systemd-udevd).
packages=(build-essential cmake pkg-config libsystemd-dev libgpiod-dev libcatch2-dev
          libtomlplusplus-dev libboost-dev nlohmann-json3-dev dbus python3 python3-dbus python3-gi python3-yaml python3-matplotlib
          systemd dpkg-dev debhelper lintian kmod i2c-tools openssh-client ccache cyclonedds-dev cyclonedds-tools
          libfastdds-dev fastddsgen nodejs iproute2 udev)
# Bump when the way the cached root is made changes.
recipe=3

say() { echo "debian13: $*"; }
die() { echo "debian13: FAIL: $*" >&2; exit 1; }

# cannot_run REASON: skipped (77) on a developer's machine; under CI a suite that cannot run fails.
cannot_run() {
  [ "${CI:-}" != true ] || die "cannot run under CI (CI=true): $*"
  say "SKIP: $*"
  echo "debian13: not run ($*)"
  exit 77
}
if [ "$(id -u)" -ne 0 ]; then
  cannot_run "needs root (debootstrap, systemd-nspawn)"
fi
if [ "${CARACARA_SKIP_DEBIAN13:-0}" = 1 ]; then
  cannot_run "CARACARA_SKIP_DEBIAN13=1"
fi
t0=$(date +%s)
need=()
command -v debootstrap >/dev/null || need+=(debootstrap)
command -v systemd-nspawn >/dev/null || need+=(systemd-container)
if ((${#need[@]})); then
  say "installing ${need[*]}"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${need[@]}" >/dev/null
fi

# --- the cached build root ---------------------------------------------------------------------
# Named apart from run.sh's roots ($suite-$arch-KEY.tar), which run.sh prunes by that pattern.
mkdir -p "$cache_dir"
exec {lock}>"$cache_dir/.$suite-build.lock"
if ! flock -n "$lock"; then
  say "waiting for another Debian 13 run to finish"
  flock "$lock"
  say "waited $(($(date +%s) - t0)) s"
  t0=$(date +%s)
fi
key=$(printf '%s\n' "$suite" "$arch" minbase "$recipe" "${packages[@]}" | sha256sum | cut -c1-16)
cache=$cache_dir/$suite-build-$arch-$key.tar
if [ ! -f "$cache" ]; then
  . "$here/mirror.sh"
  mirror=$(find_mirror "$suite") || die "no Debian mirror in this machine's apt sources (set CARACARA_SYSTEST_MIRROR)"
  say "building the $suite build root with debootstrap from $mirror (cached in $cache)"
  tmp=$(mktemp -d "$cache_dir/debootstrap.XXXXXX")
  trap 'rm -rf --one-file-system "$tmp"' EXIT
  if ! debootstrap --variant=minbase --components=main "$suite" "$tmp/root" "$mirror" >"$tmp/debootstrap.log" 2>&1; then
    tail -n 30 "$tmp/debootstrap.log" >&2
    die "debootstrap failed"
  fi
  # apt's resolver, not debootstrap's --include: lintian's Perl dependencies (virtual packages,
  # alternatives) are more than debootstrap resolves.
  if ! systemd-nspawn --quiet --keep-unit --register=no --directory="$tmp/root" --setenv=DEBIAN_FRONTEND=noninteractive \
      sh -c "apt-get update -qq && apt-get install -y -qq --no-install-recommends ${packages[*]}" >"$tmp/apt.log" 2>&1; then
    tail -n 30 "$tmp/apt.log" >&2
    die "apt-get install in the new root failed"
  fi
  chroot "$tmp/root" apt-get clean
  rm -rf "$tmp/root/var/lib/apt/lists/"* "$tmp/root/var/log/"*.log
  tar -C "$tmp/root" --numeric-owner -cpf "$tmp/root.tar" .
  mv "$tmp/root.tar" "$cache"
  rm -rf --one-file-system "$tmp"
  trap - EXIT
  say "build root made in $(($(date +%s) - t0)) s"
fi
# Roots of another package list go once unused for a week (not at once: two branches with
# different lists would otherwise rebuild theirs on every run).
touch "$cache"
find "$cache_dir" -maxdepth 1 -name "$suite-build-$arch-*.tar" ! -path "$cache" -mtime +7 -delete

# The build tree survives the run, so a rerun rebuilds only what changed: one per source
# directory (make trusts timestamps) and per root (another compiler makes everything stale).
builds=$cache_dir/builds
build=$builds/$(basename "$cache" .tar)-$(printf '%s' "$src" | sha256sum | cut -c1-12)
mkdir -p "$build"
touch "$build"
# About 200 MB each: the three used last are kept (a CI clone at a new path each time makes one).
for old in $(ls -1dt "$builds"/*/ | sed 's#/$##' | grep -v -- '-kernel$' | grep -v -- '-debs$' | tail -n +4); do
  rm -rf --one-file-system "$old" "$old-kernel" "$old-debs"
done

# --- this run's root ---------------------------------------------------------------------------
# The lock above is held by one run at a time: a run directory left now is a killed run's.
unmount_under() {
  local m
  for m in $(awk -v w="$1" 'index($2, w) == 1 { print $2 }' /proc/self/mounts | sort -r); do
    umount -l "$m" 2>/dev/null || true
  done
}
for stale in /var/tmp/caracara-debian13.*; do
  [ -d "$stale" ] || continue
  say "removing $stale, left by an earlier run"
  unmount_under "$stale"
  rm -rf --one-file-system "$stale"
done
work=$(mktemp -d /var/tmp/caracara-debian13.XXXXXX)
root=$work/root
cleanup() {
  local rc=$?
  unmount_under "$work"
  rm -rf --one-file-system "$work"
  exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT TERM
mkdir -p "$root"
tar -C "$root" --numeric-owner -xpf "$cache"
# What the chroot inside the QEMU guest finds at the host's paths (step 4).
# Not under /var/tmp: the guest mounts a tmpfs there.
kwork=$build-kernel
mkdir -p "$kwork" "$root$src" "$root$build" "$root$kwork"

cat >"$root/usr/local/bin/caracara-build-and-test" <<'SCRIPT'
#!/bin/bash
# Run by tests/system/debian13.sh inside the Debian 13 root: SRC and BUILD are host paths.
set -euo pipefail
. /etc/os-release
echo "== $PRETTY_NAME, $(g++ --version | head -n 1), cmake $(cmake --version | sed -n '1s/.* //p')"
echo "== build (scripts/build.sh, CARACARA_WERROR=ON)"
"$SRC/scripts/build.sh" "$BUILD" -DCARACARA_WERROR=ON
grep -E '^(GPIODCXX_VERSION|Catch2_DIR|TOMLPP_VERSION|SYSTEMD_VERSION)' "$BUILD/CMakeCache.txt" | sed 's/^/   /'
# Nor bridge: its npm packages come from the registry; the host's suites run it. The ros tests
# run: their npm packages were installed into the source from the host (below).
echo "== ctest (all but the tests labelled system, kernel or bridge)"
# Direction detection twice, not five times in a row: the statistics are the host's normal
# build's; here the other toolchain (tests/e2e/test_direction_detection.py).
export CARACARA_DETECTION_RUNS=2
# At the cores, not scripts/test.sh's twice: the host's tests run beside this one, and with both
# at twice the cores (and other compiles on the machine) the direction detection's and the soak's
# first tests here failed for want of CPU (2026-12-05).
CLICOLOR=0 ctest --test-dir "$BUILD" --output-on-failure -j"$TEST_JOBS" --timeout 600 -LE 'system|kernel|bridge'
echo "== Debian packages (scripts/package.sh, nocheck: the suite just ran)"
DEB_BUILD_OPTIONS=nocheck "$SRC/scripts/package.sh" native "$DEBS"
SCRIPT
chmod 0755 "$root/usr/local/bin/caracara-build-and-test"

debs=$build-debs
mkdir -p "$debs"
# The ros tests' npm packages (tests/ros/package-lock.json): the root has no network and sees the
# source read-only, so they are installed here, on the host, by the script CTest's setup test
# npm_ros runs (tests/npm_packages.py); in the root npm_ros finds them up to date and e2e_ros only
# checks them (tests/e2e/harness.py npm_ci). The root's node runs them (plain JavaScript).
/usr/bin/python3 "$src/tests/npm_packages.py" "$src/tests/ros" || die "the ros tests' npm packages could not be installed"
# The root's own ccache (GCC 14, not the host's compiler), kept between runs: CI builds mostly
# the same sources each time, from a clone at a new path (scripts/ccache.sh sets the base dir).
ccache_dir=$cache_dir/ccache-$suite-$arch
mkdir -p "$ccache_dir"
say "building, testing and packaging $src in the Debian 13 root (at most ${build_timeout_s} s)"
t1=$(date +%s)
rc=0
timeout --kill-after=20 "$build_timeout_s" \
  systemd-nspawn --quiet --keep-unit --register=no --directory="$root" --private-network \
    --bind-ro="$src" --bind="$build" --bind="$debs" --bind="$ccache_dir:/var/cache/ccache" --setenv=HOME=/root --setenv=CI="${CI:-}" --setenv=SRC="$src" \
    --setenv=BUILD="$build" --setenv=DEBS="$debs" --setenv=TEST_JOBS="$(nproc)" \
    /usr/local/bin/caracara-build-and-test >"$work/build.log" 2>&1 || rc=$?
# grep -m, not "| head": under pipefail grep's SIGPIPE, once head has its lines, ended this script
# (2026-12-05, with more than a pipe's first write of matching lines). The versions' lines are
# indented by three spaces; ctest's "Start" lines by more.
grep -m 60 -E '^== |^   [A-Za-z]|^package: |tests passed|tests failed|Total Test time|\*\*\*|Failed|error:|warning:' "$work/build.log" || true
build_s=$(($(date +%s) - t1))
say "build, ctest and packages: $build_s s (exit status $rc)"
if [ "$rc" -ne 0 ]; then
  # Each failed test's own output (ctest --output-on-failure prints it after its "***Failed"
  # line), which the tail below has mostly scrolled past: e2e_caracaractl failed in CI's run of
  # d8da134 and what it said was lost.
  echo "---- the failed tests' output ----"
  sed 's/\x1b\[[0-9;]*m//g' "$work/build.log" | awk '
    /\*\*\*(Failed|Timeout|Exception)/ { show = 1; n = 0 }
    show && n > 0 && /^ *(Start +[0-9]+:|[0-9]+\/[0-9]+ Test +#)/ { show = 0 }
    show && n++ < 300' || true
  echo "---- build and test log (last 150 lines) ----"
  tail -n 150 "$work/build.log"
  die "the build, ctest or the package build failed in the Debian 13 root"
fi
ctest_line=$(sed 's/\x1b\[[0-9;]*m//g' "$work/build.log" | grep -E 'tests passed, [0-9]+ tests failed out of' | tail -n 1 || true)

failed=0
say "system test in a booted Debian 13 container, installed from the Debian 13 packages (run.sh --debs)"
t2=$(date +%s)
system_rc=0
CARACARA_SYSTEST_SUITE=$suite "$here/run.sh" --debs "$debs" || system_rc=$?
system_s=$(($(date +%s) - t2))
[ "$system_rc" -eq 0 ] || failed=1

kernel_rc=skipped
kernel_s=0
case $src in
  # The guest mounts a tmpfs on these: the source tree would not be there.
  /var/tmp/*|/run/*|/dev/shm/*)
    say "FAIL: the kernel step needs the source tree outside /var/tmp, /run and /dev/shm ($src)"
    kernel_rc=1; failed=1 ;;
  *) ;;
esac
if [ "$kernel_rc" = skipped ] && [ "${CARACARA_DEBIAN13_KERNEL:-1}" = 0 ]; then
  # Left out on request: said, shown in scripts/test.sh's table, and a failure under CI.
  say "kernel test with the Debian 13 build: left out (CARACARA_DEBIAN13_KERNEL=0)"
  echo "kernel: not run (CARACARA_DEBIAN13_KERNEL=0)"
  if [ "${CI:-}" = true ]; then
    say "FAIL: under CI (CI=true) the Debian 13 kernel test must run"
    kernel_rc=1; failed=1
  fi
fi
if [ "$kernel_rc" = skipped ] && [ "${CARACARA_DEBIAN13_KERNEL:-1}" != 0 ]; then
  say "kernel test with the Debian 13 build (tests/kernel/run.sh, guest root: the Debian 13 root)"
  t3=$(date +%s)
  kernel_rc=0
  # caracarad, caracara-sim and caracaractl (the bus scan scenario runs it in the guest) with
  # --coverage by the root's GCC 14 (kept with the kernel work directory, so a rerun rebuilds
  # only what changed).
  kcov=$kwork/cov
  mkdir -p "$kcov"
  timeout --kill-after=20 "$build_timeout_s" \
    systemd-nspawn --quiet --keep-unit --register=no --directory="$root" --private-network \
      --bind-ro="$src" --bind="$kwork" --bind="$ccache_dir:/var/cache/ccache" --setenv=HOME=/root \
      sh -c ". '$src/scripts/ccache.sh' '$src' && cmake -S '$src' -B '$kcov' -DCMAKE_BUILD_TYPE=Debug -DCARACARA_WERROR=ON -DCMAKE_CXX_FLAGS=--coverage >/dev/null &&
             cmake --build '$kcov' -j2 --target caracarad caracara-sim caracaractl >/dev/null" >"$work/kcov.log" 2>&1 || kernel_rc=$?
  if [ "$kernel_rc" -ne 0 ]; then
    tail -n 40 "$work/kcov.log"
    say "FAIL: the coverage build for the kernel test failed in the Debian 13 root"
  else
    # The guest chroots into this root over 9p: the source, the build and the kernel test's work
    # directory must be where the host has them.
    mount --bind -o ro "$src" "$root$src"
    mount --bind "$build" "$root$build"
    mount --bind "$kwork" "$root$kwork"
    CARACARA_KERNEL_ROOT=$root CARACARA_KERNEL_SUITE=$suite CARACARA_KERNEL_BUILD=$kcov CARACARA_KERNEL_LABEL=debian13 \
      "$src/tests/kernel/run.sh" "$kwork" || kernel_rc=$?
  fi
  kernel_s=$(($(date +%s) - t3))
  [ "$kernel_rc" -eq 0 ] || failed=1
fi

say "Debian 13: ctest ${ctest_line:-?} ($build_s s with the build); system test exit $system_rc ($system_s s); kernel test exit $kernel_rc ($kernel_s s); $(($(date +%s) - t0)) s in all"
exit "$failed"
