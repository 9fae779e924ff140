"""One safety line taken away on its own (the simulator's SetLinePresent, as a chip whose driver
went away is for every line), judged from the simulator's side where it can be: an unreadable
kill switch kills by itself (source "switch", not the bus), a switch that comes back set keeps
the vehicle killed, and a kill output that goes away kills (source "device") and is asked for
again and driven asserted once it is back."""
import time
import unittest

from harness import (ERR, MOTORS, ZERO, Rig, error_name, poll, speed_byte)

KILL_SWITCH = 17  # GpioModel::kKillSwitch
KILL_OUT = 27     # GpioModel::kKillOut


class GpioLineTest(unittest.TestCase):

    def setUp(self):
        self.rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(self.rig.stop_checked)
        self.rig.start()
        self.rig.arm()
        self.rig.thrust([900] * MOTORS)
        self.rig.wait_sim_speeds([speed_byte(900)] * MOTORS)

    def line(self, name, present):
        self.rig.sim_call("SetLinePresent", name, present, signature="sb")

    def line_events(self, since, offset):
        return [e for e in self.rig.wire_log(since)[1] if e.bus == "gpio" and e.addr == offset]

    def test_unreadable_switch_alone_kills_with_source_switch(self):
        rig = self.rig
        since = rig.wire_next()
        self.line("KILL_SWITCH", False)
        poll(lambda: rig.state() == "killed", 5, message="a kill switch that cannot be read did not kill")
        self.assertEqual(rig.vget("KillSource"), "switch")
        rig.wait_sim_zero()
        # The simulator saw the line go and nothing else of the GPIO chip change but the kill
        # output's assertion: the adapter, the bus and the other lines are all still there.
        events = [(e.addr, e.result, e.data) for e in rig.wire_log(since)[1] if e.bus == "gpio"]
        self.assertIn((KILL_SWITCH, "gone", b""), events)
        self.assertIn((KILL_OUT, "edge", b"\x01"), events)
        self.assertEqual(rig.vget("State", path="/org/caracara/Vehicle1/bus", iface="org.caracara.Vehicle1.Bus"), "ok")
        self.assertIn("kill switch", rig.log())
        # While it cannot be read it counts as set: no arming.
        time.sleep(1.5)  # past a reopen attempt
        self.assertEqual(error_name(rig.vcall, "ClearKill"), ERR + "KillSwitchSet")
        # Back, and released: its level decides, and the vehicle can be armed again.
        self.line("KILL_SWITCH", True)
        poll(lambda: error_name(rig.vcall, "ClearKill") is None, 5, message="ClearKill refused after the switch came back")
        rig.wait_state("ready")
        rig.thrust([700] * MOTORS)
        rig.wait_sim_speeds([speed_byte(700)] * MOTORS)

    def test_switch_back_set_keeps_the_vehicle_killed(self):
        rig = self.rig
        self.line("KILL_SWITCH", False)
        poll(lambda: rig.state() == "killed", 5, message="a kill switch that cannot be read did not kill")
        rig.sim_call("SetKillSwitch", True, signature="b")  # pressed while it was away
        self.line("KILL_SWITCH", True)
        time.sleep(2.5)  # the daemon asks for the line again once a second
        self.assertIn("is back", rig.log())
        for _ in range(3):
            self.assertEqual(error_name(rig.vcall, "ClearKill"), ERR + "KillSwitchSet")
            self.assertEqual(rig.state(), "killed")
            time.sleep(0.2)
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)
        rig.sim_call("SetKillSwitch", False, signature="b")
        poll(lambda: error_name(rig.vcall, "ClearKill") is None, 5, message="ClearKill refused with the switch released")
        rig.wait_state("ready")

    def test_vanished_kill_output_kills_with_source_device_and_is_reopened(self):
        rig = self.rig
        since = rig.wire_next()
        self.line("KILL_OUT", False)
        poll(lambda: rig.state() == "killed", 5, message="a vanished kill output did not kill")
        self.assertEqual(rig.vget("KillSource"), "device")
        rig.wait_sim_zero()
        self.assertFalse(rig.sim_get("KillOutput"))  # gone: nobody drives it
        # No arming without a kill output.
        self.assertEqual(error_name(rig.vcall, "ClearKill"), ERR + "Hardware")
        back = rig.wire_next()
        self.line("KILL_OUT", True)
        # The daemon asks for it again (once a second) and drives it asserted: seen on the wire.
        edge = poll(lambda: next((e for e in self.line_events(back, KILL_OUT)
                                  if e.result == "edge" and e.data == b"\x01"), None), 5,
                    message="the kill output was not driven asserted after it came back")
        self.assertTrue(rig.sim_get("KillOutput"))
        # Released (the vehicle was ready: the line was low), gone, back, driven asserted.
        kinds = [e.result for e in self.line_events(since, KILL_OUT)]
        self.assertEqual(kinds[:3], ["gone", "back", "edge"])
        self.assertEqual(self.line_events(back, KILL_OUT)[0].result, "back")  # and only then driven
        self.assertIn("kill output", rig.log())
        # Armed again, the kill output is released on the wire.
        poll(lambda: error_name(rig.vcall, "ClearKill") is None, 5, message="ClearKill refused after the output came back")
        rig.wait_state("ready")
        poll(lambda: not rig.sim_get("KillOutput"), 5, message="the kill output stayed asserted after arming")
        rig.thrust([700] * MOTORS)
        rig.wait_sim_speeds([speed_byte(700)] * MOTORS)


if __name__ == "__main__":
    unittest.main()
