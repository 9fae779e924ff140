"""Safety under faults, judged from the simulator's wire and GPIO log: a thruster that hangs
its transfers does not hold up the kill output, D-Bus or the other thrusters, and a simulator
that goes away and comes back (the hardware vanishing and returning) is picked up without
restarting the daemon, with the vehicle killed until ClearKill."""
import statistics
import time
import unittest


from bounds import HUNG_KILL_OUTPUT_MS_MAX, HUNG_DEVICE_DBUS_MS_MAX
from figures import figure
from harness import (ERR, MOTORS, ZERO, Rig, error_name, poll, speed_byte)
from vehicle_checks import KILL_OUT, assert_quiet_while_gone

KILL_SWITCH = 17  # GpioModel::kKillSwitch
HUNG = 3          # the thruster that hangs


def pct(values, q):
    s = sorted(values)
    return s[min(len(s) - 1, int(q * len(s)))]


def bus_state(rig):
    return rig.vget("State", path="/org/caracara/Vehicle1/bus", iface="org.caracara.Vehicle1.Bus")


class HungThrusterTest(unittest.TestCase):
    """Thruster 3 holds every transfer for 1 s, and the adapter waits that long (the kernel's
    default timeout on a Raspberry Pi): the worst case for anything queued behind the bus."""

    @classmethod
    def setUpClass(cls):
        cls.rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000},
                      extra_config={"i2c": {"timeout_ms": 1000}})
        cls.rig.start()

    @classmethod
    def tearDownClass(cls):
        cls.rig.sim_thruster_call(HUNG, "SetHang", 0, signature="u")
        cls.rig.stop_checked()

    def drive_hung(self):
        rig = self.rig
        rig.sim_thruster_call(HUNG, "SetHang", 0, signature="u")
        # A transfer hung before that still times out; once one gets through, the thruster is
        # reachable, and an earlier test may have left the vehicle killed for it.
        poll(lambda: rig.vget("Online", path="/org/caracara/Vehicle1/thruster/%d" % HUNG,
                              iface="org.caracara.Vehicle1.Thruster"), 10)
        rig.reset()
        rig.thrust([1500] * MOTORS)
        rig.wait_sim_speeds([speed_byte(1500)] * MOTORS)
        since = rig.wire_next()
        rig.sim_thruster_call(HUNG, "SetHang", 1000, signature="u")
        # A transfer to it is on the wire now (or soon): wait until one has timed out.
        poll(lambda: any(e.result == "timeout" for e in rig.wire_log(since)[1]), 10,
             message="no transfer to the hung thruster timed out")

    def kill_output_edge(self, since):
        return poll(lambda: next((e for e in self.rig.wire_log(since)[1]
                                  if e.bus == "gpio" and e.addr == KILL_OUT and e.data == b"\x01"), None), 5,
                    message="no kill output edge")

    def zeros_since(self, since):
        return [e.index for e in self.rig.wire_log(since)[1]
                if e.bus == "i2c" and not e.read and len(e.data) == 3 and e.data[0] == ZERO]

    def assert_kill_output_first(self, since, edge, what):
        """The kill output is written before any bus transfer of the kill, and every thruster's
        zero follows (judged by wire-log order, not stamps: the simulator stamps I2C messages at
        their modelled end on the wire). The strongest test of this, for a Kill() call and for
        the kill switch: a transfer is hung on the wire when the kill comes."""
        poll(lambda: len(self.zeros_since(since)) >= MOTORS, 5)
        zeros = self.zeros_since(since)
        self.assertGreaterEqual(len(zeros), MOTORS, "%s: not every thruster got its zero" % what)
        self.assertLess(edge.index, zeros[0], "%s: the kill output came after a zero order" % what)

    def test_kill_call_reaches_the_kill_output_at_once(self):
        lat = []
        for _ in range(4):
            self.drive_hung()
            since = self.rig.wire_next()
            t0 = time.monotonic_ns()
            self.rig.vcall("Kill", timeout=10)
            edge = self.kill_output_edge(since)
            lat.append((edge.time_ns - t0) / 1e6)
            zeros = [e.index for e in self.rig.wire_log(since)[1]
                     if e.bus == "i2c" and not e.read and len(e.data) == 3 and e.data[0] == ZERO]
            self.assertTrue(zeros and edge.index < zeros[0], "the kill output came after a zero order")
            self.rig.sim_thruster_call(HUNG, "SetHang", 0, signature="u")
            self.assert_kill_output_first(since, edge, "Kill()")
            poll(lambda: error_name(self.rig.vcall, "ClearKill") is None, 10)
        for ms in lat:
            figure("hung_thruster.kill_output_ms", ms, "ms", "Kill() -> kill output with a thruster hanging 1 s")
        # On the event loop's thread the kill would wait for the transfer on the wire (up to 1 s).
        self.assertLess(max(lat), HUNG_KILL_OUTPUT_MS_MAX)

    def test_kill_switch_reaches_the_kill_output_at_once(self):
        lat = []
        for _ in range(4):
            self.drive_hung()
            since = self.rig.wire_next()
            self.rig.sim_call("SetKillSwitch", True, signature="b")
            try:
                edge = self.kill_output_edge(since)
                switch = next(e for e in self.rig.wire_log(since)[1] if e.bus == "gpio" and e.addr == KILL_SWITCH)
                lat.append((edge.time_ns - switch.time_ns) / 1e6)
                self.assertLess(switch.index, edge.index)
                poll(lambda: self.rig.state() == "killed", 5)
            finally:
                self.rig.sim_call("SetKillSwitch", False, signature="b")
            self.rig.sim_thruster_call(HUNG, "SetHang", 0, signature="u")
            self.assert_kill_output_first(since, edge, "kill switch")
            poll(lambda: error_name(self.rig.vcall, "ClearKill") is None, 10)
        for ms in lat:
            figure("hung_thruster.switch_kill_output_ms", ms, "ms",
                   "kill switch edge -> kill output with a thruster hanging 1 s")
        self.assertLess(max(lat), HUNG_KILL_OUTPUT_MS_MAX)

    def test_dbus_keeps_answering(self):
        self.drive_hung()
        vehicle = self.rig.obj("org.caracara.Vehicle1", "/org/caracara/Vehicle1")
        ping = vehicle.get_dbus_method("Ping", "org.freedesktop.DBus.Peer")
        get = vehicle.get_dbus_method("Get", "org.freedesktop.DBus.Properties")
        pings, gets = [], []
        end = time.monotonic() + 3  # three hung transfers
        while time.monotonic() < end:
            t0 = time.monotonic_ns()
            ping()
            pings.append((time.monotonic_ns() - t0) / 1e6)
            t0 = time.monotonic_ns()
            get("org.caracara.Vehicle1", "MotorValues")
            gets.append((time.monotonic_ns() - t0) / 1e6)
        figure("hung_thruster.ping_p99_ms", pct(pings, 0.99), "ms", "Ping p99 of %d, a thruster hanging 1 s" % len(pings))
        figure("hung_thruster.get_p99_ms", pct(gets, 0.99), "ms", "Get p99 of %d, a thruster hanging 1 s" % len(gets))
        figure("hung_thruster.dbus_max_ms", max(pings + gets), "ms", "slowest Ping or Get, a thruster hanging 1 s")
        self.assertLess(max(pings + gets), HUNG_DEVICE_DBUS_MS_MAX)
        # Three timeouts in a row (3 s here): the thruster is unreachable, and keeps its last order.
        poll(lambda: self.rig.state() == "killed", 5, message="the hung thruster did not kill")
        self.assertEqual(self.rig.vget("KillSource"), "device")


# A hung Teensy holds each SPI frame this long; the kill output and D-Bus must answer well
# inside it (bounds.py: HUNG_KILL_OUTPUT_MS_MAX, HUNG_DEVICE_DBUS_MS_MAX).
TEENSY_HANG_MS = 2000


class HungTeensyTest(unittest.TestCase):
    """The Teensy answers each SPI frame 2 s late (simulator fault SetHang): its frames are
    carried off the event loop, so a kill, a kill switch edge and D-Bus do not wait for one.
    Its silence is no failsafe here ([spi] silence_ms a minute): what a silent Teensy does is
    test_teensy_silence's."""

    @classmethod
    def setUpClass(cls):
        cls.rig = Rig(control={"arming_delay_ms": 0, "command_timeout_ms": 60000},
                      extra_config={"spi": {"silence_ms": 60000}})
        cls.rig.start()

    @classmethod
    def tearDownClass(cls):
        cls.rig.sim_teensy_call("SetHang", 0, signature="u")
        cls.rig.stop_checked()

    def hang(self):
        rig = self.rig
        rig.sim_teensy_call("SetHang", 0, signature="u")
        rig.reset()
        rig.thrust([1500] * MOTORS)
        rig.wait_sim_speeds([speed_byte(1500)] * MOTORS)
        frames = rig.sim_teensy("Frames")
        rig.sim_teensy_call("SetHang", TEENSY_HANG_MS, signature="u")
        # The next poll frame is held from now on: wait until one went in.
        poll(lambda: rig.sim_teensy("Frames") > frames, 5, message="the Teensy was not polled")
        time.sleep(0.1)

    def test_kill_and_switch_reach_the_kill_output_at_once(self):
        lat = []
        for source in ("dbus", "switch"):
            self.hang()
            since = self.rig.wire_next()
            t0 = time.monotonic_ns()
            if source == "dbus":
                self.rig.vcall("Kill", timeout=10)
            else:
                self.rig.sim_call("SetKillSwitch", True, signature="b")
            try:
                edge = poll(lambda: next((e for e in self.rig.wire_log(since)[1]
                                          if e.bus == "gpio" and e.addr == KILL_OUT and e.data == b"\x01"), None), 5,
                            message="no kill output edge")
                if source == "switch":
                    t0 = next(e for e in self.rig.wire_log(since)[1]
                              if e.bus == "gpio" and e.addr == KILL_SWITCH).time_ns
                lat.append((edge.time_ns - t0) / 1e6)
                # Every thruster holds zero, the Teensy notwithstanding.
                self.rig.wait_sim_speeds([speed_byte(0)] * MOTORS)
            finally:
                if source == "switch":
                    self.rig.sim_call("SetKillSwitch", False, signature="b")
        figure("hung_teensy.kill_output_ms", lat[0], "ms", "Kill() -> kill output, the Teensy holding each frame %d ms"
               % TEENSY_HANG_MS)
        figure("hung_teensy.switch_kill_output_ms", lat[1], "ms",
               "kill switch edge -> kill output, the Teensy holding each frame %d ms" % TEENSY_HANG_MS)
        self.assertLess(max(lat), HUNG_KILL_OUTPUT_MS_MAX)

    def test_dbus_keeps_answering(self):
        self.hang()
        vehicle = self.rig.obj("org.caracara.Vehicle1", "/org/caracara/Vehicle1")
        ping = vehicle.get_dbus_method("Ping", "org.freedesktop.DBus.Peer")
        calls = []
        end = time.monotonic() + 2.5  # more than one held frame
        while time.monotonic() < end:
            t0 = time.monotonic_ns()
            ping()
            calls.append((time.monotonic_ns() - t0) / 1e6)
            t0 = time.monotonic_ns()
            self.rig.thrust([1000] * MOTORS)
            calls.append((time.monotonic_ns() - t0) / 1e6)
        figure("hung_teensy.dbus_p50_ms", statistics.median(calls), "ms",
               "Ping/SetThrust p50 of %d, the Teensy holding each frame %d ms" % (len(calls), TEENSY_HANG_MS))
        figure("hung_teensy.dbus_max_ms", max(calls), "ms",
               "slowest Ping/SetThrust, the Teensy holding each frame %d ms" % TEENSY_HANG_MS)
        self.assertLess(max(calls), HUNG_DEVICE_DBUS_MS_MAX)
        # The loop kept cycling: the thrusters got the last command.
        self.rig.wait_sim_speeds([speed_byte(1000)] * MOTORS)


class HungThrusterDefaultTimeoutTest(unittest.TestCase):
    """With the default i2c.timeout_ms (20 ms) a hung thruster costs each cycle 20 ms: its
    transfers time out on the wire and the other thrusters keep being refreshed."""

    def test_others_keep_their_orders(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start()
        rig.arm()
        rig.thrust([1200] * MOTORS)
        rig.wait_sim_speeds([speed_byte(1200)] * MOTORS)
        rig.sim_thruster_call(HUNG, "SetHang", 1000, signature="u")
        time.sleep(0.3)
        since = rig.wire_next()
        time.sleep(2)
        log = rig.wire_log(since)[1]
        hung = [e for e in log if e.bus == "i2c" and e.addr == rig.sim_thruster(HUNG, "Address") >> 1 and
                e.result == "timeout"]
        t0 = [e for e in log if e.bus == "i2c" and not e.read and e.result == "ack" and
              e.addr == rig.sim_thruster(0, "Address") >> 1 and len(e.data) == 3]
        figure("hung_thruster_default_timeout.timeouts", len(hung), "count", "timed-out transfers in 2 s")
        figure("hung_thruster_default_timeout.refreshes", len(t0), "count", "thruster 0 refreshed in 2 s")
        self.assertGreater(len(hung), 10)
        self.assertGreaterEqual(len(t0), 40)  # a 50 Hz loop, less what the hung transfers take
        self.assertFalse(rig.vget("Online", path="/org/caracara/Vehicle1/thruster/%d" % HUNG,
                                  iface="org.caracara.Vehicle1.Thruster"))
        self.assertEqual(rig.state(), "killed")  # unreachable; the others' refreshes are zeros
        rig.sim_thruster_call(HUNG, "SetHang", 0, signature="u")


class UnreachableThrusterTest(unittest.TestCase):
    """A thruster the daemon cannot reach keeps its last order (a SeaBotix controller holds it
    for as long as it has power): three failed transfers in a row kill the vehicle, source
    "device", kill output first; ClearKill gets ThrusterUnreachable until it answers again, and
    its answering again does not arm the vehicle."""

    def check_unreachable(self, rig, inject, release, what):
        rig.arm()
        rig.thrust([1500] * MOTORS)
        rig.wait_sim_speeds([speed_byte(1500)] * MOTORS)
        since = rig.wire_next()
        mt = rig.sim_thruster(4, "Address")
        inject()
        try:
            poll(lambda: rig.state() == "killed", 10, message="%s: an unreachable thruster did not kill" % what)
            self.assertEqual(rig.vget("KillSource"), "device")
            self.assertEqual(error_name(rig.vcall, "ClearKill"), ERR + "ThrusterUnreachable")
            self.assertEqual(error_name(rig.thrust, [1000] * MOTORS), ERR + "Killed")
            log = rig.wire_log(since)[1]
            failed = [e for e in log if e.bus == "i2c" and e.addr == mt >> 1 and e.result != "ack"]
            edge = next(e for e in log if e.bus == "gpio" and e.addr == KILL_OUT and e.data == b"\x01")
            self.assertGreaterEqual(len(failed), 3)
            self.assertLess(failed[2].index, edge.index, "%s: killed before the third failure" % what)
            others = [i for i in range(MOTORS) if i != 4]
            poll(lambda: [rig.sim_speeds()[i] for i in others] == [ZERO] * len(others), 5,
                 message="%s: the reachable thrusters were not zeroed" % what)
            figure("unreachable_thruster.%s.kill_output_ms" % what.split()[0].lower(),
                   (edge.time_ns - failed[0].time_ns) / 1e6, "ms", "%s: first failed transfer to kill output" % what)
        finally:
            release()
        poll(lambda: rig.vget("Online", path="/org/caracara/Vehicle1/thruster/4",
                              iface="org.caracara.Vehicle1.Thruster"), 10, message="%s: never back" % what)
        self.assertEqual(rig.state(), "killed")
        poll(lambda: error_name(rig.vcall, "ClearKill") is None, 10)
        rig.wait_state("ready")
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)  # nothing sent before the kill comes back

    def test_nacking_and_hung_thruster(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(rig.stop_checked)
        rig.start()
        self.check_unreachable(rig, lambda: rig.sim_thruster_call(4, "SetNack", True, signature="b"),
                               lambda: rig.sim_thruster_call(4, "SetNack", False, signature="b"), "NACKing")
        self.check_unreachable(rig, lambda: rig.sim_thruster_call(4, "SetHang", 1000, signature="u"),
                               lambda: rig.sim_thruster_call(4, "SetHang", 0, signature="u"), "hung")


class VanishTest(unittest.TestCase):
    """A device node vanishes for 1.5 s and returns (the simulator's Vanish: hot unplug, its
    driver gone): killed, one log line, reopened once a second, killed until ClearKill."""

    def setUp(self):
        self.rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 60000})
        self.addCleanup(self.rig.stop_checked)
        self.rig.start()
        self.rig.arm()
        self.rig.thrust([600] * MOTORS)
        self.rig.wait_sim_speeds([speed_byte(600)] * MOTORS)

    def back_and_driving(self):
        rig = self.rig
        poll(lambda: error_name(rig.vcall, "ClearKill") is None, 10, message="ClearKill refused after the return")
        rig.wait_state("ready")
        rig.thrust([700] * MOTORS)
        rig.wait_sim_speeds([speed_byte(700)] * MOTORS)

    def test_adapter(self):
        rig = self.rig
        t0 = time.monotonic()
        rig.sim_call("Vanish", "i2c", 1500, signature="su")
        poll(lambda: rig.state() == "killed", 5, message="a vanished adapter did not kill")
        killed = time.monotonic() - t0
        self.assertEqual(rig.vget("KillSource"), "bus")
        self.assertEqual(error_name(rig.vcall, "ClearKill"), ERR + "BusLost")
        poll(lambda: bus_state(rig) == "ok", 10, interval=0.05, message="the adapter never came back")
        back = time.monotonic() - t0
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(rig.log().count("recovery is not configured"), 1)
        figure("vanish.adapter.killed_ms", killed * 1000, "ms", "I2C adapter gone for 1.5 s: killed after")
        figure("vanish.adapter.back_s", back, "s", "I2C adapter gone for 1.5 s: bus ok again after it went")
        self.back_and_driving()

    def test_teensy_spi(self):
        rig = self.rig
        t0 = time.monotonic()
        rig.sim_call("Vanish", "spi", 1500, signature="su")
        poll(lambda: rig.state() == "killed", 5, message="a vanished Teensy did not kill")
        killed = time.monotonic() - t0
        self.assertEqual(rig.vget("KillSource"), "failsafe")  # teensy-link-lost (test_failsafes)
        self.assertFalse(rig.vget("Online", path="/org/caracara/Vehicle1/teensy", iface="org.caracara.Vehicle1.Teensy"))
        self.assertEqual(error_name(rig.vcall, "ClearKill"), ERR + "FailsafeActive")
        poll(lambda: rig.vget("Online", path="/org/caracara/Vehicle1/teensy", iface="org.caracara.Vehicle1.Teensy"),
             10, interval=0.05, message="the Teensy never came back")
        back = time.monotonic() - t0
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(rig.log().count("Teensy SPI"), 2)  # went away; is back
        figure("vanish.teensy.killed_ms", killed * 1000, "ms", "Teensy SPI gone for 1.5 s: killed after")
        figure("vanish.teensy.back_s", back, "s", "Teensy SPI gone for 1.5 s: online again after it went")
        self.back_and_driving()


class SimulatorRestartTest(unittest.TestCase):
    """caracara-sim ends under a running daemon and is started again: the daemon stays quiet and
    killed while it is gone, then reopens the lines, the adapter and the Teensy by itself; the
    vehicle stays killed until ClearKill, then drives the new simulator's thrusters."""

    def test_restarted_simulator_is_picked_up(self):
        rig = Rig(control={"arming_delay_ms": 300, "command_timeout_ms": 500})
        self.addCleanup(rig.stop_checked)
        rig.start()
        rig.arm()
        rig.thrust([900] * MOTORS)
        rig.wait_sim_speeds([speed_byte(900)] * MOTORS)
        sim = rig.procs.pop("caracara-sim")
        sim.kill()
        sim.wait(10)
        pid = rig.procs["caracarad"].pid
        poll(lambda: rig.state() == "killed", 10, message="the vanished hardware did not kill")
        assert_quiet_while_gone(self, rig, pid)
        print("\nsimulator gone: KillSource %s, bus %s" % (rig.vget("KillSource"), bus_state(rig)))
        self.assertEqual(error_name(rig.vcall, "ClearKill")[:len(ERR)], ERR)

        t_back = time.monotonic()
        rig.start_sim()
        poll(lambda: bus_state(rig) == "ok", 15, interval=0.1, message="the bus never came back")
        back = time.monotonic() - t_back
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(rig.sim_speeds(), [ZERO] * MOTORS)  # nothing moves by itself
        poll(lambda: error_name(rig.vcall, "ClearKill") is None, 10, message="ClearKill refused after the return")
        rig.wait_state("ready")
        rig.thrust([700] * MOTORS)
        rig.wait_sim_speeds([speed_byte(700)] * MOTORS)
        poll(lambda: rig.sim_get("KillOutput") is not None and not rig.sim_get("KillOutput"), 5)
        figure("simulator_back.bus_ok_s", back, "s", "simulator back: bus ok after (killed until ClearKill)")


if __name__ == "__main__":
    unittest.main()
