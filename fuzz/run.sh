#!/usr/bin/env bash
# One bounded fuzzing run, as CTest runs it:
#   fuzz/run.sh FUZZER NAME WORKDIR SECONDS
# Fuzzes from a fresh copy-free corpus: new inputs go to WORKDIR/NAME/corpus (emptied first);
# the checked-in seeds (corpus/NAME) and regression inputs (regressions/NAME) are read, never
# written. Fails on any crash, leak, timeout, sanitizer report or failed invariant; the input
# that did it is kept as WORKDIR/NAME/crash-* (or leak-*, timeout-*).
# CARACARA_FUZZ_SECONDS in the environment overrides SECONDS; CARACARA_FUZZ_SEED fixes the seed
# (1 under CI).
set -euo pipefail
fuzzer=$1 name=$2 work=$3 seconds=${CARACARA_FUZZ_SECONDS:-$4}
here=$(cd "$(dirname "$0")" && pwd)
out="$work/$name"
rm -rf "$out"
mkdir -p "$out/corpus"
dirs=("$out/corpus" "$here/corpus/$name")
[ -d "$here/regressions/$name" ] && dirs+=("$here/regressions/$name")
opts=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1
      -artifact_prefix="$out/")
[ -f "$here/$name.dict" ] && opts+=(-dict="$here/$name.dict")
# Under CI the smoke run draws the same inputs every time (seed 1): it fails for what a change
# did, not for what one draw found; new ground is the long runs' (scripts/fuzz.sh, random
# seeds). CARACARA_FUZZ_SEED says another.
seed=${CARACARA_FUZZ_SEED:-}
[ -n "$seed" ] || [ "${CI:-}" != true ] || seed=1
[ -z "$seed" ] || opts+=(-seed="$seed")
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
echo "fuzz $name: ${seconds}s from ${dirs[*]:1}"
status=0
"$fuzzer" "${opts[@]}" "${dirs[@]}" 2>"$out/log" || status=$?
# The figures a reader wants, then the report when it failed.
grep -E '^(stat::|#[0-9]+[[:space:]]+(INITED|DONE))' "$out/log" || true
if [ "$status" -ne 0 ]; then
  echo "fuzz $name: FAILED (exit $status); log: $out/log; input: $(ls "$out" | grep -E '^(crash|leak|timeout|oom)-' || echo none)"
  tail -n 60 "$out/log"
  exit 1
fi
