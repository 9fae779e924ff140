"""The Teensy object: LEDs, servos, distance, wheels and Stop, Turn replied once the Teensy
acknowledged it, a kill ending a turn, orientation following yaw thrust.
"""

import time
import unittest

import dbus

import harness
from bounds import DEADLINE_SEEN_EARLY_MS_MAX
from harness import (ERR, TEENSY_IFACE, TEENSY_PATH, VEHICLE, VehicleTestCase, angle_diff, dbus_signature,
                     poll, pump_main_loop)

# caracara-sim's Teensy turns at this rate (TeensyConfig::turn_rate_rad_s, sim/teensy_config.hpp).
SIM_TURN_RATE_RAD_S = 1.0
# The turn the Turn test asks for.
TURN_RAD = 0.6


# --------------------------------------------------------------------------------------------
# The Teensy
# --------------------------------------------------------------------------------------------

class TeensyTest(VehicleTestCase):

    def setUp(self):
        self.rig.reset()
        # No turn left running on the simulated Teensy by an earlier test.
        poll(lambda: str(self.rig.sim_teensy("Task")) != "running", 15)

    def tcall(self, method, *args, signature=None, **kw):
        return self.rig.vcall(method, *args, signature=signature, path=TEENSY_PATH, iface=TEENSY_IFACE, **kw)

    def tget(self, name):
        return self.rig.vget(name, TEENSY_PATH, TEENSY_IFACE)

    def test_set_leds(self):
        for rgb in [(1, 2, 3), (255, 128, 0), (0, 0, 0)]:
            self.rig.vcall("SetLeds", *rgb, signature="yyy")
            # Acknowledged by the Teensy before the reply.
            self.assertEqual(tuple(self.rig.sim_teensy("Leds")), rgb)
            self.assertEqual(tuple(self.rig.vget("Leds")), rgb)

    def test_servo(self):
        self.tcall("SetServo", 1, 45, signature="yy")
        self.assertEqual(int(self.rig.sim_teensy("Servos")[1]), 45)
        self.assertEqual(int(self.tget("Servos")[1]), 45)
        self.tcall("SetServo", 3, 180, signature="yy")
        self.assertEqual(int(self.rig.sim_teensy("Servos")[3]), 180)
        self.assertEqual(int(self.tget("Servos")[3]), 180)

    def test_get_distance(self):
        for sensor, mm in [(0, 1234), (2, 5), (3, 65535)]:
            with self.subTest(sensor=sensor):
                self.rig.sim_teensy_call("SetDistance", dbus.Byte(sensor), dbus.UInt16(mm), signature="yq")
                got = self.tcall("GetDistance", sensor, signature="y")
                self.assertEqual(dbus_signature(got), "q")
                self.assertEqual(int(got), mm)
                self.assertEqual(int(self.tget("Distances")[sensor]), mm)

    def test_wheels_and_stop(self):
        self.tcall("SetSpeed", 50, -30, signature="ii")
        wheels = self.rig.sim_teensy("Wheels")
        self.assertEqual((float(wheels[0]), float(wheels[1])), (50.0, -30.0), "front left, front right")
        self.tcall("Stop", 42, signature="y")
        self.assertEqual(int(self.rig.sim_teensy("StopDuty")), 42)

    def test_turn_replies_when_the_teensy_acknowledged(self):
        rig = self.rig
        acks = int(rig.sim_teensy("Acknowledgements"))
        offset0 = float(rig.sim_teensy("HeadingOffset"))
        result = {}

        def done(*_):
            result["acks"] = int(rig.sim_teensy("Acknowledgements"))
            result["sim_task"] = str(rig.sim_teensy("Task"))
            result["t"] = time.monotonic()

        def failed(e):
            result["error"] = e
            result["t"] = time.monotonic()

        start = time.monotonic()
        rig.obj(VEHICLE, TEENSY_PATH).get_dbus_method("Turn", TEENSY_IFACE)(
            TURN_RAD, signature="d", reply_handler=done, error_handler=failed, timeout=60)
        served = []
        saw_turning = False
        leds_during = None
        while "t" not in result and time.monotonic() - start < 30:
            pump_main_loop(0.02)
            if "t" in result:
                break
            # Other calls are served while the turn runs.
            served.append(rig.state())
            if str(self.tget("Task")) == "turning" and "t" not in result:
                saw_turning = True
            if leds_during is None and saw_turning:
                rig.vcall("SetLeds", 9, 8, 7, signature="yyy")
                leds_during = tuple(rig.sim_teensy("Leds"))
        self.assertIn("t", result, "Turn never replied")
        self.assertNotIn("error", result, result.get("error"))
        self.assertTrue(saw_turning, "Task never showed turning")
        self.assertEqual(leds_during, (9, 8, 7), "SetLeds was not served during the turn")
        self.assertTrue(served and all(s == "ready" for s in served))
        # The reply came after the Teensy finished and got its acknowledgement.
        self.assertEqual(result["acks"], acks + 1)
        self.assertEqual(result["sim_task"], "idle")
        self.assertAlmostEqual(float(rig.sim_teensy("LastTurn")), TURN_RAD, places=5)
        # caracara-sim turns at turn_rate_rad_s (1 rad/s, sim/teensy_config.hpp): 0.6 rad take 0.6 s.
        took_ms = (result["t"] - start) * 1000
        self.assertGreaterEqual(took_ms, TURN_RAD / SIM_TURN_RATE_RAD_S * 1000 - DEADLINE_SEEN_EARLY_MS_MAX,
                                "0.6 rad at the simulated 1 rad/s took %.0f ms" % took_ms)
        self.assertAlmostEqual(angle_diff(float(rig.sim_teensy("HeadingOffset")), offset0), TURN_RAD, places=4)
        poll(lambda: str(self.tget("Task")) == "idle", 5)
        # The daemon's heading follows the simulated Teensy's (body yaw + the turn).
        poll(lambda: abs(angle_diff(float(self.tget("Orientation")[0]), rig.sim_yaw())) < 0.02, 10,
             message="the daemon's heading does not follow the turn")

    def test_kill_ends_a_running_turn(self):
        rig = self.rig
        result = {}
        rig.obj(VEHICLE, TEENSY_PATH).get_dbus_method("Turn", TEENSY_IFACE)(
            3.0, signature="d", reply_handler=lambda *a: result.setdefault("ok", True),
            error_handler=lambda e: result.setdefault("error", e.get_dbus_name()), timeout=60)
        poll(lambda: str(self.tget("Task")) == "turning", 10, pump=pump_main_loop)
        rig.vcall("Kill")
        poll(lambda: result, 10, pump=pump_main_loop, message="Turn never replied after the kill")
        self.assertEqual(result, {"error": ERR + "Killed"})
        self.assertEqual(str(self.tget("Task")), "idle")
        # The vehicle itself stops turning: the Teensy's turn task is ended, not left to run
        # its remaining ~3 rad after the kill.
        try:
            poll(lambda: str(rig.sim_teensy("Task")) != "running", 1.5)  # the whole turn takes 3 s
        except harness.Timeout:
            self.fail("the simulated Teensy is still turning after Kill (heading offset %.2f rad and rising)"
                      % float(rig.sim_teensy("HeadingOffset")))
        offset = float(rig.sim_teensy("HeadingOffset"))
        time.sleep(0.3)
        self.assertAlmostEqual(float(rig.sim_teensy("HeadingOffset")), offset, places=6)

    def test_turn_while_turning_is_busy(self):
        rig = self.rig
        result = {}
        rig.obj(VEHICLE, TEENSY_PATH).get_dbus_method("TurnTo", TEENSY_IFACE)(
            1.0, signature="d", reply_handler=lambda *a: result.setdefault("ok", time.monotonic()),
            error_handler=lambda e: result.setdefault("error", e), timeout=60)
        poll(lambda: str(self.tget("Task")) == "turning", 10, pump=pump_main_loop)
        self.assertDBusError(ERR + "Busy", self.tcall, "Turn", 0.1, signature="d")
        poll(lambda: result, 30, pump=pump_main_loop, message="TurnTo never replied")
        self.assertIn("ok", result, result.get("error"))
        self.assertAlmostEqual(float(rig.sim_teensy("LastTurnTo")), 1.0, places=5)
        poll(lambda: abs(angle_diff(float(rig.sim_yaw()), 1.0)) < 0.05, 5)

    def test_orientation_follows_yaw_thrust(self):
        rig = self.rig
        start_sim = rig.sim_yaw()
        yawed = [0.0]
        last = [start_sim]

        def turned():
            rig.motion(yaw=0.6)  # keep the stream alive
            now = rig.sim_yaw()
            yawed[0] += angle_diff(now, last[0])
            last[0] = now
            return yawed[0] > 0.5
        poll(turned, 30, interval=0.05, message="the vehicle did not yaw under yaw thrust")
        # Positive yaw is clockwise from above in both the axis table and the simulator.
        self.assertGreater(yawed[0], 0.5)
        # While turning, the daemon's Orientation tracks the simulated one.
        poll(lambda: abs(angle_diff(float(self.tget("Orientation")[0]), rig.sim_yaw())) < 0.25, 10)
        rig.motion()
        # Let it coast to a stop; then the daemon's reading matches the simulator closely.
        prev = [rig.sim_yaw()]

        def settled():
            time.sleep(0.5)
            now = rig.sim_yaw()
            still = abs(angle_diff(now, prev[0])) < 0.003
            prev[0] = now
            return still
        poll(settled, 20, interval=0.0)
        poll(lambda: abs(angle_diff(float(self.tget("Orientation")[0]), rig.sim_yaw())) < 0.01, 10,
             message="Orientation yaw does not follow the simulator")


if __name__ == "__main__":
    unittest.main()
