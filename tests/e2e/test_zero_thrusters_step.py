"""The zeroing step systemd runs after the daemon (caracarad --zero-thrusters): after a SIGKILL
it zeroes the thrusters and asserts the kill output; a hung bus is bounded and reported.
"""

import subprocess
import time
import unittest

from bounds import ZERO_STEP_HELD_BUS_S_MAX
from harness import (MOTORS, ZERO, Rig, command, speed_byte)
from vehicle_checks import (KILL_OUT)


class ZeroThrustersStepTest(unittest.TestCase):
    """caracarad --zero-thrusters, as systemd's ExecStopPost= runs it after a SIGKILL."""

    def test_after_sigkill_the_step_zeroes_and_asserts_the_kill_output(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start()
        rig.arm()
        values = [3000, -3000, 3000, -3000, 1000, 0, 0, 0]
        rig.thrust(values)
        rig.wait_sim_speeds([speed_byte(v) for v in values])
        proc = rig.procs["caracarad"]
        proc.kill()
        proc.wait(30)
        # The thrusters keep their last order: nothing of the daemon is left to zero them.
        time.sleep(0.2)
        self.assertEqual(rig.sim_speeds(), [speed_byte(v) for v in values])
        since = rig.wire_next()
        t0 = time.monotonic()
        p = subprocess.run(command("caracarad") + ["--zero-thrusters", "--config", rig.config_path,
                            "--hardware=sim:" + rig.sim_socket], capture_output=True, text=True, timeout=60)
        took = time.monotonic() - t0
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
        log = rig.wire_log(since)[1]
        kill_edge = [e.index for e in log if e.bus == "gpio" and e.addr == KILL_OUT and e.data == b"\x01"]
        orders = [e.index for e in log if e.bus == "i2c" and not e.read and len(e.data) == 3]
        self.assertTrue(kill_edge, "the kill output was not asserted")
        self.assertTrue(orders)
        self.assertLess(kill_edge[0], orders[0], "the kill output came after a bus transfer")
        self.assertIn("8 of 8 thrusters zeroed", p.stderr)
        print("\n--zero-thrusters: %.0f ms, %d zero orders" % (took * 1000, len(orders)))
        # systemd's restart then brings up a daemon that is killed until someone arms it.
        rig.start_daemon()
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(rig.vget("KillSource"), "start")

    def test_a_hung_bus_is_bounded_and_reported(self):
        rig = Rig(control={"arming_delay_ms": 300})
        self.addCleanup(rig.stop_checked)
        rig.start(daemon=False)
        # A slave holds SCL low: every transfer on the bus fails from then on.
        rig.sim_call("HoldScl")
        t0 = time.monotonic()
        p = subprocess.run(command("caracarad") + ["--zero-thrusters", "--config", rig.config_path,
                            "--hardware=sim:" + rig.sim_socket], capture_output=True, text=True, timeout=120)
        took = time.monotonic() - t0
        print("\n--zero-thrusters on a bus held low: exit %d in %.1f s" % (p.returncode, took))
        self.assertEqual(p.returncode, 1, p.stderr)
        self.assertIn("not tried, the bus is locked", p.stderr)
        # Given up before systemd's TimeoutStopSec would end it (tests/bounds.json).
        self.assertLess(took, ZERO_STEP_HELD_BUS_S_MAX)


if __name__ == "__main__":
    unittest.main()
