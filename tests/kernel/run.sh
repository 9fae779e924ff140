#!/usr/bin/env bash
# A real Linux kernel in the loop (issue #14): boots Debian's own kernel under QEMU (TCG, no
# KVM needed) with the test module tests/kernel/module/caracara_bridge.c, whose I2C adapter,
# SPI controller and GPIO chip are served by caracara-sim --kernel-bridge; caracarad runs
# with --hardware=linux on the kernel's /dev/i2c-1, /dev/spidev0.0 and /dev/gpiochip0, and
# the scenarios (tests/kernel/scenarios.py) judge it from the simulator's wire log.
#
#   tests/kernel/run.sh [WORK_DIR]     (default: build-kernel in the source tree)
#   CARACARA_KERNEL_SCENARIOS='start kill' tests/kernel/run.sh    only those scenarios (not under CI)
#   CARACARA_KERNEL_ROOT=DIR CARACARA_KERNEL_BUILD=BUILD CARACARA_KERNEL_LABEL=debian13 \
#     tests/kernel/run.sh WORK_DIR
#       the guest runs in the root DIR instead of the host's (tests/system/debian13.sh: a Debian
#       13 root with libgpiod 2) with the binaries of BUILD, a --coverage build made in DIR (not
#       rebuilt here; gcov is DIR's); the source tree, BUILD and WORK_DIR must be at the same
#       paths in DIR as on the host. The label names the run in its summary line and in
#       docs/kernel-bridge.md.
#   CARACARA_KERNEL_SUITE=trixie: boot that Debian release's own kernel (its linux-image-amd64,
#       fetched with an apt configuration of the run's own under /var/cache/caracara-kernel,
#       never the machine's sources) and build the test module against its linux-headers with
#       the guest root's compiler (CARACARA_KERNEL_ROOT must be a root of that release:
#       tests/system/debian13.sh sets both). Unset: the kernel of this machine's release.
#   The run writes its scenario list and coverage table (tests/kernel/write_doc.py) into a copy
#       of docs/kernel-bridge.md in WORK_DIR (the build tree) and judges the run against the
#       tracked section (write_doc.py --check): every scenario passed, the scenarios are the
#       recorded ones, each kernel-facing file's line coverage within ±3 percentage points of its
#       recorded figure, and the kernel of the recorded one's release series (6.1 for Debian 12,
#       6.12 for Debian 13); the kernel version itself is information ("measured last on"), so a
#       new point release passes. CARACARA_KERNEL_DOC=write copies the run's section over the
#       tracked docs/kernel-bridge.md (how a change of the project's is recorded);
#       CARACARA_KERNEL_DOC=0 does neither.
#
# Fetches the kernel, headers and kbuild .debs with apt-get download into
# /var/cache/caracara-kernel/VERSION (unpacked there, never installed), builds the module
# against those headers, builds caracarad and caracara-sim with --coverage in WORK_DIR/cov,
# boots the VM with the host root shared read-only over 9p (the guest chroots into it, so
# the host's binaries run unchanged) and WORK_DIR/out shared writable for the results, and
# prints the scenario results and the line coverage of the kernel-facing files.
#
# Every scenario or none: the scenario list is taken before the guest boots (scenarios.py
# --list), and the run passes only with every one of them passed; it ends with the line
# "LABEL: P of N scenarios passed" (scripts/test.sh reads it). A file of the kernel-facing set
# without coverage data fails the run too (tests/kernel/coverage.py); the percentage does not.
# Exit: 0 every scenario passed, 1 a failure, 77 cannot run here (not root, no QEMU...) outside
# CI; under CI (CI=true) a run that cannot happen fails with its reason.
set -euo pipefail
top=$(cd "$(dirname "$0")/../.." && pwd)
cache=/var/cache/caracara-kernel
t0=$(date +%s)
label=${CARACARA_KERNEL_LABEL:-kernel}
[ "$label" = kernel ] || label="kernel ($label)"

# What stops the run before any scenario: a skip outside CI, a failure under it.
cannot_run() {
  if [ "${CI:-}" = true ]; then
    echo "$label: FAIL: cannot run under CI: $*"
    exit 1
  fi
  echo "$label: SKIP: $*"
  exit 77
}
if [ "$(id -u)" -ne 0 ]; then
  cannot_run "needs root (apt-get download into $cache, packages for QEMU)"
fi
if [ -n "${CARACARA_KERNEL_SCENARIOS:-}" ] && [ "${CI:-}" = true ]; then
  echo "$label: FAIL: CARACARA_KERNEL_SCENARIOS under CI (CI runs every scenario)"
  exit 1
fi
work=$(mkdir -p "${1:-$top/build-kernel}" && cd "${1:-$top/build-kernel}" && pwd)
step() { echo "== $label: $* ($(( $(date +%s) - t0 )) s)"; }

# --- tools ---------------------------------------------------------------------------------
pkgs=(qemu-system-x86 busybox-static i2c-tools python3-dbus python3-gi dbus make gcc-12 kmod cpio)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  step "installing ${missing[*]}"
  apt-get update -qq || true
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null ||
    cannot_run "cannot install ${missing[*]}"
fi
# The scenarios to run, known before the guest boots: each must come back PASS.
mapfile -t scenario_list < <(/usr/bin/python3 "$top/tests/kernel/scenarios.py" --list ${CARACARA_KERNEL_SCENARIOS:-})
((${#scenario_list[@]})) || { echo "$label: FAIL: no scenario list (scenarios.py --list)"; exit 1; }

# --- kernel, headers -----------------------------------------------------------------------
own_suite=$(. /etc/os-release && echo "${VERSION_CODENAME:-}")
ksuite=${CARACARA_KERNEL_SUITE:-$own_suite}
apt_opts=()
if [ "$ksuite" != "$own_suite" ]; then
  # Another release's kernel: its package lists in an apt configuration of this run's own
  # (the archive this machine's apt uses, tests/system/mirror.sh; Debian's keyring).
  . "$top/tests/system/mirror.sh"
  mirror=$(find_mirror "$ksuite") || cannot_run "no Debian mirror for $ksuite (set CARACARA_SYSTEST_MIRROR)"
  aptdir=$cache/apt-$ksuite-$(dpkg --print-architecture)
  mkdir -p "$aptdir/lists/partial" "$aptdir/archives/partial"
  echo "deb [signed-by=/usr/share/keyrings/debian-archive-keyring.gpg] $mirror $ksuite main" >"$aptdir/sources.list"
  apt_opts=(-o "Dir::Etc::SourceList=$aptdir/sources.list" -o Dir::Etc::SourceParts=/nonexistent
            -o "Dir::State::Lists=$aptdir/lists" -o "Dir::Cache=$aptdir" -o "Dir::Cache::Archives=$aptdir/archives"
            -o Dir::Cache::pkgcache= -o Dir::Cache::srcpkgcache=)
  # Refreshed once a day: a point release's kernel replaces the last one in the archive.
  if [ -z "$(find "$aptdir/lists" -maxdepth 1 -name '*_Packages*' -mtime -1 2>/dev/null)" ]; then
    step "apt-get update for $ksuite ($mirror)"
    apt-get "${apt_opts[@]}" update -qq || true
  fi
elif ! ls "$cache"/*/.ok >/dev/null 2>&1; then
  # Nothing cached yet: fresh package lists, so the version asked for can still be downloaded.
  apt-get update -qq
fi
kver=$(apt-cache "${apt_opts[@]}" depends linux-image-amd64 2>/dev/null | sed -n 's/.*Depends: linux-image-\(.*-amd64\)$/\1/p' | head -1)
if [ -z "$kver" ] || { [ ! -f "$cache/$kver/.ok" ] && ! apt-cache "${apt_opts[@]}" show "linux-image-$kver" >/dev/null 2>&1; }; then
  # No package lists: whatever was cached last for this release.
  kver=$(ls -t "$cache" 2>/dev/null | grep -v "^apt-" | while read -r d; do
    [ "$(cat "$cache/$d/suite" 2>/dev/null || echo bookworm)" = "$ksuite" ] && echo "$d"; done | head -1)
fi
[ -n "$kver" ] || cannot_run "cannot tell which $ksuite kernel to fetch (apt-get update?)"
kdir=$cache/$kver
if [ ! -f "$kdir/.ok" ]; then
  step "fetching linux-image-$kver ($ksuite) and its headers"
  rm -rf "$kdir" && mkdir -p "$kdir/debs"
  kbuild=$(apt-cache "${apt_opts[@]}" depends "linux-headers-$kver" | sed -n 's/.*Depends: \(linux-kbuild-.*\)$/\1/p' | head -1)
  common=$(apt-cache "${apt_opts[@]}" depends "linux-headers-$kver" | sed -n 's/.*Depends: \(linux-headers-.*-common\)$/\1/p' | head -1)
  if ! (cd "$kdir/debs" && apt-get "${apt_opts[@]}" download -qq "linux-image-$kver" "linux-headers-$kver" "$common" "$kbuild" 2>/dev/null); then
    cannot_run "apt-get download of linux-image-$kver and its headers failed"
  fi
  for d in "$kdir"/debs/*.deb; do dpkg-deb -x "$d" "$kdir/root"; done
  echo "$ksuite" >"$kdir/suite"
  # The headers' Makefile includes the common tree by its installed path; point it here.
  sed -i "s#^include /usr/src/#include $kdir/root/usr/src/#" "$kdir/root/usr/src/linux-headers-$kver/Makefile"
  touch "$kdir/.ok"
fi
kroot=$kdir/root
# Debian 13's packages ship their modules under /usr/lib (merged /usr); this machine's depmod
# looks under /lib.
[ -e "$kroot/lib" ] || [ ! -d "$kroot/usr/lib/modules" ] || ln -s usr/lib "$kroot/lib"
modroot=$kroot/lib/modules/$kver
# The package's postinst would run depmod; unpacked, it is run here on the tree.
[ -f "$modroot/modules.dep" ] || /sbin/depmod -b "$kroot" "$kver"

# --- the test module -----------------------------------------------------------------------
guest_root=${CARACARA_KERNEL_ROOT:-/}
mod=$work/module
rm -rf "$mod" && mkdir -p "$mod"
cp "$top/tests/kernel/module/caracara_bridge.c" "$top/tests/kernel/module/Kbuild" "$top/sim/kernel_bridge_abi.h" "$mod/"
if [ "$ksuite" = "$own_suite" ]; then
  step "building caracara_bridge.ko for $kver"
  nice -n 10 make -s -C "$kroot/usr/src/linux-headers-$kver" M="$mod" -j2 modules 2>&1 | grep -v 'Skipping BTF generation' || true
else
  # Another release's headers: its kbuild tools and compiler (gcc-14 for trixie) are the guest
  # root's, so the module is built in a container of that root, with the kernel cache (the
  # headers' Makefile names it) and WORK_DIR at their own paths. Without the module's BTF (the
  # root has no pahole; nothing here reads it).
  [ "$guest_root" != / ] || cannot_run "CARACARA_KERNEL_SUITE=$ksuite needs CARACARA_KERNEL_ROOT, a $ksuite root"
  command -v systemd-nspawn >/dev/null || cannot_run "no systemd-nspawn (systemd-container) to build the module in $guest_root"
  step "building caracara_bridge.ko for $kver in the guest root $guest_root"
  nice -n 10 systemd-nspawn --quiet --keep-unit --register=no --machine="caracara-kbuild-$$" --directory="$guest_root" --private-network \
    --bind-ro="$cache" --bind="$work" \
    make -s -C "$kroot/usr/src/linux-headers-$kver" M="$mod" -j2 CONFIG_DEBUG_INFO_BTF_MODULES= modules 2>&1 |
    grep -v 'Skipping BTF generation' || true
fi
[ -f "$mod/caracara_bridge.ko" ] || { echo "$label: FAIL: module build failed"; exit 1; }

# --- gcov_flush.so: a caracarad dying of its fatal signal still writes its counters ----------
nice -n 10 gcc -O2 -Wall -Werror -shared -fPIC "$top/tests/kernel/gcov_flush.c" -o "$work/gcov_flush.so" -ldl

# --- caracarad and caracara-sim with coverage ----------------------------------------------
if [ -n "${CARACARA_KERNEL_BUILD:-}" ]; then
  cov=$CARACARA_KERNEL_BUILD
  step "using caracarad and caracara-sim of $cov in the guest root $guest_root"
  find "$cov" -name '*.gcda' -delete
else
  step "building caracarad, caracara-sim and caracaractl with --coverage"
  cov=$work/cov
  nice -n 10 cmake -S "$top" -B "$cov" -DCMAKE_BUILD_TYPE=Debug -DCARACARA_WERROR=ON -DCMAKE_CXX_FLAGS=--coverage >/dev/null
  nice -n 10 cmake --build "$cov" -j2 --target caracarad caracara-sim caracaractl >/dev/null
  find "$cov" -name '*.gcda' -delete
fi

# --- initramfs: busybox, the 9p modules, /init ----------------------------------------------
step "initramfs"
ird=$work/initramfs
rm -rf "$ird" && mkdir -p "$ird/bin" "$ird/lib/modules" "$ird/proc" "$ird/sys" "$ird/dev" "$ird/newroot"
cp /bin/busybox "$ird/bin/busybox"
ln -s busybox "$ird/bin/sh"
# Modules for the 9p root in load order: each one's dependencies (modules.dep) first.
declare -A seen=()
order=()
# A kernel's module name uses - and _ alike; built-in ones need no loading; Debian 13's modules
# are compressed (.ko.xz), which the initramfs's busybox insmod cannot read: unpacked below.
add_mod() {
  local rel deps d pat
  pat=$(echo "$1" | sed 's/[-_]/[-_]/g')
  grep -qE "/$pat\.ko$" "$modroot/modules.builtin" 2>/dev/null && return 0
  rel=$(grep -E "^kernel/.*/$pat\.ko(\.xz|\.zst|\.gz)?:" "$modroot/modules.dep" | head -1 | cut -d: -f1)
  [ -n "$rel" ] || { echo "$label: FAIL: module $1 not in modules.dep"; exit 1; }
  [ -z "${seen[$rel]:-}" ] || return 0
  seen[$rel]=1
  deps=$(grep -E "^$rel:" "$modroot/modules.dep" | cut -d: -f2)
  for d in $deps; do d=$(basename "$d"); add_mod "${d%%.ko*}"; done
  order+=("$rel")
}
# The 9p root, /dev/i2c-*, and whatever the test module needs that is not built in.
for m in virtio_pci 9pnet_virtio 9p i2c-dev $(/sbin/modinfo -F depends "$mod/caracara_bridge.ko" | tr ',' ' '); do
  add_mod "$m"
done
: > "$ird/modules"
for rel in "${order[@]}"; do
  name=$(basename "$rel")
  case $name in
    *.ko.xz) xz -dc "$modroot/$rel" >"$ird/lib/modules/${name%.xz}"; name=${name%.xz} ;;
    *.ko.zst) zstd -qdc "$modroot/$rel" >"$ird/lib/modules/${name%.zst}"; name=${name%.zst} ;;
    *.ko.gz) gzip -dc "$modroot/$rel" >"$ird/lib/modules/${name%.gz}"; name=${name%.gz} ;;
    *) cp "$modroot/$rel" "$ird/lib/modules/" ;;
  esac
  echo "$name" >> "$ird/modules"
done
out=$work/out
rm -rf "$out" && mkdir -p "$out"
cat > "$ird/env" <<EOF
TOP='$top'
WORK='$work'
OUT='$out'
COV='$cov'
SCENARIOS='$(printf '%s\n' "${scenario_list[@]}" | cut -f1 | tr '\n' ' ')'
EOF
printf '%s\n' "${scenario_list[@]}" > "$out/scenarios.tsv"
cp "$top/tests/kernel/guest-init.sh" "$ird/init"
chmod +x "$ird/init"
(cd "$ird" && find . | cpio -o -H newc --quiet | gzip -1) > "$work/initramfs.gz"

# --- boot ----------------------------------------------------------------------------------
step "booting $kver under QEMU (TCG)"
boot0=$(date +%s)
set +e
timeout 900 nice -n 10 qemu-system-x86_64 -machine q35 -accel tcg -cpu max -m 768 -smp 1 \
  -kernel "$kroot/boot/vmlinuz-$kver" -initrd "$work/initramfs.gz" \
  -append "console=ttyS0 panic=-1 quiet loglevel=4" \
  -nographic -no-reboot -nic none \
  -virtfs "local,path=$guest_root,mount_tag=hostroot,security_model=none,readonly=on,multidevs=remap" \
  -virtfs "local,path=$out,mount_tag=results,security_model=none" \
  > "$work/console.log" 2>&1
qemu_rc=$?
set -e
step "VM exited with $qemu_rc after $(( $(date +%s) - boot0 )) s"

touch "$out/results.txt"
if [ ! -s "$out/results.txt" ]; then
  echo "$label: the guest left no results; console log:"
  tail -60 "$work/console.log"
  [ -f "$out/guest.log" ] && tail -80 "$out/guest.log"
fi
[ -f "$out/dmesg.txt" ] && grep -iE 'caracara|BUG|WARNING|Oops|i2c|spi' "$out/dmesg.txt" | tail -20 || true

# --- coverage of the kernel-facing files, from this run alone -------------------------------
# Read with the gcov of the compiler that built them: the guest root's.
step "coverage"
cov_rc=0
if [ "$guest_root" = / ]; then
  /usr/bin/python3 "$top/tests/kernel/coverage.py" "$top" "$cov" "$out/gcov" "$out/coverage.json" >"$out/coverage.txt" || cov_rc=$?
else
  chroot "$guest_root" /usr/bin/python3 "$top/tests/kernel/coverage.py" "$top" "$cov" "$out/gcov" "$out/coverage.json" \
    >"$out/coverage.txt" || cov_rc=$?
fi
cat "$out/coverage.txt"

# --- every scenario listed, each passed ------------------------------------------------------
echo "== $label: scenarios"
cat "$out/results.txt"
pass=0
for entry in "${scenario_list[@]}"; do
  name=${entry%%$'\t'*}
  if grep -qE "^PASS $name \(" "$out/results.txt"; then
    pass=$((pass + 1))
  elif ! grep -qE "^FAIL $name( |:)" "$out/results.txt"; then
    echo "FAIL $name: no result (the guest stopped before it)"
  fi
done
total=${#scenario_list[@]}
# The run's section of docs/kernel-bridge.md (tests/kernel/write_doc.py): judged against the
# tracked record (every scenario passed, the recorded scenarios, each kernel-facing file's
# coverage within write_doc.py's COVERAGE_TOLERANCE_PP = 3 points of its figure, a kernel of the
# recorded release series; the kernel itself is information), or recorded
# (CARACARA_KERNEL_DOC=write). The run's own section is written into a copy in WORK_DIR either way.
doc_rc=0
doc_mode=${CARACARA_KERNEL_DOC:-check}
doc_label=${CARACARA_KERNEL_LABEL:-debian12}
if [ "$doc_mode" != 0 ]; then
  cp "$top/docs/kernel-bridge.md" "$work/kernel-bridge.md"
  /usr/bin/python3 "$top/tests/kernel/write_doc.py" "$work/kernel-bridge.md" "$doc_label" \
    "$out/scenarios.tsv" "$out/results.txt" "$out/coverage.json" "$kver" || doc_rc=1
  if [ "$doc_rc" -ne 0 ]; then
    echo "$label: FAIL: could not write $work/kernel-bridge.md"
  elif [ "$doc_mode" = write ]; then
    cp "$work/kernel-bridge.md" "$top/docs/kernel-bridge.md"
    echo "$label: wrote docs/kernel-bridge.md (CARACARA_KERNEL_DOC=write, kernel $kver)"
  elif ! /usr/bin/python3 "$top/tests/kernel/write_doc.py" --check "$top/docs/kernel-bridge.md" "$doc_label" \
      "$out/scenarios.tsv" "$out/results.txt" "$out/coverage.json" "$kver" | sed "s/^/$label: /"; then
    echo "$label: FAIL: the run does not hold against docs/kernel-bridge.md (above; this run's section is in"
    echo "$label:   $work/kernel-bridge.md). If the project changed it, rerun with CARACARA_KERNEL_DOC=write to record it."
    doc_rc=1
  fi
fi
echo "$label: whole run $(( $(date +%s) - t0 )) s"
[ "$cov_rc" -eq 0 ] || echo "$label: FAIL: a kernel-facing file has no coverage data (above)"
echo "$label: $pass of $total scenarios passed"
[ "$pass" -eq "$total" ] && [ "$cov_rc" -eq 0 ] && [ "$doc_rc" -eq 0 ]
