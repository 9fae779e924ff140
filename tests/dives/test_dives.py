"""The dive recorder end to end (docs/dive-format.md), and regression dives in the manner of gpsd.

DiveRecorderTest: a dive made as in scripts/demo.sh is listed by `caracaractl dives` and
plotted (PNG, SVG, HTML) by `caracaractl plot`; truncated, corrupt and seeded random files
get a named error from plot, export and `caracara-sim --replay`, never a crash.

RegressionTest: every tests/dives/*.cdive (recorded with the simulator's fault injection by
`test_dives.py record`) is replayed with `caracara-sim --replay` into a fresh caracarad; the
daemon's decisions (the events of the dive it records itself) and its D-Bus-visible state are
compared with tests/dives/NAME.expected. `python3 test_dives.py regen` rewrites those.
"""

import glob
import os
import random
import re
import shutil
import subprocess
import sys
import time
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "e2e"))
from harness import SIM_GPIO, Rig, command, poll, thruster_path  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
GPIO = dict(SIM_GPIO, scl={"chip": "gpiochip0", "line": "GPIO3"}, sda={"chip": "gpiochip0", "line": "GPIO2"})
RECOVERY = {"enabled": True, "driver_id": "fe804000.i2c", "attempts": 3, "backoff_ms": 50}
CONTROL = {"arming_delay_ms": 500}
THRUSTER_IFACE = "org.caracara.Vehicle1.Thruster"
BUS_PATH = "/org/caracara/Vehicle1/bus"
BUS_IFACE = "org.caracara.Vehicle1.Bus"


def ctl(*args, check=True):
    p = subprocess.run(command("caracaractl") + list(args), capture_output=True, text=True, timeout=60)
    if check and p.returncode != 0:
        raise AssertionError("caracaractl %s: %d\n%s%s" % (" ".join(args), p.returncode, p.stdout, p.stderr))
    return p


class DiveRig(Rig):
    """Recovery lines configured, so a hung bus is cleared; an optional dive to replay."""

    def __init__(self, replay=None):
        super().__init__(control=CONTROL, gpio=False, extra_config={"gpio": GPIO, "recovery": RECOVERY})
        self.replay = replay

    def start_sim(self):
        if not self.replay:
            return super().start_sim()
        argv = command("caracara-sim") + ["--socket", self.sim_socket, "--bus-address", self.address,
                                          "--replay", self.replay]
        self._spawn("caracara-sim", argv)
        poll(lambda: self.conn.name_has_owner("org.caracara.Simulator1") or self._died("caracara-sim"),
             self.START_TIMEOUT, message="caracara-sim did not take its name")

    def dives(self):
        return sorted(glob.glob(os.path.join(self.dives_dir, "dive-*.cdive")))

    def hold(self, seconds, values="1500 0 1500 0 0 1500 0 0"):
        return subprocess.Popen(command("caracaractl") + ["--bus-address", self.address, "thrust"] +
                                values.split() + ["--for", str(seconds)],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def wait_dive_closed(self):
        poll(lambda: self.dives() and "end," in ctl("export", self.dives()[-1], "--events").stdout,
             10, message="the dive was not closed")
        return self.dives()[-1]


# --- recording the regression dives (python3 test_dives.py record) ----------------------------

def scenario_overheat(rig):
    time.sleep(1.0)
    rig.sim_thruster_call(2, "SetFault", "overtemp", True)
    time.sleep(1.0)
    rig.sim_thruster_call(2, "SetFault", "overtemp", False)
    time.sleep(1.0)
    rig.vcall("Kill")


def scenario_ground_fault(rig):
    time.sleep(1.0)
    rig.sim_thruster_call(5, "SetFault", "ground-fault", True)
    time.sleep(1.5)
    rig.vcall("Kill")


def scenario_bus_recovery(rig):
    time.sleep(1.0)
    rig.sim_call("HangBus", 4, signature="u")
    poll(lambda: int(rig.get("org.caracara.Vehicle1", BUS_PATH, BUS_IFACE, "Recoveries")) >= 1, 10)
    time.sleep(1.0)
    rig.vcall("Kill")


def scenario_kill_switch(rig):
    time.sleep(1.5)
    rig.sim_call("SetKillSwitch", True, signature="b")


SCENARIOS = {"overheat": scenario_overheat, "ground_fault": scenario_ground_fault,
             "bus_recovery": scenario_bus_recovery, "kill_switch": scenario_kill_switch}


def record():
    for name, run in SCENARIOS.items():
        rig = DiveRig().start()
        try:
            rig.arm()
            hold = rig.hold(10)
            run(rig)
            hold.kill()
            hold.wait()
            shutil.copy(rig.wait_dive_closed(), os.path.join(HERE, name + ".cdive"))
            print("recorded", name)
        finally:
            rig.stop_checked()


# --- replaying them ---------------------------------------------------------------------------

def normalise(text):
    """Client names and times vary from run to run; the decisions do not."""
    text = re.sub(r":1\.\d+", ":1.*", text)
    return re.sub(r"ms=[0-9.]+", "ms=*", text)


def replay(path):
    """What caracarad decides when the dive at `path` plays in the simulator, as text."""
    rig = DiveRig(replay=path).start()
    try:
        rig.vcall("ClearKill")
        poll(lambda: "replay finished" in rig.log("caracara-sim") or rig._died("caracara-sim"), 60,
             message="the replay did not finish")
        time.sleep(0.5)  # the daemon reads each thruster's status within 8 cycles
        lines = []
        lines.append("State=%s KillSource=%s" % (rig.state(), rig.vget("KillSource")))
        for i in range(8):
            faults = [str(f) for f in rig.get("org.caracara.Vehicle1", thruster_path(i), THRUSTER_IFACE, "Faults")]
            if faults:
                lines.append("thruster/%d Faults=%s" % (i, ",".join(faults)))
        lines.append("bus Recoveries=%d" % int(rig.get("org.caracara.Vehicle1", BUS_PATH, BUS_IFACE, "Recoveries")))
        if rig.state() != "killed":
            rig.vcall("Kill")
        events = ctl("export", rig.wait_dive_closed(), "--events").stdout.splitlines()[1:]
        for e in events:
            t, kind, rest = e.split(",", 2)
            lines.append("%s %s" % (kind, normalise(rest.rstrip(","))))
        return "\n".join(lines) + "\n"
    finally:
        rig.stop_checked()


def expected_path(dive):
    return dive[: -len(".cdive")] + ".expected"


class RegressionTest(unittest.TestCase):
    def test_replays(self):
        dives = sorted(glob.glob(os.path.join(HERE, "*.cdive")))
        self.assertGreaterEqual(len(dives), 4)
        for dive in dives:
            with self.subTest(dive=os.path.basename(dive)):
                with open(expected_path(dive)) as f:
                    want = f.read()
                self.assertEqual(replay(dive), want,
                                 "replaying %s; `python3 tests/dives/test_dives.py regen` rewrites the "
                                 "expected output after a deliberate change" % dive)


class DiveRecorderTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.rig = DiveRig().start()
        cls.out = os.path.join(cls.rig.dir, "plots")
        os.makedirs(cls.out)
        cls.rig.arm()
        hold = subprocess.Popen(command("caracaractl") + ["--bus-address", cls.rig.address, "motion",
                                                          "forward=0.6", "turn-right=0.4", "--for", "2"],
                                stdout=subprocess.DEVNULL)
        hold.wait(30)
        cls.rig.vcall("Kill")
        cls.dive = cls.rig.wait_dive_closed()

    @classmethod
    def tearDownClass(cls):
        cls.rig.stop_checked()

    def test_listed(self):
        out = ctl("dives", "--dir", self.rig.dives_dir).stdout
        row = [line for line in out.splitlines() if os.path.basename(self.dive) in line]
        self.assertEqual(len(row), 1, out)
        self.assertIn("killed (dbus)", row[0])
        samples = int(row[0].split()[4])
        self.assertGreater(samples, 100, row[0])  # 2 s of motion and the arming delay at 50 Hz

    def test_recorded_motion_and_states(self):
        events = ctl("export", "last", "--dir", self.rig.dives_dir, "--events").stdout
        kinds = [line.split(",")[2].split(" ")[0] for line in events.splitlines()[1:] if ",state," in line]
        self.assertEqual(kinds, ["arming", "ready", "killed"], events)
        rows = ctl("export", self.dive).stdout.splitlines()
        header = rows[0].split(",")
        app2 = header.index("app_2")
        self.assertTrue(any(int(r.split(",")[app2]) != 0 for r in rows[1:]), "no motion recorded")
        yaw = header.index("yaw")
        self.assertGreater(max(abs(float(r.split(",")[yaw])) for r in rows[1:]), 0.05, "no yaw recorded")

    def test_plot(self):
        for ext, least in ((".png", 20000), (".svg", 20000), (".html", 20000)):
            path = os.path.join(self.out, "dive" + ext)
            ctl("plot", self.dive, "--out", path)
            self.assertGreater(os.path.getsize(path), least, path)
        with open(os.path.join(self.out, "dive.png"), "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
        with open(os.path.join(self.out, "dive.svg")) as f:
            svg = f.read()
        for label in ("motor value", "current (A)", "orientation (rad)", "kill (dbus)"):
            self.assertIn(label, svg)

    def bad(self, data, name):
        path = os.path.join(self.out, name)
        with open(path, "wb") as f:
            f.write(data)
        return path

    def assert_refused(self, path, why=None):
        """plot and export exit 1 naming the problem; the simulator refuses to replay it."""
        for args in (["plot", path, "--out", path + ".png"], ["export", path]):
            p = ctl(*args, check=False)
            self.assertEqual(p.returncode, 1, (args, p.stdout, p.stderr))
            self.assertIn("bad dive file", p.stderr)
            if why:
                self.assertIn(why, p.stderr)
            self.assertNotIn("Traceback", p.stderr)
        p = subprocess.run(command("caracara-sim") + ["--socket", path + ".sock", "--no-dbus", "--replay", path],
                           capture_output=True, text=True, timeout=30)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("cannot replay", p.stderr)

    def test_truncated_and_corrupt(self):
        with open(self.dive, "rb") as f:
            data = f.read()
        self.assert_refused(self.bad(data[: len(data) - 100], "truncated.cdive"), "truncated at byte")
        flipped = bytearray(data)
        flipped[len(data) // 2] ^= 0x40
        self.assert_refused(self.bad(bytes(flipped), "flipped.cdive"), "checksum at byte")
        self.assert_refused(self.bad(b"not a dive at all", "text.cdive"), "not-a-dive")
        # --partial plots what came before the cut, with a warning.
        p = ctl("plot", os.path.join(self.out, "truncated.cdive"), "--partial", "--out",
                os.path.join(self.out, "partial.png"))
        self.assertIn("warning", p.stderr)

    def test_seeded_random_inputs(self):
        """Mutations of a real dive (bytes flipped, cut, spliced) and pure noise: each is refused
        with a named error or read; none crashes plot's reader or the simulator."""
        with open(self.dive, "rb") as f:
            data = f.read()
        rng = random.Random(16)
        for n in range(12):
            b = bytearray(data)
            kind = n % 4
            if kind == 0:
                for _ in range(rng.randint(1, 8)):
                    b[rng.randrange(len(b))] = rng.randrange(256)
            elif kind == 1:
                b = b[: rng.randrange(len(b))]
            elif kind == 2:
                at = rng.randrange(len(b))
                b[at:at] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 64)))
            else:
                b = bytearray(rng.randrange(256) for _ in range(rng.randint(0, 4096)))
            path = self.bad(bytes(b), "random%d.cdive" % n)
            p = ctl("export", path, "--events", check=False)
            self.assertIn(p.returncode, (0, 1), (n, p.stderr))
            if p.returncode == 1:
                self.assertIn("bad dive file", p.stderr)
                s = subprocess.run(command("caracara-sim") + ["--socket", path + ".sock", "--no-dbus", "--replay",
                                                              path], capture_output=True, text=True, timeout=30)
                self.assertEqual(s.returncode, 2, s.stderr)


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "record":
        record()
    elif len(sys.argv) > 1 and sys.argv[1] == "regen":
        for dive in sorted(glob.glob(os.path.join(HERE, "*.cdive"))):
            with open(expected_path(dive), "w") as f:
                f.write(replay(dive))
            print("wrote", expected_path(dive))
    else:
        unittest.main()
