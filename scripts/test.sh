#!/usr/bin/env bash
# Installs what is needed, then builds and runs every test twice: a normal build with
# warnings as errors, and an AddressSanitizer + UndefinedBehaviorSanitizer build; and the
# arm64 cross build with its tests under qemu-user, and the arm64 Debian packages (the normal
# build's ctest builds the amd64 ones for the system test).
#   scripts/test.sh            all of it
#   scripts/test.sh normal     only the normal build (faster, for development)
#   scripts/test.sh cross      only arm64 (scripts/cross_test.sh, scripts/package.sh arm64)
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

if [ "$which" = all ] || [ "$which" = normal ]; then
  run_suite "$top/build"
fi
if [ "$which" = all ] || [ "$which" = cross ]; then
  "$top/scripts/cross_test.sh" "$top/build-arm64"
  echo "== arm64 packages"
  "$top/scripts/package.sh" arm64 "$top/build-deb"
fi
if [ "$which" = all ] || [ "$which" = sanitize ]; then
  export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1}
  export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
  run_suite "$top/build-asan" -DCARACARA_SANITIZE=ON -DCMAKE_BUILD_TYPE=Debug
fi
