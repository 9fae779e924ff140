"""A lost I2C bus keeps the vehicle killed: commands are refused with BusLost until the bus is
back, and a lockup that outlasts the command timeout kills.
"""

import threading
import time
import unittest

import dbus

import harness
from bounds import BUS_LOCKUP_KILL_LATENESS_MS_MAX
from figures import figure
from harness import (ERR, MOTORS, VehicleTestCase, error_name, poll, speed_byte)
from vehicle_checks import (packet)


RECOVERY_GPIO = dict(harness.SIM_GPIO, scl={"chip": "gpiochip0", "line": "GPIO3"},
                     sda={"chip": "gpiochip0", "line": "GPIO2"})


def bus_state(rig):
    return rig.vget("State", harness.BUS_PATH, harness.BUS_IFACE)


class LostBusStaysKilledTest(VehicleTestCase):
    """A bus that cannot be reached keeps the vehicle killed: nothing is accepted as if it could
    drive, ClearKill waits for the bus, and the bus coming back does not arm it."""
    GPIO = False
    CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 60000}
    EXTRA_CONFIG = {"gpio": harness.SIM_GPIO}  # recovery not configured

    def test_commands_refused_with_bus_lost_until_it_is_back(self):
        rig = self.rig
        rig.reset()
        rig.thrust([1200] * MOTORS)
        rig.wait_sim_speeds([speed_byte(1200)] * MOTORS)
        rig.sim_call("HoldScl")
        try:
            poll(lambda: rig.state() == "killed", 10, message="a lost bus did not kill")
            self.assertEqual(rig.vget("KillSource"), "bus")
            self.assertEqual(bus_state(rig), "lost")
            self.assertTrue(rig.sim_get("KillOutput"))
            for what, call in (
                    ("ClearKill", lambda: rig.vcall("ClearKill")),
                    ("SetThrust", lambda: rig.thrust([100] * MOTORS)),
                    ("SetMotion", lambda: rig.motion(y=0.2)),
                    ("ApplyPacket", lambda: rig.packet(packet([100] * 8))),
                    ("SetSpeed", lambda: rig.vcall("SetSpeed", 10, 10, signature="ii", path=harness.TEENSY_PATH,
                                                   iface=harness.TEENSY_IFACE)),
                    ("Turn", lambda: rig.vcall("Turn", 0.5, signature="d", path=harness.TEENSY_PATH,
                                               iface=harness.TEENSY_IFACE))):
                with self.subTest(what):
                    self.assertEqual(error_name(call), ERR + "BusLost")
            self.assertEqual(rig.state(), "killed")
        finally:
            rig.sim_call("ReleaseBus")
        # The transfers get through again: the bus is back, the vehicle stays killed.
        poll(lambda: bus_state(rig) == "ok", 10, message="the bus never came back")
        rig.wait_sim_zero()
        time.sleep(0.3)
        self.assertEqual(rig.state(), "killed")
        rig.vcall("ClearKill")
        rig.wait_state("ready")


class LongLockupKillsTest(VehicleTestCase):
    """A lockup that outlasts the command timeout is a lost bus, even while recovery attempts
    remain: the thrusters are unreachable for longer than any command may stand."""
    GPIO = False
    CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 500}
    EXTRA_CONFIG = {"gpio": RECOVERY_GPIO,
                    "recovery": {"enabled": True, "attempts": 10, "backoff_ms": 200, "driver_id": "fe804000.i2c"}}

    def test_lockup_longer_than_the_command_timeout_kills(self):
        rig = self.rig
        rig.reset()
        stream = True

        def keep_commanding():
            while stream:
                try:
                    rig.thrust([900] * MOTORS)
                except dbus.DBusException:
                    pass
                time.sleep(0.1)
        rig.thrust([900] * MOTORS)
        rig.wait_sim_speeds([speed_byte(900)] * MOTORS)
        t = threading.Thread(target=keep_commanding)
        t.start()
        try:
            t0 = time.monotonic()
            rig.sim_call("HoldScl")
            poll(lambda: rig.state() == "killed", 10, message="a long lockup did not kill")
            took_ms = (time.monotonic() - t0) * 1000
            timeout_ms = self.CONTROL["command_timeout_ms"]
            figure("bus_lockup.kill_ms", took_ms, "ms", "lockup to kill (command timeout %d ms)" % timeout_ms)
            self.assertEqual(rig.vget("KillSource"), "bus")
            self.assertEqual(bus_state(rig), "lost")
            # The recovery's timer starts at the first failed transfer, after the hold began.
            self.assertGreaterEqual(took_ms, timeout_ms)
            self.assertLessEqual(took_ms, timeout_ms + BUS_LOCKUP_KILL_LATENESS_MS_MAX)
        finally:
            stream = False
            t.join()
            rig.sim_call("ReleaseBus")
        poll(lambda: bus_state(rig) == "ok", 30, interval=0.1, message="the bus never came back")
        self.assertEqual(rig.state(), "killed")


if __name__ == "__main__":
    unittest.main()
