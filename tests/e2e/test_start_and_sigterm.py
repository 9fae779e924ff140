"""A fresh daemon zeroes the orders a crashed one left; SIGTERM zeroes and exits 0.
"""

import signal
import time
import unittest

from harness import (MOTORS, VEHICLE, ZERO, Rig, poll, speed_byte)


class SigtermTest(unittest.TestCase):

    def test_start_zeroes_orders_a_crashed_daemon_left(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start()
        rig.arm()
        values = [0, 3500, 0, 3500, 0, -3500, 0, -3500]
        rig.thrust(values)
        rig.wait_sim_speeds([speed_byte(v) for v in values])
        # A daemon that dies without zeroing: the thrusters keep their last order (the IDS
        # has no thruster-side timeout).
        proc = rig.procs["caracarad"]
        proc.kill()
        proc.wait(30)
        poll(lambda: not rig.conn.name_has_owner(VEHICLE), 10)
        time.sleep(0.2)
        self.assertEqual(rig.sim_speeds(), [speed_byte(v) for v in values])
        # The next daemon zeroes them before it takes its name.
        rig.start_daemon()
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS, "orders standing when the service appeared")
        # It comes up killed: nothing drives again until someone arms it.
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(rig.vget("KillSource"), "start")
        self.assertTrue(rig.sim_get("KillOutput"))
        rig.arm()
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)

    def test_sigterm_zeroes_and_exits_0(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start()
        rig.arm()
        values = [4000, -4000, 4000, -4000, 0, 0, 0, 0]
        rig.thrust(values)
        rig.wait_sim_speeds([speed_byte(v) for v in values])
        zeros_before = rig.sim_counters("ZeroOrders")
        proc = rig.procs["caracarad"]
        proc.send_signal(signal.SIGTERM)
        code = proc.wait(30)
        self.assertEqual(code, 0, rig.log())
        # The simulator outlives the daemon: every thruster was told zero on the way out.
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
        zeros_after = rig.sim_counters("ZeroOrders")
        for i in range(MOTORS):
            self.assertGreater(zeros_after[i], zeros_before[i])
        self.assertFalse(rig.conn.name_has_owner(VEHICLE))


if __name__ == "__main__":
    unittest.main()
