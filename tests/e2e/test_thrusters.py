"""The Thruster objects under faults injected into the simulated controllers (NACKs, bad replies,
fault bits), and a thruster mounted backwards: judged on the simulated wire.
"""

import unittest

import dbus

from harness import (BUS_IFACE, BUS_PATH, DEFAULT_MT, ERR, THRUSTER_IFACE, ZERO, VehicleTestCase, error_name,
                     poll, speed_byte, thruster_path)


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


if __name__ == "__main__":
    unittest.main()
