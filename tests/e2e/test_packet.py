"""ApplyPacket, the seed's 13-word packet: motors and LEDs, the budget, a packet kill and its
all clear.
"""

import time
import unittest

from harness import (ERR, MOTORS, ZERO, VehicleTestCase, poll, speed_byte)
from vehicle_checks import assert_zeroed_before_reply, packet


class PacketTest(VehicleTestCase):

    def setUp(self):
        self.rig.reset()

    def test_motors_and_leds(self):
        motors = [700, -700, 1400, 0, 0, -2100, 0, 350]
        self.rig.packet(packet(motors, rgb=(10, 20, 30)))
        self.rig.wait_sim_speeds([speed_byte(v) for v in motors])
        self.assertEqual(self.rig.motor_values(), motors)
        poll(lambda: tuple(self.rig.sim_teensy("Leds")) == (10, 20, 30), 10, message="LEDs never reached the Teensy")
        self.assertEqual(tuple(self.rig.vget("Leds")), (10, 20, 30))
        self.assertEqual(self.rig.vget("Controller"), self.rig.conn.get_unique_name())

    def test_packet_budget(self):
        motors = [8850] * 8
        self.rig.packet(packet(motors))
        self.rig.wait_sim_speeds([speed_byte(4200)] * 8)
        self.assertTrue(self.rig.vget("Saturated"))

    def test_kill_and_all_clear(self):
        motors = [1000, 0, -1000, 0, 0, 0, 0, 0]
        self.rig.packet(packet(motors))
        self.rig.wait_sim_speeds([speed_byte(v) for v in motors])
        zeros_before = self.rig.sim_counters("ZeroOrders")
        wire_from = self.rig.wire_next()
        # Any non-zero killState kills (the seed's "non-zero: motors de-energized").
        self.rig.packet(packet(motors, kill=-5, rgb=(255, 0, 0)))
        replied_ns = time.monotonic_ns()
        self.assertEqual(self.rig.sim_speeds(), [ZERO] * MOTORS)
        assert_zeroed_before_reply(self, self.rig, wire_from, replied_ns)
        self.assertTrue(all(a > b for a, b in zip(self.rig.sim_counters("ZeroOrders"), zeros_before)))
        self.assertEqual(self.rig.state(), "killed")
        self.assertEqual(self.rig.vget("KillSource"), "packet")
        self.assertTrue(self.rig.sim_get("KillOutput"))
        poll(lambda: tuple(self.rig.sim_teensy("Leds")) == (255, 0, 0), 10)
        # Motors in a packet that still says kill do nothing.
        self.rig.packet(packet(motors, kill=1))
        self.rig.wait_orders_refreshed()
        self.assertEqual(self.rig.sim_speeds(), [ZERO] * MOTORS)
        # killState 0 is the all clear: arming (zero output), then ready. The motors of the
        # clearing packet are not applied.
        self.rig.packet(packet(motors, kill=0, rgb=(0, 255, 0)))
        self.assertEqual(self.rig.state(), "arming")
        self.assertEqual(self.rig.vget("KillSource"), "")
        self.assertEqual(self.rig.sim_speeds(), [ZERO] * MOTORS)
        self.rig.wait_state("ready")
        self.assertFalse(self.rig.sim_get("KillOutput"))
        self.rig.wait_orders_refreshed()
        self.assertEqual(self.rig.sim_speeds(), [ZERO] * MOTORS, "the kill resumed old motors by itself")
        # The next packet drives again.
        self.rig.packet(packet(motors))
        self.rig.wait_sim_speeds([speed_byte(v) for v in motors])

    def test_all_clear_does_not_clear_a_dbus_kill(self):
        self.rig.vcall("Kill")
        self.assertDBusError(ERR + "Killed", self.rig.packet, packet([1000] + [0] * 7))
        self.assertEqual(self.rig.state(), "killed")
        self.assertEqual(self.rig.vget("KillSource"), "dbus")
        self.assertEqual(self.rig.sim_speeds(), [ZERO] * MOTORS)


# --------------------------------------------------------------------------------------------
# Kill, ClearKill, the kill switch, PropertiesChanged
# --------------------------------------------------------------------------------------------


if __name__ == "__main__":
    unittest.main()
