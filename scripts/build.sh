#!/usr/bin/env bash
# Configures and builds one build tree: scripts/build.sh DIR [cmake options...]
# CARACARA_BUILD_TARGET builds only that target (scripts/fuzz.sh: fuzzers).
set -euo pipefail
dir=$1; shift
top=$(cd "$(dirname "$0")/.." && pwd)
# ccache when present: CI builds the same sources as its last run.
. "$top/scripts/ccache.sh" "$top"
cmake -S "$top" -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo "$@" >/dev/null
cmake --build "$dir" -j"$(nproc)" ${CARACARA_BUILD_TARGET:+--target "$CARACARA_BUILD_TARGET"}
