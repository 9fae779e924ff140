"""Thrust profiles: an unknown one refused, the wire bytes under each, the budget and motion
scaled, caracaractl profile and status.
"""

import unittest

from harness import (ERR, ZERO, VehicleTestCase, error_name, speed_byte)


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


if __name__ == "__main__":
    unittest.main()
