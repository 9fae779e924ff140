#!/usr/bin/env bash
# The main job: caracarad driving the simulated vehicle on a private bus, shown through
# caracaractl as an operator would see it: status, a motion, status again, a kill.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
"$top/scripts/deps.sh"
build=${CARACARA_BUILD:-$top/build}
"$top/scripts/build.sh" "$build" >/dev/null
echo "built in $build"

dir=$(mktemp -d /tmp/caracara-demo.XXXXXX)
pids=()
cleanup() {
  # The daemon first (it zeroes the thrusters on its way out), then the vehicle, then the bus.
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do
    kill "${pids[i]}" 2>/dev/null || true
    wait "${pids[i]}" 2>/dev/null || true
  done
  rm -rf "$dir"
}
trap cleanup EXIT

cat >"$dir/bus.conf" <<CONF
<!DOCTYPE busconfig PUBLIC "-//freedesktop//DTD D-Bus Bus Configuration 1.0//EN"
 "http://www.freedesktop.org/standards/dbus/1.0/busconfig.dtd">
<busconfig><type>session</type><listen>unix:path=$dir/bus</listen><auth>EXTERNAL</auth>
<policy context="default"><allow send_destination="*" eavesdrop="true"/><allow eavesdrop="true"/><allow own="*"/></policy>
</busconfig>
CONF
bus="unix:path=$dir/bus"
# The socket file appears before dbus-daemon listens; its printed address means it does.
dbus-daemon --nofork --print-address=1 --config-file="$dir/bus.conf" >"$dir/dbus.log" 2>&1 & pids+=($!)
for _ in $(seq 200); do grep -qF "$bus" "$dir/dbus.log" 2>/dev/null && break; sleep 0.05; done

"$build/sim/caracara-sim" --socket "$dir/sim.sock" --bus-address "$bus" >"$dir/sim.log" 2>&1 & pids+=($!)
# The simulator takes its bus name after it listens on its socket.
for _ in $(seq 200); do
  busctl --address="$bus" status org.caracara.Simulator1 >/dev/null 2>&1 && break; sleep 0.05
done
# The dive recorder writes into the demo's directory instead of /var/log/caracara.
mkdir -p "$dir/dives"
printf '[recorder]\ndirectory = "%s"\n' "$dir/dives" >"$dir/caracarad.toml"
"$build/daemon/caracarad" --hardware="sim:$dir/sim.sock" --bus-address "$bus" --config "$dir/caracarad.toml" & pids+=($!)

ctl() { echo; echo "\$ caracaractl $*"; "$build/tools/caracaractl" --bus-address "$bus" "$@"; }
sim_speeds() {
  local out=""
  for i in 0 1 2 3 4 5 6 7; do
    out+=" $(busctl --address="$bus" get-property org.caracara.Simulator1 /org/caracara/Simulator1/thruster/$i \
             org.caracara.Simulator1.Thruster OrderedSpeed | awk '{printf "0x%02X", $2}')"
  done
  echo "simulated thrusters' ordered SPEED bytes (0x80 = stop):$out"
}

for _ in $(seq 200); do
  "$build/tools/caracaractl" --bus-address "$bus" status >/dev/null 2>&1 && break; sleep 0.05
done
echo; echo "== the daemon is up, killed: every start comes up killed (kill source \"start\")"
ctl status
echo; echo "== clear-kill arms it: zero output for the arming delay, then ready"
ctl clear-kill
for _ in $(seq 100); do
  busctl --address="$bus" get-property org.caracara.Vehicle1 /org/caracara/Vehicle1 org.caracara.Vehicle1 State | grep -q ready && break
  sleep 0.1
done
echo; echo "== forward at 60% while yawing at 40% for 3 seconds"
ctl motion forward=0.6 turn-right=0.4 --for 3 &
hold=$!
sleep 2
sim_speeds
ctl status
wait $hold
sleep 0.2
echo; echo "== the client let go: the daemon zeroed the thrusters"
sim_speeds
echo; echo "== kill"
ctl kill
sim_speeds
ctl status
ctl thrust 1000 0 0 0 0 0 0 0 --once || echo "(refused while killed, as it should be)"

echo; echo "== the dive, from ClearKill to the kill, as the recorder wrote it"
ctl dives --dir "$dir/dives"
plot=${CARACARA_DEMO_PLOT:-/tmp/caracara-demo-dive.png}
ctl plot last --dir "$dir/dives" --out "$plot"
echo "(motor values, currents, temperatures and orientation, the kill marked: $plot)"
