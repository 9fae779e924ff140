#!/usr/bin/env bash
# Installs what is needed, then builds and runs every test twice: a normal build with
# warnings as errors, and an AddressSanitizer + UndefinedBehaviorSanitizer build; the arm64
# cross build with its tests under qemu-user, and the arm64 Debian packages (the normal
# build's ctest builds the amd64 ones for the system test); then the libFuzzer harnesses
# (clang, fuzz/) for CARACARA_FUZZ_SECONDS (60) each, two at a time.
#   scripts/test.sh            all of it
#   scripts/test.sh normal     only the normal build (faster, for development)
#   scripts/test.sh cross      only arm64 (scripts/cross_test.sh, scripts/package.sh arm64)
#   scripts/test.sh fuzz       only the fuzzers (scripts/fuzz.sh runs them longer)
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
"$top/scripts/deps.sh"
which=${1:-all}
jobs=$(nproc)

run_suite() {
  local dir=$1; shift
  echo "== build $dir ($*)"
  "$top/scripts/build.sh" "$dir" -DCARACARA_WERROR=ON "$@"
  echo "== test $dir"
  ctest --test-dir "$dir" --output-on-failure -j"$jobs" --timeout 900
}
# Each step's wall time, so that the 30-minute budget of CI can be read from its log.
stamp() { echo "== $1 done at $((SECONDS / 60)) min $((SECONDS % 60)) s"; }

if [ "$which" = all ] || [ "$which" = normal ]; then
  run_suite "$top/build"
  stamp "normal build"
fi
if [ "$which" = all ] || [ "$which" = cross ]; then
  "$top/scripts/cross_test.sh" "$top/build-arm64"
  echo "== arm64 packages"
  "$top/scripts/package.sh" arm64 "$top/build-deb"
  stamp "arm64"
fi
if [ "$which" = all ] || [ "$which" = sanitize ]; then
  export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1}
  export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
  run_suite "$top/build-asan" -DCARACARA_SANITIZE=ON -DCMAKE_BUILD_TYPE=Debug
  stamp "ASan+UBSan build"
fi
if [ "$which" = all ] || [ "$which" = fuzz ]; then
  echo "== build $top/build-fuzz (libFuzzer harnesses)"
  cmake -S "$top" -B "$top/build-fuzz" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCARACARA_FUZZ=ON -DCARACARA_WERROR=ON \
    -DCMAKE_CXX_COMPILER="$(command -v clang++-14 || command -v clang++)" >/dev/null
  cmake --build "$top/build-fuzz" -j"$jobs" --target fuzzers
  echo "== fuzz $top/build-fuzz"
  ctest --test-dir "$top/build-fuzz" --output-on-failure -j2 -L fuzz
  stamp "fuzzers"
fi
