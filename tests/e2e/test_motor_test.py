"""Commissioning's motor test (MotorTest, caracaractl motor-test): one thruster alone, bounded,
armed only, kept alive by the caller, ended at once by a kill, the caller leaving, another test
or a pilot's command. Judged on the simulator's wire log and its thrusters' ordered speeds.
"""

import signal
import subprocess
import time
import unittest

import dbus

from bounds import CLIENT_LOSS_ZERO_MS_MAX, MOTOR_TEST_HOLD_SHORT_MS_MAX, MOTOR_TEST_KEEPALIVE_LATENESS_MS_MAX
from harness import (DEFAULT_MT, ERR, MOTORS, ZERO, VehicleTestCase, command, poll, speed_byte)


def orders_to(entries, i):
    """The speed bytes ordered to thruster i, in wire order."""
    return [e.data[0] for e in entries
            if e.bus == "i2c" and e.addr == DEFAULT_MT[i] >> 1 and not e.read and len(e.data) == 3]


def alone(i, value):
    return [speed_byte(value) if k == i else ZERO for k in range(MOTORS)]


class MotorTestTest(VehicleTestCase):
    CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 60000}
    EXTRA_CONFIG = {"commissioning": {"motor_test_limit": 2000}}

    def setUp(self):
        self.rig.reset()

    def motor_test(self, thruster, value):
        self.rig.vcall("MotorTest", dbus.Int32(thruster), dbus.Int32(value), signature="ii")

    def test_caracaractl_runs_one_thruster_alone_then_stops(self):
        rig = self.rig
        since = rig.wire_next()
        hold_s = 1.5
        p = subprocess.Popen(command("caracaractl") + ["--bus-address", rig.address, "motor-test", "3",
                                                       "--value", "1500", "--for", str(hold_s)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        rig.wait_sim_speeds(alone(3, 1500), timeout=5)
        self.assertEqual(tuple(int(v) for v in rig.vget("MotorTest")), (3, 1500))
        self.assertIn("thruster 3 at 1500", rig.ctl("status").stdout)
        out, err = p.communicate(timeout=30)
        self.assertEqual(p.returncode, 0, err)
        self.assertIn("MotorTest(3, 1500)", out)
        # It held for its 1.5 s (re-sent under the 500 ms keep-alive), then stopped.
        rig.wait_sim_zero(timeout=5)
        entries = rig.wire_log(since)[1]
        on = [e.time_ns for e in entries if e.bus == "i2c" and e.addr == DEFAULT_MT[3] >> 1 and not e.read
              and len(e.data) == 3 and e.data[0] == speed_byte(1500)]
        held_ms = (on[-1] - on[0]) / 1e6
        print("\nmotor test --for %.1f: orders on the wire for %.0f ms" % (hold_s, held_ms))
        self.assertGreaterEqual(held_ms, hold_s * 1000 - MOTOR_TEST_HOLD_SHORT_MS_MAX, "the test did not hold for --for")
        for i in range(MOTORS):
            if i != 3:
                self.assertEqual(set(orders_to(entries, i)), {ZERO}, "thruster %d moved during a motor test" % i)
        self.assertEqual(tuple(int(v) for v in rig.vget("MotorTest")), (-1, 0))

    def test_keepalive_runs_out_and_the_thruster_stops(self):
        rig = self.rig
        sent = time.monotonic_ns()  # the keep-alive is armed after this, before the reply
        self.motor_test(5, -1200)
        rig.wait_sim_speeds(alone(5, -1200))
        since = rig.wire_next()
        poll(lambda: rig.sim_speeds()[5] == ZERO, 5, message="the motor test was never stopped")
        zero = [e for e in rig.wire_log(since)[1] if e.bus == "i2c" and e.addr == DEFAULT_MT[5] >> 1
                and not e.read and e.data[:1] == bytes([ZERO])]
        self.assertTrue(zero)
        late_ms = (zero[0].time_ns - sent) / 1e6 - 500.0
        print("\nmotor test keep-alive 500 ms: first zero order %.2f ms after it ran out" % late_ms)
        self.assertGreater(late_ms, 0.0, "stopped before the keep-alive ran out")
        self.assertLess(late_ms, MOTOR_TEST_KEEPALIVE_LATENESS_MS_MAX)

    def test_bad_requests_are_refused_and_change_nothing(self):
        rig = self.rig
        self.motor_test(2, 800)
        rig.wait_sim_speeds(alone(2, 800))
        for thruster, value in ((2, 2001), (2, -2001), (8, 500), (-1, 500)):
            with self.subTest(thruster=thruster, value=value):
                self.assertDBusError(ERR + "OutOfRange", self.motor_test, thruster, value)
                self.assertEqual(rig.sim_speeds(), alone(2, 800))
        r = rig.ctl("motor-test", "1", "--value", "5000", "--once")
        self.assertEqual(r.returncode, 1)
        self.assertIn(ERR + "OutOfRange", r.stderr)
        self.assertIn("commissioning.motor_test_limit", r.stderr)
        r = rig.ctl("motor-test", "1")
        self.assertEqual(r.returncode, 2)
        self.assertIn("--value", r.stderr)

    def test_refused_unless_armed(self):
        rig = self.rig
        rig.vcall("Kill")
        self.assertDBusError(ERR + "Killed", self.motor_test, 0, 500)
        # The state is decided first: a bad thruster on a killed vehicle is told it is killed.
        self.assertDBusError(ERR + "Killed", self.motor_test, 8, 500)
        rig.wait_orders_refreshed()
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
        rig.vcall("ClearKill")
        self.assertDBusError(ERR + "Arming", self.motor_test, 0, 500)
        rig.wait_state("ready")

    def test_kill_ends_it_at_once(self):
        rig = self.rig
        self.motor_test(4, 1000)
        rig.wait_sim_speeds(alone(4, 1000))
        rig.vcall("Kill")
        # Kill replies once the zeros are on the wire: no waiting for the keep-alive.
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
        self.assertEqual(tuple(int(v) for v in rig.vget("MotorTest")), (-1, 0))

    def test_a_second_test_replaces_the_first(self):
        rig = self.rig
        self.motor_test(1, 1000)
        rig.wait_sim_speeds(alone(1, 1000))
        self.motor_test(6, -900)
        rig.wait_sim_speeds(alone(6, -900))
        self.assertEqual(tuple(int(v) for v in rig.vget("MotorTest")), (6, -900))

    def test_a_pilots_command_ends_it_and_is_not_stopped_by_the_keepalive(self):
        rig = self.rig
        self.motor_test(1, 1000)
        rig.wait_sim_speeds(alone(1, 1000))
        rig.thrust([0, 0, 500, 0, 0, 0, 0, 0])
        self.assertEqual(tuple(int(v) for v in rig.vget("MotorTest")), (-1, 0))
        rig.wait_sim_speeds(alone(2, 500))
        time.sleep(0.8)  # past the test's keep-alive: the pilot's command stands
        self.assertEqual(rig.sim_speeds(), alone(2, 500))

    def test_the_caller_leaving_ends_it_at_once(self):
        rig = self.rig
        p = subprocess.Popen(command("caracaractl") + ["--bus-address", rig.address, "motor-test", "0",
                                                       "--value", "1000"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        rig.wait_sim_speeds(alone(0, 1000), timeout=5)
        p.send_signal(signal.SIGKILL)  # no chance to send anything on the way out
        p.communicate(timeout=10)
        left = time.monotonic()
        rig.wait_sim_zero(timeout=5)
        # Well inside the keep-alive: the daemon saw the client leave the bus, and zeroed within
        # the client-loss bound.
        zeroed_ms = (time.monotonic() - left) * 1000
        print("\nthe caller killed -> zeroed %.0f ms after it was gone" % zeroed_ms)
        self.assertLessEqual(zeroed_ms, CLIENT_LOSS_ZERO_MS_MAX)


if __name__ == "__main__":
    unittest.main()
