"""The simulator (the hardware, with its GPIO chip) goes away under a running daemon: no busy
loop, and the vehicle killed.
"""

import unittest

from harness import (ERR, MOTORS, Rig, error_name, poll, speed_byte)
from vehicle_checks import assert_quiet_while_gone


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
        assert_quiet_while_gone(self, rig, pid)
        print("\nsimulator gone: KillSource %s" % rig.vget("KillSource"))
        # Everything went with the simulator; the kill is the first loss noticed: the switch (its
        # edge source), the bus, the kill output read back every 100 ms (device) or the Teensy
        # link (failsafe). test_gpio_lines takes the switch away alone.
        self.assertIn(rig.vget("KillSource"), ("switch", "bus", "device", "failsafe"))
        self.assertIn("kill switch", rig.log())
        # Still serving D-Bus.
        self.assertEqual(error_name(rig.thrust, [100] * MOTORS)[:len(ERR)], ERR)


if __name__ == "__main__":
    unittest.main()
