"""Every way a command ends must leave the thrusters at zero, judged on the simulated wire:
a kill inside an otherwise bad packet, a fresh daemon (it starts killed), the command timeout
on a timer of its own, and the zeroing step systemd runs after the daemon (--zero-thrusters).
"""

import statistics
import threading
import subprocess
import time
import unittest

import os
import signal

import dbus

import harness
from bounds import (COMMAND_TIMEOUT_LATENESS_MS_MAX, VANISHED_CPU_PERCENT_MAX, VANISHED_LOG_LINES_MAX,
                    VANISHED_WINDOW_S)
from harness import (ERR, MOTORS, ZERO, DEFAULT_MT, Rig, VehicleTestCase, command, error_name, poll, speed_byte)

MISSION = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples", "mission_square.py")
KILL_OUT = 27  # the simulator's kill output line (GpioModel::kKillOut)
POWER_OFF = 22


def packet(motors=(0,) * 8, kill=0, power_off=0, rgb=(0, 0, 0)):
    return list(motors) + [kill, power_off] + list(rgb)


def gpio_edges(rig, since, line):
    return [e for e in rig.wire_log(since)[1] if e.bus == "gpio" and e.addr == line]


class KillInABadPacketTest(VehicleTestCase):
    """A packet whose killState is non-zero kills even when another field is refused."""

    def setUp(self):
        self.rig.reset()

    def drive(self):
        values = [1200, -1200, 1200, -1200, 0, 0, 0, 0]
        self.rig.thrust(values)
        self.rig.wait_sim_speeds([speed_byte(v) for v in values])

    def test_kill_survives_every_bad_field(self):
        cases = [
            ("a motor at 9000", ERR + "OutOfRange", packet([9000] + [0] * 7, kill=1)),
            ("red 300", ERR + "OutOfRange", packet(kill=1, rgb=(300, 0, 0))),
            ("powerOffState 2", ERR + "InvalidValue", packet(kill=7, power_off=2)),
            ("9 words: killState and nothing after it", ERR + "InvalidLength", packet(kill=1)[:9]),
        ]
        for what, expected, words in cases:
            with self.subTest(what):
                self.rig.reset()
                self.drive()
                leds = tuple(self.rig.vget("Leds"))
                since = self.rig.wire_next()
                self.assertEqual(error_name(self.rig.packet, words), expected)
                # The kill happened; nothing else the packet said did.
                self.assertEqual(self.rig.state(), "killed")
                self.assertEqual(self.rig.vget("KillSource"), "packet")
                self.assertTrue(self.rig.sim_get("KillOutput"))
                self.assertEqual(self.rig.sim_speeds(), [ZERO] * MOTORS)
                self.assertEqual(tuple(self.rig.vget("Leds")), leds)
                self.assertNotEqual(self.rig.state(), "powered-off")
                zeros = [e for e in self.rig.wire_log(since)[1]
                         if e.bus == "i2c" and not e.read and len(e.data) == 3 and e.data[0] == ZERO]
                self.assertGreaterEqual(len({e.addr for e in zeros}), MOTORS, "not every thruster got its zero")

    def test_a_bad_packet_without_a_kill_changes_nothing(self):
        self.drive()
        self.assertEqual(error_name(self.rig.packet, packet([9000] + [0] * 7)), ERR + "OutOfRange")
        self.assertEqual(self.rig.state(), "ready")
        self.assertNotEqual(self.rig.sim_speeds(), [ZERO] * MOTORS)


class FaultsToldTest(VehicleTestCase):
    """A thruster fault that appears or clears is logged once, not once per status read, and
    water detect and over-temperature are spelt out by caracaractl status."""
    CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 60000, "status_reads_per_tick": 8}
    # Told, not acted on: the default failsafe (surface after 2 s) is e2e_failsafes' to judge.
    EXTRA_CONFIG = {"failsafe": {"water-detect": {"action": "warn"}}}

    def test_water_detect_logged_once_and_shown(self):
        rig = self.rig
        rig.reset()
        path = harness.thruster_path(3)
        rig.sim_thruster_call(3, "SetFault", "water-detect", True, signature="sb")
        try:
            poll(lambda: "water-detect" in list(rig.vget("Faults", path, harness.THRUSTER_IFACE)), 15)
            rig.wait_orders_refreshed(count=10)  # many more status reads of thruster 3
            r = rig.ctl("status")
            self.assertIn("Warning: thruster 3: water-detect", r.stdout)
        finally:
            rig.sim_thruster_call(3, "SetFault", "water-detect", False, signature="sb")
        poll(lambda: list(rig.vget("Faults", path, harness.THRUSTER_IFACE)) == [], 15)
        rig.wait_orders_refreshed(count=5)
        log = rig.log()
        raised = log.count("thruster 3 raised fault water-detect")
        cleared = log.count("thruster 3 cleared fault water-detect")
        print("\nlog lines: raised %d, cleared %d" % (raised, cleared))
        self.assertEqual((raised, cleared), (1, 1), log[-2000:])
        self.assertNotIn("Warning: thruster 3", rig.ctl("status").stdout)


def front_wheels(rig):
    w = rig.sim_teensy("Wheels")
    return (float(w[0]), float(w[1]))


def stop_frames(rig):
    return int(rig.sim_teensy_call("CommandCount", dbus.Byte(0x05), signature="y")[1])


class WheelsAreMotorsTest(VehicleTestCase):
    """The Teensy's SetSpeed is a command like SetThrust: the command timeout and the commanding
    client leaving stop the wheels."""
    CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 400}

    def setUp(self):
        self.rig.reset()

    def set_speed(self, left, right):
        return self.rig.vcall("SetSpeed", left, right, signature="ii", path=harness.TEENSY_PATH,
                              iface=harness.TEENSY_IFACE)

    def test_command_timeout_stops_the_wheels(self):
        self.set_speed(60, 60)
        self.assertEqual(front_wheels(self.rig), (60.0, 60.0))
        self.assertNotEqual(self.rig.vget("Controller"), "")
        t0 = time.monotonic()
        poll(lambda: front_wheels(self.rig) == (0.0, 0.0), 5, message="the wheels kept turning")
        took = time.monotonic() - t0
        print("\nwheels stopped %.0f ms after SetSpeed (command timeout 400 ms)" % (took * 1000))
        self.assertGreater(took, 0.3)

    def test_client_leaving_stops_the_wheels(self):
        # A client process commands the wheels itself, then leaves.
        script = (
            "import sys, dbus\n"
            "bus = dbus.bus.BusConnection(sys.argv[1])\n"
            "t = bus.get_object('org.caracara.Vehicle1', '/org/caracara/Vehicle1/teensy', introspect=False)\n"
            "t.SetSpeed(dbus.Int32(40), dbus.Int32(-40), dbus_interface='org.caracara.Vehicle1.Teensy')\n"
            "print(bus.get_unique_name(), flush=True)\n"
            "sys.stdin.read()\n")
        c = subprocess.Popen([harness.PYTHON, "-c", script, self.rig.address], stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        who = c.stdout.readline().strip()
        self.assertTrue(who, c.stderr.read() if c.poll() is not None else "")
        poll(lambda: front_wheels(self.rig) == (40.0, -40.0), 5)
        self.assertEqual(self.rig.vget("Controller"), who)
        c.stdin.close()
        c.wait(10)
        poll(lambda: front_wheels(self.rig) == (0.0, 0.0), 5, message="the wheels kept turning after the client left")

    def test_a_refused_speed_changes_nothing(self):
        time.sleep(0.15)
        self.assertEqual(error_name(self.set_speed, 500, 0), ERR + "OutOfRange")
        # Not taken as a command: the age of the last one kept growing.
        self.assertGreaterEqual(int(self.rig.vget("CommandAgeMs")), 150)


# Sends SetThrust with alternating values (never zero) until the daemon is gone.
STICK_SCRIPT = r"""
import sys, dbus
bus = dbus.bus.BusConnection(sys.argv[1])
vehicle = bus.get_object("org.caracara.Vehicle1", "/org/caracara/Vehicle1", introspect=False)
n = 0
try:
    while True:
        v = 1500 + 100 * (n % 2)
        vehicle.SetThrust(dbus.Array([v, -v] * 4, signature="i"), dbus_interface="org.caracara.Vehicle1")
        if n == 0:
            print("driving", flush=True)
        n += 1
except dbus.DBusException:
    pass
"""


class WheelsStopAtStartAndExitTest(unittest.TestCase):

    def test_start_and_sigterm_send_stop(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start(daemon=False)
        before = stop_frames(rig)
        rig.start_daemon()
        self.assertGreater(stop_frames(rig), before, "no Stop to the Teensy at start")
        rig.arm()
        rig.vcall("SetSpeed", 30, 30, signature="ii", path=harness.TEENSY_PATH, iface=harness.TEENSY_IFACE)
        self.assertEqual(front_wheels(rig), (30.0, 30.0))
        self.assertEqual(rig.stop_daemon(), 0)
        self.assertEqual(front_wheels(rig), (0.0, 0.0), "SIGTERM left the wheels turning")

    def test_a_crash_sends_stop(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start()
        rig.arm()
        rig.thrust([1500] * MOTORS)
        rig.vcall("SetSpeed", 30, -30, signature="ii", path=harness.TEENSY_PATH, iface=harness.TEENSY_IFACE)
        rig.wait_sim_speeds([speed_byte(1500)] * MOTORS)
        proc = rig.procs["caracarad"]
        proc.send_signal(signal.SIGSEGV)
        proc.wait(30)
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
        self.assertEqual(front_wheels(rig), (0.0, 0.0), "a crash left the wheels turning")
        rig.start_daemon()  # as systemd would; stop_checked wants a clean exit at the end

    def test_a_crash_while_the_bus_is_busy_leaves_no_order_after_the_zeros(self):
        """A fatal signal stops one thread; the bus worker's goes on. Thruster 7 answers slowly
        (15 ms, under the adapter's timeout), so the worker is always on the wire with orders
        queued behind it: none of them may land between or after the crash handler's zeros
        (the emergency stop closes the worker's gate and waits for its transfer)."""
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start()
        rig.arm()
        rig.sim_thruster_call(7, "SetHang", 15, signature="u")
        # A pilot's stick: new values as fast as the daemon takes them, until it is gone.
        pilot = subprocess.Popen([harness.PYTHON, "-c", STICK_SCRIPT, rig.address], stdout=subprocess.PIPE, text=True)
        self.assertEqual(pilot.stdout.readline().strip(), "driving")
        rig.wait_orders_refreshed(count=3)
        since = rig.wire_next()
        proc = rig.procs["caracarad"]
        proc.send_signal(signal.SIGSEGV)
        proc.wait(30)
        pilot.wait(30)
        rig.sim_thruster_call(7, "SetHang", 0, signature="u")
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
        orders = [e for e in rig.wire_log(since)[1] if e.bus == "i2c" and not e.read and len(e.data) == 3]
        for mt in DEFAULT_MT:
            mine = [e for e in orders if e.addr == mt >> 1]
            first_zero = next((e.index for e in mine if e.data[0] == ZERO), None)
            self.assertIsNotNone(first_zero, "no zero order to 0x%02x after the crash" % mt)
            late = [e.index for e in mine if e.index > first_zero and e.data[0] != ZERO]
            self.assertEqual(late, [], "orders to 0x%02x after its zero (#%d)" % (mt, first_zero))
        rig.start_daemon()


RECOVERY_GPIO = dict(harness.SIM_GPIO, scl={"chip": "gpiochip0", "line": "GPIO3"},
                     sda={"chip": "gpiochip0", "line": "GPIO2"})


def bus_state(rig):
    return rig.vget("State", harness.BUS_PATH, harness.BUS_IFACE)


class LostBusStaysKilledTest(VehicleTestCase):
    """A bus that cannot be reached keeps the vehicle killed: nothing is accepted as if it could
    drive, ClearKill waits for the bus, and the bus coming back does not arm it."""
    GPIO = False
    CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 60000}
    EXTRA_CONFIG = {"gpio": harness.SIM_GPIO}  # recovery not configured

    def test_commands_refused_with_bus_lost_until_it_is_back(self):
        rig = self.rig
        rig.reset()
        rig.thrust([1200] * MOTORS)
        rig.wait_sim_speeds([speed_byte(1200)] * MOTORS)
        rig.sim_call("HoldScl")
        try:
            poll(lambda: rig.state() == "killed", 10, message="a lost bus did not kill")
            self.assertEqual(rig.vget("KillSource"), "bus")
            self.assertEqual(bus_state(rig), "lost")
            self.assertTrue(rig.sim_get("KillOutput"))
            for what, call in (
                    ("ClearKill", lambda: rig.vcall("ClearKill")),
                    ("SetThrust", lambda: rig.thrust([100] * MOTORS)),
                    ("SetMotion", lambda: rig.motion(y=0.2)),
                    ("ApplyPacket", lambda: rig.packet(packet([100] * 8))),
                    ("SetSpeed", lambda: rig.vcall("SetSpeed", 10, 10, signature="ii", path=harness.TEENSY_PATH,
                                                   iface=harness.TEENSY_IFACE)),
                    ("Turn", lambda: rig.vcall("Turn", 0.5, signature="d", path=harness.TEENSY_PATH,
                                               iface=harness.TEENSY_IFACE))):
                with self.subTest(what):
                    self.assertEqual(error_name(call), ERR + "BusLost")
            self.assertEqual(rig.state(), "killed")
        finally:
            rig.sim_call("ReleaseBus")
        # The transfers get through again: the bus is back, the vehicle stays killed.
        poll(lambda: bus_state(rig) == "ok", 10, message="the bus never came back")
        rig.wait_sim_zero()
        time.sleep(0.3)
        self.assertEqual(rig.state(), "killed")
        rig.vcall("ClearKill")
        rig.wait_state("ready")


class LongLockupKillsTest(VehicleTestCase):
    """A lockup that outlasts the command timeout is a lost bus, even while recovery attempts
    remain: the thrusters are unreachable for longer than any command may stand."""
    GPIO = False
    CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 500}
    EXTRA_CONFIG = {"gpio": RECOVERY_GPIO,
                    "recovery": {"enabled": True, "attempts": 10, "backoff_ms": 200, "driver_id": "fe804000.i2c"}}

    def test_lockup_longer_than_the_command_timeout_kills(self):
        rig = self.rig
        rig.reset()
        stream = True

        def keep_commanding():
            while stream:
                try:
                    rig.thrust([900] * MOTORS)
                except dbus.DBusException:
                    pass
                time.sleep(0.1)
        rig.thrust([900] * MOTORS)
        rig.wait_sim_speeds([speed_byte(900)] * MOTORS)
        t = threading.Thread(target=keep_commanding)
        t.start()
        try:
            t0 = time.monotonic()
            rig.sim_call("HoldScl")
            poll(lambda: rig.state() == "killed", 10, message="a long lockup did not kill")
            took = time.monotonic() - t0
            print("\nlockup to kill: %.0f ms (command timeout 500 ms)" % (took * 1000))
            self.assertEqual(rig.vget("KillSource"), "bus")
            self.assertEqual(bus_state(rig), "lost")
            self.assertGreaterEqual(took, 0.4)
        finally:
            stream = False
            t.join()
            rig.sim_call("ReleaseBus")
        poll(lambda: bus_state(rig) == "ok", 30, interval=0.1, message="the bus never came back")
        self.assertEqual(rig.state(), "killed")


def cpu_seconds(pid):
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


class VanishedLinesTest(unittest.TestCase):
    """The simulator (the hardware, with its GPIO chip) goes away under a running daemon: the
    kill switch that can no longer be read is a pressed one, its event source is dropped instead
    of firing in a loop, and the daemon stays quiet and answers D-Bus."""

    def test_no_busy_loop_and_killed_when_the_switch_vanishes(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start()
        rig.arm()
        rig.thrust([800] * MOTORS)
        rig.wait_sim_speeds([speed_byte(800)] * MOTORS)
        sim = rig.procs.pop("caracara-sim")  # ended on purpose: not a failure of the rig
        sim.kill()
        sim.wait(10)
        pid = rig.procs["caracarad"].pid
        poll(lambda: rig.state() == "killed", 10, message="a kill switch that cannot be read did not kill")
        log_before = rig.log().count("\n")
        cpu0, t0 = cpu_seconds(pid), time.monotonic()
        time.sleep(VANISHED_WINDOW_S)
        cpu = (cpu_seconds(pid) - cpu0) / (time.monotonic() - t0) * 100
        lines = rig.log().count("\n") - log_before
        print("\nsimulator gone: daemon CPU %.2f %% of a core over %.0f s, %d log lines, KillSource %s"
              % (cpu, VANISHED_WINDOW_S, lines, rig.vget("KillSource")))
        self.assertIn(rig.vget("KillSource"), ("switch", "bus"))
        self.assertIn("kill switch", rig.log())
        # Judged natively: under qemu-user (the arm64 run) the CPU is the emulator's, every
        # instruction translated (2.2 % seen there for the same idle loop), as soak.py's RSS.
        if not harness.EMULATOR:
            self.assertLessEqual(cpu, VANISHED_CPU_PERCENT_MAX)
        self.assertLessEqual(lines, VANISHED_LOG_LINES_MAX)
        # Still serving D-Bus.
        self.assertEqual(error_name(rig.thrust, [100] * MOTORS)[:len(ERR)], ERR)


class AdapterLimitsTest(unittest.TestCase):
    """i2c.timeout_ms and i2c.retries reach the adapter as I2C_TIMEOUT and I2C_RETRIES (the
    keys were read but never applied before)."""

    def test_configured_limits_reach_the_adapter(self):
        rig = Rig(control={"arming_delay_ms": 300}, extra_config={"i2c": {"timeout_ms": 25, "retries": 2}})
        self.addCleanup(rig.stop_checked)
        rig.start()
        self.assertEqual(int(rig.sim_get("I2cTimeout")), 3)  # 10 ms units, rounded up
        self.assertEqual(int(rig.sim_get("I2cRetries")), 2)

    def test_default_timeout_is_short_and_retries_the_kernels(self):
        # 20 ms, not i2c-bcm2835's one second: what a hung thruster may hold the others up.
        rig = Rig(control={"arming_delay_ms": 300})
        self.addCleanup(rig.stop_checked)
        rig.start()
        self.assertEqual(int(rig.sim_get("I2cTimeout")), 2)
        self.assertEqual(int(rig.sim_get("I2cRetries")), -1)


class KillAndPowerOffPacketTest(unittest.TestCase):

    def test_kill_first_then_power_off(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start()
        rig.arm()
        rig.thrust([2000] * 4 + [0] * 4)
        rig.wait_sim_speeds([speed_byte(2000)] * 4 + [ZERO] * 4)
        since = rig.wire_next()
        rig.packet(packet(kill=1, power_off=1))
        self.assertEqual(rig.state(), "powered-off")
        # The line is set once the bus is idle, after the last zero order (the reply comes
        # first): under qemu-user (scripts/cross_test.sh) that is well after the reply.
        poll(lambda: rig.sim_get("PowerOffOutput"), 5, message="the power-off line was never set")
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
        log = rig.wire_log(since)[1]
        kill_edge = [e.index for e in log if e.bus == "gpio" and e.addr == KILL_OUT and e.data == b"\x01"]
        off_edge = [e.index for e in log if e.bus == "gpio" and e.addr == POWER_OFF and e.data == b"\x01"]
        self.assertTrue(kill_edge and off_edge, "edges: kill %s, power-off %s" % (kill_edge, off_edge))
        self.assertLess(kill_edge[0], off_edge[0], "the kill output came after the power-off line")


class StartKilledTest(unittest.TestCase):

    def test_a_fresh_daemon_is_killed_until_clear_kill(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start()
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(rig.vget("KillSource"), "start")
        self.assertTrue(rig.sim_get("KillOutput"), "the kill output is asserted from the start")
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
        self.assertEqual(error_name(rig.thrust, [500] * MOTORS), ERR + "Killed")
        time.sleep(0.6)  # twice the arming delay: nothing arms by itself
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
        # caracaractl status says why and what to do.
        self.assertIn("every start comes up killed: `caracaractl clear-kill` arms it", rig.ctl("status").stdout)
        # A packet's all clear clears only a packet kill, not the start kill.
        self.assertEqual(error_name(rig.packet, packet()), ERR + "Killed")
        rig.vcall("ClearKill")
        self.assertEqual(rig.state(), "arming")
        self.assertFalse(rig.sim_get("KillOutput"))
        rig.wait_state("ready")
        rig.thrust([500] * MOTORS)
        rig.wait_sim_speeds([speed_byte(500)] * MOTORS)

    def test_arm_at_start_opt_out(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000, "arm_at_start": True})
        self.addCleanup(rig.stop_checked)
        rig.start()
        self.assertIn(rig.state(), ("arming", "ready"))
        self.assertEqual(rig.vget("KillSource"), "")
        rig.wait_state("ready")
        rig.thrust([500] * MOTORS)
        rig.wait_sim_speeds([speed_byte(500)] * MOTORS)

    def test_the_mission_does_not_arm_without_being_told(self):
        rig = Rig(control={"arming_delay_ms": 300})
        self.addCleanup(rig.stop_checked)
        rig.start()
        p = subprocess.run([harness.PYTHON, MISSION, "--bus-address", rig.address, "--ready-timeout", "5"],
                           capture_output=True, text=True, timeout=60, stdin=subprocess.DEVNULL)
        self.assertEqual(p.returncode, 1, p.stdout + p.stderr)
        self.assertIn("killed", p.stderr)
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
        orders = [e for e in rig.wire_log(0)[1] if e.bus == "i2c" and not e.read and len(e.data) == 3]
        self.assertTrue(orders)
        self.assertEqual({e.data[0] for e in orders}, {ZERO}, "the mission drove a vehicle nobody armed")


class CommandTimeoutTimerTest(VehicleTestCase):
    """The command timeout fires at last command + timeout, not at the next tick."""
    CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 500, "loop_rate_hz": 50}

    def test_timeout_lands_on_time(self):
        rig = self.rig
        mt = DEFAULT_MT[0]
        lateness = []
        for _ in range(5):
            rig.reset()
            rig.thrust([1500] + [0] * 7)
            accepted = time.monotonic_ns()  # just after the reply: the command was accepted before
            rig.wait_sim_speeds([speed_byte(1500)] + [ZERO] * 7)
            since = rig.wire_next()
            poll(lambda: rig.sim_speeds()[0] == ZERO, 5, message="the command never timed out")
            zero = [e for e in rig.wire_log(since)[1]
                    if e.bus == "i2c" and e.addr == mt >> 1 and not e.read and e.data[:1] == bytes([ZERO])]
            self.assertTrue(zero)
            lateness.append((zero[0].time_ns - accepted) / 1e6 - 500.0)
        median = statistics.median(lateness)
        print("\ncommand timeout 500 ms: first zero order %s ms after it (median %.2f ms)"
              % (", ".join("%.2f" % v for v in lateness), median))
        # Before, the zero waited for the next 50 Hz tick: 13-19 ms late.
        self.assertLess(median, COMMAND_TIMEOUT_LATENESS_MS_MAX)
        self.assertGreater(median, -2.0, "zeroed before the timeout")


class ThrustProfileTest(VehicleTestCase):
    """Named scale factors, applied after mixing and before the budget, switched at run time."""
    CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 60000, "profile": "water"}
    EXTRA_CONFIG = {"profiles": {"water": 1.0, "air": 0.15, "half": 0.5}}

    def setUp(self):
        self.rig.reset()
        self.rig.vcall("SetProfile", "water", signature="s")

    def test_unknown_profile_is_refused_and_changes_nothing(self):
        self.rig.thrust([3000] + [0] * 7)
        self.rig.wait_sim_speeds([speed_byte(3000)] + [ZERO] * 7)
        self.assertEqual(error_name(self.rig.vcall, "SetProfile", "space", signature="s"), ERR + "UnknownProfile")
        self.assertEqual(self.rig.vget("Profile"), "water")
        self.assertEqual(self.rig.vget("ProfileFactor"), 1.0)
        self.rig.wait_orders_refreshed()
        self.assertEqual(self.rig.sim_speeds(), [speed_byte(3000)] + [ZERO] * 7)

    def test_wire_bytes_under_each_profile(self):
        values = [4000, -4000, 2000, 0, 0, 0, 0, 0]
        self.rig.thrust(values)
        for name, factor in (("water", 1.0), ("air", 0.15), ("half", 0.5), ("water", 1.0)):
            with self.subTest(profile=name):
                self.rig.vcall("SetProfile", name, signature="s")
                self.assertEqual(self.rig.vget("Profile"), name)
                self.assertEqual(self.rig.vget("ProfileFactor"), factor)
                expected = [round(v * factor) for v in values]
                # On the wire at once, without a new command; what was asked stays as it was.
                self.rig.wait_sim_speeds([speed_byte(v) for v in expected], timeout=2)
                self.assertEqual([int(v) for v in self.rig.vget("RequestedValues")], values)
                self.assertEqual(self.rig.motor_values(), expected)

    def test_budget_still_holds_under_a_profile(self):
        # Five motors at full thrust: 4200 each under water; at 0.5, 4425 is still over 4200.
        self.rig.vcall("SetProfile", "half", signature="s")
        self.rig.thrust([8850] * 5 + [0] * 3)
        self.rig.wait_sim_speeds([speed_byte(4200)] * 5 + [ZERO] * 3)
        self.assertTrue(self.rig.vget("Saturated"))
        self.assertEqual(self.rig.vget("BudgetLimit"), 4200)
        # At 0.15 the same command is under every limit.
        self.rig.vcall("SetProfile", "air", signature="s")
        self.rig.wait_sim_speeds([speed_byte(round(8850 * 0.15))] * 5 + [ZERO] * 3)
        self.assertFalse(self.rig.vget("Saturated"))

    def test_motion_is_scaled_too(self):
        self.rig.vcall("SetProfile", "air", signature="s")
        self.rig.motion(y=1.0)  # the seed's table: motors 0, 2, 4, 6 full forward
        v = round(8850 * 0.15)
        expected = [v, 0, v, 0, v, 0, v, 0]
        self.rig.wait_sim_speeds([speed_byte(x) for x in expected])
        self.assertEqual(self.rig.motor_values(), expected)

    def test_caracaractl_profile_and_status(self):
        r = self.rig.ctl("profile", "air")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(self.rig.vget("Profile"), "air")
        r = self.rig.ctl("status")
        self.assertIn("air (thrust x 0.15)", r.stdout)
        r = self.rig.ctl("profile", "moon")
        self.assertEqual(r.returncode, 1)
        self.assertIn(ERR + "UnknownProfile", r.stderr)


class ZeroThrustersStepTest(unittest.TestCase):
    """caracarad --zero-thrusters, as systemd's ExecStopPost= runs it after a SIGKILL."""

    def test_after_sigkill_the_step_zeroes_and_asserts_the_kill_output(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start()
        rig.arm()
        values = [3000, -3000, 3000, -3000, 1000, 0, 0, 0]
        rig.thrust(values)
        rig.wait_sim_speeds([speed_byte(v) for v in values])
        proc = rig.procs["caracarad"]
        proc.kill()
        proc.wait(30)
        # The thrusters keep their last order: nothing of the daemon is left to zero them.
        time.sleep(0.2)
        self.assertEqual(rig.sim_speeds(), [speed_byte(v) for v in values])
        since = rig.wire_next()
        t0 = time.monotonic()
        p = subprocess.run(command("caracarad") + ["--zero-thrusters", "--config", rig.config_path,
                            "--hardware=sim:" + rig.sim_socket], capture_output=True, text=True, timeout=60)
        took = time.monotonic() - t0
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
        log = rig.wire_log(since)[1]
        kill_edge = [e.index for e in log if e.bus == "gpio" and e.addr == KILL_OUT and e.data == b"\x01"]
        orders = [e.index for e in log if e.bus == "i2c" and not e.read and len(e.data) == 3]
        self.assertTrue(kill_edge, "the kill output was not asserted")
        self.assertTrue(orders)
        self.assertLess(kill_edge[0], orders[0], "the kill output came after a bus transfer")
        self.assertIn("8 of 8 thrusters zeroed", p.stderr)
        print("\n--zero-thrusters: %.0f ms, %d zero orders" % (took * 1000, len(orders)))
        # systemd's restart then brings up a daemon that is killed until someone arms it.
        rig.start_daemon()
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(rig.vget("KillSource"), "start")

    def test_a_hung_bus_is_bounded_and_reported(self):
        rig = Rig(control={"arming_delay_ms": 300})
        self.addCleanup(rig.stop_checked)
        rig.start(daemon=False)
        # A slave holds SCL low: every transfer on the bus fails from then on.
        rig.sim_call("HoldScl")
        t0 = time.monotonic()
        p = subprocess.run(command("caracarad") + ["--zero-thrusters", "--config", rig.config_path,
                            "--hardware=sim:" + rig.sim_socket], capture_output=True, text=True, timeout=120)
        took = time.monotonic() - t0
        print("\n--zero-thrusters on a bus held low: exit %d in %.1f s" % (p.returncode, took))
        self.assertEqual(p.returncode, 1, p.stderr)
        self.assertIn("not tried, the bus is locked", p.stderr)
        self.assertLess(took, 30.0)


if __name__ == "__main__":
    unittest.main()
