#!/usr/bin/env bash
# Runs the libFuzzer harnesses (fuzz/) for longer than CI does, growing a corpus outside the
# repository, and prints executions and coverage (libFuzzer's cov:/ft: and its final stats).
#   scripts/fuzz.sh                      every harness, 10 minutes each
#   scripts/fuzz.sh seabotix 3600        one harness for an hour
#   scripts/fuzz.sh config -runs=10000000
#   scripts/fuzz.sh build                only builds them (scripts/test.sh's fuzz step)
# Harnesses: those fuzz/CMakeLists.txt declares (caracara_fuzzer), or "all".
# The grown corpus and any crash-*/leak-*/timeout-* input stay in
# ${CARACARA_FUZZ_DIR:-/var/tmp/caracara-fuzz}/<harness>/; a crash input belongs in
# fuzz/regressions/<harness>/ once its cause is fixed. Builds build-fuzz/ with clang-14 first.
# Each harness's executions, coverage (cov, ft), corpus size and time go to
# bench/fuzz-results.json (CARACARA_FUZZ_RESULTS overrides), which the README cites; a run of
# some harnesses replaces only their entries.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
# The list is fuzz/CMakeLists.txt's, so that a new harness is fuzzed here too.
mapfile -t harnesses < <(sed -nE 's/^caracara_fuzzer\(([a-z_]+) .*/\1/p' "$top/fuzz/CMakeLists.txt")
which=${1:-all}
limit=${2:-600}
store=${CARACARA_FUZZ_DIR:-/var/tmp/caracara-fuzz}
build=${CARACARA_FUZZ_BUILD:-$top/build-fuzz}

# The tree of the harnesses: clang, coverage-instrumented libraries (scripts/build.sh: ccache).
# -U: a tree configured before takes fuzz/CMakeLists.txt's CARACARA_FUZZ_SECONDS again, not a
# stale cached one (the environment's CARACARA_FUZZ_SECONDS still wins when the tests run).
build_fuzzers() {
  CARACARA_BUILD_TARGET=fuzzers "$top/scripts/build.sh" "$build" -DCARACARA_FUZZ=ON -DCARACARA_WERROR=ON \
    -DCMAKE_CXX_COMPILER="$(command -v clang++-14 || command -v clang++)" -UCARACARA_FUZZ_SECONDS
}
if [ "$which" = build ]; then
  build_fuzzers
  exit
fi
if [ "$which" != all ]; then
  [[ " ${harnesses[*]} " == *" $which "* ]] || { echo "fuzz.sh: no harness '$which' (${harnesses[*]})" >&2; exit 2; }
  harnesses=("$which")
fi
case $limit in
  -runs=*) stop=("$limit") ;;
  *[!0-9]*|'') echo "fuzz.sh: '$limit' is neither seconds nor -runs=N" >&2; exit 2 ;;
  *) stop=(-max_total_time="$limit") ;;
esac

build_fuzzers >/dev/null
# The JavaScript harnesses' npm packages (fuzz/node), from its lock file.
/usr/bin/python3 "$top/tests/npm_packages.py" "$top/fuzz/node"

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
results=${CARACARA_FUZZ_RESULTS:-$top/bench/fuzz-results.json}
failed=()
summary=()
records=()
for h in "${harnesses[@]}"; do
  out="$store/$h"
  mkdir -p "$out/corpus"
  dirs=("$out/corpus" "$top/fuzz/corpus/$h")
  [ -d "$top/fuzz/regressions/$h" ] && dirs+=("$top/fuzz/regressions/$h")
  opts=("${stop[@]}" -timeout=10 -rss_limit_mb=4096 -print_final_stats=1 -print_pcs=0 -artifact_prefix="$out/")
  [ -f "$top/fuzz/$h.dict" ] && opts+=(-dict="$top/fuzz/$h.dict")
  echo "== fuzz $h (${stop[*]}), corpus $out/corpus"
  status=0
  start=$(date +%s)
  "$build/fuzz/fuzz_$h" "${opts[@]}" "${dirs[@]}" 2>"$out/log" || status=$?
  secs=$(( $(date +%s) - start ))
  grep -E '^#[0-9]+[[:space:]]+(INITED|DONE)|^stat::' "$out/log" || true
  # DONE, or after a crash the last progress line.
  done_line=$(grep -E '^#[0-9]+[[:space:]]+[A-Z]+ +cov:' "$out/log" | tail -n1 || true)
  execs=$(grep -E '^stat::number_of_executed_units' "$out/log" | awk '{print $2}')
  summary+=("$(printf '%-12s %12s execs %6ss  %s' "$h" "${execs:-?}" "$secs" \
    "$(sed -E 's/^#[0-9]+[[:space:]]+[A-Z]+ +//; s/ lim:.*exec\/s/ exec\/s/; s/ rss:.*//' <<<"$done_line")")")
  records+=("$h" "$status" "$secs" "${execs:-0}" "$done_line" "$(find "$out/corpus" -type f | wc -l)" "${stop[*]}"
           "$(date +%Y-%m-%dT%H:%M:%S%z)")
  if [ "$status" -ne 0 ]; then
    failed+=("$h")
    echo "fuzz $h: FAILED (exit $status); input: $(ls "$out" | grep -E '^(crash|leak|timeout|oom)-' | tr '\n' ' ')"
    grep -E 'ERROR|invariant failed|runtime error|SUMMARY' "$out/log" | head -n 5
  fi
done
echo "== summary"
printf '%s\n' "${summary[@]}"
/usr/bin/python3 - "$results" "${records[@]}" <<'PY'
import json, os, re, sys
path, rec = sys.argv[1], sys.argv[2:]
data = json.load(open(path)) if os.path.exists(path) else {"harnesses": {}}
for i in range(0, len(rec), 8):
    h, status, secs, execs, done, corpus, limit, finished = rec[i:i + 8]
    cov = re.search(r"cov: (\d+)", done)
    ft = re.search(r"ft: (\d+)", done)
    data["harnesses"][h] = {"passed": status == "0", "seconds": int(secs), "executions": int(execs),
                            "cov": int(cov.group(1)) if cov else None, "ft": int(ft.group(1)) if ft else None,
                            "corpus_files": int(corpus), "limit": limit,
                            "finished": finished}
data["command"] = "scripts/fuzz.sh"
data["cpus"] = os.cpu_count()
with open(path, "w") as f:
    json.dump(data, f, indent=1, sort_keys=True)
    f.write("\n")
print("fuzz.sh: counts written to %s" % path)
PY
if ((${#failed[@]})); then
  echo "fuzz.sh: failed: ${failed[*]} (logs in $store/<harness>/log)"
  exit 1
fi
