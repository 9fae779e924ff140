"""Failsafes (issue 28), judged on the wire: the simulator's per-thruster faults (SeaBotix IDS
8.4.2: water detect, ground fault, overtemp with its 110/100 C hysteresis, stall, hall) held for
their persistence time, and what each action puts on the I2C bus and the kill output:
warn leaves the orders as they were, exclude zeroes that thruster and holds the others to the
budget of one motor fewer, surface orders the mixing of the heave axis for the set time and then
kills, kill asserts the kill output and zeroes. A condition shorter than its persistence time
does nothing. After a failsafe kill ClearKill is refused while the condition holds, and
ClearKillOverride names it, in the journal with the caller. The fixed conditions are told the
same way; a lost Teensy link kills through the failsafe (pilot lost: test_pilot_lost)."""
import os
import socket
import subprocess
import tempfile
import time
import unittest

import dbus

from harness import (DEFAULT_MT, ERR, MOTORS, ROOT, SEED_AXIS_MOTORS, VEHICLE, ZERO, Rig, budget_limit, command,
                     error_name, poll, pump_main_loop, speed_byte)
from bounds import FAILSAFE_LATENESS_MS_MAX, KILL_REPLY_MS_MAX, SURFACE_ASCENT_EARLY_MS_MAX
from figures import figure
from vehicle_checks import KILL_OUT

THRUSTER_CONDITIONS = ["water-detect", "ground-fault", "overtemp", "stall", "hall"]
CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 60000, "status_reads_per_tick": 8}


def failsafe_config(rules, surface=None):
    """[failsafe]: every thruster condition warns at once, except those in `rules`
    ({condition: (action, persistence_ms)})."""
    table = {c: {"action": "warn", "persistence_ms": 0} for c in THRUSTER_CONDITIONS}
    for c, (action, ms) in rules.items():
        table[c] = {"action": action, "persistence_ms": ms}
    if surface:
        table["surface"] = surface
    return {"failsafe": table}


def thruster_of(addr):
    return next((i for i, mt in enumerate(DEFAULT_MT) if mt >> 1 == addr), None)


def orders(log):
    """[(entry, thruster, SPEED byte)] of the orders that reached a thruster."""
    out = []
    for e in log:
        if e.bus == "i2c" and not e.read and len(e.data) == 3 and e.result == "ack":
            i = thruster_of(e.addr)
            if i is not None:
                out.append((e, i, e.data[0]))
    return out


def kill_edges(log):
    return [e for e in log if e.bus == "gpio" and e.addr == KILL_OUT and e.data == b"\x01"]


def nonzero_after_kill(log, edge):
    """The non-zero orders the kill output's asserting `edge` should have stopped. The simulator
    logs a transfer when it ends and serves the kill output's GPIO write while an I2C transfer is
    on the wire (as the kernel does), so the first I2C transfer logged after the edge was on the
    wire at the kill, which nothing can take back; every later non-zero order is a failure."""
    after = [e for e in log if e.index > edge.index and e.bus == "i2c"]
    on_wire_at_kill = after[0].index if after else None
    return [e for e, i, s in orders(log) if e.index > edge.index and s != ZERO and e.index != on_wire_at_kill]


class FailsafeSignals:
    """The daemon's Failsafe signals, as a client on the bus receives them."""

    def __init__(self, rig):
        self.got = []
        self.match = rig.conn.add_signal_receiver(
            lambda c, a, t: self.got.append((str(c), str(a), int(t))), signal_name="Failsafe",
            dbus_interface=VEHICLE, path=ROOT)

    def wait(self, expected, timeout=10):
        return poll(lambda: expected in self.got, timeout, pump=pump_main_loop,
                    message="no Failsafe%r signal (got %r)" % (expected, self.got))

    def close(self):
        self.match.remove()


class Announced:
    """Every value of one of the vehicle's properties announced in PropertiesChanged."""

    def __init__(self, rig, name):
        self.values = []

        def changed(iface, props, _invalidated):
            if iface == VEHICLE and name in props:
                self.values.append(props[name])
        self.match = rig.conn.add_signal_receiver(changed, signal_name="PropertiesChanged",
                                                  dbus_interface="org.freedesktop.DBus.Properties", path=ROOT)

    def close(self):
        self.match.remove()


def assert_deadline_kept(case, announced, edge, what):
    """A deadline property (CLOCK_MONOTONIC µs, 0 none: SurfacingUntil, PilotLostKillAt) announced
    once when it began and as 0 when it ended, not at every reading, and the kill output's edge
    `edge` no sooner than it said and within a reading period or so. Returns it in ns."""
    poll(lambda: announced.values and announced.values[-1] == 0, 5, pump=pump_main_loop,
         message="%s never announced its end (saw %r)" % (what, announced.values))
    running = sorted({int(v) for v in announced.values if v})
    case.assertEqual(len(running), 1, "%s announced %r" % (what, announced.values))
    case.assertLessEqual(len(announced.values), 6, "%s announced at every reading: %r" % (what, announced.values))
    at_ns = running[0] * 1000
    late_ms = (edge.time_ns - at_ns) / 1e6
    figure("failsafe_deadline.%s.kill_late_ms" % what.lower(), late_ms, "ms", "%s -> kill output edge" % what)
    case.assertGreaterEqual(edge.time_ns, at_ns, "killed before %s" % what)
    case.assertLessEqual(late_ms, FAILSAFE_LATENESS_MS_MAX)
    return at_ns


class FailsafeCase(unittest.TestCase):
    RULES = {}
    SURFACE = None
    CONTROL = CONTROL

    @classmethod
    def setUpClass(cls):
        cls.rig = Rig(control=cls.CONTROL, extra_config=failsafe_config(cls.RULES, cls.SURFACE))
        cls.addClassCleanup(cls.rig.stop_checked)
        cls.rig.start()
        cls.rig.arm()

    def setUp(self):
        self.signals = FailsafeSignals(self.rig)
        self.addCleanup(self.signals.close)

    def failsafes(self):
        return [(str(c), str(a), int(t)) for c, a, t in self.rig.vget("Failsafes")]

    def fault(self, i, name, on):
        self.rig.sim_thruster_call(i, "SetFault", name, on, signature="sb")

    def status_reads(self, i, count=3):
        """Waits until the daemon has read thruster i's status `count` more times."""
        before = int(self.rig.sim_thruster(i, "StatusReads"))
        poll(lambda: int(self.rig.sim_thruster(i, "StatusReads")) >= before + count, 10,
             message="thruster %d's status was not read" % i)

    def drive(self, values):
        self.rig.thrust(values)
        self.rig.wait_sim_speeds([speed_byte(v) for v in values])

    def last_orders(self, log):
        """Each thruster's last order in `log`."""
        last = {}
        for _, i, s in orders(log):
            last[i] = s
        return [last.get(i) for i in range(MOTORS)]


class WarnTest(FailsafeCase):
    RULES = {"water-detect": ("warn", 300), "stall": ("exclude", 1500)}

    def test_warn_leaves_the_orders_unchanged_and_is_told(self):
        rig = self.rig
        rig.reset()
        values = [1500] * MOTORS
        self.drive(values)
        monitor = subprocess.Popen(command("caracaractl") + ["--bus-address", rig.address, "monitor"],
                                   stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        self.addCleanup(monitor.kill)
        time.sleep(0.5)  # the monitor subscribed
        since = rig.wire_next()
        self.fault(3, "water-detect", True)
        try:
            self.signals.wait(("water-detect", "warn", 3))
            self.assertEqual(self.failsafes(), [("water-detect", "warn", 3)])
            self.status_reads(3)
            rig.wait_orders_refreshed(count=5)
            log = rig.wire_log(since)[1]
            self.assertEqual(sorted({s for _, _, s in orders(log)}), [speed_byte(1500)],
                             "a warning changed an order on the wire")
            self.assertEqual(kill_edges(log), [])
            self.assertEqual(rig.state(), "ready")
            self.assertIn("water-detect warn (thruster 3)", rig.ctl("status").stdout)
        finally:
            self.fault(3, "water-detect", False)
        poll(lambda: self.failsafes() == [], 10, message="the warning did not clear")
        monitor.terminate()
        out = monitor.communicate(timeout=10)[0]
        self.assertIn("FAILSAFE water-detect -> warn (thruster 3)", out)
        log = rig.log()
        self.assertEqual(log.count("FAILSAFE water-detect warn thruster 3"), 1, log[-3000:])
        self.assertEqual(log.count("failsafe water-detect warn thruster 3 cleared"), 1, log[-3000:])

    def test_shorter_than_its_persistence_time_does_nothing(self):
        rig = self.rig
        rig.reset()
        self.drive([1500] * MOTORS)
        since = rig.wire_next()
        self.fault(5, "stall", True)
        self.status_reads(5, 3)  # seen, for less than 1.5 s
        self.fault(5, "stall", False)
        self.status_reads(5, 3)
        time.sleep(1.5)          # past the persistence time measured from the first reading
        log = rig.wire_log(since)[1]
        self.assertEqual(sorted({s for _, _, s in orders(log)}), [speed_byte(1500)])
        self.assertEqual(self.signals.got, [])
        self.assertEqual(self.failsafes(), [])
        self.assertNotIn("FAILSAFE stall", rig.log())


class ExcludeTest(FailsafeCase):
    RULES = {"ground-fault": ("exclude", 300)}

    def test_exclude_zeroes_the_thruster_and_the_others_get_its_budget(self):
        rig = self.rig
        rig.reset()
        # Three motors at 7000: the budget for three holds them to 5750.
        requested = [7000, 7000, 7000, 0, 0, 0, 0, 0]
        rig.thrust(requested)
        rig.wait_sim_speeds([speed_byte(budget_limit(3))] * 3 + [ZERO] * 5)
        since = rig.wire_next()
        self.fault(2, "ground-fault", True)
        self.fault(2, "ground-fault", False)  # the controller keeps it until its power is cycled
        self.signals.wait(("ground-fault", "exclude", 2))
        # Two running: the limit is 7850, and 7000 fits.
        expected = [speed_byte(7000), speed_byte(7000), ZERO] + [ZERO] * 5
        rig.wait_sim_speeds(expected)
        rig.wait_orders_refreshed(count=5)
        log = rig.wire_log(since)[1]
        raised = orders(log)
        self.assertEqual(self.last_orders(log), expected)
        # From thruster 2's first zero on, every order is within the budget of two motors.
        first_zero = next(e.index for e, i, s in raised if i == 2 and s == ZERO)
        after = [(i, s) for e, i, s in raised if e.index > first_zero]
        self.assertTrue(all(s == ZERO for i, s in after if i == 2), "thruster 2 ordered again")
        self.assertTrue(all(abs(s - ZERO) <= abs(speed_byte(budget_limit(2)) - ZERO) for _, s in after))
        self.assertEqual(rig.state(), "ready")
        self.assertEqual([int(v) for v in rig.vget("MotorValues")], [7000, 7000, 0, 0, 0, 0, 0, 0])
        self.assertEqual(int(rig.vget("BudgetLimit")), budget_limit(2))
        # Still excluded while the controller holds the fault, then back after a power cycle.
        self.status_reads(2, 3)
        self.assertEqual(self.failsafes(), [("ground-fault", "exclude", 2)])
        rig.sim_thruster_call(2, "PowerCycle")
        poll(lambda: self.failsafes() == [], 10, message="the power cycle did not clear the ground fault")
        rig.wait_sim_speeds([speed_byte(budget_limit(3))] * 3 + [ZERO] * 5)
        self.assertIn("(the controller's power was cycled)", rig.log())


class OvertempTest(FailsafeCase):
    RULES = {"overtemp": ("exclude", 0)}

    def temperature(self, c):
        self.rig.sim_thruster_call(2, "SetTemperature", float(c), float(c), signature="dd")

    def test_overtemp_trips_at_110_and_clears_at_100(self):
        rig = self.rig
        rig.reset()
        self.addCleanup(self.temperature, 15)
        values = [1500] * MOTORS
        self.drive(values)
        since = rig.wire_next()
        self.temperature(105)  # below the set point
        self.status_reads(2, 4)
        self.assertEqual(self.last_orders(rig.wire_log(since)[1]), [speed_byte(1500)] * MOTORS)
        self.assertEqual(self.failsafes(), [])

        self.temperature(112)
        self.signals.wait(("overtemp", "exclude", 2))
        excluded = [speed_byte(1500)] * MOTORS
        excluded[2] = ZERO
        rig.wait_sim_speeds(excluded)

        since = rig.wire_next()
        self.temperature(105)  # cooled, but not to 100 C: still excluded
        self.status_reads(2, 4)
        rig.wait_orders_refreshed(count=3)
        log = rig.wire_log(since)[1]
        self.assertTrue(all(s == ZERO for _, i, s in orders(log) if i == 2), "back before 100 C")
        self.assertEqual(self.last_orders(log), excluded)
        self.assertEqual(self.failsafes(), [("overtemp", "exclude", 2)])

        self.temperature(99)
        poll(lambda: self.failsafes() == [], 10, message="overtemp did not clear below 100 C")
        rig.wait_sim_speeds([speed_byte(1500)] * MOTORS)


class KillAndOverrideTest(FailsafeCase):
    RULES = {"hall": ("kill", 200)}

    def test_kill_then_clear_refused_until_overridden(self):
        rig = self.rig
        rig.reset()
        self.drive([1500] * MOTORS)
        since = rig.wire_next()
        self.fault(6, "hall", True)
        try:
            self.signals.wait(("hall", "kill", 6))
            rig.wait_state("killed")
            self.assertEqual(rig.vget("KillSource"), "failsafe")
            rig.wait_sim_zero()
            log = rig.wire_log(since)[1]
            edge = poll(lambda: kill_edges(rig.wire_log(since)[1]), 5, message="no kill output edge")[0]
            zeros = [e for e, i, s in orders(log) if s == ZERO]
            self.assertTrue(zeros and edge.index < zeros[0].index, "a zero order came before the kill output")
            self.assertFalse(nonzero_after_kill(log, edge),
                             "a non-zero order after the kill output")

            self.assertEqual(error_name(rig.vcall, "ClearKill"), ERR + "FailsafeActive")
            self.assertEqual(error_name(rig.vcall, "ClearKillOverride", "stall", signature="s"),
                             ERR + "FailsafeActive")
            self.assertEqual(error_name(rig.vcall, "ClearKillOverride", "leak", signature="s"), ERR + "InvalidValue")
            r = rig.ctl("clear-kill")
            self.assertEqual(r.returncode, 1)
            self.assertIn(ERR + "FailsafeActive", r.stderr)
            self.assertIn('ClearKillOverride("hall")', r.stderr)  # the way out, named
            r = rig.ctl("clear-kill-override", "stall")
            self.assertEqual(r.returncode, 1)
            self.assertIn(ERR + "FailsafeActive", r.stderr)
            self.assertEqual(rig.state(), "killed")
            me = rig.conn.get_unique_name()
            rig.vcall("ClearKillOverride", "hall", signature="s")
            rig.wait_state("ready")
            self.assertIn("FAILSAFE OVERRIDE: %s named hall" % me, rig.log())
            self.assertEqual(self.failsafes(), [("hall", "warn", 6)])
            self.assertIn("hall warn (thruster 6)", rig.ctl("status").stdout)
            # The pilot drives on, deliberately, with the condition still there.
            self.drive([1200] * MOTORS)
            time.sleep(0.5)
            self.assertEqual(rig.state(), "ready")
        finally:
            self.fault(6, "hall", False)
        poll(lambda: self.failsafes() == [], 10)
        # The dive the failsafe ended has its event, and says how it ended.
        def exports():
            return [rig.ctl("export", os.path.join(rig.dives_dir, f), "--events", "--partial").stdout
                    for f in sorted(os.listdir(rig.dives_dir))]
        ended = [x for x in exports() if "failsafe,hall kill raised thruster=6" in x]
        self.assertEqual(len(ended), 1, exports())
        self.assertIn("source=failsafe", ended[0])
        # The dive the override began is written once a second.
        poll(lambda: any("failsafe,hall warn cleared thruster=6" in x for x in exports()), 10,
             message="the clearing is not in the dive")


class SurfaceTest(FailsafeCase):
    RULES = {"water-detect": ("surface", 300)}
    SURFACE = {"heave": -0.5, "duration_ms": 1500}
    # Shorter than the ascent, many times over: the ascent must be re-sent, without a gap.
    CONTROL = dict(CONTROL, command_timeout_ms=60)

    def ascent(self):
        """The mixing of the heave axis alone (z = -0.5), from the seed's table."""
        v = [0] * MOTORS
        for m, sign in SEED_AXIS_MOTORS["z"].items():
            v[m] = round(-0.5 * sign * 8850)
        return v

    def test_surface_orders_the_heave_for_its_time_then_kills(self):
        rig = self.rig
        rig.reset()
        self.assertEqual(int(rig.vget("SurfaceDurationMs")), 1500)
        self.assertEqual(int(rig.vget("SurfacingUntil")), 0)
        self.drive([0, 0, 3000, 0, 3000, 0, 0, 0])
        until = Announced(rig, "SurfacingUntil")
        self.addCleanup(until.close)
        since = rig.wire_next()
        self.fault(3, "water-detect", True)
        try:
            self.signals.wait(("water-detect", "surface", 3))
            ascent = [speed_byte(v) for v in self.ascent()]
            rig.wait_sim_speeds(ascent)
            self.assertNotEqual(int(rig.vget("SurfacingUntil")), 0)
            self.assertEqual(error_name(rig.thrust, [1000] * MOTORS), ERR + "Surfacing")
            self.assertEqual(error_name(rig.motion, y=0.5), ERR + "Surfacing")
            # Nothing to clear yet: refused, and the failsafe is not overridden by the attempt.
            self.assertEqual(error_name(rig.vcall, "ClearKillOverride", "water-detect", signature="s"),
                             ERR + "NotKilled")
            self.assertEqual(self.failsafes(), [("water-detect", "surface", 3)])
            self.assertIn("SURFACING (water-detect surface thruster 3)", rig.log())
            rig.wait_state("killed", timeout=10)
            self.assertEqual(rig.vget("KillSource"), "failsafe")
            rig.wait_sim_zero()
            log = rig.wire_log(since)[1]
            edge = kill_edges(log)[0]
            first = next(e for e, i, s in orders(log) if i == 1 and s == ascent[1])
            between = [(i, s) for e, i, s in orders(log) if first.index <= e.index < edge.index]
            self.assertTrue(all(s == ascent[i] for i, s in between), "an order that is not the ascent: %r" %
                            [(i, hex(s)) for i, s in between if s != ascent[i]][:5])
            took = (edge.time_ns - first.time_ns) / 1e6
            duration_ms = self.SURFACE["duration_ms"]
            print("\nascent on the wire for %.0f ms (configured %d)" % (took, duration_ms))
            # From its first order, within a loop period; its end is the FailsafeMonitor's.
            self.assertGreaterEqual(took, duration_ms - SURFACE_ASCENT_EARLY_MS_MAX)
            self.assertLessEqual(took, duration_ms + FAILSAFE_LATENESS_MS_MAX)
            self.assertFalse(nonzero_after_kill(log, edge))
            # The ascent ran to the end SurfacingUntil said: its kill then, its orders up to it.
            until_ns = assert_deadline_kept(self, until, edge, "SurfacingUntil")
            self.assertLessEqual(until_ns - first.time_ns, duration_ms * 1e6, "SurfacingUntil later than its duration")
            self.assertEqual(int(rig.vget("SurfacingUntil")), 0)
            self.assertEqual(error_name(rig.vcall, "ClearKill"), ERR + "FailsafeActive")
        finally:
            self.fault(3, "water-detect", False)
        poll(lambda: self.failsafes() == [], 10)
        poll(lambda: error_name(rig.vcall, "ClearKill") is None, 10)
        rig.wait_state("ready")

    def test_a_kill_during_the_ascent_kills_at_once(self):
        rig = self.rig
        rig.reset()
        self.drive([1500] * MOTORS)
        self.fault(3, "water-detect", True)
        try:
            self.signals.wait(("water-detect", "surface", 3))
            rig.wait_sim_speeds([speed_byte(v) for v in self.ascent()])
            since = rig.wire_next()
            t0 = time.monotonic()
            rig.vcall("Kill")
            self.assertLess((time.monotonic() - t0) * 1000, KILL_REPLY_MS_MAX)
            self.assertEqual(rig.state(), "killed")
            self.assertEqual(rig.vget("KillSource"), "dbus")
            rig.wait_sim_zero()
            log = rig.wire_log(since)[1]
            self.assertTrue(kill_edges(log))
            self.assertFalse([e for e, i, s in orders(log) if e.index > kill_edges(log)[0].index and s != ZERO])
            time.sleep(2.0)  # past the ascent's end: nothing more happens
            self.assertEqual(rig.vget("KillSource"), "dbus")
            self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
        finally:
            self.fault(3, "water-detect", False)
        poll(lambda: self.failsafes() == [], 10)

    def test_the_kill_switch_during_the_ascent_kills_at_once(self):
        rig = self.rig
        rig.reset()
        self.fault(3, "water-detect", True)
        try:
            self.signals.wait(("water-detect", "surface", 3))
            rig.wait_sim_speeds([speed_byte(v) for v in self.ascent()])
            since = rig.wire_next()
            rig.sim_call("SetKillSwitch", True, signature="b")
            try:
                rig.wait_state("killed", timeout=5)
                self.assertEqual(rig.vget("KillSource"), "switch")
                rig.wait_sim_zero()
                log = rig.wire_log(since)[1]
                edge = kill_edges(log)[0]
                self.assertFalse(nonzero_after_kill(log, edge))
                time.sleep(2.0)  # past the ascent's end
                self.assertEqual(rig.vget("KillSource"), "switch")
            finally:
                rig.sim_call("SetKillSwitch", False, signature="b")
        finally:
            self.fault(3, "water-detect", False)
        poll(lambda: self.failsafes() == [], 10)


class StatusLineTest(FailsafeCase):
    """systemd's STATUS= line, read from a notify socket of the test's own, as systemd would."""
    RULES = {"water-detect": ("warn", 0)}

    @classmethod
    def setUpClass(cls):
        cls.notify_dir = tempfile.mkdtemp(prefix="caracara-notify-")
        cls.notify = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        cls.notify.bind(os.path.join(cls.notify_dir, "notify"))
        cls.notify.settimeout(0.05)
        os.environ["NOTIFY_SOCKET"] = os.path.join(cls.notify_dir, "notify")
        try:
            super().setUpClass()
        finally:
            del os.environ["NOTIFY_SOCKET"]

    @classmethod
    def tearDownClass(cls):
        cls.notify.close()
        os.unlink(os.path.join(cls.notify_dir, "notify"))
        os.rmdir(cls.notify_dir)

    def status_lines(self):
        out = []
        while True:
            try:
                msg = self.notify.recv(4096).decode()
            except socket.timeout:
                return out
            out += [line[len("STATUS="):] for line in msg.splitlines() if line.startswith("STATUS=")]

    def test_the_status_line_names_the_failsafe(self):
        rig = self.rig
        rig.reset()
        self.status_lines()
        self.fault(3, "water-detect", True)
        try:
            self.signals.wait(("water-detect", "warn", 3))
            seen = []
            poll(lambda: seen.extend(self.status_lines()) or
                 any("FAILSAFE water-detect warn thruster 3" in s for s in seen), 5,
                 message="STATUS= never named the failsafe")
        finally:
            self.fault(3, "water-detect", False)
        poll(lambda: self.failsafes() == [], 10)
        seen = []
        poll(lambda: seen.extend(self.status_lines()) or (seen and "FAILSAFE" not in seen[-1]), 5,
             message="STATUS= kept the failsafe")


class FixedConditionTest(FailsafeCase):
    def test_an_unreachable_thruster_is_told_as_a_failsafe_and_cannot_be_overridden(self):
        rig = self.rig
        rig.reset()
        self.drive([1500] * MOTORS)
        rig.sim_thruster_call(4, "SetNack", True, signature="b")
        try:
            self.signals.wait(("thruster-unreachable", "kill", -1))
            self.assertEqual(rig.state(), "killed")
            self.assertEqual(rig.vget("KillSource"), "device")  # the kill where it arose, first
            self.assertIn(("thruster-unreachable", "kill", -1), self.failsafes())
            self.assertEqual(error_name(rig.vcall, "ClearKill"), ERR + "ThrusterUnreachable")
            self.assertEqual(error_name(rig.vcall, "ClearKillOverride", "thruster-unreachable", signature="s"),
                             ERR + "FailsafeActive")
            self.assertEqual(rig.state(), "killed")
        finally:
            rig.sim_thruster_call(4, "SetNack", False, signature="b")
        poll(lambda: self.failsafes() == [], 10, message="thruster-unreachable did not clear")
        poll(lambda: error_name(rig.vcall, "ClearKill") is None, 10)
        rig.wait_state("ready")


    def test_a_lost_teensy_link_is_a_failsafe_kill_until_it_is_back(self):
        rig = self.rig
        rig.reset()
        self.drive([1500] * MOTORS)
        since = rig.wire_next()
        rig.sim_call("Vanish", "spi", 3000, signature="su")  # the Teensy's SPI device, for 3 s
        self.signals.wait(("teensy-link-lost", "kill", -1))
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(rig.vget("KillSource"), "failsafe")
        rig.wait_sim_zero()
        edge = poll(lambda: kill_edges(rig.wire_log(since)[1]), 5, message="no kill output edge")[0]
        log = rig.wire_log(since)[1]
        self.assertFalse(nonzero_after_kill(log, edge),
                         "a non-zero order after the kill output")
        # Refused while the link is down, by the failsafe that holds; fixed, so not overridable.
        self.assertIn(("teensy-link-lost", "kill", -1), self.failsafes())
        r = rig.ctl("clear-kill")
        self.assertEqual(r.returncode, 1)
        self.assertIn(ERR + "FailsafeActive", r.stderr)
        self.assertIn("teensy-link-lost is fixed at kill", r.stderr)
        self.assertEqual(error_name(rig.vcall, "ClearKillOverride", "teensy-link-lost", signature="s"),
                         ERR + "FailsafeActive")
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(rig.log().count("FAILSAFE teensy-link-lost kill"), 1)
        # Back: the failsafe clears, and a plain ClearKill re-arms.
        poll(lambda: ("teensy-link-lost", "kill", -1) not in self.failsafes(), 15,
             message="the Teensy back did not clear the failsafe")
        self.assertTrue(rig.vget("Online", path="/org/caracara/Vehicle1/teensy", iface="org.caracara.Vehicle1.Teensy"))
        poll(lambda: error_name(rig.vcall, "ClearKill") is None, 10)
        rig.wait_state("ready")

    def test_an_unreadable_kill_switch_is_told_as_a_failsafe(self):
        rig = self.rig
        rig.reset()
        sim = rig.procs.pop("caracara-sim")  # the lines and the bus go with it
        sim.kill()
        sim.wait(10)
        self.signals.wait(("kill-switch-unreadable", "kill", -1))
        self.assertEqual(rig.state(), "killed")
        self.assertIn(("kill-switch-unreadable", "kill", -1), self.failsafes())
        rig.start_sim()
        poll(lambda: ("kill-switch-unreadable", "kill", -1) not in self.failsafes(), 15,
             message="the switch read again did not clear the failsafe")
        poll(lambda: error_name(rig.vcall, "ClearKill") is None, 15)
        rig.wait_state("ready")


class ConfigCheckTest(unittest.TestCase):
    def test_weakening_a_fixed_failsafe_is_refused_by_name(self):
        rig = Rig(control=CONTROL, extra_config={"failsafe": {"bus-lost": {"action": "warn"}}})
        self.addCleanup(rig.stop_checked)
        rig.start(daemon=False)
        p = subprocess.run(command("caracarad") + ["--check-config", "--config", rig.config_path],
                           capture_output=True, text=True, timeout=60)
        self.assertEqual(p.returncode, 78, p.stdout + p.stderr)
        self.assertIn("failsafe.bus-lost.action: FixedFailsafe", p.stdout + p.stderr)


if __name__ == "__main__":
    unittest.main()
