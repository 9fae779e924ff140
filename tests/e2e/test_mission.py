"""examples/mission_square.py against the simulator: it must drive the square (the simulated
vehicle really yaws four right angles), kill the vehicle and exit 0."""

import os
import signal
import subprocess
import time
import unittest

import harness
from harness import MOTORS, PYTHON, SOURCE_DIR, ZERO, Rig, angle_diff, poll

MISSION = os.path.join(SOURCE_DIR, "examples", "mission_square.py")


def run_mission(rig, *args):
    return subprocess.Popen([PYTHON, MISSION, "--bus-address", rig.address] + [str(a) for a in args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            stdin=subprocess.DEVNULL, preexec_fn=harness._die_with_parent)


class MissionTest(unittest.TestCase):

    def start_rig(self, daemon=True, **kw):
        rig = Rig(**kw)
        self.addCleanup(rig.stop_checked)
        rig.start(daemon=daemon)
        return rig

    def test_square(self):
        # Arming takes a second: the mission has to wait for "ready" itself.
        rig = self.start_rig(control={"arming_delay_ms": 1000})
        yaw0 = rig.sim_yaw()
        pos0 = rig.sim_teensy("Position")
        proc = run_mission(rig, "--arm", "--leg-seconds", 0.5, "--yaw-demand", 0.65, "--turn-timeout", 40)
        turned = 0.0
        largest = 0.0
        last = yaw0
        deadline = time.monotonic() + 240
        try:
            while proc.poll() is None and time.monotonic() < deadline:
                yaw = rig.sim_yaw()
                turned += angle_diff(yaw, last)
                largest = max(largest, abs(angle_diff(yaw, yaw0)))
                last = yaw
                time.sleep(0.05)
        finally:
            if proc.poll() is None:
                proc.kill()
            out, err = proc.communicate()
        self.assertEqual(proc.returncode, 0, "mission failed:\n%s\n%s" % (out[-3000:], err))
        turned += angle_diff(rig.sim_yaw(), last)
        # Four clockwise right angles in the simulator (a full turn), each within the mission's
        # tolerance; the heading was away from the start in between.
        self.assertGreater(turned, 4 * 1.35, "the simulated vehicle turned only %.2f rad" % turned)
        self.assertLess(turned, 4 * 1.85, "the simulated vehicle turned %.2f rad" % turned)
        self.assertGreater(largest, 1.5, "the heading never got far from the start")
        # It moved, and it printed its orientation as it went.
        pos = rig.sim_teensy("Position")
        self.assertGreater(abs(pos[0] - pos0[0]) + abs(pos[1] - pos0[1]), 0.0)
        self.assertGreaterEqual(sum(1 for line in out.splitlines() if "heading" in line), 8)
        self.assertIn("mission complete", out)
        # Killed at the end, every thruster at zero.
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(rig.vget("KillSource"), "dbus")
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)

    def test_refuses_a_killed_vehicle(self):
        rig = self.start_rig(control={"arming_delay_ms": 300})
        rig.arm()
        rig.vcall("Kill")
        proc = run_mission(rig)
        out, err = proc.communicate(timeout=60)
        self.assertEqual(proc.returncode, 1, out + err)
        self.assertIn("killed", err)
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)

    def test_sigterm_stops_and_kills(self):
        rig = self.start_rig(control={"arming_delay_ms": 300})
        rig.arm()
        proc = run_mission(rig, "--leg-seconds", 30)
        try:
            poll(lambda: any(s != ZERO for s in rig.sim_speeds()), 30, message="the mission never drove")
            proc.send_signal(signal.SIGTERM)
            out, err = proc.communicate(timeout=60)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.communicate()
        self.assertEqual(proc.returncode, 1, out + err)
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)

    def test_daemon_not_running(self):
        rig = self.start_rig(daemon=False)
        proc = run_mission(rig)
        out, err = proc.communicate(timeout=60)
        self.assertEqual(proc.returncode, 3, out + err)
        self.assertIn("not running", err)


if __name__ == "__main__":
    unittest.main()
