#!/usr/bin/env bash
# The system test: caracarad under a real systemd, on a real system bus, with the installed
# unit files, bus policy and configuration, in a Debian 12 container.
#
#   tests/system/run.sh BUILD_DIR
#   CARACARA_SYSTEST_SUITE=trixie tests/system/run.sh BUILD_DIR    a Debian 13 container (for a
#                                  build made in Debian 13: tests/system/debian13.sh does that)
#
# 1. Builds a minimal Debian 12 root with debootstrap, once: the result is cached as a
#    tarball under /var/cache/caracara-systest/ (CARACARA_SYSTEST_CACHE), keyed by the
#    package list, so later runs unpack it in seconds.
# 2. Unpacks it into a temporary directory under /var/tmp, installs the build into it with
#    `cmake --install BUILD_DIR --prefix /usr` (DESTDIR), adds the checks (check.sh, run
#    at boot by a test-only unit) and boots it with systemd-nspawn.
# 3. check.sh does everything inside the container (systemctl, busctl, caracaractl as root,
#    as a user in the caracara group and as an unprivileged user), writes PASS/FAIL lines
#    to a bind-mounted directory, then powers the container off. The container sits in a
#    network namespace of its own, joined by a veth pair (the tether) to a second one, the
#    topside: there topside.sh runs on this machine, outside the container, and reaches the
#    container's sshd with caracaractl -H, busctl -H and the python3-dbus example
#    (check-topside.sh is the container's half).
# 4. The host prints the results and exits non-zero on any failure, a missing result or a
#    timeout. The container, its processes and the temporary root are always removed.
#
# Needs root, debootstrap, systemd-container, openssh-client and iproute2 (installed with apt-get
# when missing), and /usr/bin/python3 with python3-dbus for the example mission (scripts/deps.sh). The
# Debian mirror is the one this machine's apt uses (CARACARA_SYSTEST_MIRROR overrides it).
# Exit status 77 (skipped) when not run as root; under CI (CI=true) that fails instead.
# It passes only with every planned check passed (checks_planned below: "system: N of N checks
# passed"), so a check script cut off early, or a topside.sh that died, fails it.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
# run.sh --debs DIR: install the Debian packages built in DIR (scripts/package.sh) with apt-get
# inside the booted container instead of a build tree with cmake --install (what CTest and CI
# do); check-debs.sh adds an upgrade while the thrusters run, and the purge.
debs=
if [ "${1:-}" = --debs ]; then
  debs=$(cd "${2:?usage: run.sh --debs DIR}" && pwd)
  set -- "$debs"
fi
build=${1:?usage: run.sh BUILD_DIR}
build=$(cd "$build" && pwd)
# The Debian release of the container: bookworm (Debian 12, the default) or trixie (Debian 13,
# for tests/system/debian13.sh, which passes a build made in Debian 13).
suite=${CARACARA_SYSTEST_SUITE:-bookworm}
arch=$(dpkg --print-architecture)
cache_dir=${CARACARA_SYSTEST_CACHE:-/var/cache/caracara-systest}
timeout_s=${CARACARA_SYSTEST_TIMEOUT:-420}
# What the container needs besides debootstrap's minbase: an init, the system bus, and the
# shared libraries of caracarad, caracara-sim and caracaractl (their names differ by release).
case $suite in
  bookworm) packages=(systemd systemd-sysv dbus libsystemd0 libgpiod2 libtomlplusplus3 openssh-server libddsc0debian) ;;
  trixie) packages=(systemd systemd-sysv dbus libsystemd0 libgpiod3 libtomlplusplus3t64 openssh-server libddsc0t64) ;;
  *) echo "system-test: CARACARA_SYSTEST_SUITE must be bookworm or trixie, not '$suite'" >&2; exit 2 ;;
esac
# Bump when the way the cached root is made changes.
recipe=1

say() { echo "system-test: $*"; }
die() { echo "system-test: FAIL: $*" >&2; exit 1; }
# cannot_run REASON: skipped (77) on a developer's machine; under CI a suite that cannot run fails.
cannot_run() {
  [ "${CI:-}" != true ] || die "cannot run under CI (CI=true): $*"
  say "SKIP: $*"
  echo "system: not run ($*)"
  exit 77
}
# The number of checks (PASS/FAIL lines of check.sh, check-debs.sh, check-topside.sh and
# topside.sh) a complete run makes: with --debs (what CTest and CI run) and with a build tree
# (cmake --install: check.sh's two installation checks instead of check-debs.sh's 34). A check
# added or removed changes it here: 157 before the bridge (+5: its unit, socket, a pilot's
# upgrade, a refused non-member, its exposure), the failsafes (+3), the cockpit (+2: its page
# and the dive list on the socket) and pilot-lost (+8: the kill after the persistence and the
# re-arm, after the busctl pilot of check.sh and after each of topside.sh's three pilots that
# leave), the bridge's own user (+3: its user in the group, the name it may not own,
# MemoryMax), real-time scheduling (+2: the loop's policy, its memory locked) and the zeroing
# step judged on this step's own zero orders and journal lines (+4: the three FIGURE lines of
# check.sh asserted against tests/bounds.json, the step's zeros before the next daemon's start
# and its report after a cursor, in place of zeros that a restart also sends), caracara-ros's
# own user (+8 with --debs, +6 with a build tree: its package installed and purged, its start,
# its user in the group, the name it may not own, the devices' group on the daemon and not on
# the clients, its exposure). The install count is the debs count less check-debs.sh's 34 plus
# check.sh's two installation checks, less 7c's two package checks, as it was counted by hand;
# CI runs --debs.
checks_planned_debs=192
checks_planned_install=158

if [ "$(id -u)" -ne 0 ]; then
  cannot_run "needs root (debootstrap, systemd-nspawn)"
fi
[ -n "$debs" ] || for bin in caracarad caracara-sim caracaractl; do
  case $bin in caracarad) p=daemon/$bin ;; caracara-sim) p=sim/$bin ;; *) p=tools/$bin ;; esac
  [ -x "$build/$p" ] || die "$build/$p is not built"
done

# --- host tools ----------------------------------------------------------------------------
need=()
command -v debootstrap >/dev/null || need+=(debootstrap)
command -v systemd-nspawn >/dev/null || need+=(systemd-container)
command -v ssh-keygen >/dev/null || need+=(openssh-client)  # the topside (topside.sh)
command -v ip >/dev/null || need+=(iproute2)                 # the tether
if ((${#need[@]})); then
  say "installing ${need[*]}"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${need[@]}" >/dev/null
fi

# --- the Debian mirror this machine's apt uses (tests/system/mirror.sh) ----------------------
. "$here/mirror.sh"

# --- the cached Debian root ----------------------------------------------------------------------
key=$(printf '%s\n' "$suite" "$arch" minbase "$recipe" "${packages[@]}" | sha256sum | cut -c1-16)
cache=$cache_dir/$suite-$arch-$key.tar
t0=$(date +%s)
if [ ! -f "$cache" ]; then
  mirror=$(find_mirror "$suite") || die "no Debian $suite mirror in this machine's apt sources (set CARACARA_SYSTEST_MIRROR)"
  say "building the $suite root with debootstrap from $mirror (cached in $cache)"
  mkdir -p "$cache_dir"
  boot=$(mktemp -d "$cache_dir/debootstrap.XXXXXX")
  # Remove a half-made root on any exit from here on; the cache file appears only when complete.
  trap 'rm -rf --one-file-system "$boot"' EXIT
  if ! debootstrap --variant=minbase --components=main --include="$(IFS=,; echo "${packages[*]}")" \
      "$suite" "$boot/root" "$mirror" >"$boot/debootstrap.log" 2>&1; then
    tail -n 30 "$boot/debootstrap.log" >&2
    die "debootstrap failed"
  fi
  chroot "$boot/root" apt-get clean
  rm -rf "$boot/root/var/lib/apt/lists/"* "$boot/root/var/log/"*.log "$boot/root/var/cache/debconf/"*-old
  tar -C "$boot/root" --numeric-owner -cpf "$boot/root.tar" .
  mv "$boot/root.tar" "$cache"
  rm -rf --one-file-system "$boot"
  trap - EXIT
  say "root built in $(($(date +%s) - t0)) s"
fi
# Roots of another package list go once unused for a week (not at once: two branches with
# different lists would otherwise rebuild theirs on every run).
touch "$cache"
find "$cache_dir" -maxdepth 1 -name "$suite-$arch-*.tar" ! -path "$cache" -mtime +7 -delete

# --- this run's root --------------------------------------------------------------------------
# A run killed before its cleanup (SIGKILL from a test timeout) leaves its root behind: remove
# those whose run and container are both gone. Each root records their pids.
for stale in /var/tmp/caracara-systest.*; do
  [ -d "$stale" ] || continue
  if [ ! -f "$stale/run.pid" ] && [ -z "$(find "$stale" -maxdepth 0 -mmin +10)" ]; then
    continue  # just made by a run that has not written its pid yet
  fi
  live=0
  for f in "$stale"/*.pid; do
    [ -f "$f" ] && kill -0 "$(cat "$f")" 2>/dev/null && live=1
  done
  if [ "$live" -eq 0 ]; then
    say "removing $stale, left by an earlier run"
    rm -rf --one-file-system "$stale"
  fi
done
work=$(mktemp -d /var/tmp/caracara-systest.XXXXXX)
echo $$ >"$work/run.pid"
machine=caracara-systest-$$
nspawn_pid=
topside_pid=
# The tether: two network namespaces (the vehicle's, where the container runs, and the
# topside's, where topside.sh runs) joined by a veth pair; nothing else on either.
vehicle_ns=caracara-vehicle-$$
topside_ns=caracara-topside-$$
cleanup() {
  local rc=$?
  if [ -n "$topside_pid" ]; then
    kill -TERM "$topside_pid" 2>/dev/null || true
    wait "$topside_pid" 2>/dev/null || true
  fi
  if [ -n "$nspawn_pid" ] && kill -0 "$nspawn_pid" 2>/dev/null; then
    say "stopping the container"
    kill -TERM "$nspawn_pid" 2>/dev/null || true
    for _ in $(seq 50); do kill -0 "$nspawn_pid" 2>/dev/null || break; sleep 0.2; done
    kill -KILL "$nspawn_pid" 2>/dev/null || true
    wait "$nspawn_pid" 2>/dev/null || true
  fi
  # systemd-nspawn mounts in its own namespace; unmount anything that leaked into ours anyway.
  local m
  for m in $(awk -v w="$work" 'index($2, w) == 1 { print $2 }' /proc/self/mounts | sort -r); do
    umount -l "$m" 2>/dev/null || true
  done
  rm -rf --one-file-system "$work"
  ip netns delete "$vehicle_ns" 2>/dev/null || true
  ip netns delete "$topside_ns" 2>/dev/null || true
  exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

root=$work/root
out=$work/out
mkdir -p "$root" "$out"
chmod 0777 "$out"
tar -C "$root" --numeric-owner -xpf "$cache"

if [ -n "$debs" ]; then
  # check.sh installs them with apt-get once the container runs (the maintainer scripts under
  # a real systemd and bus). For the upgrade check, copies one version up: the same files,
  # only the version (and caracara-sim's dependency on it) changed.
  for p in caracarad caracara-sim; do
    f=$(find "$debs" -maxdepth 1 -name "${p}_*_$arch.deb" | sort -V | tail -n 1)
    [ -n "$f" ] || die "no ${p}_*_$arch.deb in $debs (scripts/package.sh $arch $debs)"
    say "the root gets $f"
    install -D -m 0644 "$f" "$root/systest-debs/$(basename "$f")"
    dpkg-deb -R "$f" "$work/next-$p"
    sed -i -E 's/^(Version: .*)$/\1+systest1/; s/^(Depends: .*caracarad \(= [^)]*)\)/\1+systest1)/' \
      "$work/next-$p/DEBIAN/control"
    mkdir -p "$root/systest-debs-next"
    dpkg-deb -b "$work/next-$p" "$root/systest-debs-next/" >/dev/null
    rm -rf "$work/next-$p"
  done
  # caracara-ros: installed, checked and purged on its own (check.sh 7c), before the upgrade.
  f=$(find "$debs" -maxdepth 1 -name "caracara-ros_*_$arch.deb" | sort -V | tail -n 1)
  [ -n "$f" ] || die "no caracara-ros_*_$arch.deb in $debs (scripts/package.sh $arch $debs)"
  install -D -m 0644 "$f" "$root/systest-debs/$(basename "$f")"
  install -D -m 0755 "$here/check-debs.sh" "$root/usr/local/libexec/caracara-systest/check-debs.sh"
else
  say "installing $build into the root (cmake --install --prefix /usr)"
  DESTDIR=$root cmake --install "$build" --prefix /usr >"$work/install.log" 2>&1 \
    || { cat "$work/install.log" >&2; die "cmake --install failed"; }
fi

# The checks: a test-only unit that runs check.sh once the system is up, then powers off.
install -D -m 0755 "$here/check.sh" "$root/usr/local/libexec/caracara-systest/check.sh"
install -D -m 0644 "$here/helpers.sh" "$root/usr/local/libexec/caracara-systest/helpers.sh"
# The bounds the checks assert, from the one file every test reads (tests/bounds.json): the
# container has no python3, so they go in as a shell file.
/usr/bin/python3 "$here/../e2e/bounds.py" --shell >"$work/bounds.sh" || die "tests/e2e/bounds.py --shell failed"
install -D -m 0644 "$work/bounds.sh" "$root/usr/local/libexec/caracara-systest/bounds.sh"
install -D -m 0755 "$here/check-topside.sh" "$root/usr/local/libexec/caracara-systest/check-topside.sh"
install -D -m 0644 "$here/caracara-systest.service" "$root/etc/systemd/system/caracara-systest.service"
mkdir -p "$root/etc/systemd/system/multi-user.target.wants"
ln -sf ../caracara-systest.service "$root/etc/systemd/system/multi-user.target.wants/caracara-systest.service"
# Nothing reads the console: no getty on it.
ln -sf /dev/null "$root/etc/systemd/system/console-getty.service"
echo caracara-systest >"$root/etc/hostname"

# --- the tether and the topside (topside.sh) ---------------------------------------------------
# Namespaces left by a killed run go with their run: only the live ones are kept.
for ns in $(ip netns list 2>/dev/null | awk '/^caracara-(vehicle|topside)-[0-9]+/ { print $1 }'); do
  kill -0 "${ns##*-}" 2>/dev/null || ip netns delete "$ns" 2>/dev/null || true
done
ip netns add "$vehicle_ns"
ip netns add "$topside_ns"
ip link add tether netns "$topside_ns" type veth peer name tether netns "$vehicle_ns"
ip -n "$vehicle_ns" addr add 10.231.0.1/30 dev tether
ip -n "$topside_ns" addr add 10.231.0.2/30 dev tether
for ns in "$vehicle_ns" "$topside_ns"; do
  ip -n "$ns" link set lo up
  ip -n "$ns" link set tether up
done
# The topside's caracaractl: the build's, or the package's run with the root's own loader and
# libraries (a Debian 13 binary needs Debian 13's glibc, which this machine may not have).
top=$work/topside
mkdir -p "$top/bin" "$out/topside"
chmod 0755 "$out/topside"
if [ -n "$debs" ]; then
  dpkg-deb -x "$(find "$debs" -maxdepth 1 -name "caracarad_*_$arch.deb" | sort -V | tail -n 1)" "$top/pkg"
  # The loader itself, not a link to it (Debian 12's /lib64 link is absolute: this machine's).
  libs=$root/usr/lib/$(uname -m)-linux-gnu
  loader=$(find "$libs" -maxdepth 1 -type f -name 'ld-linux*.so.*' | head -n 1)
  printf '#!/bin/sh
exec %s --library-path %s %s "$@"
' "$loader" "$libs" "$top/pkg/usr/bin/caracaractl" \
    >"$top/bin/caracaractl"
else
  printf '#!/bin/sh
exec %s "$@"
' "$build/tools/caracaractl" >"$top/bin/caracaractl"
fi
chmod 0755 "$top/bin/caracaractl"
"$top/bin/caracaractl" --help >/dev/null || die "the topside's caracaractl does not run"
# The topside's key: the private half stays out of the container, the public half goes in.
ssh-keygen -q -t ed25519 -N '' -C caracara-topside -f "$top/id_ed25519"
cp "$top/id_ed25519.pub" "$out/topside/id_ed25519.pub"
CARACARA_BOUNDS_SH=$work/bounds.sh CARACARA_TOPSIDE_OUT=$out CARACARA_TOPSIDE_DIR=$top CARACARA_TOPSIDE_SRC=$(cd "$here/../.." && pwd) \
  timeout --signal=TERM "$timeout_s" ip netns exec "$topside_ns" "$here/topside.sh" >"$work/topside.log" 2>&1 &
topside_pid=$!

say "booting the container (systemd-nspawn --boot; at most ${timeout_s} s)"
t1=$(date +%s)
timeout --signal=TERM --kill-after=20 "$timeout_s" \
  systemd-nspawn --quiet --boot --keep-unit --register=no --machine="$machine" \
    --directory="$root" --network-namespace-path="/run/netns/$vehicle_ns" --capability=CAP_NET_ADMIN \
    --link-journal=no --resolv-conf=off \
    --console=read-only --bind="$out:/systest-out" \
    >"$work/console.log" 2>&1 &
nspawn_pid=$!
echo "$nspawn_pid" >"$work/nspawn.pid"
set +e
wait "$nspawn_pid"
nspawn_rc=$?
set -e
nspawn_pid=
say "container ran $(($(date +%s) - t1)) s (systemd-nspawn exit status $nspawn_rc)"

kill -TERM "$topside_pid" 2>/dev/null || true
wait "$topside_pid" 2>/dev/null || true
topside_pid=
[ -f "$out/check.log" ] && cat "$out/check.log"
echo "---- topside (topside.sh, outside the container) ----"
cat "$work/topside.log"
failed=0
if [ "$nspawn_rc" -eq 124 ] || [ "$nspawn_rc" -eq 137 ]; then
  say "FAIL: the container did not finish within ${timeout_s} s"
  failed=1
fi
if [ ! -f "$out/done" ]; then
  say "FAIL: check.sh did not finish"
  failed=1
fi
npass=$(grep -c '^PASS: ' "$out/results.txt" 2>/dev/null || true)
nfail=$(grep -c '^FAIL: ' "$out/results.txt" 2>/dev/null || true)
if [ -n "$debs" ]; then planned=$checks_planned_debs; else planned=$checks_planned_install; fi
[ "${nfail:-0}" -eq 0 ] || failed=1
if [ "$((${npass:-0} + ${nfail:-0}))" -ne "$planned" ]; then
  say "FAIL: $((${npass:-0} + ${nfail:-0})) checks ran, $planned planned"
  failed=1
fi
if [ "$failed" -ne 0 ]; then
  echo "---- container console (last 80 lines) ----"
  tail -n 80 "$work/console.log" || true
  if [ -f "$out/journal.txt" ]; then
    echo "---- journal of caracarad, caracara-sim, dbus (last 150 lines) ----"
    tail -n 150 "$out/journal.txt"
  fi
  grep '^FAIL: ' "$out/results.txt" 2>/dev/null || true
fi
say "${npass:-0} passed, ${nfail:-0} failed ($(($(date +%s) - t0)) s in all)"
# The line scripts/test.sh's table reads.
echo "system: ${npass:-0} of $planned checks passed"
exit "$failed"
