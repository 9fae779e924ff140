"""The simulator (the hardware, with its GPIO chip) goes away under a running daemon: no busy
loop, and the vehicle killed.
"""

import time
import unittest

from bounds import (VANISHED_LOG_LINES_MAX, VANISHED_WINDOW_S)
from figures import figure
from harness import (ERR, MOTORS, Rig, error_name, poll, speed_byte)
from vehicle_checks import assert_idle_cpu, cpu_seconds


class VanishedLinesTest(unittest.TestCase):
    """The simulator (the hardware, with its GPIO chip) goes away under a running daemon: the
    kill switch that can no longer be read is a pressed one, its event source is dropped instead
    of firing in a loop, and the daemon stays quiet and answers D-Bus."""

    def test_no_busy_loop_and_killed_when_the_switch_vanishes(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start()
        rig.arm()
        rig.thrust([800] * MOTORS)
        rig.wait_sim_speeds([speed_byte(800)] * MOTORS)
        sim = rig.procs.pop("caracara-sim")  # ended on purpose: not a failure of the rig
        sim.kill()
        sim.wait(10)
        pid = rig.procs["caracarad"].pid
        poll(lambda: rig.state() == "killed", 10, message="a kill switch that cannot be read did not kill")
        log_before = rig.log().count("\n")
        cpu0, t0 = cpu_seconds(pid), time.monotonic()
        time.sleep(VANISHED_WINDOW_S)
        cpu = (cpu_seconds(pid) - cpu0) / (time.monotonic() - t0) * 100
        lines = rig.log().count("\n") - log_before
        print("\nsimulator gone: KillSource %s" % rig.vget("KillSource"))
        figure("simulator_gone.cpu_percent", cpu, "%", "daemon CPU over %.0f s with the simulator gone" % VANISHED_WINDOW_S)
        figure("simulator_gone.log_lines", lines, "count", "log lines over %.0f s with the simulator gone"
               % VANISHED_WINDOW_S)
        # Everything went with the simulator; the kill is the first loss noticed: the switch (its
        # edge source), the bus, the kill output read back every 100 ms (device) or the Teensy
        # link (failsafe). test_gpio_lines takes the switch away alone.
        self.assertIn(rig.vget("KillSource"), ("switch", "bus", "device", "failsafe"))
        self.assertIn("kill switch", rig.log())
        assert_idle_cpu(self, cpu)
        self.assertLessEqual(lines, VANISHED_LOG_LINES_MAX)
        # Still serving D-Bus.
        self.assertEqual(error_name(rig.thrust, [100] * MOTORS)[:len(ERR)], ERR)


if __name__ == "__main__":
    unittest.main()
