"""The pilot-lost failsafe, judged on the simulator's wire log. A pilot is a bus client that
commanded motion since the vehicle was armed. When a pilot leaves, its thrust goes at once (its
zero orders); when no pilot remains, the vehicle is killed after pilot-lost's persistence time
(kill output, KillSource "failsafe", the Failsafe signal, the Failsafes property, the journal).
Another pilot still connected, or a new one commanding within the persistence, keeps it armed;
a client that only reads, kills or clears the kill is no pilot; after the kill a plain ClearKill
re-arms (the condition ended with the kill)."""
import time
import unittest

import dbus

import harness
from bounds import CLIENT_LOSS_ZERO_MS_MAX, FAILSAFE_LATENESS_MS_MAX
from figures import figure
from harness import MOTORS, ROOT, VEHICLE, ZERO, Rig, poll, pump_main_loop, speed_byte
from test_failsafes import Announced, FailsafeSignals, assert_deadline_kept, kill_edges, nonzero_after_kill, orders

PERSISTENCE_MS = 1000
CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 60000}
PILOT_LOST = ("pilot-lost", "kill", -1)


class FailsafesSeen:
    """Every value of the Failsafes property announced in PropertiesChanged."""

    def __init__(self, rig):
        self.values = []

        def changed(iface, props, _invalidated):
            if iface == VEHICLE and "Failsafes" in props:
                self.values.append([(str(c), str(a), int(t)) for c, a, t in props["Failsafes"]])
        self.match = rig.conn.add_signal_receiver(changed, signal_name="PropertiesChanged",
                                                  dbus_interface="org.freedesktop.DBus.Properties", path=ROOT)

    def close(self):
        self.match.remove()


class PilotCase(unittest.TestCase):
    """The test's own connection only reads, kills and clears: it is no pilot."""
    CONTROL = CONTROL

    @classmethod
    def setUpClass(cls):
        cls.rig = Rig(control=cls.CONTROL,
                      extra_config={"failsafe": {"pilot-lost": {"action": "kill", "persistence_ms": PERSISTENCE_MS}}})
        cls.addClassCleanup(cls.rig.stop_checked)
        cls.rig.start()

    def setUp(self):
        self.rig.rearm()
        self.signals = FailsafeSignals(self.rig)
        self.addCleanup(self.signals.close)
        self.seen = FailsafesSeen(self.rig)
        self.addCleanup(self.seen.close)
        self.kill_at = Announced(self.rig, "PilotLostKillAt")
        self.addCleanup(self.kill_at.close)
        self.clients = []
        self.addCleanup(self.leave_all)

    def pilot(self, values):
        """A client process that commands `values` and stays connected; returns it."""
        proc, _ = harness.start_client(self.rig, values)
        self.clients.append(proc)
        return proc

    def leave(self, proc):
        """The client leaves the bus; the CLOCK_MONOTONIC time just before, in ns. PilotLostKillAt's
        announcements are looked at from then on."""
        pump_main_loop()
        self.kill_at.values = []
        t = time.monotonic_ns()
        proc.stdin.close()
        proc.wait(10)
        proc.stdout.close()
        proc.stderr.close()
        self.clients.remove(proc)
        return t

    def leave_all(self):
        for p in list(self.clients):
            self.leave(p)

    def assert_no_kill_for(self, seconds, since, speeds):
        """Ready and driving `speeds` for `seconds`, no kill output edge, no Failsafe signal."""
        time.sleep(seconds)
        pump_main_loop()
        self.rig.wait_orders_refreshed()
        self.assertEqual(self.rig.state(), "ready")
        self.assertEqual(self.rig.sim_speeds(), speeds)
        self.assertEqual(kill_edges(self.rig.wire_log(since)[1]), [])
        self.assertNotIn(PILOT_LOST, self.signals.got)

    def assert_killed_after_persistence(self, since, left_at):
        """The pilot-lost kill: its kill output edge no sooner than the persistence after the
        last pilot left, and within a reading period or so of it; zeros only from then on."""
        rig = self.rig
        self.signals.wait(PILOT_LOST)
        rig.wait_state("killed")
        self.assertEqual(rig.vget("KillSource"), "failsafe")
        edge = poll(lambda: kill_edges(rig.wire_log(since)[1]), 5, message="no kill output edge")[0]
        after_ms = (edge.time_ns - left_at) / 1e6
        figure("pilot_lost.kill_after_ms", after_ms, "ms",
               "last pilot left -> kill output edge (persistence %d ms)" % PERSISTENCE_MS)
        self.assertGreaterEqual(after_ms, PERSISTENCE_MS, "killed before the persistence time")
        self.assertLessEqual(after_ms, PERSISTENCE_MS + FAILSAFE_LATENESS_MS_MAX)
        log = rig.wire_log(since)[1]
        self.assertFalse(nonzero_after_kill(log, edge),
                         "a non-zero order after the kill output")
        poll(lambda: any(PILOT_LOST in v for v in self.seen.values), 5, pump=pump_main_loop,
             message="Failsafes never named pilot-lost (saw %r)" % self.seen.values)
        self.assertIn("FAILSAFE pilot-lost kill: the condition held for %d ms" % PERSISTENCE_MS, rig.log())
        # The countdown PilotLostKillAt announced: the persistence from the leaving, and kept.
        at_ns = assert_deadline_kept(self, self.kill_at, edge, "PilotLostKillAt")
        self.assertGreaterEqual(at_ns - left_at, PERSISTENCE_MS * 1e6)
        self.assertLessEqual(at_ns - left_at, (PERSISTENCE_MS + FAILSAFE_LATENESS_MS_MAX) * 1e6)
        self.assertEqual(int(rig.vget("PilotLostKillAt")), 0)
        return edge

    def assert_zeroed_at_once(self, since, left_at, thrusters):
        """Each of `thrusters` got its zero order within the client-loss bound, and no kill
        output edge came before the zeros."""
        rig = self.rig

        def zeros():
            first = {}
            for e, i, s in orders(rig.wire_log(since)[1]):
                if i in thrusters and s == ZERO and e.time_ns > left_at:
                    first.setdefault(i, e)
            return first if len(first) == len(thrusters) else None
        first = poll(zeros, 5, message="the pilot's thrust did not go")
        worst = max(e for e in first.values())
        ms = (worst.time_ns - left_at) / 1e6
        figure("pilot_left.last_zero_ms", ms, "ms", "pilot left -> its last zero order")
        self.assertLessEqual(ms, CLIENT_LOSS_ZERO_MS_MAX)
        edges = kill_edges(rig.wire_log(since)[1])
        self.assertTrue(not edges or edges[0].index > worst.index, "the kill output came before the zeros")


class PilotLostTest(PilotCase):

    def test_the_last_pilot_leaving_zeroes_at_once_then_kills_after_the_persistence(self):
        rig = self.rig
        values = [1500] * MOTORS
        proc = self.pilot(values)
        rig.wait_sim_speeds([speed_byte(v) for v in values])
        since = rig.wire_next()
        left_at = self.leave(proc)
        self.assert_zeroed_at_once(since, left_at, range(MOTORS))
        self.assertEqual(rig.state(), "ready")  # zeros first; the kill waits for the persistence
        self.assert_killed_after_persistence(since, left_at)
        self.assertIn("the last pilot (", rig.log())
        # The condition ended with the kill: a plain ClearKill, from a client that is no pilot,
        # re-arms, and its leaving is nothing.
        r = rig.ctl("clear-kill")
        self.assertEqual(r.returncode, 0, r.stderr)
        rig.wait_state("ready")
        since = rig.wire_next()
        poll(lambda: self.rig.vget("Failsafes") == [], 5, message="pilot-lost still listed")
        self.signals.got.clear()
        self.assert_no_kill_for(PERSISTENCE_MS / 1000 + 0.5, since, [ZERO] * MOTORS)

    def test_a_second_pilot_still_connected_keeps_the_vehicle_armed(self):
        rig = self.rig
        first = self.pilot([1000] * MOTORS)
        rig.wait_sim_speeds([speed_byte(1000)] * MOTORS)
        second = self.pilot([1200] * MOTORS)  # a second tab: it commands now
        rig.wait_sim_speeds([speed_byte(1200)] * MOTORS)
        since = rig.wire_next()
        left_at = self.leave(second)
        self.assert_zeroed_at_once(since, left_at, range(MOTORS))  # the commanding one's thrust goes
        self.assert_no_kill_for(PERSISTENCE_MS / 1000 + 0.5, since, [ZERO] * MOTORS)
        # The other was a pilot all along: its leaving is the last.
        since = rig.wire_next()
        left_at = self.leave(first)
        self.assert_killed_after_persistence(since, left_at)

    def test_a_new_pilot_within_the_persistence_keeps_the_vehicle_armed(self):
        rig = self.rig
        gone = self.pilot([1500] * MOTORS)
        rig.wait_sim_speeds([speed_byte(1500)] * MOTORS)
        since = rig.wire_next()
        self.leave(gone)
        rig.wait_sim_zero()
        time.sleep(PERSISTENCE_MS / 2000)
        back = self.pilot([800] * MOTORS)  # a reloaded page, half way through
        rig.wait_sim_speeds([speed_byte(800)] * MOTORS)
        # The countdown ran, and the daemon said it ended.
        poll(lambda: self.kill_at.values and self.kill_at.values[-1] == 0, 5, pump=pump_main_loop,
             message="PilotLostKillAt's end never announced (saw %r)" % self.kill_at.values)
        self.assertEqual(len({int(v) for v in self.kill_at.values if v}), 1, self.kill_at.values)
        self.assertEqual(int(rig.vget("PilotLostKillAt")), 0)
        self.assert_no_kill_for(PERSISTENCE_MS / 1000, since, [speed_byte(800)] * MOTORS)
        # Its own leaving counts from then, not from the first pilot's.
        since = rig.wire_next()
        left_at = self.leave(back)
        self.assert_killed_after_persistence(since, left_at)

    def test_a_client_that_only_reads_kills_or_clears_is_no_pilot(self):
        rig = self.rig
        # Killed and cleared by caracaractl, read by caracaractl and busctl: none of them pilots,
        # so their leaving is not a pilot lost.
        for args in (("kill",), ("clear-kill",), ("status",)):
            r = rig.ctl(*args)
            self.assertEqual(r.returncode, 0, "%s: %s" % (args, r.stderr))
        rig.wait_state("ready")
        r = rig.busctl("get-property", VEHICLE, ROOT, VEHICLE, "State")
        self.assertEqual(r.returncode, 0, r.stderr)
        since = rig.wire_next()
        self.assert_no_kill_for(PERSISTENCE_MS / 1000 + 0.5, since, [ZERO] * MOTORS)
        self.assertEqual([v for v in self.kill_at.values if v], [], "a pilot-lost countdown with no pilot lost")
        self.assertEqual(int(rig.vget("PilotLostPersistenceMs")), PERSISTENCE_MS)
        # With a pilot driving, a reader that comes and goes changes nothing either.
        values = [1100] * MOTORS
        proc = self.pilot(values)
        rig.wait_sim_speeds([speed_byte(v) for v in values])
        since = rig.wire_next()
        r = rig.ctl("status")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assert_no_kill_for(PERSISTENCE_MS / 1000 + 0.5, since, [speed_byte(v) for v in values])
        self.assertIn(proc, self.clients)


class SilentPilotTest(PilotCase):
    """The command timeout (300 ms here) zeroes a pilot that went silent and kills nothing: it
    is still connected, and still a pilot; its leaving afterwards is the last pilot lost."""
    CONTROL = dict(CONTROL, command_timeout_ms=300)

    def test_a_silent_pilot_is_zeroed_not_killed_and_still_counts(self):
        rig = self.rig
        since = rig.wire_next()
        proc = self.pilot([1500] * MOTORS)  # one command, then silence
        poll(lambda: any(s == speed_byte(1500) for _, _, s in orders(rig.wire_log(since)[1])), 5,
             message="the pilot's command never reached the wire")
        rig.wait_sim_zero()  # the command timeout
        self.assert_no_kill_for(PERSISTENCE_MS / 1000 + 0.5, since, [ZERO] * MOTORS)
        since = rig.wire_next()
        left_at = self.leave(proc)
        self.assert_killed_after_persistence(since, left_at)


if __name__ == "__main__":
    unittest.main()
