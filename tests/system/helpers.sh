# The helpers the system test's two sides share, sourced by check.sh (inside the container) and
# topside.sh (on the topside, outside it). Before sourcing, the caller sets `results` (the
# results file) and may set `label` (a prefix for its PASS/FAIL lines); after it, it may
# redefine vbus (how it reaches the vehicle's bus; busctl on the system bus by default).
V=org.caracara.Vehicle1
VP=/org/caracara/Vehicle1
S=org.caracara.Simulator1
SP=/org/caracara/Simulator1

pass() { echo "PASS: ${label:-}$*" | tee -a "$results"; }
fail() { echo "FAIL: ${label:-}$*" | tee -a "$results"; }
info() { echo "INFO: $*"; }
# figure KEY VALUE UNIT WHAT: a measured figure, as tests/e2e/figures.py prints it (the suite's
# record keeps it, scripts/doc_figures.py quotes it in the docs).
figure() { echo "FIGURE: $1 $2 $3  # $4"; }
# check NAME COMMAND...: PASS if the command succeeds.
check() {
  local name=$1
  shift
  if "$@"; then pass "$name"; else fail "$name"; fi
}
now_ms() { echo $(($(date +%s%N) / 1000000)); }
# wait_until SECONDS COMMAND...: true as soon as the command succeeds, false after SECONDS.
wait_until() {
  local end=$(($(now_ms) + $1 * 1000))
  shift
  until "$@"; do
    [ "$(now_ms)" -lt "$end" ] || return 1
    sleep 0.1
  done
}
# The bounds (tests/bounds.json, as NAME=VALUE lines: tests/e2e/bounds.py --shell), which run.sh
# writes beside this file in the container and names in CARACARA_BOUNDS_SH for topside.sh.
bounds_sh=${CARACARA_BOUNDS_SH:-$(dirname "$0")/bounds.sh}
if [ -r "$bounds_sh" ]; then
  . "$bounds_sh"
else
  fail "no bounds file $bounds_sh (tests/system/run.sh writes it from tests/bounds.json)"
fi
vbus() { busctl "$@"; }
# prop BUS-NAME PATH INTERFACE PROPERTY: the value without its signature and quotes.
prop() { vbus get-property "$@" 2>/dev/null | sed -E 's/^[^ ]+ //; s/^"(.*)"$/\1/'; }
state() { prop $V $VP $V State; }
state_is() { [ "$(state)" = "$1" ]; }
# The simulator's next wire-log index (entries logged from now on have it or a larger one).
wire_next() { vbus call $S $SP $S GetWireLog t 9223372036854775808 | awk '{print $2}'; }
# pilot_lost_kill T0_US: the last pilot left the bus just after T0_US (CLOCK_MONOTONIC us): the
# pilot-lost failsafe kills (KillSource failsafe), seen no sooner than the default persistence
# (PILOT_LOST_PERSISTENCE_MS, tests/bounds.json: core/failsafe.hpp's, checked by tests/bounds_lint.py)
# after T0 and at most PILOT_LOST_KILL_LATENESS_MS_MAX later (the packaged configuration has no kill output line to time on
# the wire, so the kill is timed by polling State). Without T0_US (the pilot left at a time
# unknown): the kill alone.
PILOT_LOST_MS=$PILOT_LOST_PERSISTENCE_MS
pilot_lost_kill() {
  local seen
  wait_until $((PILOT_LOST_MS / 1000 + 5)) state_is killed || { info "not killed: State $(state)"; return 1; }
  seen=$(mono_us)
  [ "$(prop $V $VP $V KillSource)" = failsafe ] || { info "KillSource $(prop $V $VP $V KillSource)"; return 1; }
  [ -n "${1:-}" ] || return 0
  figure system.pilot_lost_kill_seen_ms $(((seen - $1) / 1000)) ms "the last pilot left -> killed, as State polled shows it (pilot-lost persistence $PILOT_LOST_MS ms)"
  [ $((seen - $1)) -ge $((PILOT_LOST_MS * 1000)) ] && [ $((seen - $1)) -le $(((PILOT_LOST_MS + PILOT_LOST_KILL_LATENESS_MS_MAX) * 1000)) ]
}
