#!/usr/bin/env bash
# Builds what the benchmarks need (RelWithDebInfo, so callgrind sees symbols) and runs them:
#   bench/run.sh [--quick] [--out FILE] [--rss-seconds S] [--only dbus,wire,loop,cost] [--keep]
# Prints the table; writes the figures as JSON to bench/results.json (or --out FILE).
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
build=${CARACARA_BENCH_BUILD:-$top/build-bench}
cmake -S "$top" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$build" -j"${JOBS:-$(nproc)}" --target caracarad caracara-sim caracara-bench caracara-bench-floor caracara-bridge >/dev/null
# /usr/bin/python3 explicitly: only the standard library is used, but a pyenv python on PATH
# is not guaranteed to be a working interpreter for system tools.
exec /usr/bin/python3 "$top/bench/run.py" --build "$build" "$@"
