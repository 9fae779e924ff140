#!/usr/bin/env bash
# The long fault soak: at least a million bus transactions (issue 17; ten million by default),
# figures printed and written to bench/soak-results.json (CARACARA_SOAK_RESULTS overrides),
# which the README cites.
#   scripts/soak.sh [TRANSACTIONS] [SEED]
# The daemon's loop runs flat out (loop_rate_hz = 0): on 2 CPUs the bus carries about 60 000
# transactions a second, a million in under half a minute, so the default runs ten million
# (a few minutes, with more faults and simulator restarts); the command stream stays at 50 Hz.
# Fails on a lost command, an order after a kill's zero or in flight at a kill, fd or RSS
# growth (tests/soak/soak.py).
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
build=${CARACARA_BUILD_DIR:-$top/build}
results=${CARACARA_SOAK_RESULTS:-$top/bench/soak-results.json}
"$top/scripts/build.sh" "$build" >/dev/null
CARACARA_BUILD_DIR=$build exec /usr/bin/python3 "$top/tests/soak/soak.py" \
  --seconds 36000 --transactions "${1:-10000000}" --seed "${2:-1}" --loop-rate 0 --results "$results"
