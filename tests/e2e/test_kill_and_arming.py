"""Kill, ClearKill, the kill switch and arming: zeros at once and latched, arming with zero output,
the switch blocking ClearKill, a switch set at start, the default arming delay.
"""

import time
import unittest

from bounds import DEADLINE_SEEN_EARLY_MS_MAX, DEADLINE_SEEN_LATE_MS_MAX
from harness import (ERR, MOTORS, ZERO, Rig, VehicleTestCase, error_name, speed_byte)
from vehicle_checks import assert_zeroed_before_reply, packet


def assert_armed_after(case, armed_s, delay_ms):
    """Arming, seen from ClearKill's reply to State "ready", took the delay: no sooner (less the
    reply's own transit) and no later than the test's next poll (tests/bounds.json)."""
    armed_ms = armed_s * 1000
    case.assertGreaterEqual(armed_ms, delay_ms - DEADLINE_SEEN_EARLY_MS_MAX,
                            "arming ended after %.0f ms, before its %d ms" % (armed_ms, delay_ms))
    case.assertLessEqual(armed_ms, delay_ms + DEADLINE_SEEN_LATE_MS_MAX,
                         "arming ended after %.0f ms, %d ms configured" % (armed_ms, delay_ms))


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
        print("\narming took %.0f ms (ArmingDelayMs %d)" % (armed * 1000, self.rig.vget("ArmingDelayMs")))
        assert_armed_after(self, armed, int(self.rig.vget("ArmingDelayMs")))
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
        print("\narming took %.0f ms (ArmingDelayMs 3000)" % (armed * 1000))
        assert_armed_after(self, armed, int(rig.vget("ArmingDelayMs")))


if __name__ == "__main__":
    unittest.main()
