"""Scenarios of the kernel test (tests/kernel/run.sh), run inside the VM.

caracara-sim serves /dev/caracara-bridge (the test module's I2C adapter, SPI controller and
GPIO chip); caracarad runs with its default --hardware=linux on /dev/i2c-1, /dev/spidev0.0
and /dev/gpiochip0. Each scenario is judged from the simulator's wire log and inspection API.

    python3 scenarios.py RESULTS_FILE [SCENARIO...]

writes one line per scenario, "PASS name (seconds)" or "FAIL name: reason", to RESULTS_FILE.
"""

import os
import re
import signal
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
    values = [1500, 0, -1500, 0, 0, 0, 2500, -2500]
    since = rig.wire_next()
    rig.thrust(values)
    rig.wait_sim_speeds([speed_byte(v) for v in values], 20)
    for i, v in enumerate(values):
        got = [o for o in rig.orders(since) if o[0] == i and o[1] == order_bytes(DEFAULT_MT[i], v)]
        check(got, "thruster %d: no order %s on the wire" % (i, order_bytes(DEFAULT_MT[i], v)))
    for idx in MUXED:
        check(mux_selected_before(rig, since, idx), "thruster %d ordered without its mux channel" % idx)
    last = rig.sim_last_orders()
    for i, v in enumerate(values):
        check(list(last[i]) == order_bytes(DEFAULT_MT[i], v), "LastOrder %d" % i)


def sc_set_motion(rig):
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


def restart_with(rig, **sections):
    """Stops caracarad and starts it again with some config sections replaced."""
    rig.terminate("caracarad")
    cfg = dict(rig.extra_config)
    cfg.update(sections)
    rig.extra_config = cfg
    with open(rig.config_path, "w") as f:
        f.write(rig.config_text())
    rig.start_daemon()
    rig.arm(60)


def sc_unwired_line(rig):
    """A line the kernel refuses (the bridge wires no GPIO5): the daemon names it and exits."""
    rig.terminate("caracarad")
    gpio = dict(GPIO, kill_output={"chip": "gpiochip0", "line": "GPIO5"})
    path = os.path.join(rig.dir, "unwired.toml")
    cfg = dict(rig.extra_config, gpio=gpio)
    with open(path, "w") as f:
        f.write(harness.toml_dumps(dict({"control": rig.control}, **cfg)) + "\n" + rig.extra_toml)
    r = subprocess.run([binary("caracarad"), "--bus-address", rig.address, "--config", path],
                       capture_output=True, text=True, timeout=60)
    out = r.stdout + r.stderr
    check(r.returncode != 0, "caracarad started with an unwired kill output")
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
        since = rig.wire_next()
        rig.vcall("Kill")
        wait_wire(rig, since, lambda e: e.bus == "gpio" and e.addr == 27 and list(e.data) == [1], 5,
                  "the kill output found by label and offset did not go high")
        rig.vcall("ClearKill")
        rig.wait_state("ready", 20)
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
    an active-low kill output inverted by gpiolib: the wire shows the physical levels."""
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
    ("nacking_and_corrupt_thruster", sc_thruster_faults),
    ("teensy_busy_and_turn", sc_teensy),
    ("bus_hang_recovered_with_rebind", sc_bus_hang),
    ("scl_held_low_bus_kill", sc_scl_low),
    ("per_byte_spi_and_active_low_output", sc_per_byte_spi_active_low),
    ("unwired_gpio_line_refused", sc_unwired_line),
    ("gpio_chip_by_number_label_path_line_by_offset", sc_gpio_lookup),
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


def main():
    results_path = sys.argv[1]
    only = set(sys.argv[2:])
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
