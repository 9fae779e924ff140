"""A SIGKILL of caracarad in mid-dive (docs/dive-format.md: "a crash loses at most the last
second"): the dive file it leaves is read by caracaractl export without a complaint, holds the
dive's samples up to at most a second before the kill, and has no end record (nobody wrote it)."""
import glob
import os
import signal
import subprocess
import time
import unittest

from bounds import DIVE_CRASH_LOSS_S_MAX
from harness import MOTORS, Rig, command, speed_byte


def ctl(*args):
    p = subprocess.run(command("caracaractl") + list(args), capture_output=True, text=True, timeout=60)
    return p.returncode, p.stdout, p.stderr


class DiveCrashTest(unittest.TestCase):

    def test_sigkill_in_mid_dive_leaves_a_readable_dive_short_of_at_most_a_second(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop)
        rig.start()
        t0 = time.monotonic()
        rig.vcall("ClearKill")  # the dive starts here
        t1 = time.monotonic()
        rig.wait_state("ready")
        rig.thrust([900] * MOTORS)
        rig.wait_sim_speeds([speed_byte(900)] * MOTORS)
        # Past a few blocks, and half way between two of them (the worst case is just before one).
        time.sleep(3.5 - (time.monotonic() - t1))
        daemon = rig.procs.pop("caracarad")
        t_kill = time.monotonic()
        os.kill(daemon.pid, signal.SIGKILL)
        daemon.wait(10)
        dives = sorted(glob.glob(os.path.join(rig.dives_dir, "dive-*.cdive")))
        self.assertEqual(len(dives), 1, dives)
        rc, out, err = ctl("export", dives[0])
        self.assertEqual(rc, 0, err)
        self.assertEqual(err, "")
        rows = out.splitlines()[1:]
        self.assertGreater(len(rows), 100, "fewer samples than 2 s at 50 Hz")  # 50 Hz
        last = float(rows[-1].split(",")[0])
        # The dive's own clock starts between t0 and t1: the kill came at most t_kill - t0 in.
        lost = (t_kill - t0) - last
        print("\nSIGKILL %.2f s into the dive: the file ends at %.2f s, %.2f s lost" % (t_kill - t0, last, lost))
        self.assertLessEqual(lost, DIVE_CRASH_LOSS_S_MAX)
        self.assertGreaterEqual(last, 0.0)
        rc, events, err = ctl("export", dives[0], "--events")
        self.assertEqual(rc, 0, err)
        self.assertNotIn(",end,", events)
        # Listed like any other, with no end reason.
        rc, listing, err = ctl("dives", "--dir", rig.dives_dir)
        self.assertEqual(rc, 0, err)
        self.assertIn(os.path.basename(dives[0]), listing)


if __name__ == "__main__":
    unittest.main()
