"""The command timeout lands on a timer of its own, on time, judged on the simulated wire.
"""

import statistics
import time
import unittest

from bounds import COMMAND_TIMEOUT_EARLY_MS_MAX, COMMAND_TIMEOUT_LATENESS_MS_MAX
from figures import figure
from harness import (ZERO, DEFAULT_MT, VehicleTestCase, poll, speed_byte)


class CommandTimeoutTimerTest(VehicleTestCase):
    """The command timeout fires at last command + timeout, not at the next tick."""
    CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 500, "loop_rate_hz": 50}

    def test_timeout_lands_on_time(self):
        rig = self.rig
        mt = DEFAULT_MT[0]
        lateness = []
        for _ in range(5):
            rig.reset()
            rig.thrust([1500] + [0] * 7)
            accepted = time.monotonic_ns()  # just after the reply: the command was accepted before
            rig.wait_sim_speeds([speed_byte(1500)] + [ZERO] * 7)
            since = rig.wire_next()
            poll(lambda: rig.sim_speeds()[0] == ZERO, 5, message="the command never timed out")
            zero = [e for e in rig.wire_log(since)[1]
                    if e.bus == "i2c" and e.addr == mt >> 1 and not e.read and e.data[:1] == bytes([ZERO])]
            self.assertTrue(zero)
            lateness.append((zero[0].time_ns - accepted) / 1e6 - 500.0)
        median = statistics.median(lateness)
        for ms in lateness:
            figure("command_timeout_timer.lateness_ms", ms, "ms", "command timeout 500 ms: first zero order after it")
        # Before, the zero waited for the next 50 Hz tick: 13-19 ms late.
        self.assertLess(median, COMMAND_TIMEOUT_LATENESS_MS_MAX)
        self.assertGreater(median, -COMMAND_TIMEOUT_EARLY_MS_MAX, "zeroed before the timeout")


if __name__ == "__main__":
    unittest.main()
