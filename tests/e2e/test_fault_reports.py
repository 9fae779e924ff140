"""A thruster fault that appears or clears is told once (the journal, caracaractl status), not
once per status read.
"""

import unittest

import harness
from harness import (VehicleTestCase, poll)


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


if __name__ == "__main__":
    unittest.main()
