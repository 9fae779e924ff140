"""PowerOff (irreversible: a fresh daemon per test): the confirmation, the zeros before the reply,
the packet's power-off.
"""

import time
import unittest

from harness import (ERR, MOTORS, TEENSY_IFACE, TEENSY_PATH, ZERO, Rig, error_name, speed_byte)
from vehicle_checks import assert_zeroed_before_reply, packet


# --------------------------------------------------------------------------------------------
# Power-off (irreversible: a fresh daemon per test)
# --------------------------------------------------------------------------------------------

class PowerOffTest(unittest.TestCase):

    def setUp(self):
        self.rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(self.rig.stop_checked)
        self.rig.start()
        self.rig.arm()
        self.values = [1500, -1500, 0, 0, 3000, 0, 0, 0]
        self.rig.thrust(self.values)
        self.rig.wait_sim_speeds([speed_byte(v) for v in self.values])

    def assertDBusError(self, expected, fn, *args, **kwargs):
        self.assertEqual(error_name(fn, *args, **kwargs), expected)

    def check_powered_off(self):
        rig = self.rig
        self.assertEqual(rig.state(), "powered-off")
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS, "thrusters not zeroed by the power-off")
        self.assertTrue(rig.sim_get("PowerOffOutput"))
        before = rig.sim_snapshot()
        self.assertDBusError(ERR + "PoweredOff", rig.thrust, self.values)
        self.assertDBusError(ERR + "PoweredOff", rig.motion, y=0.2)
        self.assertDBusError(ERR + "PoweredOff", rig.packet, packet(self.values))
        self.assertDBusError(ERR + "PoweredOff", rig.vcall, "ClearKill")
        self.assertDBusError(ERR + "PoweredOff", rig.vcall, "PowerOff", "power-off", signature="s")
        self.assertDBusError(ERR + "PoweredOff", rig.vcall, "SetLeds", 1, 2, 3, signature="yyy")
        self.assertDBusError(ERR + "PoweredOff", rig.vcall, "SetServo", 0, 10, signature="yy",
                             path=TEENSY_PATH, iface=TEENSY_IFACE)
        self.assertDBusError(ERR + "PoweredOff", rig.vcall, "SetSpeed", 10, 10, signature="ii",
                             path=TEENSY_PATH, iface=TEENSY_IFACE)
        time.sleep(0.2)
        self.assertEqual([s for s, _ in rig.sim_snapshot()], [s for s, _ in before])
        self.assertEqual(rig.state(), "powered-off")

    def test_power_off_needs_confirmation(self):
        rig = self.rig
        for wrong in ("", "yes", "poweroff", "POWER-OFF", "power-off "):
            with self.subTest(confirmation=wrong):
                before = rig.sim_snapshot()
                self.assertDBusError(ERR + "ConfirmationRequired", rig.vcall, "PowerOff", wrong, signature="s")
                self.assertEqual(rig.state(), "ready")
                self.assertFalse(rig.sim_get("PowerOffOutput"))
                rig.wait_orders_refreshed()
                self.assertEqual(rig.sim_snapshot(), before)
        wire_from = rig.wire_next()
        rig.vcall("PowerOff", "power-off", signature="s")
        assert_zeroed_before_reply(self, rig, wire_from, time.monotonic_ns())
        self.check_powered_off()

    def test_packet_power_off(self):
        self.assertDBusError(ERR + "InvalidValue", self.rig.packet, packet(self.values, power_off=2))
        self.assertEqual(self.rig.state(), "ready")
        self.rig.packet(packet(power_off=1))
        self.check_powered_off()


# --------------------------------------------------------------------------------------------
# Command timeout, client loss, SIGTERM
# --------------------------------------------------------------------------------------------


if __name__ == "__main__":
    unittest.main()
