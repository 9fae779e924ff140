"""caracaractl against a running caracarad on the simulator: output, effects on the simulated
hardware, and the documented exit codes (0 ok, 1 refused, 2 usage, 3 unavailable, 4 denied)."""

import os
import re
import shutil
import signal
import subprocess
import time
import unittest

import harness
from harness import (DEFAULT_MT, ERR, MOTORS, ZERO, Rig, SEED_AXIS_MOTORS, VehicleTestCase, binary,
                     command, speed_byte)

OK, REFUSED, USAGE, UNAVAILABLE, DENIED = 0, 1, 2, 3, 4


def ctl_available():
    # Under CI (CI=true) a caracaractl that is not built fails these tests instead of skipping them.
    return os.access(binary("caracaractl"), os.X_OK) or os.environ.get("CI") == "true"


@unittest.skipUnless(ctl_available(), "caracaractl is not built")
class CaracaractlTest(VehicleTestCase):
    # The default command timeout (500 ms): holding must re-send to keep the thrusters going.
    CONTROL = {"arming_delay_ms": 300}

    def setUp(self):
        self.rig.reset()

    def ctl(self, *args, **kw):
        return self.rig.ctl(*args, **kw)

    def hold(self, *args):
        return subprocess.Popen(command("caracaractl") + ["--bus-address", self.rig.address] + [str(a) for a in args],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                stdin=subprocess.DEVNULL, preexec_fn=harness._die_with_parent)

    def finish(self, proc, timeout=30):
        try:
            out, err = proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            proc.kill()
            out, err = proc.communicate()
            self.fail("caracaractl did not end: %s %s" % (out, err))
        return proc.returncode, out, err

    # -- status --

    def test_status(self):
        r = self.ctl("status")
        self.assertEqual(r.returncode, OK, r.stderr)
        out = r.stdout
        self.assertRegex(out, r"State: ready\b")
        self.assertIn("policy scale", out)
        for i, mt in enumerate(DEFAULT_MT):
            self.assertRegex(out, r"(?m)^\s*%d\s+0x%02X\s+seabotix\s+yes\b" % (i, mt), "thruster %d row" % i)
        self.assertIn("Teensy: online", out)
        self.assertIn("Orientation:", out)
        self.assertIn("I2C bus: /dev/i2c-1", out)
        self.assertRegex(out, r"State: ok\b")
        # No command is the default.
        self.assertEqual(self.ctl().stdout.splitlines()[0], out.splitlines()[0])

    def test_status_shows_kill_and_thrust(self):
        self.rig.vcall("Kill")
        r = self.ctl("status")
        self.assertEqual(r.returncode, OK, r.stderr)
        self.assertIn("killed (source: dbus)", r.stdout)
        self.rig.reset()
        self.rig.thrust([0, 0, 0, 4000, 0, 0, 0, 0])
        r = self.ctl("status")
        self.assertIn("Motor values: 0 0 0 4000 0 0 0 0", r.stdout)
        self.assertRegex(r.stdout, r"(?m)^\s*3\s+0x5A\s+seabotix\s+yes\s+4000\s+0x%02X" % speed_byte(4000))

    # -- kill / clear-kill --

    def test_kill_and_clear_kill(self):
        values = [2000] * 4 + [0] * 4
        self.rig.thrust(values)
        self.rig.wait_sim_speeds([speed_byte(v) for v in values])
        r = self.ctl("kill")
        self.assertEqual(r.returncode, OK, r.stderr)
        self.assertEqual(self.rig.sim_speeds(), [ZERO] * MOTORS)
        self.assertEqual(self.rig.state(), "killed")
        self.assertEqual(self.rig.vget("KillSource"), "dbus")
        r = self.ctl("clear-kill")
        self.assertEqual(r.returncode, OK, r.stderr)
        self.assertIn(self.rig.state(), ("arming", "ready"))
        self.rig.wait_state("ready")

    def test_refused_request_exits_1_with_the_error_name(self):
        r = self.ctl("clear-kill")
        self.assertEqual(r.returncode, REFUSED)
        self.assertIn(ERR + "NotKilled", r.stderr)
        r = self.ctl("thrust", 8851, 0, 0, 0, 0, 0, 0, 0, "--once")
        self.assertEqual(r.returncode, REFUSED)
        self.assertIn(ERR + "OutOfRange", r.stderr)
        self.rig.vcall("Kill")
        r = self.ctl("thrust", 100, 0, 0, 0, 0, 0, 0, 0, "--for", 1)
        self.assertEqual(r.returncode, REFUSED)
        self.assertIn(ERR + "Killed", r.stderr)
        self.assertEqual(self.rig.sim_speeds(), [ZERO] * MOTORS)

    # -- leds and Teensy --

    def test_leds(self):
        r = self.ctl("leds", 12, 34, 56)
        self.assertEqual(r.returncode, OK, r.stderr)
        self.assertEqual(tuple(self.rig.sim_teensy("Leds")), (12, 34, 56))
        r = self.ctl("status")
        self.assertIn("red 12, green 34, blue 56", r.stdout)

    def test_teensy_commands(self):
        self.rig.sim_teensy_call("SetDistance", harness.dbus.Byte(1), harness.dbus.UInt16(4321), signature="yq")
        r = self.ctl("distance", 1)
        self.assertEqual(r.returncode, OK, r.stderr)
        self.assertEqual(r.stdout.strip(), "4321 mm")
        r = self.ctl("servo", 2, 33)
        self.assertEqual(r.returncode, OK, r.stderr)
        self.assertEqual(int(self.rig.sim_teensy("Servos")[2]), 33)
        acks = int(self.rig.sim_teensy("Acknowledgements"))
        r = self.ctl("turn", 0.3)
        self.assertEqual(r.returncode, OK, r.stderr)
        self.assertEqual(int(self.rig.sim_teensy("Acknowledgements")), acks + 1)

    # -- holding thrust and motion --

    def test_thrust_holds_past_the_command_timeout(self):
        values = [1500, -1500, 0, 0, 0, 0, 3000, 0]
        expected = [speed_byte(v) for v in values]
        timeout_s = int(self.rig.vget("CommandTimeoutMs")) / 1000.0
        proc = self.hold("thrust", *values, "--for", 3 * timeout_s + 2)
        try:
            self.rig.wait_sim_speeds(expected)
            held_from = time.monotonic()
            # Three command timeouts long, the thrusters keep the values.
            while time.monotonic() - held_from < 3 * timeout_s:
                self.assertEqual(self.rig.sim_speeds(), expected, "thrust not held")
                self.assertIsNone(proc.poll(), "caracaractl ended early")
                time.sleep(0.1)
        finally:
            code, out, err = self.finish(proc)
        self.assertEqual(code, OK, err)
        # caracaractl has left: the daemon zeroes.
        self.rig.wait_sim_zero()
        self.assertEqual(self.rig.state(), "ready")

    def test_thrust_until_interrupted(self):
        values = [0, 0, 0, 0, -2500, 2500, 0, 0]
        proc = self.hold("thrust", *values)
        try:
            self.rig.wait_sim_speeds([speed_byte(v) for v in values])
        finally:
            proc.send_signal(signal.SIGINT)
            code, out, err = self.finish(proc)
        self.assertEqual(code, OK, err)
        self.rig.wait_sim_zero()

    def test_thrust_once(self):
        wire_from = self.rig.wire_next()
        r = self.ctl("thrust", 0, 0, 0, 0, 0, 0, 0, 1000, "--once")
        self.assertEqual(r.returncode, OK, r.stderr)
        self.rig.wait_sim_zero()
        _, log = self.rig.wire_log(wire_from)
        orders = [e for e in log if e.bus == "i2c" and not e.read and e.addr == DEFAULT_MT[7] >> 1]
        self.assertTrue(orders)
        self.assertEqual(orders[-1].data[0], ZERO)

    def test_motion(self):
        motors = SEED_AXIS_MOTORS["x"]
        proc = self.hold("motion", "starboard=-0.2", "--for", 20)  # towards port: the seed's x
        try:
            value = round(0.2 * harness.MOTOR_MAX)
            self.rig.wait_sim_speeds([speed_byte(motors[i] * value) if i in motors else ZERO for i in range(MOTORS)])
        finally:
            proc.send_signal(signal.SIGTERM)
            code, out, err = self.finish(proc)
        self.assertEqual(code, OK, err)
        self.rig.wait_sim_zero()

    # -- usage errors: exit 2, nothing sent --

    def test_usage_errors(self):
        before = self.rig.sim_snapshot()
        for args in [("frob",), ("thrust", 1, 2, 3), ("thrust", 0, 0, 0, 0, 0, 0, 0, "x"),
                     ("leds", 256, 0, 0), ("leds", 1, 2), ("motion", 0, 0, 0, 0, 0), ("motion", "forward=0.1", "forward=0.2"), ("motion", "left=0.1"), ("motion",),
                     ("motion", "up=fast"), ("--no-such-option", "status"),
                     ("kill", "now"), ("thrust", 0, 0, 0, 0, 0, 0, 0, 0, "--for", "soon")]:
            with self.subTest(args=args):
                r = self.ctl(*args)
                self.assertEqual(r.returncode, USAGE, "%s: %s %s" % (args, r.stdout, r.stderr))
                self.assertTrue(r.stderr.strip(), "a usage error says what is wrong")
        self.assertEqual(self.rig.state(), "ready")
        self.assertEqual([s for s, _ in self.rig.sim_snapshot()], [s for s, _ in before])
        self.assertEqual(tuple(self.rig.sim_teensy("Leds")), tuple(self.rig.vget("Leds")))

    def test_power_off_needs_confirmation(self):
        r = self.ctl("power-off")  # stdin is not a terminal
        self.assertEqual(r.returncode, USAGE)
        self.assertIn("--yes-power-off", r.stderr)
        self.assertEqual(self.rig.state(), "ready")
        self.assertFalse(self.rig.sim_get("PowerOffOutput"))

    def test_help(self):
        r = self.ctl("--help")
        self.assertEqual(r.returncode, OK)
        for cmd in ("status", "thrust", "motion", "kill", "clear-kill", "leds", "power-off", "monitor", "motor-test",
                    "detect-directions"):
            self.assertRegex(r.stdout, r"(?m)^\s+%s\b" % re.escape(cmd))


@unittest.skipUnless(ctl_available(), "caracaractl is not built")
class CaracaractlPowerOffTest(unittest.TestCase):

    def test_power_off_confirmed(self):
        rig = Rig(control={"arming_delay_ms": 300})
        self.addCleanup(rig.stop_checked)
        rig.start()
        rig.arm()
        r = rig.ctl("power-off", "--yes-power-off")
        self.assertEqual(r.returncode, OK, r.stderr)
        self.assertEqual(rig.state(), "powered-off")
        self.assertTrue(rig.sim_get("PowerOffOutput"))
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
        r = rig.ctl("clear-kill")
        self.assertEqual(r.returncode, REFUSED)
        self.assertIn(ERR + "PoweredOff", r.stderr)


@unittest.skipUnless(ctl_available(), "caracaractl is not built")
class CaracaractlUnavailableTest(unittest.TestCase):

    def test_daemon_not_running(self):
        rig = Rig()
        self.addCleanup(rig.stop_checked)
        rig.start(daemon=False)  # the bus and the simulator, no caracarad
        for args in (("status",), ("kill",), ("thrust", 0, 0, 0, 0, 0, 0, 0, 0)):
            with self.subTest(args=args):
                r = rig.ctl(*args)
                self.assertEqual(r.returncode, UNAVAILABLE, r.stderr)
                self.assertIn("not running", r.stderr)

    def test_bus_unreachable(self):
        r = subprocess.run(command("caracaractl") + ["--bus-address", "unix:path=/nonexistent/caracara-bus", "status"],
                           capture_output=True, text=True, timeout=60)
        self.assertEqual(r.returncode, UNAVAILABLE)
        self.assertIn("/nonexistent/caracara-bus", r.stderr)

    def test_daemon_stopped_while_holding(self):
        rig = Rig(control={"arming_delay_ms": 300})
        self.addCleanup(rig.stop_checked)
        rig.start()
        rig.arm()
        proc = subprocess.Popen(command("caracaractl") + ["--bus-address", rig.address, "thrust", "800", "0", "0",
                                 "0", "0", "0", "0", "0"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                stdin=subprocess.DEVNULL, preexec_fn=harness._die_with_parent)
        try:
            rig.wait_sim_speeds([speed_byte(800)] + [ZERO] * 7)
            self.assertEqual(rig.stop_daemon(), 0)
            code = proc.wait(30)
        finally:
            if proc.poll() is None:
                proc.kill()
            out, err = proc.communicate()
        self.assertEqual(code, UNAVAILABLE, err)
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)


@unittest.skipUnless(ctl_available(), "caracaractl is not built")
class CaracaractlRemoteArgumentsTest(unittest.TestCase):
    """-H/--host as far as this machine goes: the over-SSH checks against a real sshd are in the
    system test (tests/system/topside.sh)."""

    def ctl(self, *args):
        return subprocess.run(command("caracaractl") + list(args), capture_output=True, text=True, timeout=60,
                              stdin=subprocess.DEVNULL)

    def test_host_that_is_no_host_is_a_usage_error(self):
        # An option for ssh is never taken as the host; sd_bus_open_system_remote's own check
        # of [USER@]HOST[:PORT] ends as a usage error too (before ssh runs).
        for args in (("-H", "-oProxyCommand=touch /tmp/caracara-pwned", "status"), ("--host=a@b@c", "status"),
                     ("--host=", "status"), ("-Hhost:1:2", "kill"), ("-H",),
                     # systemd's HOST:CONTAINER form is not taken: the port must be a port.
                     ("-H", "pilot@host:notaport", "kill"), ("-H", "host:0", "status"),
                     ("-H", "host:65536", "status"), ("-H", "user@[fd00::1]x", "status")):
            with self.subTest(args=args):
                r = self.ctl(*args)
                self.assertEqual(r.returncode, USAGE, r.stderr)
                self.assertIn("[USER@]HOST[:PORT]", r.stderr)
        self.assertFalse(os.path.exists("/tmp/caracara-pwned"))

    def test_host_not_reached_exits_3_with_what_ssh_said(self):
        # Nothing listens on 127.0.0.1 port 1: ssh says so, exits 255, and caracaractl exits 3.
        # Never skipped: scripts/deps.sh (and debian/control, the Debian 13 root) install the client.
        self.assertTrue(shutil.which("ssh"), "no ssh client: scripts/deps.sh installs openssh-client")
        r = self.ctl("-H", "nobody@127.0.0.1:1", "kill")
        self.assertEqual(r.returncode, UNAVAILABLE, r.stderr)
        self.assertIn("Connection refused", r.stderr)
        self.assertIn("caracaractl: the SSH link to nobody@127.0.0.1:1 ended", r.stderr)


@unittest.skipUnless(ctl_available(), "caracaractl is not built")
class CaracaractlDeniedTest(VehicleTestCase):
    # A bus policy that lets nobody call the mutating methods (as for a user outside the
    # caracara group on the system bus); reading stays open.
    BUS_POLICY_EXTRA = ('    <deny send_destination="org.caracara.Vehicle1" send_interface="org.caracara.Vehicle1"'
                        ' send_member="Kill"/>')

    def test_permission_denied_exits_4(self):
        r = self.rig.ctl("kill")
        self.assertEqual(r.returncode, DENIED, r.stderr)
        self.assertIn("permission denied", r.stderr.lower())
        self.assertEqual(self.rig.state(), "ready")
        r = self.rig.ctl("status")
        self.assertEqual(r.returncode, OK, r.stderr)


if __name__ == "__main__":
    unittest.main()
