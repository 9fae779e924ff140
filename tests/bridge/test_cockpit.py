"""The cockpit (docs/cockpit.md) in a real browser: Debian's chromium, headless, driven by
puppeteer-core (pinned in package-lock.json), loading the page from caracara-bridge through a
real `ssh -L` forward (the rig, bridge and private sshd of test_bridge.py), judged on the
simulator's side (its inspection API and wire log). chromium is installed here when missing
(about 460 MB; not for the demo). Under CI (CI=true) a missing chromium, node or sshd fails.
Screenshots of the ready, driving and killed states go to BUILD/tests/cockpit-artifacts.
"""
import os
import shutil
import subprocess
import unittest

from test_bridge import BUILD_DIR, HERE, BridgeRig, missing, npm_ci

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

    def test_z_bridge_stops_cleanly(self):
        self.check_bridge_stops_cleanly()


if __name__ == "__main__":
    unittest.main()
