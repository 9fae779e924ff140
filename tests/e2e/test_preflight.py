"""The preflight (Preflight(), caracaractl check): one go/no-go table before a dive.

A healthy simulated vehicle (its orientation sensor noisy, as a live IMU is) is all go, exit 0.
Then each no-go is made on the vehicle's side, through the simulator's fault injection or the
files the daemon reads: caracaractl exits 1, that row is NO-GO with its advice, every other row
is still go. The simulator's wire log shows that a check orders no thruster anything but zero.
"""

import os
import shutil
import tempfile
import unittest

import dbus

from harness import MOTORS, SIM_NOISE, TEENSY_IFACE, TEENSY_PATH, VEHICLE, ZERO, Rig, VehicleTestCase, poll, pump_main_loop

ITEMS = ["thruster-%d" % i for i in range(MOTORS)] + [
    "bus", "teensy", "kill-switch", "kill-output", "config", "recorder", "failsafes", "clock"]
MTS = [0x52, 0x56, 0x58, 0x5A, 0x5C, 0x5E, 0x60, 0x62]


def parse_table(stdout):
    """caracaractl check's table -> {item: (go, observed, advice)}."""
    rows, last = {}, None
    for line in stdout.splitlines()[1:]:
        text = line.strip()
        if text.startswith("->") and last:
            go, observed, _ = rows[last]
            rows[last] = (go, observed, text[2:].strip())
            continue
        parts = line.split(None, 2)
        if len(parts) >= 2 and parts[1] in ("go", "NO-GO"):
            last = parts[0]
            rows[last] = (parts[1] == "go", parts[2] if len(parts) > 2 else "", "")
    return rows


class PreflightCase(VehicleTestCase):
    SIM_CONFIG = SIM_NOISE
    SIM_TOML = ""

    @classmethod
    def setUpClass(cls):
        cls.rig = Rig(control=cls.CONTROL, extra_config=cls.EXTRA_CONFIG, sim_config=cls.SIM_CONFIG,
                      sim_toml=cls.SIM_TOML)
        cls.addClassCleanup(cls.rig.stop_checked)
        cls.rig.start()
        cls.rig.arm()

    def check(self):
        """caracaractl check: (exit status, {item: (go, observed, advice)}, stdout); the wire log
        over the check holds no non-zero order."""
        since = self.rig.wire_next()
        res = self.rig.ctl("check")
        print("\n" + res.stdout + res.stderr)
        orders = [e for e in self.rig.wire_log(since)[1]
                  if e.bus == "i2c" and not e.read and len(e.data) == 3 and e.addr in [m >> 1 for m in MTS]]
        self.assertTrue(orders, "the loop sent no orders during the check")
        self.assertEqual([e for e in orders if e.data[0] not in (ZERO, 0x7F)], [],
                         "a non-zero order on the wire during the check")
        rows = parse_table(res.stdout)
        self.assertEqual(sorted(rows), sorted(ITEMS), res.stdout)
        return res.returncode, rows, res.stdout

    def assert_no_go(self, item, observed, advice):
        """Exit 1, `item` NO-GO with `observed` and `advice` in its text, every other row go."""
        code, rows, out = self.check()
        self.assertEqual(code, 1, out)
        go, seen, said = rows[item]
        self.assertFalse(go, out)
        self.assertIn(observed, seen)
        self.assertIn(advice, said)
        self.assertEqual([i for i, r in rows.items() if not r[0]], [item], out)

    def wait_all_go(self, timeout=30.0):
        poll(lambda: self.check()[0] == 0, timeout, interval=0.5, message="the preflight never came back to all go")


class HealthyVehicleTest(PreflightCase):
    """One vehicle: all go, then each fault made and taken away again."""

    def test_all_go_exits_0(self):
        code, rows, out = self.check()
        self.assertEqual(code, 0, out)
        self.assertTrue(all(r[0] for r in rows.values()), out)
        self.assertIn("preflight: all go", out)
        self.assertIn("answers as seabotix at MT 0x52", rows["thruster-0"][1])
        self.assertIn("orientation changing", rows["teensy"][1])
        self.assertIn("released", rows["kill-switch"][1])

    def test_listed_in_help(self):
        self.assertRegex(self.rig.ctl("--help").stdout, r"(?m)^\s+check\s+Preflight")

    def test_dbus_rows(self):
        rows = self.rig.vcall("Preflight", timeout=30)
        self.assertEqual([str(r[0]) for r in rows], ITEMS)
        for name, go, observed, advice in rows:
            self.assertIsInstance(go, dbus.Boolean)
            self.assertTrue(go, "%s: %s" % (name, observed))
            self.assertEqual(str(advice), "")

    def test_two_callers_at_once_both_get_the_table(self):
        replies, errors = [], []
        obj = self.rig.obj(VEHICLE, "/org/caracara/Vehicle1")
        for _ in range(2):
            obj.Preflight(dbus_interface=VEHICLE, timeout=30,
                          reply_handler=replies.append, error_handler=errors.append)
        poll(lambda: len(replies) + len(errors) == 2, 10, pump=pump_main_loop)
        self.assertEqual(errors, [])
        self.assertEqual([[str(r[0]) for r in rows] for rows in replies], [ITEMS, ITEMS])

    def no_go_while(self, make, undo, item, observed, advice, then=None):
        """`make` the fault (then wait for `then`, the daemon having seen it), assert the no-go,
        `undo` it and wait for all go again."""
        make()
        try:
            if then:
                poll(then, 10, message="the daemon did not see the fault")
            self.assert_no_go(item, observed, advice)
        finally:
            undo()
        self.wait_all_go()

    def thruster_call(self, i, method, *args, signature):
        return lambda: self.rig.sim_thruster_call(i, method, *args, signature=signature)

    def sim_call(self, method, *args, signature=None, teensy=False):
        call = self.rig.sim_teensy_call if teensy else self.rig.sim_call
        return lambda: call(method, *args, signature=signature)

    def killed(self):
        return self.rig.state() == "killed"

    def test_a_thruster_that_does_not_answer(self):
        self.no_go_while(self.thruster_call(3, "SetNack", True, signature="b"),
                         self.thruster_call(3, "SetNack", False, signature="b"),
                         "thruster-3", "does not answer (nack)", "MT 0x5A")

    def test_a_fault_bit(self):
        self.no_go_while(self.thruster_call(2, "SetFault", "stall", True, signature="sb"),
                         self.thruster_call(2, "SetFault", "stall", False, signature="sb"),
                         "thruster-2", "fault bits set: stall", "inspect thruster 2")

    def test_a_hot_thruster(self):
        # 105 C: past the overtemp failsafe's clearing point (100 C), short of the bit (110 C).
        self.no_go_while(self.thruster_call(5, "SetTemperature", 105.0, 105.0, signature="dd"),
                         self.thruster_call(5, "SetTemperature", 15.0, 15.0, signature="dd"),
                         "thruster-5", "105 C", "let it cool below 100 C")

    def test_a_silent_teensy(self):
        self.no_go_while(self.sim_call("InjectFault", "no-answer", dbus.UInt32(1000000), signature="su", teensy=True),
                         self.sim_call("ClearFaults", teensy=True),
                         "teensy", "offline (silent)", "check the Teensy's power",
                         then=lambda: self.rig.vget("LinkLoss", path=TEENSY_PATH, iface=TEENSY_IFACE) != "none")

    def test_an_unreadable_kill_switch(self):
        self.no_go_while(self.sim_call("SetLinePresent", "KILL_SWITCH", False, signature="sb"),
                         self.sim_call("SetLinePresent", "KILL_SWITCH", True, signature="sb"),
                         "kill-switch", "cannot be read", "[gpio.kill_switch]", then=self.killed)

    def test_a_pressed_kill_switch(self):
        self.no_go_while(self.sim_call("SetKillSwitch", True, signature="b"),
                         self.sim_call("SetKillSwitch", False, signature="b"),
                         "kill-switch", "pressed", "release the kill switch", then=self.killed)

    def test_a_kill_output_that_went_away(self):
        self.no_go_while(self.sim_call("SetLinePresent", "KILL_OUT", False, signature="sb"),
                         self.sim_call("SetLinePresent", "KILL_OUT", True, signature="sb"),
                         "kill-output", "cannot be read", "[gpio.kill_output]", then=self.killed)

    def test_a_config_file_the_checker_refuses(self):
        path = self.rig.config_path
        with open(path) as f:
            good = f.read()

        def write(text):
            return lambda: open(path, "w").write(text)
        # A second [control] table: the checker refuses the file (caracarad would not start).
        self.no_go_while(write(good + "\n[control]\nloop_rate_hz = 50\n"), write(good),
                         "config", path, "caracarad --check-config " + path)

    def test_a_missing_recorder_directory(self):
        dives = os.path.join(self.rig.dir, "dives")
        self.no_go_while(lambda: os.rename(dives, dives + ".away"), lambda: os.rename(dives + ".away", dives),
                         "recorder", "missing or not writable", "create " + dives)


class SlowLoopTest(PreflightCase):
    """At 5 Hz one status read per tick reaches each thruster every 1.6 s: the window grows to
    three rounds (4.8 s), so no thruster that answers is taken for one that does not."""
    CONTROL = dict(PreflightCase.CONTROL, loop_rate_hz=5)

    def test_all_go_at_a_slow_loop(self):
        for _ in range(2):
            code, rows, out = self.check()
            self.assertEqual(code, 0, out)


class FrozenOrientationTest(PreflightCase):
    """The simulator's orientation without noise on a still vehicle: the same answer every time,
    as a stuck IMU gives."""
    SIM_CONFIG = {"orientation_noise_rad": 0.0}

    def test_frozen_orientation_is_no_go(self):
        self.assert_no_go("teensy", "orientation frozen", "check the IMU")


class WrongVariantTest(PreflightCase):
    """Thruster 5's controller is a legacy one where the configuration says SeaBotix."""
    SIM_TOML = "".join('[[thruster]]\naddress = %d\nvariant = "%s"\n\n' % (mt, "legacy" if i == 5 else "seabotix")
                       for i, mt in enumerate(MTS))

    def test_wrong_variant_is_no_go(self):
        self.assert_no_go("thruster-5", "not as configured", "configured seabotix at MT 0x5E")


class RecorderFullTest(PreflightCase):
    """recorder.max_total_mb (1 TiB) more than the filesystem can hold."""
    DIVES = tempfile.mkdtemp(prefix="caracara-preflight-dives-")
    EXTRA_CONFIG = {"recorder": {"directory": DIVES, "max_total_mb": 1048576}}

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.DIVES, ignore_errors=True)

    def test_recorder_without_space_is_no_go(self):
        self.assert_no_go("recorder", "MiB free", "free space on that filesystem")


class WarnOnlyFailsafeTest(PreflightCase):
    """A thruster fault configured to warn only."""
    EXTRA_CONFIG = {"failsafe.stall": {"action": "warn", "persistence_ms": 1000}}

    def test_warn_only_failsafe_is_no_go(self):
        self.assert_no_go("failsafes", "stall warn", "only warn on stall")


if __name__ == "__main__":
    unittest.main()
