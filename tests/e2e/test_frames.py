"""Forward is forward (issue 43, docs/frames.md): SetMotion in the seed's axes and `caracaractl
motion` in a pilot's words, each axis judged by where the simulated vehicle went
(tests/e2e/vehicle_motion.py), not by the motor values another interface of ours would give.
"""

import signal
import subprocess
import time
import unittest

import harness
from harness import VehicleTestCase, command
from vehicle_motion import judge

# The seed's axes ("caracara-usb-packet", axis table) and the motion each one means, both ways.
SEED_AXES = {"x": ("port", "starboard"), "y": ("forward", "backward"), "z": ("deeper", "up"),
             "yaw": ("clockwise", "counter-clockwise"), "pitch": ("nose up", "nose down"),
             "roll": ("roll right", "roll left")}
# caracaractl motion's words and what each means.
PILOT_WORDS = {"forward": ("forward", "backward"), "starboard": ("starboard", "port"), "up": ("up", "deeper"),
               "turn-right": ("clockwise", "counter-clockwise"), "nose-up": ("nose up", "nose down"),
               "roll-right": ("roll right", "roll left")}


class FramesTest(VehicleTestCase):

    def setUp(self):
        self.rig.reset()

    def test_setmotion_moves_the_vehicle_along_the_seeds_axes(self):
        for axis, (plus, minus) in SEED_AXES.items():
            for demand, motion in ((0.5, plus), (-0.5, minus)):
                with self.subTest(axis=axis, demand=demand):
                    def hold(seconds):
                        end = time.monotonic() + seconds
                        while time.monotonic() < end:
                            self.rig.motion(**{axis: demand})  # within the 500 ms command timeout
                            time.sleep(0.1)
                        self.rig.motion()
                    judge(self, self.rig, motion, hold, "SetMotion %s=%+.1f" % (axis, demand))

    def test_caracaractl_motion_moves_the_vehicle_as_its_words_say(self):
        for word, (plus, minus) in PILOT_WORDS.items():
            for demand, motion in ((0.5, plus), (-0.5, minus)):
                with self.subTest(word=word, demand=demand):
                    def hold(seconds):
                        proc = subprocess.Popen(command("caracaractl") + ["--bus-address", self.rig.address, "motion",
                                                "%s=%g" % (word, demand)], stdout=subprocess.PIPE,
                                                stderr=subprocess.PIPE, text=True, stdin=subprocess.DEVNULL,
                                                preexec_fn=harness._die_with_parent)
                        try:
                            time.sleep(seconds)
                        finally:
                            proc.send_signal(signal.SIGINT)
                            out, err = proc.communicate(timeout=20)
                        self.assertEqual(proc.returncode, 0, out + err)
                    judge(self, self.rig, motion, hold, "caracaractl motion %s=%g" % (word, demand))

    def test_caracaractl_refuses_the_old_positional_axes(self):
        out = self.rig.ctl("motion", "0", "0.5", "0", "0", "0", "0")
        self.assertNotEqual(out.returncode, 0)
        self.assertIn("motion takes WORD=VALUE (forward, starboard, up, turn-right", out.stderr)
        self.assertEqual(self.rig.state(), "ready")


if __name__ == "__main__":
    unittest.main()
