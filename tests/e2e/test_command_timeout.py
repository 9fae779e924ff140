"""The command timeout: a silent stream zeroes the thrusters without killing, a stream faster
than the timeout keeps driving.
"""

import time
import unittest

from bounds import DEADLINE_SEEN_EARLY_MS_MAX, DEADLINE_SEEN_LATE_MS_MAX
from figures import figure
from harness import (MOTORS, VehicleTestCase, speed_byte)


class CommandTimeoutTest(VehicleTestCase):
    """The default command timeout (500 ms)."""
    CONTROL = {"arming_delay_ms": 300}

    def test_silent_stream_zeroes_without_killing(self):
        rig = self.rig
        timeout_ms = rig.vget("CommandTimeoutMs")
        self.assertEqual(timeout_ms, 500)
        values = [0, 2500, 0, -2500, 0, 0, 0, 0]
        rig.thrust(values)
        sent = time.monotonic()
        rig.wait_sim_speeds([speed_byte(v) for v in values], 5)
        # Given up well after the bound, so that a late zero is reported with its figure.
        rig.wait_sim_zero(5)
        silent_ms = (time.monotonic() - sent) * 1000
        figure("command_timeout.zeroed_ms", silent_ms, "ms", "zeroed after the last command (command timeout %d ms)"
               % timeout_ms)
        self.assertGreaterEqual(silent_ms, timeout_ms - DEADLINE_SEEN_EARLY_MS_MAX,
                                "zeroed %.0f ms after the command: before the timeout" % silent_ms)
        self.assertLessEqual(silent_ms, timeout_ms + DEADLINE_SEEN_LATE_MS_MAX,
                             "zeroed %.0f ms after the command: the timeout is %d ms" % (silent_ms, timeout_ms))
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
            last = time.monotonic()
            self.assertEqual(rig.sim_speeds(), expected, "zeroed while the stream was live")
            time.sleep(0.1)
        rig.wait_sim_zero(5)
        silent_ms = (time.monotonic() - last) * 1000
        self.assertLessEqual(silent_ms, rig.vget("CommandTimeoutMs") + DEADLINE_SEEN_LATE_MS_MAX,
                             "zeroed %.0f ms after the stream stopped" % silent_ms)


if __name__ == "__main__":
    unittest.main()
