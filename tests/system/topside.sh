#!/bin/bash
# The topside half of the system test's SSH checks: run by run.sh on this machine, outside the
# container, in the network namespace at the topside end of the tether (a veth pair to the
# container's namespace, 10.231.0.2 -> 10.231.0.1). It waits for the container's check.sh
# (check-topside.sh) to say the vehicle's sshd and users are ready, then reaches the vehicle the
# way a pilot's laptop does: caracaractl -H, busctl -H and the python3-dbus example over SSH.
# PASS/FAIL lines go to the shared results.txt; BOUND lines give the measured bounds.
#
# Environment (run.sh sets it): CARACARA_TOPSIDE_OUT (the results directory, also bound into
# the container), CARACARA_TOPSIDE_DIR (this side's directory: key, ssh config, bin/caracaractl),
# CARACARA_TOPSIDE_SRC (the source tree, for examples/).
set -u
OUT=$CARACARA_TOPSIDE_OUT
TOP=$CARACARA_TOPSIDE_DIR
SRC=$CARACARA_TOPSIDE_SRC
results=$OUT/results.txt
label="topside: "
. "$(dirname "$0")/helpers.sh"
# CLOCK_MONOTONIC in microseconds: the clock of the simulator's wire log (one kernel, no time
# namespace between this side and the container).
mono_us() { /usr/bin/python3 -c 'import time; print(time.monotonic_ns() // 1000)'; }

# ssh as docs/topside.md sets it up, from a config of this test's own (never ~/.ssh): every
# ssh that caracaractl, busctl and python start finds this wrapper first in PATH.
cat >"$TOP/ssh_config" <<CONF
Host vehicle
  HostName 10.231.0.1
Host *
  IdentityFile $TOP/id_ed25519
  IdentitiesOnly yes
  UserKnownHostsFile $OUT/topside/known_hosts
  GlobalKnownHostsFile /dev/null
  StrictHostKeyChecking yes
  BatchMode yes
  ConnectTimeout 5
  ServerAliveInterval 2
  ServerAliveCountMax 3
CONF
printf '#!/bin/sh\nexec /usr/bin/ssh -F %s "$@"\n' "$TOP/ssh_config" >"$TOP/bin/ssh"
chmod 0755 "$TOP/bin/ssh"
export PATH=$TOP/bin:$PATH

echo "== topside: waiting for the vehicle's sshd (check-topside.sh)"
if ! wait_until 300 test -e "$OUT/topside/ready"; then
  fail "the vehicle never said its sshd was ready"
  exit 1
fi
t0=$(now_ms)

# Reads go through the visitor, who is not in the caracara group: anyone may read.
rd() { busctl -H visitor@vehicle "$@"; }
vbus() { rd "$@"; }
# orders_since INDEX: "time_ns addr7 speed" of every thruster order on the wire since INDEX.
orders_since() {
  rd call $S $SP $S GetWireLog t "$1" |
    grep -oE '[0-9]+ [0-9]+ [0-9]+ "i2c" [0-9]+ false 3 [0-9]+ 100 [0-9]+' | awk '{print $2, $5, $8}'
}
# latest_at INDEX SPEED N: at least N thrusters' latest order since INDEX carries SPEED.
latest_at() {
  orders_since "$1" | awk -v s="$2" -v n="$3" '{ last[$2] = $3 } END { c = 0; for (a in last) if (last[a] == s) c++; exit !(c >= n) }'
}
# all_zero_since INDEX: all eight thrusters' latest order since INDEX is a zero (0x80 or 0x7F).
all_zero_since() {
  orders_since "$1" | awk '{ last[$2] = $3 } END { c = 0; for (a in last) if (last[a] == 128 || last[a] == 127) c++; exit !(c == 8) }'
}
# first_zeros_us INDEX: when the last of the eight thrusters got its first zero order since INDEX (us).
first_zeros_us() {
  orders_since "$1" | awk '($3 == 128 || $3 == 127) && !($2 in z) { z[$2] = $1; n++ }
    END { if (n < 8) exit 1; m = 0; for (a in z) if (z[a] > m) m = z[a]; printf "%.0f\n", m / 1000 }'
}
ctl_pid=
stop_ctl() {
  if [ -n "$ctl_pid" ]; then
    kill -INT "$ctl_pid" 2>/dev/null
    wait "$ctl_pid" 2>/dev/null
    ctl_rc=$?
    ctl_pid=
  fi
}
trap 'stop_ctl; [ -n "${mon_pid:-}" ] && kill "$mon_pid" 2>/dev/null' EXIT

# --- reading, as a user outside the caracara group -------------------------------------------------
t=$(now_ms)
st=$(state)
info "busctl -H visitor@vehicle get-property State: '$st' ($(($(now_ms) - t)) ms, SSH login included)"
check "busctl -H visitor@vehicle reads State over SSH (ready)" [ "$st" = ready ]
status=$(caracaractl -H visitor@vehicle status 2>&1)
rc=$?
echo "$status" | sed 's/^/  | /'
check "caracaractl -H visitor@vehicle status exits 0 and shows the vehicle ready" \
  bash -c '[ "$1" = 0 ] && grep -q "State: ready" <<<"$2"' _ "$rc" "$status"

# --- refusals: the bus policy (4), SSH (4), an unreachable vehicle (3) -------------------------------
rc=0; out=$(caracaractl -H visitor@vehicle motion forward=0.5 --once 2>&1) || rc=$?
info "visitor motion: exit $rc: $out"
check "caracaractl -H visitor@vehicle motion: exit 4 (the bus policy refuses a user outside caracara)" [ "$rc" = 4 ]
rc=0; out=$(caracaractl -H visitor@vehicle kill 2>&1) || rc=$?
check "caracaractl -H visitor@vehicle kill: exit 4" [ "$rc" = 4 ]
check "after the refused commands the vehicle is still ready" state_is ready
rc=0; out=$(caracaractl -H nosuchuser@vehicle status 2>&1) || rc=$?
info "nosuchuser: exit $rc: $out"
check "caracaractl -H nosuchuser@vehicle status: exit 4 (SSH refuses the login)" \
  bash -c '[ "$1" = 4 ] && grep -q "SSH refused" <<<"$2"' _ "$rc" "$out"
rc=0; out=$(caracaractl -H skipper@vehicle:2222 status 2>&1) || rc=$?
info "port 2222: exit $rc: $out"
check "caracaractl -H skipper@vehicle:2222 (nothing listens there): exit 3" [ "$rc" = 3 ]
rc=0; out=$(caracaractl -H skipper@10.231.9.9 status 2>&1) || rc=$?
info "10.231.9.9: exit $rc: $out"
check "caracaractl -H skipper@10.231.9.9 (no route): exit 3" [ "$rc" = 3 ]

# --- motion in hold mode, as a member of the caracara group -----------------------------------------
# Y 0.5 drives motors 0, 2, 4, 6 at 4425: SPEED 0x80 + round(4425 * 102 / 8850) = 179.
idx=$(wire_next)
caracaractl -H skipper@vehicle motion forward=0.5 --for 60 >"$TOP/hold.log" 2>&1 &
ctl_pid=$!
check "caracaractl -H skipper@vehicle motion forward=0.5 (held): four thrusters at SPEED 179 on the wire" \
  wait_until 10 latest_at "$idx" 179 4
controller=$(prop $V $VP $V Controller)
creds=$(rd call org.freedesktop.DBus /org/freedesktop/DBus org.freedesktop.DBus GetConnectionCredentials s "$controller" 2>&1)
info "the commanding client $controller: $creds"
# The bridge is skipper's process on the vehicle: the bus knows no other side of the link.
check "the daemon's commanding client $controller is a connection of skipper's on the vehicle (the bridge)" \
  bash -c 'grep -qE "\"UnixUserID\" u $2( |$)" <<<"$1"' _ "$creds" "$(cat "$OUT/topside/skipper.uid")"
sleep 1
check "the hold keeps them there over SSH (1 s later, latest orders still SPEED 179)" latest_at "$idx" 179 4
idx=$(wire_next)
t_left=$(mono_us)
stop_ctl
check "Ctrl-C (SIGINT) ends the remote hold with exit 0" [ "$ctl_rc" = 0 ]
check "the daemon zeroed all eight thrusters when the bridge left" wait_until 5 all_zero_since "$idx"
cat "$TOP/hold.log" | sed 's/^/  hold | /'
# That bridge was the last pilot: the pilot-lost failsafe kills after its persistence, and a
# plain clear-kill re-arms (the condition ended with the kill).
rearm() {
  local rc=0
  caracaractl -H skipper@vehicle clear-kill || rc=$?
  [ "$rc" = 0 ] && wait_until 10 state_is ready
}
check "the bridge was the last pilot: killed by the failsafe (pilot-lost) after its persistence" \
  pilot_lost_kill "$t_left"
check "caracaractl -H skipper@vehicle clear-kill re-arms after the pilot-lost kill" rearm

# --- monitor, kill, a refused command, clear-kill -----------------------------------------------------
caracaractl -H visitor@vehicle monitor >"$TOP/monitor.log" 2>&1 &
mon_pid=$!
wait_until 10 grep -q . "$TOP/monitor.log"
rc=0; caracaractl -H skipper@vehicle kill || rc=$?
check "caracaractl -H skipper@vehicle kill: exit 0" [ "$rc" = 0 ]
check "the vehicle is killed" state_is killed
check "caracaractl -H visitor@vehicle monitor shows State=killed" wait_until 5 grep -q "State=killed" "$TOP/monitor.log"
rc=0; out=$(caracaractl -H skipper@vehicle thrust 1000 0 0 0 0 0 0 0 --once 2>&1) || rc=$?
check "while killed, thrust over SSH is refused by the daemon: exit 1 ($out)" \
  bash -c '[ "$1" = 1 ] && grep -q Killed <<<"$2"' _ "$rc" "$out"
rc=0; caracaractl -H skipper@vehicle clear-kill || rc=$?
check "caracaractl -H skipper@vehicle clear-kill: exit 0" [ "$rc" = 0 ]
ready_after_kill() { awk '/State=killed/ { k = 1 } k && /State=ready/ { r = 1 } END { exit !r }' "$TOP/monitor.log"; }
check "monitor shows the vehicle ready again after the arming delay" wait_until 10 ready_after_kill
kill -INT "$mon_pid"
wait "$mon_pid"
rc=$?
mon_pid=
check "Ctrl-C ends the remote monitor with exit 0" [ "$rc" = 0 ]
sed 's/^/  monitor | /' "$TOP/monitor.log"

# --- a dropped link: the ssh process killed -------------------------------------------------------------
# 2000 on every motor: SPEED 0x80 + round(2000 * 102 / 8850) = 151.
v=2000
spd=151
drive_all() {
  idx=$(wire_next)
  caracaractl -H skipper@vehicle thrust $v $v $v $v $v $v $v $v --for 120 >"$TOP/hold.log" 2>&1 &
  ctl_pid=$!
  wait_until 10 latest_at "$idx" $spd 8
}
wait_until 10 state_is ready
check "dropped link: skipper holds all eight thrusters at SPEED $spd over SSH" drive_all
ssh_pid=$(pgrep -P "$ctl_pid" -x ssh)
[ -n "$ssh_pid" ] || fail "dropped link: no ssh process under caracaractl (pid $ctl_pid)"
idx=$(wire_next)
t_kill=$(mono_us)
kill -KILL "$ssh_pid"
wait "$ctl_pid"
ctl_rc=$?
ctl_pid=
check "caracaractl exits 3 when its ssh is killed (the link dropped)" [ "$ctl_rc" = 3 ]
sed 's/^/  hold | /' "$TOP/hold.log"
check "dropped link: the daemon zeroes all eight thrusters" wait_until 5 all_zero_since "$idx"
z=$(first_zeros_us "$idx")
drop_ms=$(((z - t_kill) / 1000))
figure topside.dropped_link_zero_ms "$drop_ms" ms "dropped link (ssh killed on the topside) to the last thruster's first zero order"
check "dropped link: zero on the wire within CLIENT_LOSS_ZERO_MS_MAX ($CLIENT_LOSS_ZERO_MS_MAX ms) of the kill ($drop_ms ms)" \
  bash -c '[ -n "$1" ] && [ "$2" -le "$3" ]' _ "$z" "$drop_ms" "$CLIENT_LOSS_ZERO_MS_MAX"
check "dropped link: the last pilot gone, killed by the failsafe (pilot-lost) after its persistence" \
  pilot_lost_kill "$t_kill"
check "dropped link: clear-kill re-arms" rearm

# --- a stalled link: the tether cut without closing ----------------------------------------------------
timeout_ms=$(prop $V $VP $V CommandTimeoutMs)
check "stalled link: skipper holds all eight thrusters at SPEED $spd over SSH" drive_all
idx=$(wire_next)
t_cut=$(mono_us)
ip link set tether down
sleep 1.5
ip link set tether up
wait_until 10 state_is ready # the link is back (a read gets through)
z=$(first_zeros_us "$idx")
stall_ms=$(( (${z:-0} - t_cut) / 1000))
figure topside.stalled_link_zero_ms "$stall_ms" ms "stalled link (tether down, TCP open) to the last thruster's first zero order (CommandTimeoutMs $timeout_ms)"
check "stalled link: the command timeout zeroes all eight thrusters within ${timeout_ms} + STALLED_LINK_ZERO_MARGIN_MS ($STALLED_LINK_ZERO_MARGIN_MS) ms ($stall_ms ms)" \
  bash -c '[ -n "$1" ] && [ "$2" -le $(($3 + $4)) ]' _ "$z" "$stall_ms" "$timeout_ms" "$STALLED_LINK_ZERO_MARGIN_MS"
sleep 1
idx_stop=$(wire_next)
if kill -0 "$ctl_pid" 2>/dev/null; then
  resumed=$(latest_at "$idx" $spd 8 && echo "resumed at SPEED $spd" || echo "not resumed")
  info "after the tether came back (1.5 s cut): caracaractl still holds; thrusters $resumed"
  t_left=$(mono_us)
else
  info "after the tether came back (1.5 s cut): caracaractl had ended"
  t_left= # its bridge left when it ended: the kill is checked, not its time
fi
idx=$idx_stop
stop_ctl
check "after the stall the hold is released and the thrusters are zero" wait_until 5 all_zero_since "$idx"
check "after the stall: the last pilot gone, killed by the failsafe (pilot-lost) after its persistence" \
  pilot_lost_kill "$t_left"
check "after the stall: clear-kill re-arms" rearm

# --- the python3-dbus mission example over SSH ------------------------------------------------------------
t=$(now_ms)
rc=0
timeout 120 /usr/bin/python3 "$SRC/examples/mission_square.py" --host skipper@vehicle --leg-seconds 0.3 \
  --turn-degrees 20 >"$TOP/mission.log" 2>&1 || rc=$?
sed 's/^/  mission | /' "$TOP/mission.log"
check "examples/mission_square.py --host skipper@vehicle drives its square over SSH and kills ($(($(now_ms) - t)) ms, exit $rc)" \
  [ "$rc" = 0 ]

echo "== topside: $(($(now_ms) - t0)) ms"
touch "$OUT/topside/done"
