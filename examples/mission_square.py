#!/usr/bin/python3
"""Example mission for the Caracara vehicle: drive a square with SetMotion.

    mission_square.py [--system | --user | --bus-address ADDR | --host [USER@]HOST[:PORT]] [--leg-seconds S] ...

Waits until caracarad (org.caracara.Vehicle1) is ready (every start of the daemon comes up
killed, kill source "start": --arm clears that kill, and only that one), then four times: drive forward for
--leg-seconds, and yaw 90 degrees clockwise by thrust while watching the Teensy's heading
(Orientation). Commands are re-sent faster than the daemon's command timeout, which zeroes the
thrusters when a command stream goes silent. At the end (or on any error, or Ctrl-C) the
vehicle is killed, and the mission checks that the state is "killed".

Exit status: 0 the square was driven and the vehicle is killed; 1 the mission failed (the
reason is printed); 2 bad arguments; 3 the daemon is not there.

Try it against the simulator:
    caracara-sim --socket /tmp/sim.sock --user &
    caracarad --hardware=sim:/tmp/sim.sock --user &
    ./mission_square.py --user --arm

From the topside, over SSH (the vehicle's sshd, a key, and a user in the caracara group:
docs/topside.md):
    ./mission_square.py --host pilot@vehicle --arm

--host connects libdbus to the address "unixexec:path=ssh,argv1=-xT,...,argv4=systemd-stdio-bridge":
libdbus runs ssh itself, and ssh runs systemd-stdio-bridge on the vehicle, which connects to the
vehicle's system bus as the SSH user. That is the address systemctl -H, busctl -H and
caracaractl -H use (sd_bus_open_system_remote), so the bus policy judges the SSH user, and when
the link drops, the bridge leaves the bus and caracarad zeroes the thrusters (and, no other
pilot being connected, the pilot-lost failsafe kills the vehicle after 5 s). (A Unix socket
forwarded with ssh -L does not work for python3-dbus: the bus authenticates the topside's uid,
sent by libdbus, against the vehicle user sshd runs as, and refuses them when they differ.)

Needs python3-dbus (Debian: apt install python3-dbus).
"""

import argparse
import math
import re
import signal
import sys
import time

import dbus

SERVICE = "org.caracara.Vehicle1"
ROOT = "/org/caracara/Vehicle1"
VEHICLE_IFACE = "org.caracara.Vehicle1"
TEENSY_PATH = ROOT + "/teensy"
TEENSY_IFACE = "org.caracara.Vehicle1.Teensy"
PROPS = "org.freedesktop.DBus.Properties"


class MissionError(Exception):
    pass


def wrap(angle):
    """An angle in radians wrapped into (-pi, pi]."""
    a = math.fmod(angle + math.pi, 2 * math.pi)
    if a <= 0:
        a += 2 * math.pi
    return a - math.pi


def deg(rad):
    return math.degrees(rad)


class Vehicle:
    def __init__(self, bus):
        self.bus = bus
        self.root = bus.get_object(SERVICE, ROOT, introspect=False)
        self.teensy = bus.get_object(SERVICE, TEENSY_PATH, introspect=False)
        self.vehicle = dbus.Interface(self.root, VEHICLE_IFACE)

    def prop(self, name):
        return self.root.Get(VEHICLE_IFACE, name, dbus_interface=PROPS)

    def state(self):
        return str(self.prop("State"))

    def kill_source(self):
        return str(self.prop("KillSource"))

    def clear_kill(self):
        self.vehicle.ClearKill()

    def orientation(self):
        """(heading, pitch, roll) in radians, as the Teensy reports them (docs/frames.md): heading
        clockwise from above, pitch + nose up, roll + right side down."""
        o = self.teensy.Get(TEENSY_IFACE, "Orientation", dbus_interface=PROPS)
        return float(o[0]), float(o[1]), float(o[2])

    def motion(self, forward=0.0, turn_right=0.0):
        """SetMotion takes the packet seed's axes (docs/frames.md): x + towards port, y + forward,
        z + deeper, yaw + clockwise seen from above, pitch + nose up, roll + right side down. This
        mission only drives forward and turns right (clockwise); each -1..1, 0 stops."""
        self.vehicle.SetMotion(0.0, float(forward), 0.0, float(turn_right), 0.0, 0.0)

    def kill(self):
        self.vehicle.Kill()


class Mission:
    def __init__(self, vehicle, args):
        self.v = vehicle
        self.args = args
        self.t0 = time.monotonic()
        self.last_print = 0.0
        # Re-send (and read the heading) every 50 ms, and at least three times per command
        # timeout, so that one late message never lets the daemon zero the thrusters.
        timeout_ms = int(vehicle.prop("CommandTimeoutMs"))
        self.period = min(0.05, timeout_ms / 3000.0)

    def log(self, text):
        print("[%6.2f s] %s" % (time.monotonic() - self.t0, text), flush=True)

    def report(self, what, force=False):
        now = time.monotonic()
        if force or now - self.last_print >= 0.5:
            self.last_print = now
            heading, pitch, roll = self.v.orientation()
            self.log("%-14s heading %7.1f deg  nose up %5.1f deg  roll right %5.1f deg" %
                     (what, deg(heading), deg(pitch), deg(roll)))

    def wait_ready(self):
        deadline = time.monotonic() + self.args.ready_timeout
        shown = None
        while True:
            state = self.v.state()
            if state == "ready":
                self.log("vehicle ready")
                return
            if state == "killed" and self.args.arm and self.v.kill_source() == "start":
                # Every daemon start comes up killed; --arm is the pilot's decision to arm it.
                self.log("arming the vehicle (ClearKill; it started killed)")
                self.v.clear_kill()
                continue
            if state in ("killed", "powered-off", "fault"):
                raise MissionError("the vehicle is %s; clear it before running a mission" % state)
            if state != shown:
                self.log("waiting for the vehicle (state %s)" % state)
                shown = state
            if time.monotonic() > deadline:
                raise MissionError("the vehicle did not become ready within %g s" % self.args.ready_timeout)
            time.sleep(0.05)

    def check_state(self):
        state = self.v.state()
        if state != "ready":
            raise MissionError("the vehicle left the ready state (now %s)" % state)

    def forward(self, leg):
        what = "leg %d forward" % leg
        end = time.monotonic() + self.args.leg_seconds
        while time.monotonic() < end:
            self.v.motion(forward=self.args.speed)
            self.report(what)
            time.sleep(self.period)
        self.check_state()

    def turn(self, leg):
        """Yaw 90 degrees clockwise by thrust: a PD controller on the Teensy's heading."""
        what = "leg %d turn" % leg
        start = self.v.orientation()[0]
        target = wrap(start + math.radians(self.args.turn_degrees))
        self.log("%s: heading %.1f deg -> %.1f deg" % (what, deg(start), deg(target)))
        deadline = time.monotonic() + self.args.turn_timeout
        prev_yaw, prev_t = start, time.monotonic()
        rate = 0.0
        settled = 0
        while True:
            yaw = self.v.orientation()[0]
            now = time.monotonic()
            if yaw != prev_yaw and now > prev_t:
                rate = wrap(yaw - prev_yaw) / (now - prev_t)
                prev_yaw, prev_t = yaw, now
            err = wrap(target - yaw)
            if abs(err) < self.args.tolerance and abs(rate) < 0.1:
                settled += 1
                if settled >= 3:
                    break
            else:
                settled = 0
            demand = max(-self.args.yaw_demand, min(self.args.yaw_demand, 1.5 * err - 0.6 * rate))
            self.v.motion(turn_right=demand)
            self.report(what)
            if now > deadline:
                raise MissionError("%s did not reach %.1f deg within %g s (at %.1f deg)" %
                                   (what, deg(target), self.args.turn_timeout, deg(yaw)))
            time.sleep(self.period)
        self.v.motion()
        self.check_state()
        self.report("%s done" % what, force=True)

    def run(self):
        self.wait_ready()
        self.report("start", force=True)
        for leg in range(1, 5):
            self.forward(leg)
            self.turn(leg)
        self.v.motion()
        self.report("square done", force=True)


def on_sigterm(signum, frame):
    raise KeyboardInterrupt


def escape_address_value(text):
    """A value of a D-Bus address: bytes outside [-0-9A-Za-z_/.*] become %XX (libdbus insists)."""
    return "".join(chr(b) if re.fullmatch(rb"[-0-9A-Za-z_/.*]", bytes([b])) else "%%%02x" % b
                   for b in text.encode())


def remote_address(host):
    """The address of a vehicle's system bus over SSH, as sd_bus_open_system_remote() builds it:
    [USER@]HOST[:PORT] (an IPv6 HOST in brackets)."""
    m = re.fullmatch(r"(?:([^@\[\]/:]+)@)?(\[[0-9A-Fa-f:.]+\]|[^@\[\]/:]+)(?::([0-9]+))?", host)
    if not m:
        raise ValueError("--host needs [USER@]HOST[:PORT], not %r" % host)
    user, name, port = m.groups()
    target = (user + "@" if user else "") + name.strip("[]")
    argv = ["-xT"] + (["-p", port] if port else []) + ["--", target, "systemd-stdio-bridge"]
    return "unixexec:path=ssh," + ",".join("argv%d=%s" % (i, escape_address_value(a))
                                              for i, a in enumerate(argv, 1))


def connect(args):
    if args.host:
        return dbus.bus.BusConnection(remote_address(args.host))
    if args.bus_address:
        return dbus.bus.BusConnection(args.bus_address)
    if args.user:
        return dbus.SessionBus()
    return dbus.SystemBus()


def main():
    p = argparse.ArgumentParser(description="Drive a square with the Caracara vehicle, then kill it.")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--system", action="store_true", help="use the system bus (default)")
    where.add_argument("--user", action="store_true", help="use the session bus")
    where.add_argument("--bus-address", metavar="ADDR", help="use the bus at ADDR, e.g. unix:path=/tmp/bus")
    where.add_argument("-H", "--host", metavar="[USER@]HOST[:PORT]",
                       help="use the system bus of HOST over SSH (systemd-stdio-bridge there, as caracaractl -H)")
    p.add_argument("--leg-seconds", type=float, default=3.0, help="forward time per side (default 3)")
    p.add_argument("--speed", type=float, default=0.4, help="forward demand, 0..1 (default 0.4)")
    p.add_argument("--yaw-demand", type=float, default=0.5, help="largest yaw demand, 0..1 (default 0.5)")
    p.add_argument("--turn-degrees", type=float, default=90.0, help="turn per corner (default 90)")
    p.add_argument("--tolerance", type=float, default=0.08, help="heading tolerance in radians (default 0.08)")
    p.add_argument("--turn-timeout", type=float, default=30.0, help="seconds allowed per turn (default 30)")
    p.add_argument("--arm", action="store_true",
                   help="arm a vehicle that started killed (kill source \"start\") with ClearKill; "
                        "any other kill is left for a person to clear")
    p.add_argument("--ready-timeout", type=float, default=30.0, help="seconds to wait for ready (default 30)")
    args = p.parse_args()
    if not (0 < args.speed <= 1 and 0 < args.yaw_demand <= 1 and args.leg_seconds >= 0):
        p.error("--speed and --yaw-demand must be in (0, 1], --leg-seconds >= 0")
    if args.host:
        try:
            remote_address(args.host)
        except ValueError as e:
            p.error(str(e))

    # SIGTERM ends the mission like Ctrl-C: stop and kill on the way out.
    signal.signal(signal.SIGTERM, on_sigterm)

    try:
        bus = connect(args)
        if not bus.name_has_owner(SERVICE):
            print("mission: caracarad (%s) is not running on this bus" % SERVICE, file=sys.stderr)
            return 3
        vehicle = Vehicle(bus)
    except dbus.DBusException as e:
        print("mission: cannot reach the bus: %s" % e.get_dbus_message(), file=sys.stderr)
        return 3

    mission = Mission(vehicle, args)
    failure = None
    try:
        mission.run()
    except MissionError as e:
        failure = str(e)
    except dbus.DBusException as e:
        failure = "%s: %s" % (e.get_dbus_name(), e.get_dbus_message())
    except KeyboardInterrupt:
        failure = "interrupted"
    finally:
        # Whatever happened: stop the vehicle.
        try:
            vehicle.kill()
        except dbus.DBusException as e:
            failure = failure or "Kill failed: %s" % e.get_dbus_message()
    try:
        state = vehicle.state()
    except dbus.DBusException as e:
        state = "unknown (%s)" % e.get_dbus_message()
    mission.log("vehicle killed, state %s" % state)
    if failure:
        print("mission: FAILED: %s" % failure, file=sys.stderr)
        return 1
    if state != "killed":
        print("mission: FAILED: the vehicle is %s after Kill" % state, file=sys.stderr)
        return 1
    mission.log("mission complete")
    return 0


if __name__ == "__main__":
    sys.exit(main())
