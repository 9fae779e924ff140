#!/usr/bin/env bash
# Installs what is needed, then builds and runs every test twice: a normal build with
# warnings as errors, and an AddressSanitizer + UndefinedBehaviorSanitizer build; the arm64
# cross build with its tests under qemu-user, and the arm64 Debian packages (the normal
# build's ctest builds the amd64 ones for the system test); then the libFuzzer harnesses
# (clang, fuzz/) for CARACARA_FUZZ_SECONDS (20) each, two at a time: a smoke run (they build,
# run from their seeds and regression inputs, find nothing); scripts/fuzz.sh runs them long.
#   scripts/test.sh            all of it
#   scripts/test.sh normal     only the normal build (faster, for development)
#   scripts/test.sh cross      only arm64 (scripts/cross_test.sh, scripts/package.sh arm64)
#   scripts/test.sh fuzz       only the fuzzers (scripts/fuzz.sh runs them longer)
# It ends with one table (scripts/suite_table.py): each suite, ran or not, its counts and its
# time; it fails when a suite failed or did not run where this machine can run it, and under CI
# (CI=true) on any skip. The table is also written as a record: bench/suite-results.json after
# a full run (scripts/test.sh alone), build-results/suites.json otherwise. Every step runs even after one failed, so the table is whole.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
# Warm or cold: a run that finds none of the suite's caches (ccache, the debootstrapped roots,
# the kernel packages, the npm packages) is a cold one, as on a fresh machine; the record keeps
# the last of each (scripts/suite_table.py). CARACARA_SUITE_CACHES=warm|cold says it instead.
if [ -z "${CARACARA_SUITE_CACHES:-}" ]; then
  CARACARA_SUITE_CACHES=cold
  for c in /var/cache/ccache /var/cache/caracara-systest /var/cache/caracara-kernel /var/cache/caracara-npm; do
    [ -n "$(ls -A "$c" 2>/dev/null)" ] && CARACARA_SUITE_CACHES=warm
  done
fi
export CARACARA_SUITE_CACHES
echo "== caches: $CARACARA_SUITE_CACHES"
"$top/scripts/deps.sh"
which=${1:-all}
jobs=$(nproc)
# Tests at twice the cores: the end-to-end tests wait on the vehicle's clock, not the CPU (43 of
# them, 643 s of test time, took 30 s user and 26 s system CPU at -j4 on 2 cores, 2026-12-05);
# the Debian 13 suite, which compiles, takes two slots (tests/system/system.cmake) and runs its
# own ctest at the cores. scripts/cross_test.sh reads it too; the sanitized build's tests run at
# the cores (sanitize_suite).
export CARACARA_TEST_JOBS=${CARACARA_TEST_JOBS:-$((2 * jobs))}

# What the table reads: each step's selection, exit status and time, and each ctest run's
# results (JUnit, passed tests' output kept whole: the suites' counts are in it) and labels.
results=${CARACARA_SUITE_RESULTS:-$top/build-results}
rm -rf "$results"
mkdir -p "$results"
# ctest_run STEP DIR [ctest options...]
ctest_run() {
  local step=$1 dir=$2; shift 2
  # (Called where set -e does not hold: each command's failure is returned by hand.)
  ctest --test-dir "$dir" --show-only=json-v1 "$@" >"$results/$step.json" || return
  ctest --test-dir "$dir" --output-on-failure --output-junit "$results/$step.xml" \
    --test-output-size-passed 1048576 --test-output-size-failed 1048576 "$@"
}
# run_suite STEP DIR CTEST_JOBS [cmake options...]
run_suite() {
  local step=$1 dir=$2 test_jobs=$3; shift 3
  echo "== build $dir ($*)"
  "$top/scripts/build.sh" "$dir" -DCARACARA_WERROR=ON "$@" || return
  echo "== test $dir (ctest -j$test_jobs)"
  ctest_run "$step" "$dir" -j"$test_jobs" --timeout 900
}
# Each step's wall time, so that the 30-minute budget of CI can be read from its log.
stamp() { echo "== $1 done at $((SECONDS / 60)) min $((SECONDS % 60)) s"; }
# step NAME COMMAND...: runs it if selected, records "NAME SELECTED EXIT SECONDS", goes on.
failed=0
step() {
  local name=$1 selected=0 rc=0 t0=$SECONDS; shift
  case $which in all|"$name") selected=1 ;; esac
  [ "$name" = arm64-packages ] && case $which in all|cross) selected=1 ;; esac
  if [ "$selected" = 1 ]; then
    "$@" || rc=$?
    [ "$rc" -eq 0 ] || failed=1
    stamp "$name (exit $rc)"
  fi
  echo "$name $selected $rc $((SECONDS - t0))" >>"$results/steps.txt"
}
fuzz_suite() {
  echo "== build $top/build-fuzz (libFuzzer harnesses)"
  CARACARA_FUZZ_BUILD="$top/build-fuzz" "$top/scripts/fuzz.sh" build || return
  echo "== fuzz $top/build-fuzz"
  ctest_run fuzz "$top/build-fuzz" -j2 -L fuzz
}
cross_suite() {
  CARACARA_CTEST_JUNIT="$results/cross.xml" "$top/scripts/cross_test.sh" "$top/build-arm64"
}
arm64_packages() {
  echo "== arm64 packages"
  "$top/scripts/package.sh" arm64 "$top/build-deb"
}
sanitize_suite() {
  export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1}
  export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
  # At the cores, not twice: under ASan the bridge's and the cockpit's tests keep a core busy,
  # and beside three others they missed their waits (the 256 MB listing's first page, the
  # failsafe banner while surfacing; 2026-12-05).
  run_suite sanitize "$top/build-asan" "$jobs" -DCARACARA_SANITIZE=ON -DCMAKE_BUILD_TYPE=Debug
}

step normal run_suite normal "$top/build" "$CARACARA_TEST_JOBS"
step cross cross_suite
step arm64-packages arm64_packages
step sanitize sanitize_suite
step fuzz fuzz_suite
# The figures the normal step's tests printed, as the record the docs quote (bench/figures.json;
# scripts/doc_figures.py --write then rewrites README.md and docs/ from it, CTest doc_figures
# checks them). Written after the last step: the later steps' own doc_figures check judges the
# docs against the record they were committed with, not against this run's figures.
[ ! -f "$results/normal.xml" ] || /usr/bin/python3 "$top/scripts/doc_figures.py" --record "$results/normal.xml" || failed=1

# The table as a record too: a full run's is bench/suite-results.json (commit it; README's CI
# table is written from it by scripts/suite_table.py --readme, checked by CTest readme_suites).
record=$results/suites.json
[ "$which" != all ] || record=$top/bench/suite-results.json
table=0
CARACARA_SUITE_SECONDS=$SECONDS /usr/bin/python3 "$top/scripts/suite_table.py" "$results" --record "$record" || table=$?
stamp "all"
[ "$failed" -eq 0 ] && [ "$table" -eq 0 ]
