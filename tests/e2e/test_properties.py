"""The contract of org.caracara.Vehicle1 read back: every property of every object, with its type
and a meaningful value, checked against the simulated hardware.
"""

import time
import unittest

import dbus

import harness
from harness import (BUS_IFACE, BUS_PATH, DEFAULT_MT, MOTORS, ROOT, TEENSY_IFACE, TEENSY_PATH,
                     THRUSTER_IFACE, VEHICLE, ZERO, VehicleTestCase, dbus_signature, poll, speed_byte,
                     thruster_path)


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
        self.assertEqual(p["MotorTestLimit"], 1500)
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


if __name__ == "__main__":
    unittest.main()
