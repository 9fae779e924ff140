"""Scenarios of the kernel test (tests/kernel/run.sh), run inside the VM.

caracara-sim serves /dev/caracara-bridge (the test module's I2C adapter, SPI controller and
GPIO chip); caracarad runs with its default --hardware=linux on /dev/i2c-1, /dev/spidev0.0
and /dev/gpiochip0. Each scenario is judged from the simulator's wire log and inspection API.

    python3 scenarios.py RESULTS_FILE [SCENARIO...]
    python3 scenarios.py --list [SCENARIO...]

writes one line per scenario, "PASS name (seconds)" or "FAIL name: reason", to RESULTS_FILE.
--list prints the scenarios that a run would take, "name<TAB>what it proves" (the first line
of its docstring), one a line: tests/kernel/run.sh counts them before the guest boots, and a
scenario without a result line is a failure. An unknown name is an error.
"""

import errno
import fcntl
import grp
import os
import pwd
import re
import signal
import struct
import subprocess
import sys
import time
import traceback

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "e2e"))
import dbus  # noqa: E402
import harness  # noqa: E402
from harness import (BUS_IFACE, BUS_PATH, DEFAULT_MT, ERR, MOTORS, TEENSY_IFACE, TEENSY_PATH,  # noqa: E402
                     VEHICLE, ZERO, Rig, binary, error_name, order_bytes,
                     poll, pump_main_loop, speed_byte)

BRIDGE = "/dev/caracara-bridge"
I2C_BUS = 1
I2C_DEV = "/dev/i2c-%d" % I2C_BUS
DRIVER = "/sys/bus/platform/drivers/caracara-i2c"
DRIVER_ID = "caracara-i2c"
# Thrusters 6 and 7 sit behind a PCA9544A at 0x70, channels 1 and 2 (the daemon and the
# simulator read the same file).
MUX = 0x70
MUXED = {6: 1, 7: 2}
THRUSTERS = "".join(
    "[[thruster]]\naddress = 0x%02X\n%s\n" % (
        mt, ("mux_address = 0x%02X\nmux_channel = %d\n" % (MUX, MUXED[i])) if i in MUXED else "")
    for i, mt in enumerate(DEFAULT_MT))
# The test module's GPIO chip names its lines like a Raspberry Pi header.
GPIO = {
    "kill_switch": {"chip": "gpiochip0", "line": "GPIO17"},
    "kill_output": {"chip": "gpiochip0", "line": "GPIO27"},
    "power_off_output": {"chip": "gpiochip0", "line": "GPIO22"},
    "scl": {"chip": "gpiochip0", "line": "GPIO3"},
    "sda": {"chip": "gpiochip0", "line": "GPIO2"},
}
# The test module's injected faults (tests/kernel/module/caracara_bridge.c, at its top).
PARAMS = "/sys/module/caracara_bridge/parameters/"
GPIO_OP_REQUEST, GPIO_OP_GET = 1, 6
RECOVERY = {"enabled": True, "attempts": 3, "backoff_ms": 50, "driver_id": DRIVER_ID,
            "unbind_path": DRIVER + "/unbind", "bind_path": DRIVER + "/bind", "device_wait_ms": 3000}


class KernelRig(Rig):
    """harness.Rig with the simulator on the kernel bridge and the daemon on the kernel."""

    START_TIMEOUT = 60.0  # TCG is slow

    def __init__(self, **kw):
        kw.setdefault("control", {"arming_delay_ms": 300, "command_timeout_ms": 60000})
        kw.setdefault("gpio", False)
        # timeout_ms and retries: the real i2c-dev takes I2C_TIMEOUT and I2C_RETRIES at every open.
        kw.setdefault("extra_config", {"gpio": GPIO, "recovery": RECOVERY,
                                       "i2c": {"device": I2C_DEV, "timeout_ms": 100, "retries": 1}})
        kw.setdefault("extra_toml", THRUSTERS)
        # devices_for_the_daemon_alone runs the daemon and a pilot as users of their own.
        kw.setdefault("bus_policy_extra", '<allow user="*"/>')
        super().__init__(**kw)

    def start(self, daemon=True):
        # The simulator reads the daemon's file too (thrusters, muxes, driver id).
        orig_spawn = self._spawn

        def spawn(name, argv):
            if name == "caracara-sim":
                with open(self.config_path, "w") as f:
                    f.write(self.config_text())
                argv = [binary("caracara-sim"), "--kernel-bridge", BRIDGE, "--config", self.config_path,
                        "--bus-address", self.address]
            return orig_spawn(name, argv)

        self._spawn = spawn
        return super().start(daemon)

    def start_daemon(self):
        self.daemon_exit = None
        self._spawn("caracarad", [binary("caracarad"), "--bus-address", self.address, "--config", self.config_path])
        poll(lambda: self.conn.name_has_owner(VEHICLE) or self._died("caracarad"), self.START_TIMEOUT,
             message="caracarad did not take its name")
        self._check_alive("caracarad")

    # -- the wire log --

    def orders(self, since=0):
        """[(thruster index, data bytes, entry)] of the order writes logged since `since`."""
        _, entries = self.wire_log(since)
        out = []
        for e in entries:
            if e.bus == "i2c" and not e.read and e.result == "ack" and len(e.data) == 3:
                mt = e.addr << 1
                if mt in DEFAULT_MT:
                    out.append((DEFAULT_MT.index(mt), list(e.data), e))
        return out

    def bus(self, name):
        return self.vget(name, BUS_PATH, BUS_IFACE)


class Fail(AssertionError):
    pass


def check(cond, message):
    if not cond:
        raise Fail(message)


def wait_wire(rig, since, pred, timeout=10.0, message="not in the wire log"):
    def f():
        return [e for e in rig.wire_log(since)[1] if pred(e)]
    return poll(f, timeout, message=message)


# --- scenarios ------------------------------------------------------------------------------

def sc_start(rig):
    """The daemon's first orders are zero, to all eight, before it takes its name; the muxes
    are selected through the real adapter. It comes up killed (source "start"), the kill output
    asserted through the real GPIO chip, until ClearKill arms it."""
    check(rig.state() == "killed" and rig.vget("KillSource") == "start",
          "a fresh daemon is %s (%s), not killed by start" % (rig.state(), rig.vget("KillSource")))
    check(bool(rig.sim_get("KillOutput")), "the kill output is not asserted at start")
    rig.arm(60)
    orders = rig.orders()
    check(orders, "no orders in the wire log")
    first_nonzero = [o for o in orders if o[1][0] != ZERO]
    check(not first_nonzero, "non-zero orders before any command: %s" % first_nonzero[:3])
    seen = {i for i, _, _ in orders}
    check(seen == set(range(MOTORS)), "zero orders reached only %s" % sorted(seen))
    for i, data, _ in orders[:MOTORS]:
        check(data == order_bytes(DEFAULT_MT[i], 0), "thruster %d zero order %s" % (i, data))
    check(rig.sim_speeds() == [ZERO] * MOTORS, "sim speeds %s" % rig.sim_speeds())
    check(os.path.exists(I2C_DEV), I2C_DEV + " missing")


def mux_selected_before(rig, since, idx):
    """Every non-zero order to muxed thruster idx logged since `since` went out with the mux
    on the thruster's channel: the last control byte written to the mux before it (possibly
    before `since`: the tracker does not select a channel that is already on) selects it."""
    _, entries = rig.wire_log(0)
    want = 0x04 | MUXED[idx]
    sel = None
    orders = 0
    for e in entries:
        if e.bus != "i2c" or e.result != "ack":
            continue
        if e.addr == MUX and not e.read and e.data:
            sel = e.data[-1]
        if e.addr << 1 == DEFAULT_MT[idx] and not e.read and len(e.data) == 3 and e.data[0] != ZERO \
                and e.index >= since:
            orders += 1
            if sel != want:
                return False
    return orders > 0


def sc_set_thrust(rig):
    """Per-thruster orders reach the wire through the real adapter, thrusters 6 and 7 with their mux channel selected first."""
    values = [1500, 0, -1500, 0, 0, 0, 2500, -2500]
    since = rig.wire_next()
    rig.thrust(values)
    rig.wait_sim_speeds([speed_byte(v) for v in values], 20)
    # Read before the wire log is searched: under a loaded TCG guest that search once took long
    # enough for the 60 s command timeout to zero the orders first.
    last = rig.sim_last_orders()
    for i, v in enumerate(values):
        got = [o for o in rig.orders(since) if o[0] == i and o[1] == order_bytes(DEFAULT_MT[i], v)]
        check(got, "thruster %d: no order %s on the wire" % (i, order_bytes(DEFAULT_MT[i], v)))
    for idx in MUXED:
        check(mux_selected_before(rig, since, idx), "thruster %d ordered without its mux channel" % idx)
    for i, v in enumerate(values):
        check(list(last[i]) == order_bytes(DEFAULT_MT[i], v), "LastOrder %d" % i)


def sc_set_motion(rig):
    """SetMotion(y) mixes to the four forward thrusters (one behind the mux); the wire matches MotorValues."""
    rig.thrust([0] * MOTORS)
    rig.wait_sim_zero(20)
    since = rig.wire_next()
    rig.motion(y=0.5)
    # y moves motors 0, 2, 4, 6 forward (6 behind the mux), the others stay at zero.
    def ok():
        s = rig.sim_speeds()
        return all(s[i] > ZERO for i in (0, 2, 4, 6)) and all(s[i] == ZERO for i in (1, 3, 5, 7)) and \
            len({s[i] for i in (0, 2, 4, 6)}) == 1
    poll(ok, 20, message="SetMotion(y) did not reach the thrusters: %s" % rig.sim_speeds())
    check(mux_selected_before(rig, since, 6), "thruster 6 ordered without its mux channel")
    vals = rig.motor_values()
    for i in range(MOTORS):
        check(rig.sim_speeds()[i] == speed_byte(vals[i]), "motor %d value %d vs wire" % (i, vals[i]))


def sc_kill(rig):
    """Kill: zero orders on the wire and the kill output high (a real GPIO line) by the reply; orders stay zero while killed; ClearKill drops the output."""
    rig.thrust([2000] * 4 + [0] * 4)
    rig.wait_sim_speeds([speed_byte(2000)] * 4 + [ZERO] * 4, 20)
    since = rig.wire_next()
    rig.vcall("Kill")
    check(rig.state() == "killed", "state %s" % rig.state())
    check(rig.sim_speeds() == [ZERO] * MOTORS, "not zero at the reply: %s" % rig.sim_speeds())
    zeros = {i for i, d, _ in rig.orders(since) if d[0] == ZERO}
    check(zeros >= {0, 1, 2, 3}, "zero orders only to %s" % sorted(zeros))
    check(bool(rig.sim_get("KillOutput")), "kill output not asserted")
    edges = wait_wire(rig, since, lambda e: e.bus == "gpio" and e.addr == 27 and list(e.data) == [1], 5,
                      "no kill output edge (line 27 high) in the wire log")
    check(edges, "kill output edge")
    # Orders while killed stay zero.
    rig.thrust([2000] + [0] * 7) if error_name(rig.thrust, [2000] + [0] * 7) is None else None
    rig.wait_orders_refreshed()
    check(rig.sim_speeds() == [ZERO] * MOTORS, "a killed vehicle drove")
    since = rig.wire_next()
    rig.vcall("ClearKill")
    rig.wait_state("ready", 20)
    wait_wire(rig, since, lambda e: e.bus == "gpio" and e.addr == 27 and list(e.data) == [0], 5,
              "no kill output release edge in the wire log")
    check(not rig.sim_get("KillOutput"), "kill output still asserted")


def sc_kill_switch(rig):
    """A kill switch edge (a real GPIO line event) kills with source "switch", zeroes the thrusters, asserts the kill output; ClearKill is refused while set."""
    rig.thrust([1800] + [0] * 7)
    rig.wait_sim_speeds([speed_byte(1800)] + [ZERO] * 7, 20)
    since = rig.wire_next()
    rig.sim_call("SetKillSwitch", True, signature="b")
    try:
        rig.wait_state("killed", 10)
        check(rig.vget("KillSource") == "switch", "KillSource %r" % rig.vget("KillSource"))
        rig.wait_sim_zero(5)
        _, entries = rig.wire_log(since)
        sw = [e for e in entries if e.bus == "gpio" and e.addr == 17]
        check(sw and list(sw[0].data) == [1], "no kill switch edge logged")
        zero = [e for e in entries if e.bus == "i2c" and len(e.data) == 3 and e.addr << 1 == DEFAULT_MT[0]
                and e.data[0] == ZERO and e.index > sw[0].index]
        check(zero, "no zero order to thruster 0 after the switch edge")
        check(bool(rig.sim_get("KillOutput")), "kill output not asserted by the switch")
        check(error_name(rig.vcall, "ClearKill") == ERR + "KillSwitchSet", "ClearKill not refused while set")
    finally:
        rig.sim_call("SetKillSwitch", False, signature="b")
    time.sleep(0.3)
    check(rig.state() == "killed", "releasing the switch cleared the kill")
    rig.vcall("ClearKill")
    rig.wait_state("ready", 20)


def sc_thruster_faults(rig):
    """A NACKing thruster (-EREMOTEIO through i2c-dev) is counted, named, and once unreachable kills with source "device"; corrupted replies are counted as bad-checksum."""
    rig.thrust([0] * MOTORS)
    n0 = int(rig.vget("Nacks", harness.thruster_path(5), harness.THRUSTER_IFACE))
    since = rig.wire_next()
    rig.sim_thruster_call(5, "SetNack", True, signature="b")
    try:
        # The count goes on from earlier scenarios: a NACK of this one makes it grow.
        poll(lambda: int(rig.vget("Nacks", harness.thruster_path(5), harness.THRUSTER_IFACE)) > n0, 15)
        check(rig.vget("LastError", harness.thruster_path(5), harness.THRUSTER_IFACE) == "nack", "LastError")
        wait_wire(rig, since, lambda e: e.bus == "i2c" and e.result == "nack" and e.addr << 1 == DEFAULT_MT[5], 10,
                  "no NACK of thruster 5 in the wire log")
        # Unreachable (three failed transfers in a row): it would keep its last order, so killed.
        poll(lambda: rig.state() == "killed", 10, message="an unreachable thruster did not kill")
        check(rig.vget("KillSource") == "device", "kill source %s" % rig.vget("KillSource"))
    finally:
        rig.sim_thruster_call(5, "SetNack", False, signature="b")
    poll(lambda: bool(rig.vget("Online", harness.thruster_path(5), harness.THRUSTER_IFACE)), 15,
         message="thruster 5 did not come back")
    check(rig.vget("State", BUS_PATH, BUS_IFACE) == "ok", "one NACKing thruster failed the bus")
    rig.sim_thruster_call(6, "CorruptReplies", dbus.UInt32(2), "checksum", signature="us")
    poll(lambda: int(rig.vget("BadReplies", harness.thruster_path(6), harness.THRUSTER_IFACE)) >= 2, 20,
         message="corrupted replies not counted")
    check(rig.vget("LastError", harness.thruster_path(6), harness.THRUSTER_IFACE) == "bad-checksum", "bad-checksum")


def sc_teensy(rig):
    """The Teensy over spidev: frames, busy answers retried and counted, a Turn acknowledged."""
    tget = lambda n: rig.vget(n, TEENSY_PATH, TEENSY_IFACE)  # noqa: E731
    poll(lambda: bool(tget("Online")), 15, message="Teensy not online over spidev")
    since = rig.wire_next()
    spi = wait_wire(rig, since, lambda e: e.bus == "spi", 10, "no SPI frames in the wire log")
    check(all(e.result == "ok" for e in spi), "SPI results %s" % {e.result for e in spi})
    b0 = int(tget("BusyRetries"))
    rig.sim_teensy_call("InjectFault", "busy", dbus.UInt32(2), signature="su")
    poll(lambda: int(tget("BusyRetries")) >= b0 + 2, 15, message="busy answers not counted")
    acks = int(rig.sim_teensy("Acknowledgements"))
    result = {}
    rig.obj(VEHICLE, TEENSY_PATH).get_dbus_method("Turn", TEENSY_IFACE)(
        0.3, signature="d", reply_handler=lambda *a: result.setdefault("ok", True),
        error_handler=lambda e: result.setdefault("error", e), timeout=60)
    poll(lambda: result, 40, pump=pump_main_loop, message="Turn never replied")
    check("error" not in result, "Turn failed: %s" % result.get("error"))
    check(int(rig.sim_teensy("Acknowledgements")) >= acks + 1, "no acknowledgement of the turn")
    check(abs(float(rig.sim_teensy("LastTurn")) - 0.3) < 1e-5, "LastTurn %s" % rig.sim_teensy("LastTurn"))


def sc_bus_hang(rig):
    """A slave holding SDA: the daemon unbinds the adapter's driver, clocks SCL through the GPIO lines, sends a STOP, binds again and resumes the orders."""
    values = [0, 1700, 0, 0, 0, 0, -1700, 0]
    rig.thrust(values)
    rig.wait_sim_speeds([speed_byte(v) for v in values], 20)
    rec0 = int(rig.bus("Recoveries"))
    unb0, bind0 = int(rig.sim_get("Unbinds")), int(rig.sim_get("Binds"))
    since = rig.wire_next()
    rig.sim_call("HangBus", dbus.UInt32(5), signature="u")
    poll(lambda: int(rig.bus("Recoveries")) > rec0, 30, message="no recovery")
    check(rig.sim_get("BusHang") == "none", "BusHang %s" % rig.sim_get("BusHang"))
    _, entries = rig.wire_log(since)
    pulses = [e for e in entries if e.bus == "i2c-lines" and e.result == "scl-pulse"]
    stops = [e for e in entries if e.bus == "i2c-lines" and e.result == "stop"]
    check(len(pulses) >= 5, "%d SCL pulses" % len(pulses))
    check(stops, "no STOP")
    check(int(rig.sim_get("Unbinds")) == unb0 + 1 and int(rig.sim_get("Binds")) == bind0 + 1,
          "driver unbinds/binds %s/%s" % (rig.sim_get("Unbinds"), rig.sim_get("Binds")))
    check(bool(rig.sim_get("I2cFunction")), "pins not given back to the I2C controller")
    check(os.path.exists(DRIVER + "/" + DRIVER_ID), "the platform driver is not bound again")
    check(os.path.exists(I2C_DEV), I2C_DEV + " did not come back")
    poll(lambda: rig.bus("State") == "ok", 15)
    rig.wait_orders_refreshed()
    check(rig.sim_speeds() == [speed_byte(v) for v in values], "orders not resumed")
    check(rig.state() == "ready", "state %s" % rig.state())
    # The orders after the recovery go through the rebound adapter.
    after = [o for o in rig.orders(stops[-1].index) if o[1] == order_bytes(DEFAULT_MT[1], 1700)]
    check(after, "no order after the recovery")


def sc_scl_low(rig):
    """SCL held low cannot be cleared: the bus is lost, the vehicle killed with source "bus"; it stays killed after the bus returns until ClearKill."""
    rig.thrust([1200] + [0] * 7)
    rig.wait_sim_speeds([speed_byte(1200)] + [ZERO] * 7, 20)
    rig.sim_call("HoldScl")
    try:
        rig.wait_state("killed", 60)
        check(rig.vget("KillSource") == "bus", "KillSource %r" % rig.vget("KillSource"))
        check(rig.bus("State") == "lost", "bus state %s" % rig.bus("State"))
        check(bool(rig.sim_get("KillOutput")), "kill output not asserted")
    finally:
        rig.sim_call("ReleaseBus")
    poll(lambda: rig.bus("State") == "ok", 60, interval=0.2, message="the bus never came back")
    rig.wait_sim_zero(20)
    check(rig.state() == "killed", "a bus kill cleared itself")
    rig.vcall("ClearKill")
    rig.wait_state("ready", 20)


def sc_power_off(rig):
    """A new daemon zeroes the orders it finds standing before it takes its name; PowerOff needs its confirmation, then zeroes and raises the power-off line."""
    if rig._died("caracarad") or "caracarad" not in rig.procs:
        left = rig.sim_speeds()
        since = rig.wire_next()
        rig.start_daemon()
        # Zero orders to every thruster went out before the name appeared.
        check(rig.sim_speeds() == [ZERO] * MOTORS, "orders standing when the service appeared: %s (before: %s)"
              % (rig.sim_speeds(), left))
        zeros = {i for i, d, _ in rig.orders(since) if d[0] == ZERO}
        check(zeros == set(range(MOTORS)), "start zeroed only %s" % sorted(zeros))
        rig.arm(60)
    check(error_name(rig.vcall, "PowerOff", "yes", signature="s") == ERR + "ConfirmationRequired",
          "PowerOff without confirmation")
    check(not rig.sim_get("PowerOffOutput"), "power-off asserted early")
    since = rig.wire_next()
    rig.vcall("PowerOff", "power-off", signature="s")
    check(bool(rig.sim_get("PowerOffOutput")), "power-off output not asserted")
    wait_wire(rig, since, lambda e: e.bus == "gpio" and e.addr == 22 and list(e.data) == [1], 5,
              "no power-off edge (line 22 high) in the wire log")
    check(rig.sim_speeds() == [ZERO] * MOTORS, "thrusters not zero at power-off")


def sc_sigterm(rig):
    """SIGTERM: exit status 0 with zero orders to all eight on the way out."""
    values = [4000, -4000, 4000, -4000, 0, 0, 0, 0]
    if rig.state() != "ready":
        rig.reset(30)
    rig.thrust(values)
    rig.wait_sim_speeds([speed_byte(v) for v in values], 20)
    since = rig.wire_next()
    proc = rig.procs["caracarad"]
    proc.send_signal(signal.SIGTERM)
    code = proc.wait(60)
    check(code == 0, "caracarad exited %s" % code)
    check(rig.sim_speeds() == [ZERO] * MOTORS, "not zeroed on SIGTERM: %s" % rig.sim_speeds())
    zeros = {i for i, d, _ in rig.orders(since) if d[0] == ZERO}
    check(zeros == set(range(MOTORS)), "zero orders on the way out only to %s" % sorted(zeros))


def sc_fatal_signal(rig):
    """A crash (SIGABRT): the emergency stop in the signal handler sets the kill output through
    the real GPIO chip (GpioLine::set_in_signal_handler: one ioctl) before its zero orders."""
    # All eight running: the loop's own refreshes to idle thrusters would be zero orders too.
    values = [2000, -2000] * 4
    rig.thrust(values)
    rig.wait_sim_speeds([speed_byte(v) for v in values], 20)
    since = rig.wire_next()
    proc = rig.procs["caracarad"]
    proc.send_signal(signal.SIGABRT)
    code = proc.wait(60)
    check(code == -signal.SIGABRT, "caracarad ended with %s, not of SIGABRT" % code)
    check(rig.sim_speeds() == [ZERO] * MOTORS, "not zeroed after the crash: %s" % rig.sim_speeds())
    _, entries = rig.wire_log(since)
    edge = next((e.index for e in entries if e.bus == "gpio" and e.addr == 27 and list(e.data) == [1]), None)
    zeros = [e.index for i, d, e in rig.orders(since) if d[0] == ZERO]
    check(edge is not None, "the kill output was not set by the signal handler")
    check(zeros and edge < zeros[0], "the kill output (#%s) after the first zero order (#%s)" % (edge, zeros[:1]))


def sc_i2ctransfer(rig):
    """i2c-tools as a reference client, with no daemon running: the bytes of one of the
    daemon's own orders, sent by i2ctransfer through the same kernel adapter, land in the
    wire log exactly as the daemon's did, and the thruster takes them the same way."""
    mt = DEFAULT_MT[1]
    daemon_orders = [o for o in rig.orders() if o[0] == 1 and o[1][0] != ZERO]
    check(daemon_orders, "no non-zero order of the daemon to thruster 1 in the log")
    ref = daemon_orders[-1][2]
    check(list(ref.data) == order_bytes(mt, -4000), "the daemon's order %s is not the encoding of -4000" % list(ref.data))
    since = rig.wire_next()
    r = subprocess.run(["/usr/sbin/i2ctransfer", "-y", str(I2C_BUS), "w%d@0x%02x" % (len(ref.data), ref.addr)] +
                       ["0x%02x" % b for b in ref.data], capture_output=True, text=True, timeout=30)
    check(r.returncode == 0, "i2ctransfer: %s" % (r.stderr.strip() or r.returncode))
    got = [e for e in rig.wire_log(since)[1] if e.bus == "i2c"]
    check(len(got) == 1, "i2ctransfer made %d wire entries" % len(got))
    g = got[0]
    check((g.addr, g.read, g.data, g.result) == (ref.addr, ref.read, ref.data, ref.result),
          "i2ctransfer %s vs the daemon %s" % (g, ref))
    check(rig.sim_speeds()[1] == speed_byte(-4000), "the thruster did not take the order")
    # A status read of 7 bytes through the same adapter, and a NACK surfacing as an error.
    r = subprocess.run(["/usr/sbin/i2ctransfer", "-y", str(I2C_BUS), "r7@0x%02x" % (mt >> 1)],
                       capture_output=True, text=True, timeout=30)
    check(r.returncode == 0 and len(r.stdout.split()) == 7, "status read: %r %r" % (r.stdout, r.stderr))
    r = subprocess.run(["/usr/sbin/i2ctransfer", "-y", str(I2C_BUS), "w1@0x11", "0x00"],
                       capture_output=True, text=True, timeout=30)
    check(r.returncode != 0, "a write to an absent address succeeded")
    nack = [e for e in rig.wire_log(since)[1] if e.bus == "i2c" and e.addr == 0x11]
    check(nack and nack[-1].result == "nack", "no NACK of 0x11 in the wire log")


def sc_bus_scan(rig):
    """caracaractl scan through the real i2c-dev: killed, every probe address on the trunk and on
    each of the mux's four channels, each thruster found where the configuration puts it (6 and 7
    behind their channels), the empty addresses NACKed by the kernel; refused while armed; i2c-tools
    reads the same status reply at thruster 0's address."""
    refused = rig.ctl("scan")
    check(refused.returncode == 1 and "NotKilled" in refused.stderr, "scan while armed: %r" % refused.stderr)
    rig.vcall("Kill")
    rig.wait_state("killed", 20)
    since = rig.wire_next()
    p = rig.ctl("scan", timeout=300)
    print(p.stdout)
    check(p.returncode == 0, "caracaractl scan exited %d: %s%s" % (p.returncode, p.stdout, p.stderr))
    check("the bus matches the configuration" in p.stdout, "no match in %r" % p.stdout)
    for i in MUXED:
        check("0x70/%d     0x%02x" % (MUXED[i], DEFAULT_MT[i]) in p.stdout, "thruster %d not on its channel" % i)
    # From a little before the scan: the mux's channel as the scan found it (the routine orders
    # to 6 and 7 switch it every cycle); the whole log is long by now, and slow to read under TCG.
    entries = [e for e in rig.wire_log(max(1, since - 400))[1] if e.bus == "i2c"]
    check(not [e for e in entries if e.index >= since and not e.read and e.addr != MUX and e.data[:1] != bytes([ZERO])],
          "a non-zero order during the scan")
    channels = set()
    channel = None
    for e in entries:
        if e.addr == MUX and not e.read and e.data and e.result == "ack":
            channel = e.data[-1] & 0x03 if e.data[-1] & 0x04 else -1
        elif e.index >= since and e.read and e.addr == 0x54 >> 1 and channel is not None:
            check(e.result == "nack", "the empty legacy address answered: %s" % (e,))
            channels.add(channel)
    check(channels == {-1, 0, 1, 2, 3}, "0x54 probed on %s, not the trunk and channels 0-3" % sorted(channels))
    r = subprocess.run(["/usr/sbin/i2ctransfer", "-y", str(I2C_BUS), "r7@0x%02x" % (DEFAULT_MT[0] >> 1)],
                       capture_output=True, text=True, timeout=30)
    reply = [int(x, 16) for x in r.stdout.split()]
    check(r.returncode == 0 and len(reply) == 7 and reply[0] == DEFAULT_MT[0] | 1
          and sum(reply[:6]) & 0xFF == reply[6], "i2ctransfer status read: %r %r" % (r.stdout, r.stderr))
    row = [line for line in p.stdout.splitlines() if line.startswith("trunk") and "0x%02x" % DEFAULT_MT[0] in line]
    check(row and row[0].split()[2] == "seabotix" and int(row[0].split()[3]) == reply[1] >> 4,
          "scan row %r vs the status byte 0x%02x" % (row, reply[1]))
    rig.vcall("ClearKill")
    rig.wait_state("ready", 20)


def write_config(rig, **sections):
    """Replaces some sections of the daemon's configuration file (read at its next start)."""
    rig.extra_config = dict(rig.extra_config, **sections)
    with open(rig.config_path, "w") as f:
        f.write(rig.config_text())


def restart_with(rig, **sections):
    """Stops caracarad and starts it again with some config sections replaced."""
    rig.terminate("caracarad")
    write_config(rig, **sections)
    rig.start_daemon()
    rig.arm(60)


def kill_and_clear(rig, message):
    """Kill raises the kill output (line 27) on the wire; ClearKill makes the vehicle ready."""
    since = rig.wire_next()
    rig.vcall("Kill")
    wait_wire(rig, since, lambda e: e.bus == "gpio" and e.addr == 27 and list(e.data) == [1], 5, message)
    rig.vcall("ClearKill")
    rig.wait_state("ready", 20)


def sc_unwired_line(rig):
    """A line the kernel refuses (the bridge wires no GPIO5): the daemon names it and exits."""
    rig.terminate("caracarad")
    code, out = restart_refused(rig, os.path.join(rig.dir, "unwired.toml"),
                                gpio=dict(GPIO, kill_output={"chip": "gpiochip0", "line": "GPIO5"}))
    check(code != 0, "caracarad started with an unwired kill output")
    check("GPIO5" in out and "kill_output" in out, "the error does not name the line: %r" % out[-400:])


def gpio_debugfs():
    """The kernel's own view of the GPIO lines in use: {line name: (consumer, "in"/"out")}."""
    try:
        with open("/sys/kernel/debug/gpio") as f:
            text = f.read()
    except OSError as e:
        raise AssertionError("cannot read /sys/kernel/debug/gpio: %s" % e)
    lines = {}
    for m in re.finditer(r"^\s*gpio-\d+ \((.*?)\s*\|(.*?)\s*\) (in|out) ", text, re.M):
        lines[m.group(1)] = (m.group(2), m.group(3))
    return lines


def sc_gpio_lookup(rig):
    """The chip named by number, label and path, lines by offset as well as by name (as
    configurations written for either libgpiod find them): the kernel shows each line requested
    by "caracarad" in its direction, and the kill output and the kill switch work through them."""
    gpio = dict(GPIO,
                kill_switch={"chip": "0", "line": 17},
                kill_output={"chip": "caracara-gpio", "line": 27},
                power_off_output={"chip": "/dev/gpiochip0", "line": "GPIO22"})
    try:
        restart_with(rig, gpio=gpio)
        used = gpio_debugfs()
        for name, direction in (("GPIO17", "in"), ("GPIO27", "out"), ("GPIO22", "out")):
            check(used.get(name, ("", ""))[0] == "caracarad", "%s not requested by caracarad: %r" % (name, used))
            check(used[name][1] == direction, "%s is %s, not %s" % (name, used[name][1], direction))
        kill_and_clear(rig, "the kill output found by label and offset did not go high")
        rig.sim_call("SetKillSwitch", True, signature="b")
        try:
            rig.wait_state("killed", 10)
            check(rig.vget("KillSource") == "switch", "KillSource %r" % rig.vget("KillSource"))
        finally:
            rig.sim_call("SetKillSwitch", False, signature="b")
        rig.vcall("ClearKill")
        rig.wait_state("ready", 20)
    finally:
        restart_with(rig, gpio=GPIO)


def sc_per_byte_spi_active_low(rig):
    """Per-byte SPI transfers (one spi_ioc_transfer per byte with a delay) through spidev, and
    an active-low kill output and kill switch inverted by gpiolib: the wire shows the physical
    levels, and a switch physically low reads set."""
    gpio = dict(GPIO, kill_output={"chip": "gpiochip0", "line": "GPIO27", "active_low": True})
    restart_with(rig, gpio=gpio, spi={"per_byte_delay_us": 20})
    tget = lambda n: rig.vget(n, TEENSY_PATH, TEENSY_IFACE)  # noqa: E731
    poll(lambda: bool(tget("Online")), 15, message="Teensy not online in per-byte mode")
    f0 = int(tget("Frames"))
    poll(lambda: int(tget("Frames")) > f0 + 2, 15, message="no frames in per-byte mode")
    n = int(rig.sim_teensy("SpiLastTransfers"))
    check(n > 1, "SpiLastTransfers %d: not one transfer per byte" % n)
    since = rig.wire_next()
    spi = wait_wire(rig, since, lambda e: e.bus == "spi", 10, "no SPI frames")
    check(all(e.result == "ok" for e in spi), "SPI results %s" % {e.result for e in spi})
    # Deasserted active-low output: high on the wire. Kill: low.
    since = rig.wire_next()
    rig.vcall("Kill")
    wait_wire(rig, since, lambda e: e.bus == "gpio" and e.addr == 27 and list(e.data) == [0], 5,
              "the active-low kill output did not go low on the wire")
    since = rig.wire_next()
    rig.vcall("ClearKill")
    rig.wait_state("ready", 20)
    wait_wire(rig, since, lambda e: e.bus == "gpio" and e.addr == 27 and list(e.data) == [1], 5,
              "the active-low kill output did not go back high")
    # An active-low kill switch, inverted by gpiolib too: at rest (physically low) it reads set.
    rig.terminate("caracarad")
    try:
        write_config(rig, gpio=dict(gpio, kill_switch=dict(GPIO["kill_switch"], active_low=True)))
        rig.start_daemon()
        rig.wait_state("killed", 10)
        # The start kill stands (source "start"); the switch read set keeps it from being cleared.
        check(rig.vget("KillSource") in ("start", "switch"), "KillSource %r" % rig.vget("KillSource"))
        poll(lambda: error_name(rig.vcall, "ClearKill") == ERR + "KillSwitchSet", 10,
             message="ClearKill not refused with an active-low switch at rest")
        rig.sim_call("SetKillSwitch", True, signature="b")  # physically high: released
        poll(lambda: error_name(rig.vcall, "ClearKill") is None, 10, message="ClearKill refused once released")
        rig.wait_state("ready", 20)
        rig.sim_call("SetKillSwitch", False, signature="b")  # physically low: set
        rig.wait_state("killed", 10)
        check(rig.vget("KillSource") == "switch", "KillSource %r" % rig.vget("KillSource"))
    finally:
        rig.sim_call("SetKillSwitch", False, signature="b")
        restart_with(rig, gpio=gpio)


# --- the kernel's own errors: injected by the test module, judged from the daemon -----------

def inject(**params):
    """Writes the test module's fault parameters (a count arms a fault for that many requests)."""
    for k, v in params.items():
        with open(PARAMS + k, "w") as f:
            f.write(str(v))


def injected(name):
    with open(PARAMS + name) as f:
        return int(f.read())


def clear_faults():
    inject(i2c_fail_count=0, i2c_func_fail_count=0, i2c_probe_fail_count=0, spi_fail_count=0,
           spi_setup_fail_count=0, spi_silent_count=0, gpio_fail_count=0, gpio_fail_skip=0, i2c_fail_addr=-1,
           gpio_fail_offset=-1, gpio_fail_op=0, gpio_fail_errno=errno.EIO)


def log_since(rig, mark):
    return rig.log("caracarad")[mark:]


def wait_log(rig, mark, pattern, timeout=15.0):
    """The daemon's log since `mark` (a length of the log) comes to match `pattern`."""
    return poll(lambda: re.search(pattern, log_since(rig, mark)), timeout,
                message="caracarad never logged /%s/" % pattern)


def tget(rig, name):
    return rig.vget(name, TEENSY_PATH, TEENSY_IFACE)


def thruster(rig, i, name):
    return rig.vget(name, harness.thruster_path(i), harness.THRUSTER_IFACE)


def sc_i2c_kernel_errors(rig):
    """A transfer that times out (ETIMEDOUT), loses arbitration (EAGAIN, also on the i2c
    core's one retry: I2C_RETRIES 1), or comes back short (the adapter moved no message):
    each is counted against that thruster under its own name, no kill for one failure, and
    the next orders go out."""
    i = 5
    addr = DEFAULT_MT[i] >> 1
    values = [0, 0, 0, 0, 0, 1600, 0, 0]
    rig.thrust(values)
    rig.wait_sim_speeds([speed_byte(v) for v in values], 20)
    for what, err, count, name in (("timeout", errno.ETIMEDOUT, 1, "timeout"),
                                   ("lost arbitration", errno.EAGAIN, 2, "arbitration-lost"),
                                   ("short transfer", 0, 1, "clock-stretch")):
        e0 = int(rig.bus("Errors"))
        t0 = int(thruster(rig, i, "Timeouts"))
        inject(i2c_fail_addr=addr, i2c_fail_errno=err, i2c_fail_count=count)
        try:
            poll(lambda: injected("i2c_fail_count") == 0, 10, message="%s: no transfer to 0x%02x" % (what, addr))
            poll(lambda: thruster(rig, i, "LastError") == name, 10,
                 message="%s: thruster %d LastError %r, not %r" % (what, i, thruster(rig, i, "LastError"), name))
        finally:
            inject(i2c_fail_count=0, i2c_fail_addr=-1)
        check(int(rig.bus("Errors")) > e0, "%s: the bus's error count did not grow" % what)
        if err == errno.ETIMEDOUT:
            check(int(thruster(rig, i, "Timeouts")) > t0, "the timeout not counted")
        since = rig.wire_next()
        wait_wire(rig, since, lambda e: e.bus == "i2c" and e.result == "ack" and e.addr == addr and
                  list(e.data) == order_bytes(DEFAULT_MT[i], 1600), 10, "%s: no order after it" % what)
        check(rig.state() == "ready", "%s: one failed transfer made the vehicle %s (%s)"
              % (what, rig.state(), rig.vget("KillSource")))
        check(rig.bus("State") == "ok", "%s: bus %s" % (what, rig.bus("State")))


def bind_driver(driver, bound):
    """Binds or unbinds one of the test module's platform drivers (device = driver name)."""
    with open("/sys/bus/platform/drivers/%s/%s" % (driver, "bind" if bound else "unbind"), "w") as f:
        f.write(driver)


def sc_spi_silent(rig):
    """The Teensy stops answering on SPI while the thrusters run (the module completes every
    message with MISO low, spi_silent_count): after [spi] silence_ms (200 ms) the teensy-link-lost
    failsafe kills (source "failsafe", the Teensy's LinkLoss "silent"), the kill output asserted and
    every thruster zeroed on the wire; ClearKill refused while it is silent; answering again, the
    failsafe clears and ClearKill re-arms."""
    poll(lambda: bool(tget(rig, "Online")), 15, message="Teensy not online")
    rig.thrust([1600] * MOTORS)
    rig.wait_sim_speeds([speed_byte(1600)] * MOTORS, 20)
    since = rig.wire_next()
    silent = 1000000
    inject(spi_silent_count=silent)
    try:
        rig.wait_state("killed", 10)
        check(injected("spi_silent_count") < silent, "no SPI message answered silently")
        check(rig.vget("KillSource") == "failsafe", "KillSource %r" % rig.vget("KillSource"))
        check(str(tget(rig, "LinkLoss")) == "silent", "LinkLoss %r" % tget(rig, "LinkLoss"))
        check(("teensy-link-lost", "kill", -1) in [(str(c), str(a), int(t)) for c, a, t in rig.vget("Failsafes")],
              "teensy-link-lost not among the failsafes")
        wait_wire(rig, since, lambda e: e.bus == "gpio" and e.addr == 27 and list(e.data) == [1], 5,
                  "no kill output edge (line 27 high) in the wire log")
        rig.wait_sim_zero(5)
        time.sleep(0.5)
        check(error_name(rig.vcall, "ClearKill") == ERR + "FailsafeActive", "ClearKill not refused while silent")
        check(rig.state() == "killed", "state %s while silent" % rig.state())
    finally:
        inject(spi_silent_count=0)
    poll(lambda: str(tget(rig, "LinkLoss")) == "none", 15, message="the Teensy answering did not clear LinkLoss")
    poll(lambda: error_name(rig.vcall, "ClearKill") is None, 10, message="ClearKill refused with the Teensy back")
    rig.wait_state("ready", 20)


def sc_spi_refused(rig):
    """SPI messages the module refuses (EIO): the Teensy reads offline, and once no valid frame
    came for [spi] silence_ms the teensy-link-lost failsafe kills, ClearKill refused until
    the messages go through again. Then the SPI controller's driver unbound under the open spidev (spidev
    answers ESHUTDOWN): the Teensy is gone, the vehicle killed by the teensy-link-lost failsafe (source
    "failsafe") and ClearKill refused until it is back; bound again,
    the first reopen is refused (the controller refuses the mode: SPI_IOC_WR_MODE), the next
    one brings the Teensy back."""
    poll(lambda: bool(tget(rig, "Online")), 15, message="Teensy not online")
    refusals = 1000000
    inject(spi_fail_errno=errno.EIO, spi_fail_count=refusals)
    try:
        # Every message refused: the Teensy reads offline, silent: killed by the failsafe.
        poll(lambda: not tget(rig, "Online"), 15, message="refused SPI messages left the Teensy online")
        check(injected("spi_fail_count") < refusals, "no SPI message refused")
        rig.wait_state("killed", 10)
        check(rig.vget("KillSource") == "failsafe", "KillSource %r" % rig.vget("KillSource"))
        check(str(tget(rig, "LinkLoss")) == "silent", "LinkLoss %r" % tget(rig, "LinkLoss"))
        time.sleep(0.5)
        check(not tget(rig, "Online"), "the Teensy reads online while every message is refused")
        check(error_name(rig.vcall, "ClearKill") == ERR + "FailsafeActive", "ClearKill not refused while refused")
    finally:
        inject(spi_fail_count=0)
    poll(lambda: bool(tget(rig, "Online")), 15, message="Teensy not back online after EIO")
    poll(lambda: error_name(rig.vcall, "ClearKill") is None, 10, message="ClearKill refused after EIO")
    rig.wait_state("ready", 20)
    mark = len(rig.log("caracarad"))
    bound = True
    try:
        bind_driver("caracara-spi", False)
        bound = False
        rig.wait_state("killed", 15)
        check(rig.vget("KillSource") == "failsafe", "KillSource %r" % rig.vget("KillSource"))
        check(error_name(rig.vcall, "ClearKill") == ERR + "FailsafeActive", "ClearKill not refused without the Teensy")
        wait_log(rig, mark, r"Teensy SPI /dev/spidev0\.0 went away \(ENODEV")
        check(not os.path.exists("/dev/spidev0.0"), "/dev/spidev0.0 still there with its controller unbound")
        time.sleep(1.5)  # a reopen or two find no node
        check(not tget(rig, "Online"), "the Teensy reads online without its controller")
        inject(spi_setup_fail_count=1)
        bind_driver("caracara-spi", True)
        bound = True
        poll(lambda: injected("spi_setup_fail_count") == 0, 10, message="no reopen set the mode")
        wait_log(rig, mark, r"Teensy SPI /dev/spidev0\.0 is back", 15)
    finally:
        inject(spi_setup_fail_count=0)
        if not bound:
            bind_driver("caracara-spi", True)
    check(log_since(rig, mark).count("Teensy SPI") == 2, "not one line when it went, one when back: %r"
          % [line for line in log_since(rig, mark).splitlines() if "Teensy SPI" in line])
    poll(lambda: bool(tget(rig, "Online")), 15, message="Teensy not online after the reopen")
    rig.vcall("ClearKill")
    rig.wait_state("ready", 20)


def sc_recovery_driver_path_missing(rig):
    """A recovery whose driver's sysfs files do not exist (a driver name that is not there): the
    unbind and the bind fail with ENOENT and are named; the bus clear takes SCL and SDA away from
    the controller, and with no probe to give them back (as on a Raspberry Pi) no transfer gets
    through: the bus is lost, the vehicle killed with source "bus". With the right paths again, a
    new daemon's recovery rebinds the adapter and the bus comes back."""
    missing = "/sys/bus/platform/drivers/caracara-nosuch/"
    restart_with(rig, recovery=dict(RECOVERY, unbind_path=missing + "unbind", bind_path=missing + "bind"))
    try:
        mark = len(rig.log("caracarad"))
        rig.sim_call("HangBus", dbus.UInt32(2), signature="u")
        rig.wait_state("killed", 60)
        check(rig.vget("KillSource") == "bus", "KillSource %r" % rig.vget("KillSource"))
        check(rig.bus("State") == "lost", "bus state %s" % rig.bus("State"))
        text = log_since(rig, mark)
        for what, node in (("unbinding", "unbind"), ("binding", "bind")):
            check(re.search(r"\b%s caracara-i2c via %s%s: ENOENT" % (what, re.escape(missing), node), text),
                  "the failed %s is not named: %r" % (what, text[-600:]))
    finally:
        rig.terminate("caracarad")
        write_config(rig, recovery=RECOVERY)
        rig.start_daemon()
    poll(lambda: rig.bus("State") == "ok", 60, interval=0.2, message="the bus never came back")
    rig.arm(60)


def sc_adapter_lost_without_recovery(rig):
    """Recovery not configured: every transfer failing (EIO) loses the bus and kills with source
    "bus"; the adapter is closed and opened again once a second, the first reopens refused
    (I2C_FUNCS without plain I2C) with the transfers in between failing as no device, until
    the adapter answers again: the bus is back, the vehicle stays killed until ClearKill."""
    restart_with(rig, recovery=dict(RECOVERY, enabled=False))
    mark = len(rig.log("caracarad"))
    try:
        inject(i2c_fail_addr=-1, i2c_fail_errno=errno.EIO, i2c_fail_count=1000000, i2c_func_fail_count=2)
        rig.wait_state("killed", 30)
        check(rig.vget("KillSource") == "bus", "KillSource %r" % rig.vget("KillSource"))
        check(rig.bus("State") == "lost", "bus state %s" % rig.bus("State"))
        wait_log(rig, mark, r"recovery is not configured: reopening the adapter once a second")
        poll(lambda: injected("i2c_func_fail_count") == 0, 15, message="the adapter was not opened again")
    finally:
        clear_faults()
    poll(lambda: rig.bus("State") == "ok", 30, interval=0.2, message="the bus never came back")
    rig.wait_sim_zero(20)
    check(rig.state() == "killed", "a bus kill cleared itself")
    rig.vcall("ClearKill")
    rig.wait_state("ready", 20)
    restart_with(rig, recovery=RECOVERY)


def sc_adapter_never_binds(rig):
    """The adapter's driver refuses every bind after a bus recovery's unbind: the node does not
    come back, each attempt says why, the bus is declared lost and the vehicle killed with source
    "bus"; once the driver binds again the bus comes back on its own, and the vehicle stays
    killed until ClearKill."""
    values = [0, 0, 1500, 0, 0, 0, 0, 0]
    rig.thrust(values)
    rig.wait_sim_speeds([speed_byte(v) for v in values], 20)
    mark = len(rig.log("caracarad"))
    inject(i2c_probe_errno=errno.EIO, i2c_probe_fail_count=1000)
    try:
        rig.sim_call("HangBus", dbus.UInt32(2), signature="u")
        rig.wait_state("killed", 60)
        check(rig.vget("KillSource") == "bus", "KillSource %r" % rig.vget("KillSource"))
        check(rig.bus("State") == "lost", "bus state %s" % rig.bus("State"))
        check(not os.path.exists(I2C_DEV), I2C_DEV + " exists with its driver refusing to bind")
        text = log_since(rig, mark)
        check(re.search(r"binding caracara-i2c via .*: EIO", text), "the failed bind is not named")
        check(re.search(r"the I2C device node did not come back", text), "the missing node is not named")
    finally:
        inject(i2c_probe_fail_count=0)
    poll(lambda: rig.bus("State") == "ok", 60, interval=0.2, message="the bus never came back")
    check(os.path.exists(I2C_DEV), I2C_DEV + " did not come back")
    rig.wait_sim_zero(20)  # the zeros of the killed vehicle, once there is a bus to carry them
    check(rig.state() == "killed", "a bus kill cleared itself")
    rig.vcall("ClearKill")
    rig.wait_state("ready", 20)


def restart_refused(rig, path, gpio=None, **sections):
    """caracarad with a configuration it must refuse: its exit status and its words."""
    cfg = dict(rig.extra_config, **sections)
    if gpio is not None:
        cfg["gpio"] = gpio
    with open(path, "w") as f:
        f.write(harness.toml_dumps(dict({"control": rig.control}, **cfg)) + "\n" + rig.extra_toml)
    r = subprocess.run([binary("caracarad"), "--bus-address", rig.address, "--config", path],
                       capture_output=True, text=True, timeout=60)
    return r.returncode, r.stdout + r.stderr


# struct gpiohandle_request (linux/gpio.h, the v1 uAPI both libgpiod versions sit on):
# lineoffsets[64], flags, default_values[64], consumer_label[32], lines, fd.
GPIOHANDLE_FORMAT = "64I I 64B 32s I i"
GPIO_GET_LINEHANDLE_IOCTL = (3 << 30) | (struct.calcsize(GPIOHANDLE_FORMAT) << 16) | (0xB4 << 8) | 0x03


def hold_line(offset):
    """Requests a line of gpiochip0 as an input for this process: (chip fd, line fd)."""
    chip = os.open("/dev/gpiochip0", os.O_RDWR | os.O_CLOEXEC)
    req = bytearray(struct.pack(GPIOHANDLE_FORMAT, *([offset] + [0] * 63), 1, *([0] * 64), b"kernel-test", 1, 0))
    try:
        fcntl.ioctl(chip, GPIO_GET_LINEHANDLE_IOCTL, req, True)
    except OSError:
        os.close(chip)
        raise
    return chip, struct.unpack_from("i", req, len(req) - 4)[0]


def sc_gpio_refused(rig):
    """A line another process holds (EBUSY), a chip that does not exist (or has no name), a line
    name or offset the chip does not have, an adapter without plain I2C: caracarad names the line (or the
    bus) and the kernel's reason, and does not start. Output and input lines both (libgpiod's
    output and input request paths differ). Then it starts again on the real lines."""
    rig.terminate("caracarad")
    path = os.path.join(rig.dir, "refused.toml")
    cases = []
    for key, offset, line in (("kill_output", 27, "GPIO27"), ("kill_switch", 17, "GPIO17")):
        held = hold_line(offset)
        try:
            code, out = restart_refused(rig, path, gpio=GPIO)
        finally:
            for fd in held:
                os.close(fd)
        cases.append(("%s held elsewhere" % key, code, out, ["gpio." + key, line, "busy"]))
        for what, spec, words in (("on a missing chip", {"chip": "gpiochip9", "line": line}, ["gpiochip9"]),
                                  ("a missing line name", {"chip": "gpiochip0", "line": "NOSUCH"}, ["NOSUCH"]),
                                  ("a missing offset", {"chip": "gpiochip0", "line": 40}, ["gpiochip0 line 40"]),
                                  ("an empty chip name", {"chip": "", "line": line}, [])):
            code, out = restart_refused(rig, path, gpio=dict(GPIO, **{key: spec}))
            cases.append(("%s %s" % (key, what), code, out, ["gpio." + key] + words))
    inject(i2c_func_fail_count=1)
    try:
        code, out = restart_refused(rig, path, gpio=GPIO)
    finally:
        inject(i2c_func_fail_count=0)
    cases.append(("an adapter without I2C_FUNC_I2C", code, out, [I2C_DEV, "EOPNOTSUPP"]))
    code, out = restart_refused(rig, path, gpio=GPIO, i2c=dict(rig.extra_config["i2c"], device="/dev/i2c-9"))
    cases.append(("a missing I2C adapter", code, out, ["/dev/i2c-9", "ENOENT"]))
    for what, code, out, words in cases:
        check(code != 0, "caracarad started with %s" % what)
        low = out.lower()
        missing = [w for w in words if w.lower() not in low]
        check(not missing, "%s: the error lacks %s: %r" % (what, missing, out.strip().splitlines()[-3:]))
    rig.start_daemon()
    rig.arm(60)


def sc_kill_switch_read_fails(rig):
    """The kill switch's value read (after an edge) fails in the kernel, with EIO and with the
    errnos libgpiod 2's C++ binding turns into exceptions of their own (E2BIG, EDOM, ENOMEM):
    each time the switch counts as set (a kill, source "switch") under the kernel's errno, and
    the line is asked for again; once it reads clear the vehicle can be armed."""
    for err in (errno.EIO, errno.E2BIG, errno.EDOM, errno.ENOMEM):
        name = errno.errorcode[err]
        mark = len(rig.log("caracarad"))
        inject(gpio_fail_offset=17, gpio_fail_op=GPIO_OP_GET, gpio_fail_errno=err, gpio_fail_count=1)
        try:
            rig.sim_call("SetKillSwitch", True, signature="b")
            rig.sim_call("SetKillSwitch", False, signature="b")
            rig.wait_state("killed", 10)
            check(rig.vget("KillSource") == "switch", "%s: KillSource %r" % (name, rig.vget("KillSource")))
            check(injected("gpio_fail_count") == 0, "%s: the read never failed" % name)
            wait_log(rig, mark, r"kill switch gpiochip0:GPIO17 cannot be read \(%s" % name)
            wait_log(rig, mark, r"kill switch gpiochip0:GPIO17 is back", 10)
        finally:
            clear_faults()
        rig.vcall("ClearKill")
        rig.wait_state("ready", 20)


def sc_kill_switch_event_overflow(rig):
    """More edges than the kernel's event buffer holds (16) while the daemon is stopped: it
    drains what is left and the level decides: a switch left set kills, source "switch"."""
    proc = rig.procs["caracarad"]
    proc.send_signal(signal.SIGSTOP)
    try:
        for k in range(41):  # odd: ends set
            rig.sim_call("SetKillSwitch", k % 2 == 0, signature="b")
    finally:
        proc.send_signal(signal.SIGCONT)
    try:
        rig.wait_state("killed", 10)
        check(rig.vget("KillSource") == "switch", "KillSource %r" % rig.vget("KillSource"))
        check(error_name(rig.vcall, "ClearKill") == ERR + "KillSwitchSet", "ClearKill not refused while set")
    finally:
        rig.sim_call("SetKillSwitch", False, signature="b")
    poll(lambda: error_name(rig.vcall, "ClearKill") is None, 10, message="ClearKill refused after the release")
    rig.wait_state("ready", 20)


def bind_gpio(bound):
    bind_driver("caracara-gpio", bound)


def sc_gpio_chip_gone(rig):
    """The GPIO chip goes while caracarad holds its lines (its driver unbound: the module
    cannot be unloaded while they are held): the daemon finds the kill switch unreadable and
    the kill output unwritable, the vehicle is killed, the lines are asked for once a second,
    and when the chip is bound again (found by its label, whatever number it comes back
    under) the lines are back, the kill output works, and the vehicle can be armed. The
    scenarios after this one find the chip by its label too."""
    by_label = {k: dict(v, chip="caracara-gpio") for k, v in GPIO.items()}
    restart_with(rig, gpio=by_label)
    mark = len(rig.log("caracarad"))
    bound = True
    try:
        bind_gpio(False)
        bound = False
        rig.wait_state("killed", 10)
        check(rig.vget("KillSource") in ("switch", "device"), "KillSource %r" % rig.vget("KillSource"))
        wait_log(rig, mark, r"kill switch caracara-gpio:GPIO17 cannot be read")
        # The kill output is written at the kill: the kernel refuses it (the chip is gone).
        wait_log(rig, mark, r"kill output cannot be written \(ENODEV")
        time.sleep(1.5)
        check(rig.state() == "killed", "a vehicle without its lines came back to %s" % rig.state())
        bind_gpio(True)
        bound = True
        wait_log(rig, mark, r"kill output caracara-gpio:GPIO27 is back", 15)
        wait_log(rig, mark, r"kill switch caracara-gpio:GPIO17 is back", 15)
        check(bool(rig.sim_get("KillOutput")), "the kill output came back deasserted on a killed vehicle")
        rig.vcall("ClearKill")
        rig.wait_state("ready", 20)
        kill_and_clear(rig, "the kill output on the chip bound again did not go high")
    finally:
        if not bound:
            bind_gpio(True)
        restart_with(rig, gpio=by_label)


def sc_bus_clear_faults(rig):
    """Bus recoveries the kernel makes harder: the SCL line refused at its request and the
    adapter's driver refusing to bind (attempt 1 fails and names both), the node back without
    plain I2C once, then SDA, then SCL unreadable, the SDA line busy, SCL read low after a
    pulse, SDA read low through all nine pulses in the next hangs: each time the next attempt clears
    the bus, the adapter comes back, and the orders resume without a kill."""
    values = [0, 1700, 0, 0, 0, 0, 0, 0]
    rig.thrust(values)
    rig.wait_sim_speeds([speed_byte(v) for v in values], 20)
    for round_, faults, words in (
            (1, dict(gpio_fail_offset=3, gpio_fail_op=GPIO_OP_REQUEST, gpio_fail_errno=errno.EIO, gpio_fail_count=1,
                     i2c_probe_errno=errno.EIO, i2c_probe_fail_count=1, i2c_func_fail_count=1),
             [r"SCL: gpiochip0:GPIO3", r"binding caracara-i2c via .*: EIO"]),
            (2, dict(gpio_fail_offset=2, gpio_fail_op=GPIO_OP_GET, gpio_fail_errno=errno.EIO, gpio_fail_count=1),
             [r"reading SDA: EIO"]),
            (3, dict(gpio_fail_offset=3, gpio_fail_op=GPIO_OP_GET, gpio_fail_errno=errno.EIO, gpio_fail_count=1),
             [r"reading SCL: EIO"]),
            (4, dict(gpio_fail_offset=2, gpio_fail_op=GPIO_OP_REQUEST, gpio_fail_errno=errno.EBUSY, gpio_fail_count=1),
             [r"SDA: gpiochip0:GPIO2: .*busy"]),
            # Levels, not errors: SCL read low after the first pulse, SDA low through all nine.
            (5, dict(gpio_fail_offset=3, gpio_fail_op=GPIO_OP_GET, gpio_fail_errno=0, gpio_fail_skip=1,
                     gpio_fail_count=1),
             [r"SCL stayed low after a clock pulse"]),
            (6, dict(gpio_fail_offset=2, gpio_fail_op=GPIO_OP_GET, gpio_fail_errno=0, gpio_fail_count=10),
             [r"SDA still low after 9 clock pulses"])):
        rec0 = int(rig.bus("Recoveries"))
        bind0 = int(rig.sim_get("Binds"))
        mark = len(rig.log("caracarad"))
        inject(**faults)
        try:
            rig.sim_call("HangBus", dbus.UInt32(3), signature="u")
            poll(lambda: int(rig.bus("Recoveries")) > rec0, 40, message="round %d: no recovery" % round_)
            for k in faults:
                if k.endswith("_count"):
                    check(injected(k) == 0, "round %d: %s not taken" % (round_, k))
        finally:
            clear_faults()
        for w in words:
            check(re.search(w, log_since(rig, mark)), "round %d: the log does not name /%s/" % (round_, w))
        check(int(rig.sim_get("Binds")) >= bind0 + 1, "round %d: the adapter was not bound again" % round_)
        check(os.path.exists(I2C_DEV), I2C_DEV + " did not come back")
        poll(lambda: rig.bus("State") == "ok", 15)
        rig.wait_orders_refreshed()
        check(rig.sim_speeds() == [speed_byte(v) for v in values], "round %d: orders not resumed" % round_)
        check(rig.state() == "ready", "round %d: state %s (%s)" % (round_, rig.state(), rig.vget("KillSource")))


# --- who may open the devices (issue 46): the installed sysusers.d and udev rules, for real --------

def device_nodes():
    """Every node and sysfs file the daemon drives: the I2C, SPI and GPIO nodes and the adapter
    driver's bind files."""
    nodes = sorted(os.path.join("/dev", n) for n in os.listdir("/dev")
                   if re.fullmatch(r"i2c-\d+|spidev\d+\.\d+|gpiochip\d+", n))
    return nodes + [DRIVER + "/bind", DRIVER + "/unbind"]


def as_user(user, argv):
    """argv to run as `user` with that user's groups (setpriv --init-groups), as a login would."""
    return ["setpriv", "--reuid=" + user, "--regid=" + user, "--init-groups"] + argv


def users_from_sysusers():
    """systemd-sysusers with the shipped systemd/caracara.sysusers (and a pilot in caracara) on a
    copy of /etc's user files, put over the read-only ones: the users and groups a package makes."""
    root = "/run/sysroot"
    os.makedirs(root + "/etc", exist_ok=True)
    for f in ("passwd", "group", "shadow", "gshadow"):
        subprocess.run(["cp", "-p", "/etc/" + f, root + "/etc/" + f], check=True)
    with open(root + "/pilot.conf", "w") as f:
        f.write('u pilot - "A pilot" - -\nm pilot caracara\n')
    subprocess.run(["systemd-sysusers", "--root=" + root, os.path.join(harness.SOURCE_DIR, "systemd", "caracara.sysusers"),
                    root + "/pilot.conf"], check=True, capture_output=True)
    for f in ("passwd", "group", "shadow", "gshadow"):
        subprocess.run(["mount", "--bind", root + "/etc/" + f, "/etc/" + f], check=True)


def nodes_from_udev():
    """systemd-udevd with the shipped systemd/60-caracara.rules (and its driver line for the test
    adapter's driver, as the file tells an integrator to add), every node and driver replayed."""
    os.makedirs("/run/udev/rules.d", exist_ok=True)
    with open(os.path.join(harness.SOURCE_DIR, "systemd", "60-caracara.rules")) as f:
        rules = f.read()
    driver_line = next(line for line in rules.splitlines() if 'KERNEL=="i2c-bcm2835"' in line)
    with open("/run/udev/rules.d/60-caracara.rules", "w") as f:
        f.write(rules + "\n" + driver_line.replace("i2c-bcm2835", DRIVER_ID) + "\n")
    # The guest runs chrooted into the host's root: systemd's tools refuse to act there unless told.
    env = dict(os.environ, SYSTEMD_IGNORE_CHROOT="1")
    udevd = subprocess.Popen(["/lib/systemd/systemd-udevd", "--debug"], stdout=subprocess.DEVNULL,
                             stderr=open("/run/udevd.log", "w"), env=env)
    # A trigger before udevd listens is lost: wait until it answers (its control socket comes first).
    poll(lambda: subprocess.run(["udevadm", "control", "--ping", "--timeout=5"], env=env,
                                stderr=subprocess.DEVNULL).returncode == 0, 30, interval=0.2,
         message="systemd-udevd never answered")
    subprocess.run(["udevadm", "trigger", "--action=add", "--subsystem-match=i2c-dev", "--subsystem-match=spidev",
                    "--subsystem-match=gpio"], check=True, env=env)
    subprocess.run(["udevadm", "trigger", "--type=subsystems", "--action=add", "--subsystem-match=drivers",
                    "--sysname-match=" + DRIVER_ID],
                   check=True, env=env)
    subprocess.run(["udevadm", "settle", "--timeout=30"], check=True, env=env)
    return udevd


def sc_device_access(rig):
    """Only the daemon's user opens the devices: the shipped sysusers and udev rules give every I2C, SPI and GPIO node and the adapter driver's bind files to caracara-io; a pilot (in caracara) is refused open() on each, while caracarad, run as caracara, drives all eight thrusters through them and rebinds the driver."""
    users_from_sysusers()
    udevd = nodes_from_udev()
    try:
        io_gid = grp.getgrnam("caracara-io").gr_gid
        check(grp.getgrnam("caracara-io").gr_mem == ["caracara"], "caracara-io members %s" % grp.getgrnam("caracara-io").gr_mem)
        check("pilot" in grp.getgrnam("caracara").gr_mem, "the pilot is not in caracara")
        nodes = device_nodes()
        check(len(nodes) >= 5, "nodes %s" % nodes)
        for n in nodes:
            st = os.stat(n)
            check(st.st_gid == io_gid and st.st_mode & 0o007 == 0, "%s: group %d mode %o" % (n, st.st_gid, st.st_mode))
        # A pilot's shell: open() refused on every one (EACCES), before any driver sees it.
        probe = ("import os,sys\nfor n in sys.argv[1:]:\n"
                 "    try:\n        os.close(os.open(n, os.O_WRONLY if n.endswith('bind') else os.O_RDWR)); print(n, 'opened')\n"
                 "    except OSError as e:\n        print(n, e.errno)\n")
        r = subprocess.run(as_user("pilot", ["/usr/bin/python3", "-c", probe] + nodes), capture_output=True,
                           text=True, timeout=60)
        got = dict(line.rsplit(" ", 1) for line in r.stdout.split("\n") if line)
        check(got == {n: str(errno.EACCES) for n in nodes}, "the pilot's open(): %s %s" % (got, r.stderr))
        # The daemon's user: caracarad drives them (the dives' and the rig's files readable to it).
        rig.thrust([0] * MOTORS)
        rig.stop_daemon()
        for d in (rig.dir, rig.dives_dir):
            os.chmod(d, 0o755)
        os.chown(rig.dives_dir, pwd.getpwnam("caracara").pw_uid, io_gid)
        rig.daemon_exit = None
        rig._spawn("caracarad", as_user("caracara", [binary("caracarad"), "--bus-address", rig.address,
                                                     "--config", rig.config_path]))
        poll(lambda: rig.conn.name_has_owner(VEHICLE) or rig._died("caracarad"), rig.START_TIMEOUT,
             message="caracarad (as caracara) did not take its name")
        rig._check_alive("caracarad")
        rig.arm(60)
        values = [1100, -1100, 1100, -1100, 1100, -1100, 1100, -1100]
        rig.thrust(values)
        rig.wait_sim_speeds([speed_byte(v) for v in values], 20)
        unb0, bind0 = int(rig.sim_get("Unbinds")), int(rig.sim_get("Binds"))
        rec0 = int(rig.bus("Recoveries"))
        rig.sim_call("HangBus", dbus.UInt32(5), signature="u")
        poll(lambda: int(rig.bus("Recoveries")) > rec0, 30, message="no recovery as caracara")
        check(int(rig.sim_get("Unbinds")) == unb0 + 1 and int(rig.sim_get("Binds")) == bind0 + 1,
              "as caracara, driver unbinds/binds %s/%s" % (rig.sim_get("Unbinds"), rig.sim_get("Binds")))
        poll(lambda: rig.bus("State") == "ok", 15)
        rig.wait_orders_refreshed()
        check(rig.sim_speeds() == [speed_byte(v) for v in values], "orders not resumed after the rebind")
        rig.vcall("Kill")
        rig.wait_sim_zero()
    finally:
        udevd.terminate()
        udevd.wait(10)
        with open("/run/udevd.log") as f:
            log = f.read()
        print("--- systemd-udevd on the nodes:\n" + "\n".join(
            line for line in log.splitlines() if re.search(r"i2c-\d|spidev|gpiochip|caracara-i2c", line))[-4000:])
        # The next scenarios' daemon runs as root again, as every other scenario's.
        if not rig._died("caracarad"):
            rig.stop_daemon()
        rig.start_daemon()




def diagnose(rig):
    """Where caracarad and caracara-sim are stuck, as the kernel sees them."""
    for name in ("caracarad", "caracara-sim"):
        p = rig.procs.get(name)
        if p is None or p.poll() is not None:
            continue
        for what in ("wchan", "stack"):
            try:
                with open("/proc/%d/%s" % (p.pid, what)) as f:
                    print("--- %s %s:\n%s" % (name, what, f.read()))
            except OSError as e:
                print("--- %s %s: %s" % (name, what, e))
    holders = []
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            for fd in os.listdir("/proc/%s/fd" % pid):
                target = os.readlink("/proc/%s/fd/%s" % (pid, fd))
                if target.startswith(I2C_DEV) or target == BRIDGE:
                    holders.append("%s(%s) fd %s -> %s" % (pid, open("/proc/%s/comm" % pid).read().strip(), fd, target))
        except OSError:
            pass
    print("--- open %s / %s: %s" % (I2C_DEV, BRIDGE, holders))
    print("--- caracarad log (end)\n" + rig.log("caracarad")[-2000:])


SCENARIOS = [
    ("start", sc_start),
    ("set_thrust_through_muxes", sc_set_thrust),
    ("set_motion_through_muxes", sc_set_motion),
    ("kill", sc_kill),
    ("kill_switch_edge", sc_kill_switch),
    ("bus_scan_through_the_kernel", sc_bus_scan),
    ("nacking_and_corrupt_thruster", sc_thruster_faults),
    ("teensy_busy_and_turn", sc_teensy),
    ("bus_hang_recovered_with_rebind", sc_bus_hang),
    ("i2c_timeout_arbitration_short_transfer", sc_i2c_kernel_errors),
    ("spi_message_and_mode_refused", sc_spi_refused),
    ("spi_teensy_silent_kills", sc_spi_silent),
    ("bus_clear_gpio_faults_and_failed_bind", sc_bus_clear_faults),
    ("adapter_never_binds_bus_lost", sc_adapter_never_binds),
    ("adapter_lost_without_recovery_reopened", sc_adapter_lost_without_recovery),
    ("recovery_driver_path_missing", sc_recovery_driver_path_missing),
    ("scl_held_low_bus_kill", sc_scl_low),
    ("per_byte_spi_and_active_low_output", sc_per_byte_spi_active_low),
    ("unwired_gpio_line_refused", sc_unwired_line),
    ("gpio_chip_by_number_label_path_line_by_offset", sc_gpio_lookup),
    ("busy_missing_gpio_and_i2c_refused", sc_gpio_refused),
    ("kill_switch_read_fails", sc_kill_switch_read_fails),
    ("kill_switch_event_overflow", sc_kill_switch_event_overflow),
    ("gpio_chip_gone_while_held", sc_gpio_chip_gone),
    ("devices_for_the_daemon_alone", sc_device_access),
    # Restarted by the loop below (it died).
    ("fatal_signal_kill_output_first", sc_fatal_signal),
    ("sigterm", sc_sigterm),
    # With no daemon: i2c-tools alone on the adapter; it leaves thruster 1 running.
    ("i2ctransfer_reference", sc_i2ctransfer),
    # A new daemon zeroes what was left running before it takes its name, then powers off.
    ("restart_zeroes_then_power_off", sc_power_off),
]
# These start without a ready daemon (they stop or start it themselves).
NO_READY_CHECK = {"start", "i2ctransfer_reference", "restart_zeroes_then_power_off", "sigterm"}


def selected(names):
    known = {n for n, _ in SCENARIOS}
    unknown = [n for n in names if n not in known]
    if unknown:
        raise SystemExit("scenarios.py: unknown scenario(s) %s" % " ".join(unknown))
    return [(n, fn) for n, fn in SCENARIOS if not names or n in names]


def main():
    if sys.argv[1:2] == ["--list"]:
        for name, fn in selected(set(sys.argv[2:])):
            print("%s\t%s" % (name, " ".join((fn.__doc__ or "").split("\n\n")[0].split())))
        return 0
    results_path = sys.argv[1]
    only = set(sys.argv[2:])
    selected(only)
    out = open(results_path, "a")
    rig = KernelRig()
    try:
        rig.start()
    except Exception as e:
        out.write("FAIL rig_start: %s\n" % e)
        print(rig.log("caracara-sim"), rig.log("caracarad"), sep="\n")
        rig.stop(remove_dir=False)
        return 1
    failed = 0
    for name, fn in SCENARIOS:
        if only and name not in only:
            continue
        t = time.monotonic()
        try:
            if name not in NO_READY_CHECK and rig.state() != "ready":
                rig.reset(60)
            fn(rig)
            line = "PASS %s (%.1f s)" % (name, time.monotonic() - t)
        except Exception as e:
            failed += 1
            line = "FAIL %s (%.1f s): %s" % (name, time.monotonic() - t, str(e).splitlines()[0] if str(e) else repr(e))
            traceback.print_exc()
            diagnose(rig)
        print(line, flush=True)
        out.write(line + "\n")
        out.flush()
        if rig._died("caracarad") and name not in ("sigterm", "i2ctransfer_reference"):
            print("--- caracarad died:\n" + rig.log("caracarad")[-3000:])
            try:
                rig.start_daemon()
            except Exception as e:
                print("cannot restart caracarad: %s" % e)
    print("--- caracarad log (end)\n" + rig.log("caracarad")[-6000:])
    print("--- caracara-sim log (end)\n" + rig.log("caracara-sim")[-3000:])
    rig.stop(remove_dir=True)
    out.close()
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
