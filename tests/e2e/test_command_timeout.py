"""The command timeout: a silent stream zeroes the thrusters without killing, a stream faster
than the timeout keeps driving.
"""

import time
import unittest

from harness import (MOTORS, VehicleTestCase, speed_byte)


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


if __name__ == "__main__":
    unittest.main()
