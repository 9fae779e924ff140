"""The cockpit (docs/cockpit.md) in a real browser: Debian's chromium, headless, driven by
puppeteer-core (pinned in package-lock.json), loading the page from caracara-bridge through a
real `ssh -L` forward (the rig, bridge and private sshd of test_bridge.py), judged on the
simulator's side (its inspection API and wire log). chromium is installed here when missing
(about 460 MB; not for the demo). Under CI (CI=true) a missing chromium, node or sshd fails.
Screenshots of the ready, driving and killed states go to BUILD/tests/cockpit-artifacts.
Which pages may drive (issue 46): origin.test.mjs through `caracaractl bridge`'s forward and its key.
The sticks are judged by where the simulated vehicle went (tests/e2e/vehicle_motion.py, issue 43),
on a rig of their own whose thrusters are all mounted as configured.
"""
import os
import shutil
import subprocess
import sys
import unittest

from test_bridge import BUILD_DIR, HERE, BridgeRig, HeldPilot, free_port, missing, npm_ci
from vehicle_motion import describe, judge

CHROMIUM = "/usr/bin/chromium"


def ensure_chromium():
    if os.access(CHROMIUM, os.X_OK):
        return
    if os.geteuid() == 0 and shutil.which("apt-get"):
        subprocess.run(["apt-get", "install", "-y", "--no-install-recommends", "chromium"], check=False,
                       stdout=subprocess.DEVNULL, env={**os.environ, "DEBIAN_FRONTEND": "noninteractive"})
    if not os.access(CHROMIUM, os.X_OK):
        missing("Debian's chromium is needed (apt-get install chromium)")


class CockpitTest(BridgeRig, unittest.TestCase):
    # The commissioning page's detection (cockpit.test.mjs): thruster 2 mounted reversed, a
    # quiet sensor, and a short settle, so one run takes seconds, not a minute.
    SIM_CONFIG = {"reversed_thrusters": [2]}
    COMMISSIONING = {"detect_settle_ms": 700}

    @classmethod
    def setUpClass(cls):
        ensure_chromium()
        npm_ci(HERE)
        super().setUpClass()

    def test_a_gamepad_mapping(self):
        self.node("gamepad.test.mjs")

    def test_cockpit_in_chromium(self):
        artifacts = os.path.join(BUILD_DIR, "tests", "cockpit-artifacts")
        os.makedirs(artifacts, exist_ok=True)
        forward = self.procs[-1]
        self.node("cockpit.test.mjs", CARACARA_HTTP_URL="http://127.0.0.1:%d/" % self.port,
                  CARACARA_CHROMIUM=CHROMIUM, CARACARA_ARTIFACTS=artifacts, CARACARA_FORWARD_PID=str(forward.pid),
                  CARACARA_DIVES_DIR=self.rig.dives_dir)
        self.assertIsNone(self.bridge.poll(), "the bridge survived the cockpit")

    def test_other_origins_and_the_forward_key_in_chromium(self):
        # Issue 46: through caracaractl bridge's forward (its key), to the rig's bridge (its Origin
        # check, one allow-listed origin); origin.test.mjs serves the other pages itself.
        port = free_port()
        _, ws_url, http_url, _, err_path, _ = self.caracaractl_bridge(port)
        self.node("origin.test.mjs", CARACARA_FORWARD_HTTP=http_url, CARACARA_FORWARD_WS=ws_url,
                  CARACARA_FORWARD_PORT=str(port), CARACARA_OTHER_PORT=str(free_port()),
                  CARACARA_ALLOWED_PORT=str(self.allowed_port), CARACARA_CHROMIUM=CHROMIUM,
                  CARACARA_BRIDGE_LOG=os.path.join(self.rig.dir, "caracara-bridge.log"), CARACARA_FORWARD_LOG=err_path)
        self.assertIsNone(self.bridge.poll(), "the bridge survived")

    def test_z_bridge_stops_cleanly(self):
        self.check_bridge_stops_cleanly()


# The default mapping (docs/cockpit.md, tools/cockpit/gamepad.js) on the standard gamepad, and the
# motion each input means to a pilot; the deadman is held by the pilot (hold_motion.mjs). A stick
# pushed forward reads -1 on its axis.
STICKS = [
    ("left stick forward", {"axes": {"1": -1.0}}, "forward"), ("left stick back", {"axes": {"1": 1.0}}, "backward"),
    ("left stick right", {"axes": {"0": 1.0}}, "starboard"), ("left stick left", {"axes": {"0": -1.0}}, "port"),
    ("left trigger", {"buttons": {"6": 1.0}}, "up"), ("right trigger", {"buttons": {"7": 1.0}}, "deeper"),
    ("right stick right", {"axes": {"2": 1.0}}, "clockwise"), ("right stick left", {"axes": {"2": -1.0}}, "counter-clockwise"),
    ("right stick forward", {"axes": {"3": -1.0}}, "nose up"), ("right stick back", {"axes": {"3": 1.0}}, "nose down"),
    ("d-pad right", {"buttons": {"15": 1.0}}, "roll right"), ("d-pad left", {"buttons": {"14": 1.0}}, "roll left"),
]


class CockpitSticksTest(BridgeRig, unittest.TestCase):
    """Each input of the default mapping, in chromium, moves the simulated vehicle the way a pilot
    expects (at the default gain 0.5, full stick: a demand of 0.5, as test_frames')."""

    @classmethod
    def setUpClass(cls):
        ensure_chromium()
        super().setUpClass()

    def test_sticks_move_the_vehicle_as_a_pilot_expects(self):
        self.rearm()
        with HeldPilot(self.rig, "cockpit", CARACARA_HTTP_URL="http://127.0.0.1:%d/" % self.port,
                       CARACARA_CHROMIUM=CHROMIUM) as pilot:
            for name, inputs, motion in STICKS:
                with self.subTest(name):
                    answer = {}

                    def hold(seconds):
                        answer.update(pilot.hold(seconds=seconds, **inputs))
                    m = judge(self, self.rig, motion, hold, "the cockpit's %s" % name)
                    print("# %s: %s; %d commands" % (name, describe(m), answer["sent"]), file=sys.stderr)
                    self.assertGreater(answer["sent"], 10, "%s: the page's commands while held" % name)

    def test_z_bridge_stops_cleanly(self):
        self.check_bridge_stops_cleanly()


if __name__ == "__main__":
    unittest.main()
