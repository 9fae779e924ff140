"""A fresh daemon starts killed and arms only on ClearKill (control.arm_at_start opts out); the
example mission does not arm without being told.
"""

import os
import subprocess
import time
import unittest

import harness
from harness import (ERR, MOTORS, ZERO, Rig, error_name, speed_byte)
from vehicle_checks import (packet)


MISSION = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples", "mission_square.py")


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


if __name__ == "__main__":
    unittest.main()
