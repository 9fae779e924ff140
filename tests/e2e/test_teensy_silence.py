"""A silent Teensy fails safe (issue 35 item 5), judged on the wire. A Teensy that answers no
valid frame for [spi] silence_ms (no answer at all, every frame held, garbage) while the
thrusters run is teensy-link-lost: the kill output's edge and a zero order to every thruster
in the simulator's wire log within silence_ms and TEENSY_SILENCE_LATENESS_MS_MAX, no non-zero
order after the edge, ClearKill refused (FailsafeActive) while it is silent and accepted once
it answers again. One silent from the start is killed the same way. A Teensy the
configuration says is fitted but absent at start keeps the vehicle killed (failsafe teensy-link-lost, LinkLoss "absent", a journal line naming it) until
it is there; one not fitted is no failsafe."""
import re
import time
import unittest

from bounds import TEENSY_SILENCE_EARLY_MS_MAX, TEENSY_SILENCE_LATENESS_MS_MAX
from figures import figure
from harness import ERR, MOTORS, TEENSY_IFACE, TEENSY_PATH, ZERO, Rig, error_name, poll, speed_byte
from test_failsafes import kill_edges, nonzero_after_kill, orders

SILENCE_MS = 200  # [spi] silence_ms's default at the 50 Hz loop
LINK_LOST = ("teensy-link-lost", "kill", -1)


def failsafes(rig):
    return [(str(c), str(a), int(t)) for c, a, t in rig.vget("Failsafes")]


def link_loss(rig):
    return str(rig.vget("LinkLoss", path=TEENSY_PATH, iface=TEENSY_IFACE))


class TeensySilenceTest(unittest.TestCase):
    """The thrusters run at 1500 when the Teensy falls silent; the configuration leaves
    silence_ms at its default."""

    @classmethod
    def setUpClass(cls):
        cls.rig = Rig(control={"arming_delay_ms": 0, "command_timeout_ms": 60000})
        cls.addClassCleanup(cls.rig.stop_checked)
        cls.rig.start()
        cls.rig.arm()

    def tearDown(self):
        self.rig.sim_teensy_call("ClearFaults")

    def silent_then_back(self, fall_silent, answer_again):
        rig = self.rig
        rig.reset()
        poll(lambda: link_loss(rig) == "none" and bool(rig.vget("Online", path=TEENSY_PATH, iface=TEENSY_IFACE)),
             10, message="the Teensy is not answering before the test")
        rig.thrust([1500] * MOTORS)
        rig.wait_sim_speeds([speed_byte(1500)] * MOTORS)
        since = rig.wire_next()
        silent_at = time.monotonic_ns()
        fall_silent()
        edge = poll(lambda: next(iter(kill_edges(rig.wire_log(since)[1])), None), 10,
                    message="a silent Teensy did not assert the kill output")
        rig.wait_sim_zero()
        log = rig.wire_log(since)[1]
        late_ms = (edge.time_ns - silent_at) / 1e6
        zeros = {}
        for e, i, s in orders(log):
            if e.index > edge.index and s == ZERO and i not in zeros:
                zeros[i] = (e.time_ns - silent_at) / 1e6
        figure("teensy_silence.kill_output_ms", late_ms, "ms",
               "%s: kill output after the Teensy fell silent (silence_ms %d)" % (self._testMethodName, SILENCE_MS))
        if zeros:
            figure("teensy_silence.last_zero_ms", max(zeros.values()), "ms",
                   "%s: last thruster zero after the Teensy fell silent" % self._testMethodName)
        # Not before the silence: the last valid frame was at most one poll (20 ms) before.
        self.assertGreaterEqual(late_ms, SILENCE_MS - TEENSY_SILENCE_EARLY_MS_MAX)
        self.assertLess(late_ms, SILENCE_MS + TEENSY_SILENCE_LATENESS_MS_MAX)
        self.assertEqual(sorted(zeros), list(range(MOTORS)), "not every thruster got a zero after the kill output")
        self.assertLess(max(zeros.values()), SILENCE_MS + TEENSY_SILENCE_LATENESS_MS_MAX)
        self.assertFalse(nonzero_after_kill(log, edge), "a non-zero order after the kill output")
        # Named everywhere: the state, the kill source, the failsafe, the Teensy's LinkLoss, the journal.
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(rig.vget("KillSource"), "failsafe")
        self.assertIn(LINK_LOST, failsafes(rig))
        self.assertEqual(link_loss(rig), "silent")
        self.assertFalse(rig.vget("Online", path=TEENSY_PATH, iface=TEENSY_IFACE))
        self.assertRegex(rig.log(), r"Teensy on SPI \S+ answered no valid frame for \d+ ms: failsafe teensy-link-lost")
        # Refused while it is silent, by the failsafe; fixed, so not overridable.
        time.sleep(0.3)
        self.assertEqual(error_name(rig.vcall, "ClearKill"), ERR + "FailsafeActive")
        self.assertEqual(error_name(rig.vcall, "ClearKillOverride", "teensy-link-lost", signature="s"),
                         ERR + "FailsafeActive")
        self.assertEqual(rig.state(), "killed")
        # Judged as every kill is (the one transfer on the wire at the kill excepted).
        self.assertFalse(nonzero_after_kill(rig.wire_log(edge.index)[1], edge),
                         "a non-zero order while the Teensy is silent")
        # It answers again: the failsafe clears, and a plain ClearKill re-arms.
        answer_again()
        poll(lambda: LINK_LOST not in failsafes(rig), 15, message="valid frames again did not clear the failsafe")
        self.assertEqual(link_loss(rig), "none")
        self.assertIn("Teensy answers again (it was silent): teensy-link-lost clears", rig.log())
        poll(lambda: error_name(rig.vcall, "ClearKill") is None, 10, message="ClearKill refused after the Teensy is back")
        rig.wait_state("ready")

    def test_no_answer_mid_dive_kills_and_clears_when_it_answers(self):
        self.silent_then_back(lambda: self.rig.sim_teensy_call("InjectFault", "no-answer", 1000000, signature="su"),
                              lambda: self.rig.sim_teensy_call("ClearFaults"))

    def test_a_hung_teensy_mid_dive_kills_and_clears_when_it_answers(self):
        # Each frame held 1.5 s (busy for ever, as the SPI controller sees it): longer than the
        # silence; the frame held when it ends still takes its time.
        self.silent_then_back(lambda: self.rig.sim_teensy_call("SetHang", 1500, signature="u"),
                              lambda: self.rig.sim_teensy_call("SetHang", 0, signature="u"))

    def test_garbage_answers_mid_dive_kill_and_clear_when_it_answers(self):
        self.silent_then_back(lambda: self.rig.sim_teensy_call("InjectFault", "garbage-ack", 1000000, signature="su"),
                              lambda: self.rig.sim_teensy_call("ClearFaults"))

    def test_busy_for_ever_mid_dive_kills(self):
        self.silent_then_back(lambda: self.rig.sim_teensy_call("InjectFault", "busy", 1000000, signature="su"),
                              lambda: self.rig.sim_teensy_call("ClearFaults"))


class TeensyAbsentAtStartTest(unittest.TestCase):
    """The Teensy's SPI node is not there when the daemon starts (simulator fault Vanish), with
    arm_at_start: the vehicle comes up killed by teensy-link-lost, never ready, until it is there."""

    ABSENT_MS = 4000

    @classmethod
    def setUpClass(cls):
        cls.rig = Rig(control={"arming_delay_ms": 0, "arm_at_start": True})
        cls.addClassCleanup(cls.rig.stop_checked)
        cls.rig.start(daemon=False)

    def test_fitted_but_absent_at_start_comes_up_killed_with_the_reason(self):
        rig = self.rig
        rig.sim_call("Vanish", "spi", self.ABSENT_MS, signature="su")
        since = rig.wire_next()
        rig.start_daemon()
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(rig.vget("KillSource"), "failsafe")
        self.assertIn(LINK_LOST, failsafes(rig))
        self.assertEqual(link_loss(rig), "absent")
        self.assertRegex(rig.log(), r"Teensy is fitted \(\[spi\] fitted\) but SPI \S+ is absent at start")
        self.assertIn("FAILSAFE teensy-link-lost kill", rig.log())
        log = rig.wire_log(since)[1]
        self.assertTrue(kill_edges(log) or rig.sim_get("KillOutput"), "the kill output is not asserted")
        self.assertFalse([s for _, _, s in orders(log) if s != ZERO], "a non-zero order with the Teensy absent")
        self.assertEqual(error_name(rig.vcall, "ClearKill"), ERR + "FailsafeActive")
        self.assertEqual(rig.state(), "killed")
        # There at last: its first valid frame clears the failsafe and ClearKill arms.
        poll(lambda: LINK_LOST not in failsafes(rig), self.ABSENT_MS / 1000 + 10,
             message="the Teensy there did not clear the failsafe")
        self.assertEqual(link_loss(rig), "none")
        poll(lambda: error_name(rig.vcall, "ClearKill") is None, 10, message="ClearKill refused with the Teensy there")
        rig.wait_state("ready")


class TeensySilentAtStartTest(unittest.TestCase):
    """The Teensy's node is there at start but nothing answers on it (simulator fault
    no-answer), with arm_at_start: killed by teensy-link-lost (LinkLoss "silent") within the
    silence, until it answers."""

    @classmethod
    def setUpClass(cls):
        cls.rig = Rig(control={"arming_delay_ms": 0, "arm_at_start": True})
        cls.addClassCleanup(cls.rig.stop_checked)
        cls.rig.start(daemon=False)

    def test_silent_at_start_is_killed_until_it_answers(self):
        rig = self.rig
        rig.sim_teensy_call("InjectFault", "no-answer", 1000000, signature="su")
        since = rig.wire_next()
        rig.start_daemon()
        rig.wait_state("killed", 10)
        self.assertEqual(rig.vget("KillSource"), "failsafe")
        self.assertIn(LINK_LOST, failsafes(rig))
        self.assertEqual(link_loss(rig), "silent")
        self.assertTrue(kill_edges(rig.wire_log(since)[1]) or rig.sim_get("KillOutput"), "the kill output is not asserted")
        self.assertEqual(error_name(rig.vcall, "ClearKill"), ERR + "FailsafeActive")
        rig.sim_teensy_call("ClearFaults")
        poll(lambda: LINK_LOST not in failsafes(rig), 10, message="the Teensy answering did not clear the failsafe")
        poll(lambda: error_name(rig.vcall, "ClearKill") is None, 10, message="ClearKill refused with the Teensy answering")
        rig.wait_state("ready")


class TeensyNotFittedTest(unittest.TestCase):
    """[spi] fitted = false: a Teensy absent at start is no failsafe."""

    @classmethod
    def setUpClass(cls):
        cls.rig = Rig(control={"arming_delay_ms": 0, "arm_at_start": True}, extra_config={"spi": {"fitted": False}})
        cls.addClassCleanup(cls.rig.stop_checked)
        cls.rig.start(daemon=False)

    def test_not_fitted_and_absent_is_no_failsafe(self):
        rig = self.rig
        rig.sim_call("Vanish", "spi", 3000, signature="su")
        rig.start_daemon()
        rig.wait_state("ready")
        time.sleep(0.5)  # longer than the silence
        self.assertEqual(rig.state(), "ready")
        self.assertEqual(failsafes(rig), [])
        self.assertEqual(link_loss(rig), "none")
        self.assertTrue(re.search(r"Teensy SPI \S+ unavailable .*continuing without it", rig.log()))


if __name__ == "__main__":
    unittest.main()
