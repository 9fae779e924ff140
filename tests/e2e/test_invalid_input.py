"""Invalid input: a named error (or InvalidArgs for a malformed call) and no change on the
hardware, for every method and random calls.
"""

import random
import unittest

import dbus

from harness import (ERR, INVALID_ARGS, ROOT, TEENSY_IFACE, TEENSY_PATH, VEHICLE, VehicleTestCase,
                     error_name, poll, speed_byte)
from vehicle_checks import packet


# Invalid input: a named error and no change on the hardware
# --------------------------------------------------------------------------------------------

NAN = float("nan")
INF = float("inf")


class InvalidInputTest(VehicleTestCase):

    values = [1000, -2000, 3000, 0, 0, 0, 0, -500]

    def setUp(self):
        # A known, non-zero output that every refused call must leave alone.
        self.rig.thrust(self.values)
        self.rig.wait_sim_speeds([speed_byte(v) for v in self.values])

    def vehicle_view(self):
        """What a refused call must leave alone: the thrusters' orders on the simulated wire, the
        requested values, the LEDs on the simulated Teensy."""
        rig = self.rig
        return rig.sim_snapshot(), list(rig.vget("RequestedValues")), tuple(rig.sim_teensy("Leds"))

    def check_unchanged(self, before):
        rig = self.rig
        rig.wait_orders_refreshed()
        snapshot, requested, leds = self.vehicle_view()
        self.assertEqual(snapshot, before[0], "the simulated thrusters changed")
        self.assertEqual(requested, before[1])
        self.assertEqual(leds, before[2])
        self.assertEqual(rig.state(), "ready")
        self.assertEqual(rig.vget("Controller"), rig.conn.get_unique_name())

    def check_refused(self, expected_error, fn, *args, **kwargs):
        before = self.vehicle_view()
        self.assertEqual(error_name(fn, *args, **kwargs), expected_error)
        self.check_unchanged(before)

    def test_set_thrust(self):
        rig = self.rig
        cases = [
            ("7 values", ERR + "InvalidLength", [100] * 7),
            ("9 values", ERR + "InvalidLength", [100] * 9),
            ("no values", ERR + "InvalidLength", []),
            ("8851", ERR + "OutOfRange", [0, 0, 0, 8851, 0, 0, 0, 0]),
            ("-8851", ERR + "OutOfRange", [0, 0, 0, 0, 0, 0, 0, -8851]),
            ("int32 min", ERR + "OutOfRange", [-2 ** 31] + [0] * 7),
        ]
        for label, err, values in cases:
            with self.subTest(label):
                self.check_refused(err, rig.thrust, values)

    def test_set_motion(self):
        rig = self.rig
        for label, err, kwargs in [
            ("NaN", ERR + "InvalidValue", {"x": NAN}),
            ("inf", ERR + "InvalidValue", {"yaw": INF}),
            ("-inf", ERR + "InvalidValue", {"roll": -INF}),
            ("1.5", ERR + "OutOfRange", {"y": 1.5}),
            ("-1.0001", ERR + "OutOfRange", {"pitch": -1.0001}),
            ("NaN with valid others", ERR + "InvalidValue", {"x": 0.1, "z": NAN}),
        ]:
            with self.subTest(label):
                self.check_refused(err, rig.motion, **kwargs)

    def test_apply_packet(self):
        rig = self.rig
        good = packet([100] * 8)
        for label, err, words in [
            ("12 values", ERR + "InvalidLength", good[:12]),
            ("14 values", ERR + "InvalidLength", good + [0]),
            ("powerOff 2", ERR + "InvalidValue", packet([100] * 8, power_off=2)),
            ("powerOff -1", ERR + "InvalidValue", packet([100] * 8, power_off=-1)),
            ("red 256", ERR + "OutOfRange", packet([100] * 8, rgb=(256, 0, 0))),
            ("blue -1", ERR + "OutOfRange", packet([100] * 8, rgb=(0, 0, -1))),
            ("motor 8851", ERR + "OutOfRange", packet([0, 0, 0, 0, 0, 8851, 0, 0])),
        ]:
            with self.subTest(label):
                self.check_refused(err, rig.packet, words)

    def test_wrong_signature(self):
        rig = self.rig
        for label, method, args, sig in [
            ("SetThrust s", "SetThrust", ("hello",), "s"),
            ("SetThrust ad", "SetThrust", (dbus.Array([1.0] * 8, signature="d"),), "ad"),
            ("SetMotion 5 doubles", "SetMotion", (0.0,) * 5, "ddddd"),
            ("SetMotion ints", "SetMotion", (0,) * 6, "iiiiii"),
            ("ApplyPacket au", "ApplyPacket", (dbus.Array([0] * 13, signature="u"),), "au"),
            ("PowerOff i", "PowerOff", (1,), "i"),
            ("SetLeds iii", "SetLeds", (1, 2, 3), "iii"),
        ]:
            with self.subTest(label):
                self.check_refused(INVALID_ARGS, rig.vcall, method, *args, signature=sig)
        with self.subTest("busctl SetThrust s"):
            before = rig.sim_snapshot()
            r = rig.busctl("call", VEHICLE, ROOT, VEHICLE, "SetThrust", "s", "hello")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("Invalid arguments", r.stderr)
            rig.wait_orders_refreshed()
            self.assertEqual(rig.sim_snapshot(), before)
            self.assertEqual(rig.state(), "ready")

    def test_power_off_confirmation(self):
        self.check_refused(ERR + "ConfirmationRequired", self.rig.vcall, "PowerOff", "please", signature="s")
        self.assertFalse(self.rig.sim_get("PowerOffOutput"))

    def test_teensy_arguments(self):
        rig = self.rig
        for label, err, method, args, sig in [
            ("servo id 4", ERR + "OutOfRange", "SetServo", (4, 90), "yy"),
            ("servo 181 degrees", ERR + "OutOfRange", "SetServo", (0, 181), "yy"),
            ("distance sensor 9", ERR + "OutOfRange", "GetDistance", (9,), "y"),
            ("wheel speed 128", ERR + "OutOfRange", "SetSpeed", (128, 0), "ii"),
            ("wheel speed -129", ERR + "OutOfRange", "SetSpeed", (0, -129), "ii"),
            ("turn NaN", ERR + "InvalidValue", "Turn", (NAN,), "d"),
            ("turn-to inf", ERR + "InvalidValue", "TurnTo", (INF,), "d"),
            ("turn with a string", INVALID_ARGS, "Turn", ("left",), "s"),
        ]:
            with self.subTest(label):
                servos = list(rig.sim_teensy("Servos"))
                self.check_refused(err, rig.vcall, method, *args, signature=sig, path=TEENSY_PATH,
                                   iface=TEENSY_IFACE)
                self.assertEqual(list(rig.sim_teensy("Servos")), servos)
                self.assertEqual(rig.sim_teensy("Task"), "idle")


    def test_random_calls(self):
        """In the manner of a fuzzer: calls with random argument vectors (lengths, values at and
        past every limit, NaN and infinities, arguments of other types). Each is accepted or
        refused with a named error, and a refused one changes nothing (check_unchanged)."""
        rig = self.rig
        rng = random.Random(20261121)
        # Each value is valid but for a one-in-ten chance of one at or past a limit, so that
        # calls are accepted about as often as they are refused.
        def value(good, bad):
            return rng.choice(bad) if rng.random() < 0.1 else rng.choice(good)

        def motor():
            return value([0, 1, -1, 100, -2500, 8850, -8850], [8851, -8851, 2 ** 31 - 1, -2 ** 31])

        def thrust():
            n = 8 if rng.random() < 0.85 else rng.choice([0, 1, 7, 9, 13])
            return "SetThrust", (dbus.Array([motor() for _ in range(n)], signature="i"),), "ai"

        def motion():
            axis = [value([0.0, -0.0, 0.25, -1.0, 1.0, 5e-324], [1.0000001, -1.5, NAN, INF, -INF, 1e308])
                    for _ in range(6)]
            return "SetMotion", tuple(axis), "dddddd"

        def apply_packet():
            # killState stays 0 and powerOffState is never 1: a kill or a power-off is a valid
            # call whose effect is the point, not a refusal (KillTest and PowerOffTest).
            words = [motor() for _ in range(8)] + [0, value([0], [2, -1, 7])]
            words += [value([0, 40, 255], [256, -1]) for _ in range(3)]
            n = 13 if rng.random() < 0.9 else rng.choice([12, 14])
            return "ApplyPacket", (dbus.Array((words + [0])[:n], signature="i"),), "ai"

        def other_types():
            method = rng.choice(["SetThrust", "SetMotion", "ApplyPacket", "SetLeds", "PowerOff"])
            sig, args = rng.choice([("s", ("x",)), ("ad", (dbus.Array([0.5] * 8, signature="d"),)),
                                    ("au", (dbus.Array([1] * 13, signature="u"),)), ("iii", (1, 2, 3)),
                                    ("ddddd", (0.0,) * 5), ("", ()), ("ay", (dbus.ByteArray(b"\x01" * 8),))])
            return method, args, sig

        outcomes = {}
        for i in range(150):
            method, args, sig = rng.choice([thrust, motion, apply_packet, other_types])()
            with self.subTest(i=i, method=method, signature=sig, args=repr(args)[:200]):
                before = self.vehicle_view()
                err = error_name(rig.vcall, method, *args, signature=sig)
                outcomes[err] = outcomes.get(err, 0) + 1
                if err is None:
                    # Accepted: let its orders (and a packet's LEDs) reach the vehicle, so that
                    # the next refusal is compared with a settled vehicle.
                    rig.wait_orders_refreshed()
                    if method == "ApplyPacket":
                        poll(lambda: tuple(rig.sim_teensy("Leds")) == tuple(args[0][10:13]), 10)
                    self.assertEqual(rig.state(), "ready")
                    continue
                self.assertTrue(err.startswith(ERR) or err == INVALID_ARGS, "unnamed error %s" % err)
                self.check_unchanged(before)
        # Both outcomes and several kinds of refusal were reached.
        self.assertGreater(outcomes.get(None, 0), 10, outcomes)
        self.assertGreaterEqual(len([e for e in outcomes if e]), 4, outcomes)


if __name__ == "__main__":
    unittest.main()
