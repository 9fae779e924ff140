"""A packet's kill is never lost, judged on the simulated wire: a non-zero killState kills even
when another field of the packet is refused, and a packet that kills and powers off does both,
the kill output first.
"""

import unittest

from harness import (ERR, MOTORS, ZERO, Rig, VehicleTestCase, error_name, poll, speed_byte)
from vehicle_checks import (KILL_OUT, POWER_OFF, packet)


def gpio_edges(rig, since, line):
    return [e for e in rig.wire_log(since)[1] if e.bus == "gpio" and e.addr == line]


class KillInABadPacketTest(VehicleTestCase):
    """A packet whose killState is non-zero kills even when another field is refused."""

    def setUp(self):
        self.rig.reset()

    def drive(self):
        values = [1200, -1200, 1200, -1200, 0, 0, 0, 0]
        self.rig.thrust(values)
        self.rig.wait_sim_speeds([speed_byte(v) for v in values])

    def test_kill_survives_every_bad_field(self):
        cases = [
            ("a motor at 9000", ERR + "OutOfRange", packet([9000] + [0] * 7, kill=1)),
            ("red 300", ERR + "OutOfRange", packet(kill=1, rgb=(300, 0, 0))),
            ("powerOffState 2", ERR + "InvalidValue", packet(kill=7, power_off=2)),
            ("9 words: killState and nothing after it", ERR + "InvalidLength", packet(kill=1)[:9]),
        ]
        for what, expected, words in cases:
            with self.subTest(what):
                self.rig.reset()
                self.drive()
                leds = tuple(self.rig.vget("Leds"))
                since = self.rig.wire_next()
                self.assertEqual(error_name(self.rig.packet, words), expected)
                # The kill happened; nothing else the packet said did.
                self.assertEqual(self.rig.state(), "killed")
                self.assertEqual(self.rig.vget("KillSource"), "packet")
                self.assertTrue(self.rig.sim_get("KillOutput"))
                self.assertEqual(self.rig.sim_speeds(), [ZERO] * MOTORS)
                self.assertEqual(tuple(self.rig.vget("Leds")), leds)
                self.assertNotEqual(self.rig.state(), "powered-off")
                zeros = [e for e in self.rig.wire_log(since)[1]
                         if e.bus == "i2c" and not e.read and len(e.data) == 3 and e.data[0] == ZERO]
                self.assertGreaterEqual(len({e.addr for e in zeros}), MOTORS, "not every thruster got its zero")

    def test_a_bad_packet_without_a_kill_changes_nothing(self):
        self.drive()
        self.assertEqual(error_name(self.rig.packet, packet([9000] + [0] * 7)), ERR + "OutOfRange")
        self.assertEqual(self.rig.state(), "ready")
        self.assertNotEqual(self.rig.sim_speeds(), [ZERO] * MOTORS)


class KillAndPowerOffPacketTest(unittest.TestCase):

    def test_kill_first_then_power_off(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start()
        rig.arm()
        rig.thrust([2000] * 4 + [0] * 4)
        rig.wait_sim_speeds([speed_byte(2000)] * 4 + [ZERO] * 4)
        since = rig.wire_next()
        rig.packet(packet(kill=1, power_off=1))
        self.assertEqual(rig.state(), "powered-off")
        # The line is set once the bus is idle, after the last zero order (the reply comes
        # first): under qemu-user (scripts/cross_test.sh) that is well after the reply.
        poll(lambda: rig.sim_get("PowerOffOutput"), 5, message="the power-off line was never set")
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
        log = rig.wire_log(since)[1]
        kill_edge = [e.index for e in log if e.bus == "gpio" and e.addr == KILL_OUT and e.data == b"\x01"]
        off_edge = [e.index for e in log if e.bus == "gpio" and e.addr == POWER_OFF and e.data == b"\x01"]
        self.assertTrue(kill_edge and off_edge, "edges: kill %s, power-off %s" % (kill_edge, off_edge))
        self.assertLess(kill_edge[0], off_edge[0], "the kill output came after the power-off line")


if __name__ == "__main__":
    unittest.main()
