"""The I2C bus and its Bus object: a lockup cleared by the bus clear, the BusLost/BusRestored
signals, a bus that cannot be cleared killing with source bus.
"""

import time
import unittest

import dbus

import harness
from harness import (BUS_IFACE, BUS_PATH, ZERO, VehicleTestCase, poll, pump_main_loop, speed_byte)


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


if __name__ == "__main__":
    unittest.main()
