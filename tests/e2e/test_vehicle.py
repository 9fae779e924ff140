"""End-to-end tests of org.caracara.Vehicle1: python3-dbus (and busctl) against caracarad, every
effect checked on the simulated hardware (org.caracara.Simulator1).

Expected motor values and SPEED bytes are computed here from the seeds (harness.speed_byte,
harness.budget_limit, harness.SEED_AXIS_MOTORS), never read back from the daemon.
"""

import math
import random
import signal
import time
import unittest

import dbus
import dbus.bus
import dbus.lowlevel

import harness
from harness import (BUS_IFACE, BUS_PATH, DEFAULT_MT, ERR, INVALID_ARGS, MOTORS, MOTOR_MAX, PROPS, ROOT,
                     SEED_AXIS_MOTORS, TEENSY_IFACE, TEENSY_PATH, THRUSTER_IFACE, VEHICLE, ZERO, Rig,
                     VehicleTestCase, angle_diff, budget_limit, dbus_signature, error_name, poll,
                     pump_main_loop, speed_byte, thruster_path)


def hexes(bs):
    return [hex(b) for b in bs]


def assert_zeroed_before_reply(test, rig, wire_from, replied_ns):
    """Every thruster got a zero order before the daemon's reply arrived: at once, not at a
    later tick. The wire log and time.monotonic_ns() share CLOCK_MONOTONIC; the log stamps
    the end of the modelled transfer, so its wire time is taken off."""
    bit_ns = 1e9 / int(rig.sim_get("ClockHz"))
    _, log = rig.wire_log(wire_from)
    for i, mt in enumerate(DEFAULT_MT):
        zero = [e for e in log if e.bus == "i2c" and not e.read and e.addr == mt >> 1
                and list(e.data) == harness.order_bytes(mt, 0)]
        test.assertTrue(zero, "no zero order to thruster %d in the wire log" % i)
        started = zero[0].time_ns - (10 + 9 * len(zero[0].data)) * bit_ns
        test.assertLessEqual(started, replied_ns, "thruster %d zeroed only after the reply" % i)


class PropertyWatcher:
    """Collects PropertiesChanged signals of one object and interface."""

    def __init__(self, rig, path, iface):
        self.events = []
        self.iface = iface
        self.match = rig.conn.add_signal_receiver(self._on, signal_name="PropertiesChanged",
                                                  dbus_interface=PROPS, path=path)

    def _on(self, iface, changed, invalidated):
        if iface == self.iface:
            self.events.append((dict(changed), list(invalidated)))

    def clear(self):
        pump_main_loop(0.05)
        self.events = []

    def wait_for(self, name, predicate=lambda v: True, timeout=10.0):
        """Waits for a signal announcing `name` (with a value passing predicate, when the value
        is carried); returns the value (None if only invalidated)."""
        def seen():
            for changed, invalidated in self.events:
                if name in changed and predicate(changed[name]):
                    return ("value", changed[name])
                if name in invalidated:
                    return ("invalidated", None)
            return None
        return poll(seen, timeout, pump=pump_main_loop, message="no PropertiesChanged for %s" % name)[1]

    def remove(self):
        self.match.remove()


# --------------------------------------------------------------------------------------------
# The contract: every property of every object, with its type and a meaningful value
# --------------------------------------------------------------------------------------------

class PropertiesTest(VehicleTestCase):

    def setUp(self):
        self.rig.reset()

    def check_interface_props(self, path, iface):
        contract = harness.load_contract()[iface]["properties"]
        props = self.rig.get_all(VEHICLE, path, iface)
        self.assertEqual(sorted(props), sorted(contract), "%s %s: property names" % (path, iface))
        for name, value in props.items():
            self.assertEqual(dbus_signature(value), contract[name]["type"], "%s.%s: type" % (iface, name))
            # Get agrees with GetAll
            self.assertEqual(dbus_signature(self.rig.get(VEHICLE, path, iface, name)), contract[name]["type"])
        return props

    def test_vehicle_properties(self):
        p = self.check_interface_props(ROOT, VEHICLE)
        self.assertEqual(p["State"], "ready")
        self.assertEqual(p["KillSource"], "")
        self.assertEqual(list(p["MotorValues"]), [0] * MOTORS)
        self.assertEqual(p["BudgetPolicy"], "scale")
        self.assertEqual(p["CommandTimeoutMs"], 60000)
        self.assertEqual(p["ArmingDelayMs"], 300)
        self.assertEqual(p["LoopRateHz"], 50.0)
        # Cycles count up with the control loop; CommandAgeMs grows while nobody commands.
        c0 = int(p["Cycles"])
        poll(lambda: int(self.rig.vget("Cycles")) >= c0 + 5, 10, message="Cycles does not advance")
        self.rig.thrust([0] * MOTORS)
        a0 = int(self.rig.vget("CommandAgeMs"))
        self.assertGreaterEqual(a0, 0)
        poll(lambda: int(self.rig.vget("CommandAgeMs")) >= a0 + 100, 10, message="CommandAgeMs does not grow")
        # Controller is our unique name once we command.
        self.assertEqual(self.rig.vget("Controller"), self.rig.conn.get_unique_name())

    def test_loop_rate_is_honoured(self):
        # LoopRateHz is 50: the thrusters' orders are refreshed about that often, also when
        # no client is calling the daemon (nothing else wakes its event loop).
        rate = float(self.rig.vget("LoopRateHz"))
        c0 = int(self.rig.vget("Cycles"))
        o0 = self.rig.sim_counters("OrdersReceived")
        t0 = time.monotonic()
        time.sleep(2.0)
        dt = time.monotonic() - t0
        cycles = (int(self.rig.vget("Cycles")) - c0) / dt
        orders = min(b - a for a, b in zip(o0, self.rig.sim_counters("OrdersReceived"))) / dt
        self.assertGreaterEqual(cycles, 0.5 * rate, "control loop ran at %.1f Hz, configured %g Hz" % (cycles, rate))
        self.assertGreaterEqual(orders, 0.5 * rate, "orders refreshed at %.1f Hz, configured %g Hz" % (orders, rate))

    def test_requested_and_motor_values(self):
        # 1 motor over the 1-2 motor limit: requested keeps the demand, MotorValues the budgeted one.
        self.rig.thrust([0, 0, 0, 8000, 0, 0, 0, 0])
        self.assertEqual(list(self.rig.vget("RequestedValues")), [0, 0, 0, 8000, 0, 0, 0, 0])
        self.assertEqual(list(self.rig.vget("MotorValues")), [0, 0, 0, 7850, 0, 0, 0, 0])
        self.assertEqual(self.rig.vget("BudgetLimit"), 7850)
        self.assertTrue(self.rig.vget("Saturated"))
        self.rig.wait_sim_speeds([ZERO, ZERO, ZERO, speed_byte(7850), ZERO, ZERO, ZERO, ZERO])
        self.rig.thrust([0] * MOTORS)
        self.assertEqual(self.rig.vget("BudgetLimit"), 0)
        self.assertFalse(self.rig.vget("Saturated"))

    def test_busctl_reads_properties(self):
        r = self.rig.busctl("get-property", VEHICLE, ROOT, VEHICLE, "State")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout.strip(), 's "ready"')
        r = self.rig.busctl("get-property", VEHICLE, thruster_path(3), THRUSTER_IFACE, "Address")
        self.assertEqual(r.stdout.strip(), "y %d" % DEFAULT_MT[3])

    def test_thruster_properties(self):
        values = [1200, -2400, 0, 3600, 0, 0, -600, 0]
        self.rig.thrust(values)
        expected = [speed_byte(v) for v in values]
        self.rig.wait_sim_speeds(expected)
        for i in range(MOTORS):
            with self.subTest(thruster=i):
                p = self.check_interface_props(thruster_path(i), THRUSTER_IFACE)
                sim = self.rig.get_all(harness.SIM, harness.sim_thruster_path(i), harness.SIM_THRUSTER_IFACE)
                self.assertEqual(p["Index"], i)
                self.assertEqual(p["Address"], DEFAULT_MT[i])
                self.assertEqual(p["Address"], sim["Address"])
                self.assertEqual(p["Variant"], "seabotix")
                self.assertEqual(p["Variant"], sim["Variant"])
                self.assertEqual(p["MuxAddress"], 0)
                self.assertEqual(p["MuxChannel"], -1)
                self.assertFalse(p["Reversed"])
                self.assertTrue(p["Online"])
                self.assertEqual(p["OrderedValue"], values[i])
                self.assertEqual(p["OrderedSpeed"], expected[i])
                self.assertEqual(p["OrderedSpeed"], sim["OrderedSpeed"])
                self.assertEqual(list(p["Faults"]), [])
                self.assertEqual(p["LastError"], "")
                self.assertEqual(p["Nacks"], 0)
                self.assertEqual(p["Timeouts"], 0)
                self.assertEqual(p["BadReplies"], 0)
                self.assertEqual(p["OrderFailures"], 0)
                self.assertGreater(p["OrdersSent"], 0)
                self.assertLessEqual(p["OrdersSent"], sim["OrdersReceived"] + sim["OrdersRejected"])
                self.assertGreater(p["Temperature"], 0.0)
        # Status replies are read round robin: ActualSpeed follows the simulated ramp, the
        # counters grow, and a running motor draws current.
        poll(lambda: int(self.rig.vget("ActualSpeed", thruster_path(3), THRUSTER_IFACE)) == expected[3], 15,
             message="ActualSpeed of thruster 3 never reached the ordered speed")
        poll(lambda: float(self.rig.vget("Current", thruster_path(3), THRUSTER_IFACE)) > 0.0, 15,
             message="a running thruster reports no current")
        reads = int(self.rig.vget("StatusReads", thruster_path(0), THRUSTER_IFACE))
        poll(lambda: int(self.rig.vget("StatusReads", thruster_path(0), THRUSTER_IFACE)) > reads, 10)
        self.assertGreater(int(self.rig.sim_thruster(0, "StatusReads")), 0)
        fw = self.rig.vget("FirmwareRevision", thruster_path(0), THRUSTER_IFACE)
        self.assertEqual(dbus_signature(fw), "y")

    def test_bus_properties(self):
        p = self.check_interface_props(BUS_PATH, BUS_IFACE)
        self.assertEqual(p["Device"], "/dev/i2c-1")
        self.assertEqual(p["State"], "ok")
        self.assertEqual(p["Recoveries"], 0)
        self.assertEqual(p["RecoveryFailures"], 0)
        self.assertEqual(p["LastPulses"], 0)
        self.assertEqual(p["LastRecoveryError"], "")
        t0 = int(p["Transactions"])
        poll(lambda: int(self.rig.vget("Transactions", BUS_PATH, BUS_IFACE)) > t0 + 10, 10)
        # The daemon counts I2C transactions; the simulator saw at least as many on its wire.
        self.assertGreaterEqual(int(self.rig.sim_get("Transactions")), t0)

    def test_teensy_properties(self):
        p = self.check_interface_props(TEENSY_PATH, TEENSY_IFACE)
        self.assertTrue(p["Online"])
        self.assertEqual(p["Task"], "idle")
        self.assertEqual(len(p["Distances"]), 4)
        self.assertEqual(len(p["Servos"]), 4)
        f0 = int(p["Frames"])
        poll(lambda: int(self.rig.vget("Frames", TEENSY_PATH, TEENSY_IFACE)) > f0, 10)
        # Distances follow the simulated sensors (polled by the control loop).
        self.rig.sim_teensy_call("SetDistance", dbus.Byte(3), dbus.UInt16(777), signature="yq")
        poll(lambda: int(self.rig.vget("Distances", TEENSY_PATH, TEENSY_IFACE)[3]) == 777, 15,
             message="Distances[3] never showed the simulated 777 mm")
        # A busy Teensy is retried and counted; a garbled acknowledgement is a link error.
        b0 = int(self.rig.vget("BusyRetries", TEENSY_PATH, TEENSY_IFACE))
        self.rig.sim_teensy_call("InjectFault", "busy", dbus.UInt32(2), signature="su")
        poll(lambda: int(self.rig.vget("BusyRetries", TEENSY_PATH, TEENSY_IFACE)) >= b0 + 2, 10,
             message="busy answers not counted")
        e0 = int(self.rig.vget("LinkErrors", TEENSY_PATH, TEENSY_IFACE))
        self.rig.sim_teensy_call("InjectFault", "garbage-ack", dbus.UInt32(1), signature="su")
        poll(lambda: int(self.rig.vget("LinkErrors", TEENSY_PATH, TEENSY_IFACE)) >= e0 + 1, 10,
             message="a garbled acknowledgement was not counted")
        poll(lambda: bool(self.rig.vget("Online", TEENSY_PATH, TEENSY_IFACE)), 10)


class ThrusterFaultTest(VehicleTestCase):
    """Faults injected into the simulated controllers (a rig of its own: LastError and the
    error counters stay as evidence)."""

    def setUp(self):
        self.rig.reset()

    def test_thruster_faults_nacks_and_bad_replies(self):
        # A fault the simulated controller raises shows up in Faults.
        self.rig.sim_thruster_call(2, "SetFault", "overtemp", True, signature="sb")
        try:
            poll(lambda: "overtemp" in list(self.rig.vget("Faults", thruster_path(2), THRUSTER_IFACE)), 15,
                 message="the overtemp fault never reached Faults")
        finally:
            self.rig.sim_thruster_call(2, "SetFault", "overtemp", False, signature="sb")
        poll(lambda: list(self.rig.vget("Faults", thruster_path(2), THRUSTER_IFACE)) == [], 15)

        # A NACKing controller: counted, LastError "nack", Online false; back when it answers.
        # Not a bus failure, but a thruster the daemon cannot reach keeps its last order: the
        # vehicle is killed (source "device") and ClearKill is refused until it answers.
        self.rig.sim_thruster_call(5, "SetNack", True, signature="b")
        try:
            poll(lambda: int(self.rig.vget("Nacks", thruster_path(5), THRUSTER_IFACE)) > 0, 10)
            self.assertEqual(self.rig.vget("LastError", thruster_path(5), THRUSTER_IFACE), "nack")
            self.assertFalse(self.rig.vget("Online", thruster_path(5), THRUSTER_IFACE))
            self.assertGreater(int(self.rig.vget("OrderFailures", thruster_path(5), THRUSTER_IFACE)), 0)
            poll(lambda: self.rig.state() == "killed", 10, message="an unreachable thruster did not kill")
            self.assertEqual(self.rig.vget("KillSource"), "device")
            self.assertEqual(error_name(self.rig.vcall, "ClearKill"), ERR + "ThrusterUnreachable")
        finally:
            self.rig.sim_thruster_call(5, "SetNack", False, signature="b")
        poll(lambda: bool(self.rig.vget("Online", thruster_path(5), THRUSTER_IFACE)), 10,
             message="thruster 5 did not come back online")
        self.assertEqual(self.rig.vget("State", BUS_PATH, BUS_IFACE), "ok")
        self.assertEqual(self.rig.state(), "killed")  # answering again does not arm it
        self.rig.reset()

        # Corrupted status replies are counted and never believed.
        self.rig.sim_thruster_call(6, "CorruptReplies", dbus.UInt32(2), "checksum", signature="us")
        poll(lambda: int(self.rig.vget("BadReplies", thruster_path(6), THRUSTER_IFACE)) >= 2, 15,
             message="corrupted replies not counted")
        self.assertEqual(self.rig.vget("LastError", thruster_path(6), THRUSTER_IFACE), "bad-checksum")

REVERSED_THRUSTERS = "".join(
    "[[thruster]]\naddress = 0x%02X\n%s\n" % (mt, "reversed = true\n" if i == 2 else "")
    for i, mt in enumerate(DEFAULT_MT))


class ReversedThrusterTest(VehicleTestCase):
    """Thruster 2 mounted backwards: the motor value keeps its meaning, the wire is reversed."""
    EXTRA_TOML = REVERSED_THRUSTERS

    def test_reversal_applies_on_the_wire_only(self):
        self.assertTrue(self.rig.vget("Reversed", thruster_path(2), THRUSTER_IFACE))
        self.assertFalse(self.rig.vget("Reversed", thruster_path(0), THRUSTER_IFACE))
        values = [1000, 0, 1000, 0, 0, 0, 0, 0]
        self.rig.thrust(values)
        self.rig.wait_sim_speeds([speed_byte(1000), ZERO, speed_byte(-1000), ZERO, ZERO, ZERO, ZERO, ZERO])
        self.assertEqual(self.rig.motor_values(), values)
        self.assertEqual(self.rig.vget("OrderedValue", thruster_path(2), THRUSTER_IFACE), 1000)
        self.assertEqual(self.rig.vget("OrderedSpeed", thruster_path(2), THRUSTER_IFACE), speed_byte(-1000))
        # Motion: forward drives motor 2 forward, i.e. reversed on its wire.
        self.rig.motion(y=0.5)
        self.rig.wait_sim_speeds([speed_byte(4425), ZERO, speed_byte(-4425), ZERO, speed_byte(4425), ZERO,
                                  speed_byte(4425), ZERO])


# --------------------------------------------------------------------------------------------
# The I2C bus: lockup, bus clear, the BusLost/BusRestored signals
# --------------------------------------------------------------------------------------------

RECOVERY_GPIO = dict(harness.SIM_GPIO, scl={"chip": "gpiochip0", "line": "GPIO3"},
                     sda={"chip": "gpiochip0", "line": "GPIO2"})
# The simulator plays a Raspberry Pi 4: taking the pins as GPIO steals them from the I2C
# controller until its driver is rebound (its default driver id is fe804000.i2c).
RECOVERY = {"enabled": True, "attempts": 3, "backoff_ms": 50, "driver_id": "fe804000.i2c"}


class BusSignals:
    def __init__(self, rig):
        self.events = []
        self.match = rig.conn.add_signal_receiver(
            lambda *args, **kw: self.events.append((kw["member"],) + tuple(args)),
            dbus_interface=BUS_IFACE, path=BUS_PATH, member_keyword="member")

    def wait(self, member, timeout=20.0):
        return poll(lambda: [e for e in self.events if e[0] == member], timeout, pump=pump_main_loop,
                    message="no %s signal" % member)

    def remove(self):
        self.match.remove()


class BusRecoveryTest(VehicleTestCase):
    GPIO = False
    EXTRA_CONFIG = {"gpio": RECOVERY_GPIO, "recovery": RECOVERY}

    def setUp(self):
        self.rig.reset()

    def bus(self, name):
        return self.rig.vget(name, BUS_PATH, BUS_IFACE)

    def test_sda_stuck_low_is_cleared_and_orders_resume(self):
        rig = self.rig
        values = [0, 1700, 0, 0, 0, 0, -1700, 0]
        rig.thrust(values)
        rig.wait_sim_speeds([speed_byte(v) for v in values])
        recoveries = int(self.bus("Recoveries"))
        signals = BusSignals(rig)
        try:
            rig.sim_call("HangBus", dbus.UInt32(5), signature="u")  # a slave holds SDA for 5 clocks
            lost = signals.wait("BusLost")
            restored = signals.wait("BusRestored")
        finally:
            signals.remove()
        self.assertTrue(str(lost[0][1]))
        self.assertEqual(int(restored[0][1]), 5, "pulses the bus clear needed")
        self.assertGreater(float(restored[0][2]), 0.0)
        self.assertEqual(rig.sim_get("BusHang"), "none")
        self.assertGreaterEqual(int(rig.sim_get("SclPulses")), 5)
        self.assertTrue(rig.sim_get("I2cFunction"), "the pins were not given back to the I2C controller")
        poll(lambda: self.bus("State") == "ok", 10)
        self.assertEqual(int(self.bus("Recoveries")), recoveries + 1)
        self.assertEqual(int(self.bus("LastPulses")), 5)
        self.assertGreater(float(self.bus("LastRecoveryMs")), 0.0)
        # The orders were re-sent, and the vehicle never stopped being ready.
        rig.wait_orders_refreshed()
        self.assertEqual(rig.sim_speeds(), [speed_byte(v) for v in values])
        self.assertEqual(rig.state(), "ready")
        time.sleep(1.0)
        self.assertEqual(int(self.bus("Recoveries")), recoveries + 1, "recovering again after a good recovery")

    def test_scl_held_low_kills_with_source_bus(self):
        rig = self.rig
        rig.thrust([1200] + [0] * 7)
        rig.wait_sim_speeds([speed_byte(1200)] + [ZERO] * 7)
        failures = int(self.bus("RecoveryFailures"))
        rig.sim_call("HoldScl")  # clocking cannot clear this
        try:
            rig.wait_state("killed", 30)
            self.assertEqual(rig.vget("KillSource"), "bus")
            self.assertEqual(self.bus("State"), "lost")
            self.assertGreaterEqual(int(self.bus("RecoveryFailures")), failures + RECOVERY["attempts"])
            self.assertTrue(self.bus("LastRecoveryError"))
            self.assertTrue(rig.sim_get("KillOutput"), "the kill output de-energizes what the bus cannot reach")
        finally:
            rig.sim_call("ReleaseBus")
        # The background retries bring the bus back; the pending kill's zero orders go out first.
        poll(lambda: self.bus("State") == "ok", 30, interval=0.1, message="the bus never came back")
        rig.wait_sim_zero(10)
        self.assertEqual(rig.state(), "killed", "a bus kill must be cleared explicitly")


class BusRecoveryAtLoopRateZeroTest(VehicleTestCase):
    """At loop rate 0 the cycles follow each other at once; while the bus is lost there is
    nothing to clock out, and they must not turn into a busy loop."""
    GPIO = False
    CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 60000, "loop_rate_hz": 0}
    EXTRA_CONFIG = {"gpio": RECOVERY_GPIO, "recovery": RECOVERY}

    def test_lost_bus_paces_the_cycles(self):
        rig = self.rig
        rig.thrust([1200] + [0] * 7)
        rig.wait_sim_speeds([speed_byte(1200)] + [ZERO] * 7)
        rig.sim_call("HoldScl")
        try:
            rig.wait_state("killed", 30)
            self.assertEqual(rig.vget("State", BUS_PATH, BUS_IFACE), "lost")
            start = int(rig.vget("Cycles"))
            time.sleep(1.0)
            # The 50 Hz backstop tick: about 50 cycles a second (a busy loop makes tens of thousands).
            self.assertLess(int(rig.vget("Cycles")) - start, 500)
        finally:
            rig.sim_call("ReleaseBus")
        poll(lambda: rig.vget("State", BUS_PATH, BUS_IFACE) == "ok", 30, interval=0.1,
             message="the bus never came back")
        rig.wait_sim_zero(10)
        # Back to flat out once the bus is back.
        start = int(rig.vget("Cycles"))
        poll(lambda: int(rig.vget("Cycles")) - start > 500, 10, message="cycles did not go back to flat out")


class BusRecoveryWithoutRebindTest(VehicleTestCase):
    """A bus clear that does not give the bus back (here: no driver_id, so the pins stay GPIO,
    as on a Raspberry Pi configured without it) is a failed recovery: the vehicle must end up
    killed with source "bus", not loop through "successful" recoveries while it reaches no
    thruster."""
    GPIO = False
    EXTRA_CONFIG = {"gpio": RECOVERY_GPIO, "recovery": dict(RECOVERY, driver_id="")}

    def test_ineffective_recovery_escalates_to_a_kill(self):
        rig = self.rig
        rig.thrust([1200] + [0] * 7)
        rig.wait_sim_speeds([speed_byte(1200)] + [ZERO] * 7)
        rig.sim_call("HangBus", dbus.UInt32(3), signature="u")
        poll(lambda: int(rig.vget("RecoveryFailures", BUS_PATH, BUS_IFACE)) >= 1, 20)
        self.assertFalse(rig.sim_get("I2cFunction"))  # the simulated pins stay GPIO
        self.assertIn("no thruster answers", rig.vget("LastRecoveryError", BUS_PATH, BUS_IFACE))
        try:
            rig.wait_state("killed", 10)  # 3 attempts 50 ms apart: well under a second
        except harness.Timeout:
            self.fail("not killed while no transaction reaches the thrusters: State %s, bus %s, %d recoveries, "
                      "thruster 0 still at %s" % (rig.state(), rig.vget("State", BUS_PATH, BUS_IFACE),
                                                  int(rig.vget("Recoveries", BUS_PATH, BUS_IFACE)),
                                                  hex(rig.sim_speeds()[0])))
        self.assertEqual(rig.vget("KillSource"), "bus")
        self.assertTrue(rig.sim_get("KillOutput"))
        self.assertEqual(int(rig.vget("Recoveries", BUS_PATH, BUS_IFACE)), 0, "nothing was recovered")


# --------------------------------------------------------------------------------------------
# The current budget, on every count of running motors
# --------------------------------------------------------------------------------------------

# Motors picked for a count n: the first n of a permutation, so each count uses other motors.
MOTOR_ORDER = [0, 3, 6, 1, 4, 7, 2, 5]
MAGNITUDES = [8850, 8000, 7200, 6400, 5600, 4800, 4400, 4000]


def demand_for(n, magnitudes=MAGNITUDES):
    values = [0] * MOTORS
    for k in range(n):
        values[MOTOR_ORDER[k]] = magnitudes[k] * (1 if k % 2 == 0 else -1)
    return values


class BudgetScaleTest(VehicleTestCase):

    def setUp(self):
        self.rig.reset()

    def check_sim(self, values, tolerate_rounding=True):
        """Waits until every simulated thruster shows the expected order for `values` (floats
        allowed: a scaled value may round either way by one unit)."""
        def matches():
            speeds = self.rig.sim_speeds()
            for i, v in enumerate(values):
                ok = {speed_byte(math.floor(v)), speed_byte(math.ceil(v)), speed_byte(int(v))}
                if speeds[i] not in ok:
                    return False
            return speeds
        return poll(matches, 10, message="simulated thrusters never showed %r (now %s)" %
                    (values, hexes(self.rig.sim_speeds())))

    def test_scale_on_every_count(self):
        for n in range(1, MOTORS + 1):
            with self.subTest(running=n):
                values = demand_for(n)
                limit = budget_limit(n)
                self.rig.thrust(values)
                largest = max(abs(v) for v in values)
                factor = limit / largest
                expected = [v * factor for v in values]
                self.check_sim(expected)
                # The orders on the wire are complete and well-formed: [SPEED, INFO, CSUM].
                orders = self.rig.sim_last_orders()
                speeds = self.rig.sim_speeds()
                for i in range(MOTORS):
                    s = speeds[i]
                    self.assertEqual(list(orders[i]), [s, 100, (DEFAULT_MT[i] + s + 100) & 0xFF])
                # The daemon reports what it did.
                self.assertEqual(self.rig.vget("BudgetLimit"), limit)
                self.assertTrue(self.rig.vget("Saturated"))
                self.assertEqual(list(self.rig.vget("RequestedValues")), values)
                mv = self.rig.motor_values()
                self.assertEqual(max(abs(v) for v in mv), limit, "the largest motor is held at the limit")
                for i in range(MOTORS):
                    self.assertLessEqual(abs(mv[i]), limit)
                    self.assertAlmostEqual(mv[i], expected[i], delta=1.0,
                                           msg="motor %d: one factor for all motors keeps the direction" % i)
                    self.assertEqual(mv[i] == 0, values[i] == 0)
                    self.assertEqual(mv[i] > 0, values[i] > 0)

    def test_within_budget_is_not_scaled(self):
        for n in range(1, MOTORS + 1):
            with self.subTest(running=n):
                limit = budget_limit(n)
                values = demand_for(n, [limit] * MOTORS)
                self.rig.thrust(values)
                self.rig.wait_sim_speeds([speed_byte(v) for v in values])
                self.assertEqual(self.rig.motor_values(), values)
                self.assertFalse(self.rig.vget("Saturated"))
                self.assertEqual(self.rig.vget("BudgetLimit"), limit)

    def test_one_over_the_limit_is_scaled(self):
        # limit + 1 on one motor: the budget must not be exceeded even by one unit.
        for n in (2, 4, 8):
            with self.subTest(running=n):
                limit = budget_limit(n)
                values = demand_for(n, [limit] * MOTORS)
                values[MOTOR_ORDER[0]] = limit + 1
                self.rig.thrust(values)
                mv = self.rig.motor_values()
                self.assertLessEqual(max(abs(v) for v in mv), limit)
                self.assertTrue(self.rig.vget("Saturated"))
                self.check_sim([v * limit / (limit + 1) for v in values])


class BudgetRejectTest(VehicleTestCase):
    CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 60000, "budget_policy": "reject"}

    def setUp(self):
        self.rig.reset()

    def test_policy_property(self):
        self.assertEqual(self.rig.vget("BudgetPolicy"), "reject")

    def test_reject_on_every_count(self):
        base = [500, 0, 0, 0, 0, 0, 0, -500]
        for n in range(1, MOTORS + 1):
            with self.subTest(running=n):
                self.rig.thrust(base)
                self.rig.wait_sim_speeds([speed_byte(v) for v in base])
                limit = budget_limit(n)
                over = demand_for(n, [limit] * MOTORS)
                over[MOTOR_ORDER[n - 1]] += 1 if over[MOTOR_ORDER[n - 1]] > 0 else -1
                before = self.rig.sim_snapshot()
                self.assertDBusError(ERR + "OverBudget", self.rig.thrust, over)
                self.rig.wait_orders_refreshed()
                self.assertEqual(self.rig.sim_snapshot(), before, "a rejected command changed the thrusters")
                self.assertEqual(list(self.rig.vget("RequestedValues")), base)
                self.assertEqual(self.rig.motor_values(), base)
                self.assertFalse(self.rig.vget("Saturated"))
                # Exactly at the limit is accepted and reaches the thrusters unchanged.
                at = demand_for(n, [limit] * MOTORS)
                self.rig.thrust(at)
                self.rig.wait_sim_speeds([speed_byte(v) for v in at])
                self.assertEqual(self.rig.motor_values(), at)

    def test_reject_motion_over_budget(self):
        # y = 1 drives four motors at full scale: over the 4-motor limit.
        self.rig.thrust([0] * MOTORS)
        self.assertDBusError(ERR + "OverBudget", self.rig.motion, y=1.0)
        self.rig.wait_orders_refreshed()
        self.assertEqual(self.rig.sim_speeds(), [ZERO] * MOTORS)


# --------------------------------------------------------------------------------------------
# SetMotion through the default mixing matrix
# --------------------------------------------------------------------------------------------

class MotionTest(VehicleTestCase):

    def setUp(self):
        self.rig.reset()

    def test_each_axis_moves_the_seed_motors(self):
        for axis, motors in SEED_AXIS_MOTORS.items():
            for demand in (0.5, -0.5):
                with self.subTest(axis=axis, demand=demand):
                    self.rig.motion(**{axis: demand})
                    value = round(demand * MOTOR_MAX)  # 4 motors at 4425: within the 5750 budget
                    expected = [speed_byte(motors[i] * value) if i in motors else ZERO for i in range(MOTORS)]
                    self.rig.wait_sim_speeds(expected)
                    self.assertFalse(self.rig.vget("Saturated"))
                    self.assertEqual(self.rig.motor_values(),
                                     [motors.get(i, 0) * value for i in range(MOTORS)])

    def test_full_axis_is_held_to_the_budget(self):
        self.rig.motion(z=-1.0)
        limit = budget_limit(4)
        motors = SEED_AXIS_MOTORS["z"]
        self.rig.wait_sim_speeds([speed_byte(-motors[i] * limit) if i in motors else ZERO for i in range(MOTORS)])
        self.assertTrue(self.rig.vget("Saturated"))
        self.assertEqual(self.rig.vget("BudgetLimit"), limit)

    def test_combined_axes_keep_direction(self):
        # forward + clockwise yaw: motors 0 and 2 add up (2), 4 and 6 cancel (0); the mix is
        # scaled by one factor (not clipped), leaving two motors at full scale, then the
        # two-motor budget.
        self.rig.motion(y=1.0, yaw=1.0)
        limit = budget_limit(2)
        self.rig.wait_sim_speeds([speed_byte(limit), ZERO, speed_byte(limit), ZERO, ZERO, ZERO, ZERO, ZERO])
        self.assertTrue(self.rig.vget("Saturated"))


# --------------------------------------------------------------------------------------------
# ApplyPacket, the seed's 13-word packet
# --------------------------------------------------------------------------------------------

def packet(motors=(0,) * 8, kill=0, power_off=0, rgb=(0, 0, 0)):
    return list(motors) + [kill, power_off] + list(rgb)


class PacketTest(VehicleTestCase):

    def setUp(self):
        self.rig.reset()

    def test_motors_and_leds(self):
        motors = [700, -700, 1400, 0, 0, -2100, 0, 350]
        self.rig.packet(packet(motors, rgb=(10, 20, 30)))
        self.rig.wait_sim_speeds([speed_byte(v) for v in motors])
        self.assertEqual(self.rig.motor_values(), motors)
        poll(lambda: tuple(self.rig.sim_teensy("Leds")) == (10, 20, 30), 10, message="LEDs never reached the Teensy")
        self.assertEqual(tuple(self.rig.vget("Leds")), (10, 20, 30))
        self.assertEqual(self.rig.vget("Controller"), self.rig.conn.get_unique_name())

    def test_packet_budget(self):
        motors = [8850] * 8
        self.rig.packet(packet(motors))
        self.rig.wait_sim_speeds([speed_byte(4200)] * 8)
        self.assertTrue(self.rig.vget("Saturated"))

    def test_kill_and_all_clear(self):
        motors = [1000, 0, -1000, 0, 0, 0, 0, 0]
        self.rig.packet(packet(motors))
        self.rig.wait_sim_speeds([speed_byte(v) for v in motors])
        zeros_before = self.rig.sim_counters("ZeroOrders")
        wire_from = self.rig.wire_next()
        # Any non-zero killState kills (the seed's "non-zero: motors de-energized").
        self.rig.packet(packet(motors, kill=-5, rgb=(255, 0, 0)))
        replied_ns = time.monotonic_ns()
        self.assertEqual(self.rig.sim_speeds(), [ZERO] * MOTORS)
        assert_zeroed_before_reply(self, self.rig, wire_from, replied_ns)
        self.assertTrue(all(a > b for a, b in zip(self.rig.sim_counters("ZeroOrders"), zeros_before)))
        self.assertEqual(self.rig.state(), "killed")
        self.assertEqual(self.rig.vget("KillSource"), "packet")
        self.assertTrue(self.rig.sim_get("KillOutput"))
        poll(lambda: tuple(self.rig.sim_teensy("Leds")) == (255, 0, 0), 10)
        # Motors in a packet that still says kill do nothing.
        self.rig.packet(packet(motors, kill=1))
        self.rig.wait_orders_refreshed()
        self.assertEqual(self.rig.sim_speeds(), [ZERO] * MOTORS)
        # killState 0 is the all clear: arming (zero output), then ready. The motors of the
        # clearing packet are not applied.
        self.rig.packet(packet(motors, kill=0, rgb=(0, 255, 0)))
        self.assertEqual(self.rig.state(), "arming")
        self.assertEqual(self.rig.vget("KillSource"), "")
        self.assertEqual(self.rig.sim_speeds(), [ZERO] * MOTORS)
        self.rig.wait_state("ready")
        self.assertFalse(self.rig.sim_get("KillOutput"))
        self.rig.wait_orders_refreshed()
        self.assertEqual(self.rig.sim_speeds(), [ZERO] * MOTORS, "the kill resumed old motors by itself")
        # The next packet drives again.
        self.rig.packet(packet(motors))
        self.rig.wait_sim_speeds([speed_byte(v) for v in motors])

    def test_all_clear_does_not_clear_a_dbus_kill(self):
        self.rig.vcall("Kill")
        self.assertDBusError(ERR + "Killed", self.rig.packet, packet([1000] + [0] * 7))
        self.assertEqual(self.rig.state(), "killed")
        self.assertEqual(self.rig.vget("KillSource"), "dbus")
        self.assertEqual(self.rig.sim_speeds(), [ZERO] * MOTORS)


# --------------------------------------------------------------------------------------------
# Kill, ClearKill, the kill switch, PropertiesChanged
# --------------------------------------------------------------------------------------------

class KillTest(VehicleTestCase):

    def setUp(self):
        self.rig.reset()

    def drive(self):
        values = [3000, -3000, 2000, -2000, 1000, -1000, 500, -500]
        self.rig.thrust(values)
        self.rig.wait_sim_speeds([speed_byte(v) for v in values])
        return values

    def test_kill_zeroes_at_once_and_latches(self):
        values = self.drive()
        zeros_before = self.rig.sim_counters("ZeroOrders")
        wire_from = self.rig.wire_next()
        self.rig.vcall("Kill")
        replied_ns = time.monotonic_ns()
        # Right after the reply, without waiting for a tick.
        self.assertEqual(self.rig.sim_speeds(), [ZERO] * MOTORS)
        zeros_after = self.rig.sim_counters("ZeroOrders")
        for i in range(MOTORS):
            self.assertGreater(zeros_after[i], zeros_before[i], "thruster %d got no zero order" % i)
        assert_zeroed_before_reply(self, self.rig, wire_from, replied_ns)
        self.assertEqual(self.rig.state(), "killed")
        self.assertEqual(self.rig.vget("KillSource"), "dbus")
        self.assertTrue(self.rig.sim_get("KillOutput"))
        self.assertEqual(self.rig.motor_values(), [0] * MOTORS)
        self.assertEqual(list(self.rig.vget("RequestedValues")), [0] * MOTORS, "stored commands not dropped")

        # Latched: thrust, motion and packets are refused, the hardware stays at zero.
        before = self.rig.sim_snapshot()
        self.assertDBusError(ERR + "Killed", self.rig.thrust, values)
        self.assertDBusError(ERR + "Killed", self.rig.motion, y=0.5)
        self.assertDBusError(ERR + "Killed", self.rig.packet, packet(values))
        self.rig.wait_orders_refreshed()
        self.assertEqual(self.rig.sim_snapshot(), before)
        # A second Kill is accepted and keeps the first source.
        self.rig.vcall("Kill")
        self.assertEqual(self.rig.vget("KillSource"), "dbus")
        # Nothing resumes by itself.
        time.sleep(0.3)
        self.assertEqual(self.rig.state(), "killed")
        self.assertEqual(self.rig.sim_speeds(), [ZERO] * MOTORS)

    def test_clear_kill_arms_then_ready(self):
        values = self.drive()
        self.rig.vcall("Kill")
        self.rig.vcall("ClearKill")
        cleared = time.monotonic()
        self.assertEqual(self.rig.state(), "arming")
        self.assertEqual(self.rig.vget("KillSource"), "")
        self.assertFalse(self.rig.sim_get("KillOutput"), "the kill output stays asserted while arming")
        self.assertDBusError(ERR + "Arming", self.rig.thrust, values)
        samples = []
        while self.rig.state() == "arming" and time.monotonic() - cleared < 20:
            samples.append(self.rig.sim_speeds())
            time.sleep(0.02)
        armed = time.monotonic() - cleared
        self.assertEqual(self.rig.state(), "ready")
        self.assertTrue(samples)
        for s in samples:
            self.assertEqual(s, [ZERO] * MOTORS, "output while arming")
        # ArmingDelayMs is 300 here: roughly that, with room for a noisy machine.
        self.assertGreaterEqual(armed, 0.2)
        self.assertLess(armed, 10.0)
        # Ready, and still zero until someone commands again.
        self.rig.wait_orders_refreshed()
        self.assertEqual(self.rig.sim_speeds(), [ZERO] * MOTORS)
        self.rig.thrust(values)
        self.rig.wait_sim_speeds([speed_byte(v) for v in values])

    def test_clear_kill_when_not_killed(self):
        self.assertDBusError(ERR + "NotKilled", self.rig.vcall, "ClearKill")
        self.assertEqual(self.rig.state(), "ready")

    def test_kill_switch(self):
        self.drive()
        self.rig.sim_call("SetKillSwitch", True, signature="b")
        try:
            self.rig.wait_state("killed", 10)
            self.assertEqual(self.rig.vget("KillSource"), "switch")
            self.rig.wait_sim_zero(5)
            self.assertTrue(self.rig.sim_get("KillOutput"))
            # Clearing is refused while the switch is set.
            self.assertDBusError(ERR + "KillSwitchSet", self.rig.vcall, "ClearKill")
            self.assertEqual(self.rig.state(), "killed")
        finally:
            self.rig.sim_call("SetKillSwitch", False, signature="b")
        # Releasing the switch does not clear the kill by itself.
        time.sleep(0.2)
        self.assertEqual(self.rig.state(), "killed")
        self.rig.vcall("ClearKill")
        self.assertEqual(self.rig.state(), "arming")
        self.rig.wait_state("ready")

    def test_properties_changed(self):
        watcher = PropertyWatcher(self.rig, ROOT, VEHICLE)
        try:
            watcher.clear()
            values = [2000, 0, 0, 0, 0, 0, 0, -9]
            self.rig.thrust(values)
            mv = watcher.wait_for("MotorValues", lambda v: list(v) == values)
            self.assertTrue(mv is None or list(mv) == values)
            watcher.clear()
            self.rig.vcall("Kill")
            state = watcher.wait_for("State", lambda v: v == "killed")
            source = watcher.wait_for("KillSource", lambda v: v == "dbus")
            self.assertIn(state, (None, "killed"))
            self.assertIn(source, (None, "dbus"))
            watcher.clear()
            self.rig.vcall("ClearKill")
            watcher.wait_for("State", lambda v: v == "arming")
            watcher.wait_for("State", lambda v: v == "ready")
        finally:
            watcher.remove()

    def test_properties_changed_of_every_object(self):
        # Every object announces its changes; each announced property is one the contract
        # declares on that interface with EmitsChangedSignal true, carried with its declared type.
        contract = harness.load_contract()
        events = []

        def on_signal(iface, changed, invalidated, path=None):
            events.append((str(path), str(iface), dict(changed), list(invalidated)))

        match = self.rig.conn.add_signal_receiver(on_signal, signal_name="PropertiesChanged", dbus_interface=PROPS,
                                                  bus_name=VEHICLE, path_keyword="path")
        try:
            values = [0, 0, 0, 1234, 0, 0, 0, 0]
            self.rig.thrust(values)
            pump_main_loop(1.5)  # the steady counters are announced once a second
            self.rig.thrust([0] * MOTORS)
            pump_main_loop(0.3)
        finally:
            match.remove()
        expected_iface = {ROOT: VEHICLE, TEENSY_PATH: TEENSY_IFACE, BUS_PATH: BUS_IFACE}
        expected_iface.update({thruster_path(i): THRUSTER_IFACE for i in range(MOTORS)})
        seen = {}
        for path, iface, changed, invalidated in events:
            self.assertEqual(iface, expected_iface.get(path), f"PropertiesChanged from {path}")
            self.assertEqual(invalidated, [], f"{path}: values are carried, not invalidated")
            self.assertTrue(changed, f"{path}: an empty PropertiesChanged")
            declared = contract[iface]["properties"]
            for name, value in changed.items():
                self.assertIn(name, declared, f"{path}: {name} is not in the contract of {iface}")
                self.assertNotIn(declared[name]["annotations"].get(harness.EMITS, "true"), ("false", "const"),
                                 f"{iface}.{name} announced but declared without change signals")
                self.assertEqual(dbus_signature(value), declared[name]["type"], f"{iface}.{name}")
                seen.setdefault(path, {}).setdefault(name, []).append(value)
        self.assertEqual(seen[thruster_path(3)]["OrderedValue"][0], 1234)
        self.assertIn(values, [list(v) for v in seen[ROOT]["MotorValues"]])
        self.assertIn("Cycles", seen[ROOT])
        self.assertIn("Transactions", seen[BUS_PATH])
        self.assertIn("Frames", seen[TEENSY_PATH])
        self.assertEqual(set(seen), set(expected_iface), "every object announced its changes")


def check_announced_while_bus_busy(test):
    """The bus work never rests: a command's PropertiesChanged and the telemetry still go out."""
    rig = test.rig
    watcher = PropertyWatcher(rig, ROOT, VEHICLE)
    try:
        watcher.clear()
        values = [1500, 0, 0, 0, 0, 0, 0, -1500]
        rig.thrust(values)
        watcher.wait_for("MotorValues", lambda v: list(v) == values, timeout=5)
        first = watcher.wait_for("Cycles", timeout=5)
        watcher.wait_for("Cycles", lambda v: v > first, timeout=5)
        rig.wait_sim_speeds([speed_byte(v) for v in values], timeout=10)
        rig.thrust([0] * MOTORS)
        watcher.wait_for("MotorValues", lambda v: list(v) == [0] * MOTORS, timeout=5)
    finally:
        watcher.remove()


class AnnouncementsAtLoopRateZeroTest(VehicleTestCase):
    """loop_rate_hz = 0: the next cycle starts as soon as the last one's work is done."""

    CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 60000, "loop_rate_hz": 0}

    def test_announced_while_the_loop_runs_flat_out(self):
        check_announced_while_bus_busy(self)


class AnnouncementsOnASlowWireTest(VehicleTestCase):
    """A 10 kHz wire with real waits: one cycle's transactions take about 40 ms, longer than
    the 20 ms tick, so there is always bus work due."""

    def setUp(self):
        self.rig.sim_call("SetRealisticTiming", True, signature="b")
        self.rig.sim_call("SetClock", dbus.UInt32(10000), signature="u")
        self.addCleanup(self.rig.sim_call, "SetRealisticTiming", False, signature="b")
        self.addCleanup(self.rig.sim_call, "SetClock", dbus.UInt32(100000), signature="u")

    def test_announced_while_cycles_overrun_the_tick(self):
        check_announced_while_bus_busy(self)

    def test_every_thruster_still_read(self):
        # Cycles run back to back instead of each tick re-sending the orders in front of the
        # status reads: every thruster's status keeps being read.
        before = self.rig.sim_counters("StatusReads")
        poll(lambda: all(a > b for a, b in zip(self.rig.sim_counters("StatusReads"), before)), 10,
             message="a thruster's status is no longer read")
        cycles = self.rig.vget("Cycles")
        poll(lambda: self.rig.vget("Cycles") >= cycles + 5, 10, message="cycles stopped")


class KillSwitchAtStartTest(unittest.TestCase):

    def test_start_with_the_switch_set_is_killed(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start(daemon=False)
        rig.sim_call("SetKillSwitch", True, signature="b")
        rig.start_daemon()
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(rig.vget("KillSource"), "switch")
        self.assertTrue(rig.sim_get("KillOutput"))
        self.assertEqual(error_name(rig.thrust, [100] * MOTORS), ERR + "Killed")
        self.assertEqual(error_name(rig.vcall, "ClearKill"), ERR + "KillSwitchSet")
        time.sleep(0.5)
        self.assertEqual(rig.state(), "killed", "the kill switch kill ended by itself")
        rig.sim_call("SetKillSwitch", False, signature="b")
        rig.vcall("ClearKill")
        rig.wait_state("ready")
        rig.thrust([100] * MOTORS)
        rig.wait_sim_speeds([speed_byte(100)] * MOTORS)


class DefaultArmingTest(VehicleTestCase):
    """The default 3 s arming delay (the board firmware's), at start and after ClearKill."""
    CONTROL = {"command_timeout_ms": 60000}
    WAIT_READY = False

    def test_default_arming_delay(self):
        rig = self.rig
        # Nobody has commanded this fresh daemon yet.
        self.assertEqual(rig.vget("CommandAgeMs"), -1)
        self.assertEqual(rig.vget("Controller"), "")
        self.assertEqual(rig.vget("ArmingDelayMs"), 3000)
        # At start: killed (source "start"), zero output, commands refused until ClearKill,
        # then arming for the delay.
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(rig.vget("KillSource"), "start")
        self.assertDBusError(ERR + "Killed", rig.thrust, [1000] + [0] * 7)
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
        rig.vcall("ClearKill")
        self.assertDBusError(ERR + "Arming", rig.thrust, [1000] + [0] * 7)
        rig.wait_state("ready", 30)
        rig.vcall("Kill")
        rig.vcall("ClearKill")
        cleared = time.monotonic()
        while rig.state() == "arming" and time.monotonic() - cleared < 30:
            self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
            time.sleep(0.05)
        armed = time.monotonic() - cleared
        self.assertEqual(rig.state(), "ready")
        self.assertGreaterEqual(armed, 2.5, "arming ended after %.2f s" % armed)
        self.assertLess(armed, 15.0)


# --------------------------------------------------------------------------------------------
# Power-off (irreversible: a fresh daemon per test)
# --------------------------------------------------------------------------------------------

class PowerOffTest(unittest.TestCase):

    def setUp(self):
        self.rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(self.rig.stop_checked)
        self.rig.start()
        self.rig.arm()
        self.values = [1500, -1500, 0, 0, 3000, 0, 0, 0]
        self.rig.thrust(self.values)
        self.rig.wait_sim_speeds([speed_byte(v) for v in self.values])

    def assertDBusError(self, expected, fn, *args, **kwargs):
        self.assertEqual(error_name(fn, *args, **kwargs), expected)

    def check_powered_off(self):
        rig = self.rig
        self.assertEqual(rig.state(), "powered-off")
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS, "thrusters not zeroed by the power-off")
        self.assertTrue(rig.sim_get("PowerOffOutput"))
        before = rig.sim_snapshot()
        self.assertDBusError(ERR + "PoweredOff", rig.thrust, self.values)
        self.assertDBusError(ERR + "PoweredOff", rig.motion, y=0.2)
        self.assertDBusError(ERR + "PoweredOff", rig.packet, packet(self.values))
        self.assertDBusError(ERR + "PoweredOff", rig.vcall, "ClearKill")
        self.assertDBusError(ERR + "PoweredOff", rig.vcall, "PowerOff", "power-off", signature="s")
        self.assertDBusError(ERR + "PoweredOff", rig.vcall, "SetLeds", 1, 2, 3, signature="yyy")
        self.assertDBusError(ERR + "PoweredOff", rig.vcall, "SetServo", 0, 10, signature="yy",
                             path=TEENSY_PATH, iface=TEENSY_IFACE)
        self.assertDBusError(ERR + "PoweredOff", rig.vcall, "SetSpeed", 10, 10, signature="ii",
                             path=TEENSY_PATH, iface=TEENSY_IFACE)
        time.sleep(0.2)
        self.assertEqual([s for s, _ in rig.sim_snapshot()], [s for s, _ in before])
        self.assertEqual(rig.state(), "powered-off")

    def test_power_off_needs_confirmation(self):
        rig = self.rig
        for wrong in ("", "yes", "poweroff", "POWER-OFF", "power-off "):
            with self.subTest(confirmation=wrong):
                before = rig.sim_snapshot()
                self.assertDBusError(ERR + "ConfirmationRequired", rig.vcall, "PowerOff", wrong, signature="s")
                self.assertEqual(rig.state(), "ready")
                self.assertFalse(rig.sim_get("PowerOffOutput"))
                rig.wait_orders_refreshed()
                self.assertEqual(rig.sim_snapshot(), before)
        wire_from = rig.wire_next()
        rig.vcall("PowerOff", "power-off", signature="s")
        assert_zeroed_before_reply(self, rig, wire_from, time.monotonic_ns())
        self.check_powered_off()

    def test_packet_power_off(self):
        self.assertDBusError(ERR + "InvalidValue", self.rig.packet, packet(self.values, power_off=2))
        self.assertEqual(self.rig.state(), "ready")
        self.rig.packet(packet(power_off=1))
        self.check_powered_off()


# --------------------------------------------------------------------------------------------
# Command timeout, client loss, SIGTERM
# --------------------------------------------------------------------------------------------

class CommandTimeoutTest(VehicleTestCase):
    """The default command timeout (500 ms)."""
    CONTROL = {"arming_delay_ms": 300}

    def test_silent_stream_zeroes_without_killing(self):
        rig = self.rig
        self.assertEqual(rig.vget("CommandTimeoutMs"), 500)
        values = [0, 2500, 0, -2500, 0, 0, 0, 0]
        rig.thrust(values)
        sent = time.monotonic()
        rig.wait_sim_speeds([speed_byte(v) for v in values], 5)
        rig.wait_sim_zero(15)
        silent = time.monotonic() - sent
        self.assertGreaterEqual(silent, 0.35, "zeroed %.2f s after the command: before the timeout" % silent)
        self.assertEqual(rig.state(), "ready")
        self.assertEqual(rig.vget("KillSource"), "")
        self.assertEqual(rig.motor_values(), [0] * MOTORS)
        self.assertFalse(rig.sim_get("KillOutput"))
        # Not a kill: the next command drives again.
        rig.thrust(values)
        rig.wait_sim_speeds([speed_byte(v) for v in values], 5)
        rig.thrust([0] * MOTORS)

    def test_stream_faster_than_the_timeout_keeps_driving(self):
        rig = self.rig
        values = [1800, 0, 1800, 0, 0, 0, 0, 0]
        expected = [speed_byte(v) for v in values]
        rig.thrust(values)
        rig.wait_sim_speeds(expected, 5)
        end = time.monotonic() + 1.5
        while time.monotonic() < end:
            rig.thrust(values)
            self.assertEqual(rig.sim_speeds(), expected, "zeroed while the stream was live")
            time.sleep(0.1)
        rig.wait_sim_zero(15)


class ClientLossTest(VehicleTestCase):
    """The command timeout is 60 s here: only the client leaving can zero the thrusters."""

    def setUp(self):
        self.rig.reset()

    def test_commanding_process_exits(self):
        rig = self.rig
        values = [0, 0, 0, 0, 2222, -2222, 0, 0]
        proc, name = harness.start_client(rig, values)
        try:
            rig.wait_sim_speeds([speed_byte(v) for v in values])
            self.assertEqual(rig.vget("Controller"), name)
            # Still driving while the client is connected.
            time.sleep(0.3)
            self.assertEqual(rig.sim_speeds(), [speed_byte(v) for v in values])
        finally:
            proc.stdin.close()
            proc.wait(10)
            proc.stdout.close()
            proc.stderr.close()
        rig.wait_sim_zero(10)
        self.assertEqual(rig.motor_values(), [0] * MOTORS)
        self.assertEqual(rig.vget("Controller"), "")
        self.assertEqual(rig.state(), "ready", "a client leaving is not a kill")

    def test_other_client_leaving_changes_nothing(self):
        rig = self.rig
        values = [900, 900, 0, 0, 0, 0, 0, 0]
        rig.thrust(values)
        rig.wait_sim_speeds([speed_byte(v) for v in values])
        proc, name = harness.start_client(rig)  # connects, commands nothing
        proc.stdin.close()
        proc.wait(10)
        proc.stdout.close()
        proc.stderr.close()
        time.sleep(0.3)
        rig.wait_orders_refreshed()
        self.assertEqual(rig.sim_speeds(), [speed_byte(v) for v in values])
        self.assertEqual(rig.vget("Controller"), rig.conn.get_unique_name())

    def test_busctl_one_shot(self):
        rig = self.rig
        wire_from = rig.wire_next()
        r = rig.busctl("call", "--", VEHICLE, ROOT, VEHICLE, "SetThrust", "ai", 8, 3000, 0, 0, 0, 0, 0, 0, -3000)
        self.assertEqual(r.returncode, 0, r.stderr)
        # busctl left the bus right after the reply: the thrusters end at zero...
        rig.wait_sim_zero(10)
        poll(lambda: rig.motor_values() == [0] * MOTORS, 10)
        self.assertEqual(rig.vget("Controller"), "")
        self.assertEqual(rig.state(), "ready")
        # ...and the accepted command reached the wire before the zero order.
        self.assert_order_then_zero(wire_from, {0: 3000, 7: -3000})
        rig.wait_orders_refreshed()
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)

    def test_client_gone_before_its_reply(self):
        # The call and the disconnect arrive together, so the daemon learns that the client
        # left before its loop had a chance to send the orders: they still go out first.
        rig = self.rig
        for round_ in range(5):
            with self.subTest(round=round_):
                wire_from = rig.wire_next()
                conn = dbus.bus.BusConnection(rig.address)
                msg = dbus.lowlevel.MethodCallMessage(VEHICLE, ROOT, VEHICLE, "SetThrust")
                msg.append(dbus.Array([0, 0, 1500 + round_, 0, 0, 0, 0, 0], signature="i"), signature="ai")
                conn.send_message(msg)
                conn.flush()
                conn.close()
                self.assert_order_then_zero(wire_from, {2: 1500 + round_})
                poll(lambda: rig.vget("Controller") == "", 10)

    def assert_order_then_zero(self, wire_from, commanded, timeout=10.0):
        """Each thruster's commanded order appears on the wire, and its last order is zero."""
        def orders():
            _, log = self.rig.wire_log(wire_from)
            return {i: [e.data[0] for e in log if e.bus == "i2c" and not e.read and e.addr == DEFAULT_MT[i] >> 1]
                    for i in commanded}

        def done():
            got = orders()
            return all(speed_byte(v) in got[i] and got[i][-1] == ZERO for i, v in commanded.items())

        try:
            poll(done, timeout)
        except harness.Timeout:
            got = {i: sorted(set(speeds)) for i, speeds in orders().items()}
            self.fail(f"commanded {commanded} (SPEED {[speed_byte(v) for v in commanded.values()]}): "
                      f"the wire carried only SPEED {got}")


class SigtermTest(unittest.TestCase):

    def test_start_zeroes_orders_a_crashed_daemon_left(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start()
        rig.arm()
        values = [0, 3500, 0, 3500, 0, -3500, 0, -3500]
        rig.thrust(values)
        rig.wait_sim_speeds([speed_byte(v) for v in values])
        # A daemon that dies without zeroing: the thrusters keep their last order (the IDS
        # has no thruster-side timeout).
        proc = rig.procs["caracarad"]
        proc.kill()
        proc.wait(30)
        poll(lambda: not rig.conn.name_has_owner(VEHICLE), 10)
        time.sleep(0.2)
        self.assertEqual(rig.sim_speeds(), [speed_byte(v) for v in values])
        # The next daemon zeroes them before it takes its name.
        rig.start_daemon()
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS, "orders standing when the service appeared")
        # It comes up killed: nothing drives again until someone arms it.
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(rig.vget("KillSource"), "start")
        self.assertTrue(rig.sim_get("KillOutput"))
        rig.arm()
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)

    def test_sigterm_zeroes_and_exits_0(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start()
        rig.arm()
        values = [4000, -4000, 4000, -4000, 0, 0, 0, 0]
        rig.thrust(values)
        rig.wait_sim_speeds([speed_byte(v) for v in values])
        zeros_before = rig.sim_counters("ZeroOrders")
        proc = rig.procs["caracarad"]
        proc.send_signal(signal.SIGTERM)
        code = proc.wait(30)
        self.assertEqual(code, 0, rig.log())
        # The simulator outlives the daemon: every thruster was told zero on the way out.
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
        zeros_after = rig.sim_counters("ZeroOrders")
        for i in range(MOTORS):
            self.assertGreater(zeros_after[i], zeros_before[i])
        self.assertFalse(rig.conn.name_has_owner(VEHICLE))


# --------------------------------------------------------------------------------------------
# Invalid input: a named error and no change on the hardware
# --------------------------------------------------------------------------------------------

NAN = float("nan")
INF = float("inf")


class InvalidInputTest(VehicleTestCase):

    values = [1000, -2000, 3000, 0, 0, 0, 0, -500]

    def setUp(self):
        # A known, non-zero output that every refused call must leave alone.
        self.rig.thrust(self.values)
        self.rig.wait_sim_speeds([speed_byte(v) for v in self.values])

    def vehicle_view(self):
        """What a refused call must leave alone: the thrusters' orders on the simulated wire, the
        requested values, the LEDs on the simulated Teensy."""
        rig = self.rig
        return rig.sim_snapshot(), list(rig.vget("RequestedValues")), tuple(rig.sim_teensy("Leds"))

    def check_unchanged(self, before):
        rig = self.rig
        rig.wait_orders_refreshed()
        snapshot, requested, leds = self.vehicle_view()
        self.assertEqual(snapshot, before[0], "the simulated thrusters changed")
        self.assertEqual(requested, before[1])
        self.assertEqual(leds, before[2])
        self.assertEqual(rig.state(), "ready")
        self.assertEqual(rig.vget("Controller"), rig.conn.get_unique_name())

    def check_refused(self, expected_error, fn, *args, **kwargs):
        before = self.vehicle_view()
        self.assertEqual(error_name(fn, *args, **kwargs), expected_error)
        self.check_unchanged(before)

    def test_set_thrust(self):
        rig = self.rig
        cases = [
            ("7 values", ERR + "InvalidLength", [100] * 7),
            ("9 values", ERR + "InvalidLength", [100] * 9),
            ("no values", ERR + "InvalidLength", []),
            ("8851", ERR + "OutOfRange", [0, 0, 0, 8851, 0, 0, 0, 0]),
            ("-8851", ERR + "OutOfRange", [0, 0, 0, 0, 0, 0, 0, -8851]),
            ("int32 min", ERR + "OutOfRange", [-2 ** 31] + [0] * 7),
        ]
        for label, err, values in cases:
            with self.subTest(label):
                self.check_refused(err, rig.thrust, values)

    def test_set_motion(self):
        rig = self.rig
        for label, err, kwargs in [
            ("NaN", ERR + "InvalidValue", {"x": NAN}),
            ("inf", ERR + "InvalidValue", {"yaw": INF}),
            ("-inf", ERR + "InvalidValue", {"roll": -INF}),
            ("1.5", ERR + "OutOfRange", {"y": 1.5}),
            ("-1.0001", ERR + "OutOfRange", {"pitch": -1.0001}),
            ("NaN with valid others", ERR + "InvalidValue", {"x": 0.1, "z": NAN}),
        ]:
            with self.subTest(label):
                self.check_refused(err, rig.motion, **kwargs)

    def test_apply_packet(self):
        rig = self.rig
        good = packet([100] * 8)
        for label, err, words in [
            ("12 values", ERR + "InvalidLength", good[:12]),
            ("14 values", ERR + "InvalidLength", good + [0]),
            ("powerOff 2", ERR + "InvalidValue", packet([100] * 8, power_off=2)),
            ("powerOff -1", ERR + "InvalidValue", packet([100] * 8, power_off=-1)),
            ("red 256", ERR + "OutOfRange", packet([100] * 8, rgb=(256, 0, 0))),
            ("blue -1", ERR + "OutOfRange", packet([100] * 8, rgb=(0, 0, -1))),
            ("motor 8851", ERR + "OutOfRange", packet([0, 0, 0, 0, 0, 8851, 0, 0])),
        ]:
            with self.subTest(label):
                self.check_refused(err, rig.packet, words)

    def test_wrong_signature(self):
        rig = self.rig
        for label, method, args, sig in [
            ("SetThrust s", "SetThrust", ("hello",), "s"),
            ("SetThrust ad", "SetThrust", (dbus.Array([1.0] * 8, signature="d"),), "ad"),
            ("SetMotion 5 doubles", "SetMotion", (0.0,) * 5, "ddddd"),
            ("SetMotion ints", "SetMotion", (0,) * 6, "iiiiii"),
            ("ApplyPacket au", "ApplyPacket", (dbus.Array([0] * 13, signature="u"),), "au"),
            ("PowerOff i", "PowerOff", (1,), "i"),
            ("SetLeds iii", "SetLeds", (1, 2, 3), "iii"),
        ]:
            with self.subTest(label):
                self.check_refused(INVALID_ARGS, rig.vcall, method, *args, signature=sig)
        with self.subTest("busctl SetThrust s"):
            before = rig.sim_snapshot()
            r = rig.busctl("call", VEHICLE, ROOT, VEHICLE, "SetThrust", "s", "hello")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("Invalid arguments", r.stderr)
            rig.wait_orders_refreshed()
            self.assertEqual(rig.sim_snapshot(), before)
            self.assertEqual(rig.state(), "ready")

    def test_power_off_confirmation(self):
        self.check_refused(ERR + "ConfirmationRequired", self.rig.vcall, "PowerOff", "please", signature="s")
        self.assertFalse(self.rig.sim_get("PowerOffOutput"))

    def test_teensy_arguments(self):
        rig = self.rig
        for label, err, method, args, sig in [
            ("servo id 4", ERR + "OutOfRange", "SetServo", (4, 90), "yy"),
            ("servo 181 degrees", ERR + "OutOfRange", "SetServo", (0, 181), "yy"),
            ("distance sensor 9", ERR + "OutOfRange", "GetDistance", (9,), "y"),
            ("wheel speed 128", ERR + "OutOfRange", "SetSpeed", (128, 0), "ii"),
            ("wheel speed -129", ERR + "OutOfRange", "SetSpeed", (0, -129), "ii"),
            ("turn NaN", ERR + "InvalidValue", "Turn", (NAN,), "d"),
            ("turn-to inf", ERR + "InvalidValue", "TurnTo", (INF,), "d"),
            ("turn with a string", INVALID_ARGS, "Turn", ("left",), "s"),
        ]:
            with self.subTest(label):
                servos = list(rig.sim_teensy("Servos"))
                self.check_refused(err, rig.vcall, method, *args, signature=sig, path=TEENSY_PATH,
                                   iface=TEENSY_IFACE)
                self.assertEqual(list(rig.sim_teensy("Servos")), servos)
                self.assertEqual(rig.sim_teensy("Task"), "idle")


    def test_random_calls(self):
        """In the manner of a fuzzer: calls with random argument vectors (lengths, values at and
        past every limit, NaN and infinities, arguments of other types). Each is accepted or
        refused with a named error, and a refused one changes nothing (check_unchanged)."""
        rig = self.rig
        rng = random.Random(20261121)
        # Each value is valid but for a one-in-ten chance of one at or past a limit, so that
        # calls are accepted about as often as they are refused.
        def value(good, bad):
            return rng.choice(bad) if rng.random() < 0.1 else rng.choice(good)

        def motor():
            return value([0, 1, -1, 100, -2500, 8850, -8850], [8851, -8851, 2 ** 31 - 1, -2 ** 31])

        def thrust():
            n = 8 if rng.random() < 0.85 else rng.choice([0, 1, 7, 9, 13])
            return "SetThrust", (dbus.Array([motor() for _ in range(n)], signature="i"),), "ai"

        def motion():
            axis = [value([0.0, -0.0, 0.25, -1.0, 1.0, 5e-324], [1.0000001, -1.5, NAN, INF, -INF, 1e308])
                    for _ in range(6)]
            return "SetMotion", tuple(axis), "dddddd"

        def apply_packet():
            # killState stays 0 and powerOffState is never 1: a kill or a power-off is a valid
            # call whose effect is the point, not a refusal (KillTest and PowerOffTest).
            words = [motor() for _ in range(8)] + [0, value([0], [2, -1, 7])]
            words += [value([0, 40, 255], [256, -1]) for _ in range(3)]
            n = 13 if rng.random() < 0.9 else rng.choice([12, 14])
            return "ApplyPacket", (dbus.Array((words + [0])[:n], signature="i"),), "ai"

        def other_types():
            method = rng.choice(["SetThrust", "SetMotion", "ApplyPacket", "SetLeds", "PowerOff"])
            sig, args = rng.choice([("s", ("x",)), ("ad", (dbus.Array([0.5] * 8, signature="d"),)),
                                    ("au", (dbus.Array([1] * 13, signature="u"),)), ("iii", (1, 2, 3)),
                                    ("ddddd", (0.0,) * 5), ("", ()), ("ay", (dbus.ByteArray(b"\x01" * 8),))])
            return method, args, sig

        outcomes = {}
        for i in range(150):
            method, args, sig = rng.choice([thrust, motion, apply_packet, other_types])()
            with self.subTest(i=i, method=method, signature=sig, args=repr(args)[:200]):
                before = self.vehicle_view()
                err = error_name(rig.vcall, method, *args, signature=sig)
                outcomes[err] = outcomes.get(err, 0) + 1
                if err is None:
                    # Accepted: let its orders (and a packet's LEDs) reach the vehicle, so that
                    # the next refusal is compared with a settled vehicle.
                    rig.wait_orders_refreshed()
                    if method == "ApplyPacket":
                        poll(lambda: tuple(rig.sim_teensy("Leds")) == tuple(args[0][10:13]), 10)
                    self.assertEqual(rig.state(), "ready")
                    continue
                self.assertTrue(err.startswith(ERR) or err == INVALID_ARGS, "unnamed error %s" % err)
                self.check_unchanged(before)
        # Both outcomes and several kinds of refusal were reached.
        self.assertGreater(outcomes.get(None, 0), 10, outcomes)
        self.assertGreaterEqual(len([e for e in outcomes if e]), 4, outcomes)


# --------------------------------------------------------------------------------------------
# The Teensy
# --------------------------------------------------------------------------------------------

class TeensyTest(VehicleTestCase):

    def setUp(self):
        self.rig.reset()
        # No turn left running on the simulated Teensy by an earlier test.
        poll(lambda: str(self.rig.sim_teensy("Task")) != "running", 15)

    def tcall(self, method, *args, signature=None, **kw):
        return self.rig.vcall(method, *args, signature=signature, path=TEENSY_PATH, iface=TEENSY_IFACE, **kw)

    def tget(self, name):
        return self.rig.vget(name, TEENSY_PATH, TEENSY_IFACE)

    def test_set_leds(self):
        for rgb in [(1, 2, 3), (255, 128, 0), (0, 0, 0)]:
            self.rig.vcall("SetLeds", *rgb, signature="yyy")
            # Acknowledged by the Teensy before the reply.
            self.assertEqual(tuple(self.rig.sim_teensy("Leds")), rgb)
            self.assertEqual(tuple(self.rig.vget("Leds")), rgb)

    def test_servo(self):
        self.tcall("SetServo", 1, 45, signature="yy")
        self.assertEqual(int(self.rig.sim_teensy("Servos")[1]), 45)
        self.assertEqual(int(self.tget("Servos")[1]), 45)
        self.tcall("SetServo", 3, 180, signature="yy")
        self.assertEqual(int(self.rig.sim_teensy("Servos")[3]), 180)
        self.assertEqual(int(self.tget("Servos")[3]), 180)

    def test_get_distance(self):
        for sensor, mm in [(0, 1234), (2, 5), (3, 65535)]:
            with self.subTest(sensor=sensor):
                self.rig.sim_teensy_call("SetDistance", dbus.Byte(sensor), dbus.UInt16(mm), signature="yq")
                got = self.tcall("GetDistance", sensor, signature="y")
                self.assertEqual(dbus_signature(got), "q")
                self.assertEqual(int(got), mm)
                self.assertEqual(int(self.tget("Distances")[sensor]), mm)

    def test_wheels_and_stop(self):
        self.tcall("SetSpeed", 50, -30, signature="ii")
        wheels = self.rig.sim_teensy("Wheels")
        self.assertEqual((float(wheels[0]), float(wheels[1])), (50.0, -30.0), "front left, front right")
        self.tcall("Stop", 42, signature="y")
        self.assertEqual(int(self.rig.sim_teensy("StopDuty")), 42)

    def test_turn_replies_when_the_teensy_acknowledged(self):
        rig = self.rig
        acks = int(rig.sim_teensy("Acknowledgements"))
        offset0 = float(rig.sim_teensy("HeadingOffset"))
        result = {}

        def done(*_):
            result["acks"] = int(rig.sim_teensy("Acknowledgements"))
            result["sim_task"] = str(rig.sim_teensy("Task"))
            result["t"] = time.monotonic()

        def failed(e):
            result["error"] = e
            result["t"] = time.monotonic()

        start = time.monotonic()
        rig.obj(VEHICLE, TEENSY_PATH).get_dbus_method("Turn", TEENSY_IFACE)(
            0.6, signature="d", reply_handler=done, error_handler=failed, timeout=60)
        served = []
        saw_turning = False
        leds_during = None
        while "t" not in result and time.monotonic() - start < 30:
            pump_main_loop(0.02)
            if "t" in result:
                break
            # Other calls are served while the turn runs.
            served.append(rig.state())
            if str(self.tget("Task")) == "turning" and "t" not in result:
                saw_turning = True
            if leds_during is None and saw_turning:
                rig.vcall("SetLeds", 9, 8, 7, signature="yyy")
                leds_during = tuple(rig.sim_teensy("Leds"))
        self.assertIn("t", result, "Turn never replied")
        self.assertNotIn("error", result, result.get("error"))
        self.assertTrue(saw_turning, "Task never showed turning")
        self.assertEqual(leds_during, (9, 8, 7), "SetLeds was not served during the turn")
        self.assertTrue(served and all(s == "ready" for s in served))
        # The reply came after the Teensy finished and got its acknowledgement.
        self.assertEqual(result["acks"], acks + 1)
        self.assertEqual(result["sim_task"], "idle")
        self.assertAlmostEqual(float(rig.sim_teensy("LastTurn")), 0.6, places=5)
        self.assertGreaterEqual(result["t"] - start, 0.3, "0.6 rad at the simulated 1 rad/s took no time")
        self.assertAlmostEqual(angle_diff(float(rig.sim_teensy("HeadingOffset")), offset0), 0.6, places=4)
        poll(lambda: str(self.tget("Task")) == "idle", 5)
        # The daemon's heading follows the simulated Teensy's (body yaw + the turn).
        poll(lambda: abs(angle_diff(float(self.tget("Orientation")[0]), rig.sim_yaw())) < 0.02, 10,
             message="the daemon's heading does not follow the turn")

    def test_kill_ends_a_running_turn(self):
        rig = self.rig
        result = {}
        rig.obj(VEHICLE, TEENSY_PATH).get_dbus_method("Turn", TEENSY_IFACE)(
            3.0, signature="d", reply_handler=lambda *a: result.setdefault("ok", True),
            error_handler=lambda e: result.setdefault("error", e.get_dbus_name()), timeout=60)
        poll(lambda: str(self.tget("Task")) == "turning", 10, pump=pump_main_loop)
        rig.vcall("Kill")
        poll(lambda: result, 10, pump=pump_main_loop, message="Turn never replied after the kill")
        self.assertEqual(result, {"error": ERR + "Killed"})
        self.assertEqual(str(self.tget("Task")), "idle")
        # The vehicle itself stops turning: the Teensy's turn task is ended, not left to run
        # its remaining ~3 rad after the kill.
        try:
            poll(lambda: str(rig.sim_teensy("Task")) != "running", 1.5)  # the whole turn takes 3 s
        except harness.Timeout:
            self.fail("the simulated Teensy is still turning after Kill (heading offset %.2f rad and rising)"
                      % float(rig.sim_teensy("HeadingOffset")))
        offset = float(rig.sim_teensy("HeadingOffset"))
        time.sleep(0.3)
        self.assertAlmostEqual(float(rig.sim_teensy("HeadingOffset")), offset, places=6)

    def test_turn_while_turning_is_busy(self):
        rig = self.rig
        result = {}
        rig.obj(VEHICLE, TEENSY_PATH).get_dbus_method("TurnTo", TEENSY_IFACE)(
            1.0, signature="d", reply_handler=lambda *a: result.setdefault("ok", time.monotonic()),
            error_handler=lambda e: result.setdefault("error", e), timeout=60)
        poll(lambda: str(self.tget("Task")) == "turning", 10, pump=pump_main_loop)
        self.assertDBusError(ERR + "Busy", self.tcall, "Turn", 0.1, signature="d")
        poll(lambda: result, 30, pump=pump_main_loop, message="TurnTo never replied")
        self.assertIn("ok", result, result.get("error"))
        self.assertAlmostEqual(float(rig.sim_teensy("LastTurnTo")), 1.0, places=5)
        poll(lambda: abs(angle_diff(float(rig.sim_yaw()), 1.0)) < 0.05, 5)

    def test_orientation_follows_yaw_thrust(self):
        rig = self.rig
        start_sim = rig.sim_yaw()
        yawed = [0.0]
        last = [start_sim]

        def turned():
            rig.motion(yaw=0.6)  # keep the stream alive
            now = rig.sim_yaw()
            yawed[0] += angle_diff(now, last[0])
            last[0] = now
            return yawed[0] > 0.5
        poll(turned, 30, interval=0.05, message="the vehicle did not yaw under yaw thrust")
        # Positive yaw is clockwise from above in both the axis table and the simulator.
        self.assertGreater(yawed[0], 0.5)
        # While turning, the daemon's Orientation tracks the simulated one.
        poll(lambda: abs(angle_diff(float(self.tget("Orientation")[0]), rig.sim_yaw())) < 0.25, 10)
        rig.motion()
        # Let it coast to a stop; then the daemon's reading matches the simulator closely.
        prev = [rig.sim_yaw()]

        def settled():
            time.sleep(0.5)
            now = rig.sim_yaw()
            still = abs(angle_diff(now, prev[0])) < 0.003
            prev[0] = now
            return still
        poll(settled, 20, interval=0.0)
        poll(lambda: abs(angle_diff(float(self.tget("Orientation")[0]), rig.sim_yaw())) < 0.01, 10,
             message="Orientation yaw does not follow the simulator")


if __name__ == "__main__":
    unittest.main()
