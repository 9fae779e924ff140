"""Commissioning in the dive recording (docs/dive-format.md, docs/commissioning.md), judged on the
simulator's wire log.

MotorTestDiveTest: four motor tests during a dive, each ended another way, appear in `caracaractl export --events` with their
thruster and value, started and stopped when the wire got the thruster's first non-zero order
and its first zero order after it.

DetectionDiveTest: a direction detection run on a vehicle with thrusters 2 and 5 mounted reversed
and a noisy, drifting orientation sensor (the setup of tests/e2e/test_direction_detection.py) is
in the dive: each pulse at the time the wire got it, each verdict as DetectDirections answered
it. `caracaractl plot DIVE --detection --wire FILE` plots it and names the thrusters it found
pulsed, in the dive and on the wire: the eight the wire log saw.

    python3 test_commissioning_dive.py plot OUT.png    runs the detection and plots it (the image
                                                       in docs/commissioning.md)
"""

import csv
import os
import sys
import time
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "e2e"))
import dbus  # noqa: E402

from bounds import DIVE_COMMISSIONING_SKEW_MS_MAX  # noqa: E402
from harness import DEFAULT_MT, MOTORS, SIM_NOISE, ZERO, Rig, poll, speed_byte  # noqa: E402

CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 60000}
REVERSED = [2, 5]
SIM_CONFIG = dict(SIM_NOISE, reversed_thrusters=REVERSED, noise_seed=11)


def start_mono_ns(path):
    """The dive's start on CLOCK_MONOTONIC: the header's second field (docs/dive-format.md)."""
    with open(path, "rb") as f:
        data = f.read(28)
    assert data[:8] == b"CARADIVE", data[:8]
    return int.from_bytes(data[20:28], "little")


def dive_events(rig, path):
    """(t_s, kind, {field: value}) of every event of the dive, from `caracaractl export --events`."""
    r = rig.ctl("export", path, "--events")
    assert r.returncode == 0, r.stderr
    out = []
    for row in csv.DictReader(r.stdout.splitlines()):
        fields = dict(p.split("=", 1) for p in row["detail"].split(" ") if "=" in p)
        fields["detail"] = row["detail"]
        out.append((float(row["t_s"]), row["kind"], fields))
    return out


def orders(entries):
    """(time_ns, thruster, speed byte) of every order on the wire (an order: three bytes written)."""
    out = []
    for e in entries:
        if e.bus == "i2c" and not e.read and len(e.data) == 3:
            for i, mt in enumerate(DEFAULT_MT):
                if e.addr == mt >> 1:
                    out.append((e.time_ns, i, e.data[0]))
    return out


def on_and_off(wire, thruster, after_ns):
    """The first non-zero order to `thruster` after `after_ns`, and its first zero order after that."""
    on = next(t for t, i, s in wire if i == thruster and t > after_ns and s != ZERO)
    off = next(t for t, i, s in wire if i == thruster and t > on and s == ZERO)
    return on, off


def closed_dive(rig):
    def closed():
        dives = sorted(f for f in os.listdir(rig.dives_dir) if f.endswith(".cdive"))
        return dives and "end," in rig.ctl("export", os.path.join(rig.dives_dir, dives[-1]), "--events").stdout
    poll(closed, 10, message="the dive was not closed")
    return os.path.join(rig.dives_dir, sorted(f for f in os.listdir(rig.dives_dir) if f.endswith(".cdive"))[-1])


def write_wire_csv(wire, path):
    with open(path, "w") as f:
        f.write("time_ns,thruster,speed\n")
        for t, i, s in wire:
            f.write("%d,%d,%d\n" % (t, i, s))


def detection_run(rig):
    """Arms, runs DetectDirections, kills: (its rows, the dive, the wire's orders during the run)."""
    rig.arm()
    since = rig.wire_next()
    rows, _ = rig.vcall("DetectDirections", timeout=300)
    rig.vcall("Kill")
    dive = closed_dive(rig)
    return [str(r[0]) for r in rows], dive, orders(rig.wire_log(since)[1])


class SkewCase(unittest.TestCase):
    def assert_at_wire(self, what, dive_t_s, wire_ns, start_ns):
        """A dive event at `dive_t_s` describes the wire at `wire_ns`: stamped at the cycle that saw it."""
        skew_ms = (start_ns + dive_t_s * 1e9 - wire_ns) / 1e6
        self.skews.append(skew_ms)
        self.assertLess(abs(skew_ms), DIVE_COMMISSIONING_SKEW_MS_MAX,
                        "%s: the dive says %.4f s, the wire %.1f ms from it" % (what, dive_t_s, skew_ms))

    def print_skews(self):
        print("\ndive event minus wire: %.1f .. %.1f ms over %d events"
              % (min(self.skews), max(self.skews), len(self.skews)))


class MotorTestDiveTest(SkewCase):
    def setUp(self):
        self.rig = Rig(control=CONTROL, extra_config={"commissioning": {"motor_test_limit": 2000}})
        self.addCleanup(self.rig.stop_checked)
        self.rig.start()
        self.skews = []

    def motor_test(self, thruster, value):
        self.rig.vcall("MotorTest", dbus.Int32(thruster), dbus.Int32(value), signature="ii")
        self.rig.wait_sim_speeds([speed_byte(value) if i == thruster else ZERO for i in range(MOTORS)])

    def test_motor_tests_in_the_dive_at_the_wires_times(self):
        """Four tests, each ended its own way: its caller leaving (caracaractl --for), another test
        replacing it, its keep-alive running out, a kill (which also ends the dive)."""
        rig = self.rig
        rig.arm()
        since = rig.wire_next()
        r = rig.ctl("motor-test", "3", "--value", "1500", "--for", "1")
        self.assertEqual(r.returncode, 0, r.stderr)
        rig.wait_sim_zero()
        self.motor_test(6, -900)
        self.motor_test(1, 700)  # within 6's keep-alive: replaces it
        rig.wait_sim_zero()      # 1's keep-alive ran out
        self.motor_test(4, 1000)
        rig.vcall("Kill")
        dive = closed_dive(rig)
        tests = [(t, f) for t, kind, f in dive_events(rig, dive) if kind == "motor-test"]
        self.assertEqual([f["detail"] for _, f in tests],
                         ["thruster=3 value=1500", "thruster=3 stopped", "thruster=6 value=-900", "thruster=6 stopped",
                          "thruster=1 value=700", "thruster=1 stopped", "thruster=4 value=1000", "thruster=4 stopped"])
        self.assertEqual(tests[3][0], tests[4][0], "the replaced test stopped as the next one started")
        wire = orders(rig.wire_log(since)[1])
        start = start_mono_ns(dive)
        for (t_on, f), (t_off, _) in zip(tests[0::2], tests[1::2]):
            k = int(f["thruster"])
            on, off = on_and_off(wire, k, 0)
            self.assertEqual({s for t, i, s in wire if i == k and on <= t < off}, {speed_byte(int(f["value"]))})
            self.assert_at_wire("thruster %d's test start" % k, t_on, on, start)
            self.assert_at_wire("thruster %d's test stop" % k, t_off, off, start)
            # Nothing else moved while it ran (up to its last order: the next test's first is
            # in the transfer that stops it).
            last = max(t for t, i, s in wire if i == k and on <= t < off)
            self.assertLessEqual({s for t, i, s in wire if i != k and on <= t <= last}, {ZERO})
        self.print_skews()


class DetectionDiveTest(SkewCase):
    def setUp(self):
        self.rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 500}, sim_config=SIM_CONFIG)
        self.addCleanup(self.rig.stop_checked)
        self.rig.start()
        self.skews = []

    def test_detection_run_in_the_dive_and_its_plot(self):
        rig = self.rig
        verdicts, dive, wire = detection_run(rig)
        self.assertEqual(verdicts, ["reversed" if i in REVERSED else "ok" for i in range(MOTORS)])
        events = dive_events(rig, dive)
        runs = [f["detail"] for _, kind, f in events if kind == "detection"]
        self.assertEqual(runs, ["started", "ended judged=8"])
        results = [(int(f["thruster"]), f["verdict"]) for _, kind, f in events if kind == "detection-result"]
        self.assertEqual(results, list(enumerate(verdicts)))
        pulses = [(t, f) for t, kind, f in events if kind == "detection-pulse"]
        self.assertEqual([f["detail"] for _, f in pulses],
                         [d for i in range(MOTORS) for d in ("thruster=%d value=3000" % i, "thruster=%d stopped" % i)])
        start = start_mono_ns(dive)
        after = 0
        for (t_on, f), (t_off, _) in zip(pulses[0::2], pulses[1::2]):
            k = int(f["thruster"])
            on, off = on_and_off(wire, k, after)
            self.assert_at_wire("thruster %d's pulse" % k, t_on, on, start)
            self.assert_at_wire("thruster %d's pulse's end" % k, t_off, off, start)
            after = off
        self.print_skews()

        # The plot of the run, from the dive and the wire.
        wire_csv = os.path.join(rig.dir, "wire.csv")
        write_wire_csv(wire, wire_csv)
        out = os.path.join(rig.dir, "detection.png")
        r = rig.ctl("plot", dive, "--detection", "--wire", wire_csv, "--out", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        pulsed = sorted({i for _, i, s in wire if s != ZERO})
        self.assertEqual(pulsed, list(range(MOTORS)))
        self.assertIn("pulses in the dive: %s\n" % " ".join(map(str, pulsed)), r.stdout)
        self.assertIn("pulses on the wire: %s\n" % " ".join(map(str, pulsed)), r.stdout)
        self.assertIn("verdicts: %s\n" % ", ".join("%d %s" % kv for kv in enumerate(verdicts)), r.stdout)
        with open(out, "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
        self.assertGreater(os.path.getsize(out), 20000)
        # A dive without a detection run: refused by name.
        rig.vcall("ClearKill")
        rig.wait_state("ready")
        rig.vcall("Kill")
        bare = closed_dive(rig)
        self.assertNotEqual(bare, dive)
        r = rig.ctl("plot", bare, "--detection", "--out", os.path.join(rig.dir, "none.png"))
        self.assertEqual(r.returncode, 1)
        self.assertIn("no direction detection run", r.stderr)


def plot_for_docs(out):
    rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 500}, sim_config=SIM_CONFIG)
    rig.start()
    try:
        verdicts, dive, wire = detection_run(rig)
        wire_csv = os.path.join(rig.dir, "wire.csv")
        write_wire_csv(wire, wire_csv)
        r = rig.ctl("plot", dive, "--detection", "--wire", wire_csv, "--out", out)
        print(r.stdout + r.stderr, end="")
        print("%s: %s; sim %s; %s" % (time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), os.path.basename(dive),
                                      SIM_CONFIG, verdicts))
    finally:
        rig.stop_checked()


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "plot":
        plot_for_docs(os.path.abspath(sys.argv[2]))
    else:
        unittest.main()
