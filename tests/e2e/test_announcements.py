"""PropertiesChanged: what each change announces, on every object, and announcements that still go
out while the bus work never rests (loop rate 0, cycles longer than the tick).
"""

import time
import unittest

import dbus

import harness
from harness import (BUS_IFACE, BUS_PATH, MOTORS, PROPS, ROOT, TEENSY_IFACE, TEENSY_PATH, THRUSTER_IFACE,
                     VEHICLE, VehicleTestCase, dbus_signature, poll, pump_main_loop, thruster_path)
from vehicle_checks import PropertyWatcher, check_announced_while_bus_busy


class PropertiesChangedTest(VehicleTestCase):
    """Every change is announced: a command's values, a kill and its clearing, and every object's
    properties, each as the contract declares it."""

    def setUp(self):
        self.rig.reset()

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


class CoalescingTest(VehicleTestCase):
    """One batch, one PropertiesChanged per object with everything it changed; the documented
    rates kept under a command stream: the vehicle's values at each command, each thruster's
    telemetry at 5 Hz with its counters (1 Hz) in the same signals."""

    def setUp(self):
        self.rig.reset()

    def test_a_stream_announced_once_per_object_and_batch(self):
        events = []

        def on_signal(iface, changed, invalidated, path=None):
            events.append((time.monotonic(), str(path), set(changed)))

        match = self.rig.conn.add_signal_receiver(on_signal, signal_name="PropertiesChanged", dbus_interface=PROPS,
                                                  bus_name=VEHICLE, path_keyword="path")
        commands = 40
        try:
            start = time.monotonic()
            for i in range(commands):  # 20 Hz, every motor changing at each command
                self.rig.thrust([3000] * MOTORS if i % 2 else [-2000] * MOTORS)
                pump_main_loop(0.05)
            pump_main_loop(0.3)
            seconds = time.monotonic() - start
        finally:
            match.remove()
        vehicle = [c for _, p, c in events if p == ROOT]
        values = [c for c in vehicle if c & {"MotorValues", "RequestedValues"}]
        self.assertTrue(values, "no command announced")
        for c in values:
            self.assertLessEqual({"MotorValues", "RequestedValues"}, c, "a command's values split over signals")
        ticks = 5 * seconds + 2  # the telemetry ticks the window can hold
        self.assertLessEqual(len(vehicle), commands + ticks, "the vehicle announced more than once per batch")
        for i in range(MOTORS):
            n = sum(1 for _, p, _ in events if p == thruster_path(i))
            self.assertGreaterEqual(n, 2, "thruster %d's telemetry not announced" % i)
            self.assertLessEqual(n, ticks, "thruster %d announced past its 5 Hz telemetry" % i)


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


if __name__ == "__main__":
    unittest.main()
