#!/usr/bin/env bash
# The long fault soak: at least a million bus transactions (issue 17), figures printed.
#   scripts/soak.sh [TRANSACTIONS] [SEED]
# The daemon's loop runs flat out (loop_rate_hz = 0) so the bus carries a million transactions
# in minutes; the command stream stays at 50 Hz.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
build=${CARACARA_BUILD_DIR:-$top/build}
"$top/scripts/build.sh" "$build" >/dev/null
CARACARA_BUILD_DIR=$build exec /usr/bin/python3 "$top/tests/soak/soak.py" \
  --seconds 36000 --transactions "${1:-1000000}" --seed "${2:-1}" --loop-rate 0
