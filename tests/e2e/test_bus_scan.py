"""Commissioning's bus scan (ScanBus, caracaractl scan) against a simulated vehicle whose
thrusters sit behind a PCA9544A: one moved to another channel, one missing, one of the other
controller variant and a stranger on a free channel ([[thruster]] tables in caracara-sim's own
file, which caracarad never reads). Judged on the simulator's wire log: the probes happen while
killed only, no non-zero order goes out, a refusal while armed puts nothing on the wire, a kill
ends a scan at once, and the mux is left where normal operation wants it.
"""

import os
import subprocess
import time
import unittest

from bounds import KILL_REPLY_MS_MAX
from harness import (DEFAULT_MT, ERR, MOTORS, SIM, ZERO, Rig, VehicleTestCase, command, error_name, poll,
                     toml_value)

MUX = 0x70
LEGACY_MT = 0x54  # the IDS's Aveox/legacy address, configured for no thruster here
# The configuration: thrusters 0-3 behind channel 0, 4-7 behind channel 1, at the default addresses.
CHANNEL = [0, 0, 0, 0, 1, 1, 1, 1]


def thruster_tables(layout):
    """[[thruster]] tables from [(mt, variant, channel)]."""
    out = []
    for mt, variant, channel in layout:
        out.append("[[thruster]]\naddress = %s\nvariant = %s\nmux_address = %s\nmux_channel = %d\n"
                   % (toml_value(mt), toml_value(variant), toml_value(MUX), channel))
    return "\n".join(out)


CONFIGURED = [(DEFAULT_MT[i], "seabotix", CHANNEL[i]) for i in range(MOTORS)]


class SimLayoutRig(Rig):
    """A rig whose caracara-sim has its own [[thruster]] tables (--config)."""

    def __init__(self, sim_layout, sim_args=(), **kwargs):
        super().__init__(**kwargs)
        self.sim_layout = sim_layout
        self.sim_args = list(sim_args)

    def start_sim(self):
        path = os.path.join(self.dir, "sim.toml")
        with open(path, "w") as f:
            f.write(thruster_tables(self.sim_layout))
        self._spawn("caracara-sim", command("caracara-sim") + ["--socket", self.sim_socket, "--bus-address",
                                                               self.address, "--config", path] + self.sim_args)
        poll(lambda: self.conn.name_has_owner(SIM) or self._died("caracara-sim"), self.START_TIMEOUT,
             message="caracara-sim did not take its name")
        self._check_alive("caracara-sim")


def orders(entries):
    return [e for e in entries if e.bus == "i2c" and not e.read and e.addr != MUX and len(e.data) == 3]


def with_channels(rig, since):
    """[(entry, mux channel then: -1 all off, None unknown)] of the wire log from `since`; the
    channel followed from the log's start (the mux keeps what was written before `since`)."""
    out = []
    channel = None
    for e in rig.wire_log(0)[1]:
        if e.bus == "i2c" and e.addr == MUX and not e.read and e.data and e.result == "ack":
            channel = e.data[0] & 0x03 if e.data[0] & 0x04 else -1
        if e.index >= since:
            out.append((e, channel))
    return out


def probes(walk):
    """The transfers only a scan makes: reads while every mux channel is off (the trunk), reads
    at an address no thruster is configured at, reads on a channel where the configuration puts
    no thruster at that address; and the control writes that switch every channel off."""
    routine = {(DEFAULT_MT[i] >> 1, CHANNEL[i]) for i in range(MOTORS)}
    out = []
    for e, channel in walk:
        if e.bus != "i2c":
            continue
        if e.addr == MUX and not e.read and e.data[:1] == bytes([0]):
            out.append(e)
        elif e.read and e.addr != MUX and channel is not None and (e.addr, channel) not in routine:
            out.append(e)
    return out


class ScanCase(VehicleTestCase):
    SIM_LAYOUT = CONFIGURED
    SIM_ARGS = ()
    WAIT_READY = False
    EXTRA_TOML = thruster_tables(CONFIGURED)

    @classmethod
    def setUpClass(cls):
        cls.rig = SimLayoutRig(cls.SIM_LAYOUT, cls.SIM_ARGS, control=cls.CONTROL, extra_toml=cls.EXTRA_TOML)
        cls.addClassCleanup(cls.rig.stop_checked)
        cls.rig.start()
        cls.rig.wait_state("killed")

    def setUp(self):
        if self.rig.state() != "killed":
            self.rig.vcall("Kill")
        self.rig.wait_state("killed")

    def scan(self):
        """ScanBus: ([(mux, channel, mt, variant, revision, thruster)], [(verdict, advice)])."""
        devices, thrusters = self.rig.vcall("ScanBus", timeout=120)
        devices = [(int(d[0]), int(d[1]), int(d[2]), str(d[3]), int(d[4]), int(d[5])) for d in devices]
        thrusters = [(str(t[0]), str(t[1])) for t in thrusters]
        print("\n" + "\n".join("device %s" % (d,) for d in devices)
              + "\n" + "\n".join("thruster %d %s %s" % (i, v, a) for i, (v, a) in enumerate(thrusters)))
        return devices, thrusters

    def assert_scan_on_wire(self, walk):
        """Every probe address on the trunk and on every channel; zeros only; the kill output held."""
        entries = [e for e, _ in walk]
        self.assertEqual(set(o.data[0] for o in orders(entries)) - {ZERO}, set(),
                         "a non-zero order went out during the scan")
        self.assertEqual([e for e in entries if e.bus == "gpio"], [], "a safety line changed during the scan")
        seen = {(channel, e.addr) for e, channel in walk if e.bus == "i2c" and e.read}
        wanted = {(ch, mt >> 1) for ch in (-1, 0, 1, 2, 3) for mt in set(DEFAULT_MT) | {0x52, LEGACY_MT}}
        self.assertEqual(wanted - seen, set(), "addresses the scan did not probe (channel, addr7)")


class MatchingBusTest(ScanCase):
    """The simulator is what the configuration says."""

    def test_scan_while_killed_finds_every_thruster_where_configured(self):
        rig = self.rig
        since = rig.wire_next()
        t0 = time.monotonic()
        devices, thrusters = self.scan()
        print("a scan of %d probes took %.0f ms" % (len(set(DEFAULT_MT) | {LEGACY_MT}) * 5, (time.monotonic() - t0) * 1e3))
        walk = with_channels(rig, since)
        self.assertEqual(rig.state(), "killed")
        self.assertEqual(thrusters, [("ok", "")] * MOTORS)
        self.assertEqual(sorted((d[0], d[1], d[2], d[3], d[5]) for d in devices),
                         sorted((MUX, CHANNEL[i], DEFAULT_MT[i], "seabotix", i) for i in range(MOTORS)))
        self.assert_scan_on_wire(walk)
        # Afterwards the orders reach every thruster again, each through its own channel (the sim
        # NACKs an address whose channel is not selected).
        after = rig.wire_next()
        rig.wait_orders_refreshed(count=3)
        later = orders(rig.wire_log(after)[1])
        self.assertTrue(later)
        self.assertEqual({o.result for o in later}, {"ack"}, "an order went to a channel the scan left selected")

    def test_caracaractl_scan_prints_the_table_and_exits_0(self):
        p = self.rig.ctl("scan")
        print(p.stdout)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn("the bus matches the configuration", p.stdout)
        self.assertEqual(p.stdout.count(" ok "), MOTORS)

    def test_refused_while_armed_and_nothing_on_the_wire(self):
        rig = self.rig
        rig.rearm()
        since = rig.wire_next()
        self.assertEqual(error_name(rig.vcall, "ScanBus"), ERR + "NotKilled")
        p = rig.ctl("scan")
        self.assertEqual(p.returncode, 1)
        self.assertIn("NotKilled", p.stderr)
        rig.wait_orders_refreshed(count=2)
        self.assertEqual(probes(with_channels(rig, since)), [], "a refused scan probed")
        self.assertEqual(rig.state(), "ready")

class KillDuringScanTest(ScanCase):
    """The wire really waited, at 10 kHz: a scan lasts long enough to be killed in the middle."""
    SIM_ARGS = ("--realistic-timing", "--clock-hz", "10000")

    def start_scan(self, since):
        """caracaractl scan, running; returned once its probes are on the wire."""
        scan = subprocess.Popen(command("caracaractl") + ["--bus-address", self.rig.address, "scan"],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        poll(lambda: probes(with_channels(self.rig, since)), 10, interval=0.001, message="the scan never started probing")
        return scan

    def test_a_clear_kill_during_a_scan_ends_it(self):
        rig = self.rig
        since = rig.wire_next()
        scan = self.start_scan(since)
        rig.vcall("ClearKill")
        t_reply = time.monotonic_ns()
        out, err = scan.communicate(timeout=30)
        self.assertEqual(scan.returncode, 1, "the scan went on after ClearKill: %s" % out)
        self.assertIn("NotKilled", err)
        # At most the one probe already handed to the bus follows the ClearKill (its mux write and
        # its read, logged with the time its end is due); then none.
        late = [e for e in probes(with_channels(rig, since)) if e.read and e.time_ns > t_reply]
        self.assertLessEqual(len(late), 1, "probes after ClearKill: %s" % late)
        rig.wait_state("ready")

    def test_a_second_scan_while_one_runs_is_busy_and_a_kill_ends_it(self):
        rig = self.rig
        since = rig.wire_next()
        scan = self.start_scan(since)  # killed once it has started probing
        busy = error_name(rig.vcall, "ScanBus")
        t_kill = time.monotonic_ns()
        rig.vcall("Kill")
        t_reply = time.monotonic_ns()
        out, err = scan.communicate(timeout=30)
        late_ms = (t_reply - t_kill) / 1e6
        print("\nKill() during a scan: replied (its zeros on the wire) after %.2f ms" % late_ms)
        self.assertLess(late_ms, KILL_REPLY_MS_MAX)
        self.assertEqual(scan.returncode, 1, "the scan was not ended by the kill: %s" % out)
        self.assertIn("Killed", err)
        self.assertEqual(busy, ERR + "Busy")
        walk = with_channels(rig, since)
        entries = [e for e, _ in walk]
        # The kill's zeros went out; after them, no probe (at most the one on the wire at the kill).
        zeros_after = [e for e in orders(entries) if e.time_ns >= t_kill]
        self.assertTrue(zeros_after)
        self.assertEqual({e.data[0] for e in zeros_after}, {ZERO})
        late_probes = [e for e in probes(walk) if e.read and e.time_ns > t_reply]
        self.assertLessEqual(len(late_probes), 1, "probes after the kill's reply: %s" % late_probes)
        # A new scan runs to its end.
        self.assertEqual(self.scan()[1], [("ok", "")] * MOTORS)


class MismatchedBusTest(ScanCase):
    """Thruster 3 missing, thruster 5 moved from channel 1 to channel 2, thruster 6 a legacy
    controller, a legacy controller nobody configured on channel 3."""
    SIM_LAYOUT = ([CONFIGURED[i] for i in (0, 1, 2, 4)] + [(DEFAULT_MT[5], "seabotix", 2), (DEFAULT_MT[6], "legacy", 1),
                                                           CONFIGURED[7], (LEGACY_MT, "legacy", 3)])

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        # The thrusters that do not answer as configured raise the thruster-unreachable failsafe,
        # whose kill (the vehicle is killed already: its zeros) would end a scan begun before it.
        poll(lambda: any(str(f[0]) == "thruster-unreachable" for f in cls.rig.vget("Failsafes")), 20,
             message="the thruster-unreachable failsafe never fired")

    def test_scan_reports_missing_moved_wrong_variant_and_unexpected(self):
        rig = self.rig
        since = rig.wire_next()
        devices, thrusters = self.scan()
        walk = with_channels(rig, since)
        verdicts = [v for v, _ in thrusters]
        self.assertEqual(verdicts, ["ok", "ok", "ok", "missing", "ok", "moved", "wrong-variant", "ok"])
        by_thruster = {d[5]: d for d in devices}
        self.assertEqual(by_thruster[5][:4], (MUX, 2, DEFAULT_MT[5], "seabotix"))
        self.assertEqual(by_thruster[6][:4], (MUX, 1, DEFAULT_MT[6], "legacy"))
        self.assertEqual(by_thruster[-1][:4], (MUX, 3, LEGACY_MT, "legacy"))
        self.assertIn("channel 2", thrusters[5][1])
        self.assertIn("legacy", thrusters[6][1])
        self.assertIn("cable", thrusters[3][1])
        self.assert_scan_on_wire(walk)

    def test_caracaractl_scan_exits_1_and_says_what_to_do(self):
        p = self.rig.ctl("scan")
        print(p.stdout)
        self.assertEqual(p.returncode, 1, p.stderr)
        self.assertIn("does NOT match", p.stdout)
        for word in ("missing", "moved", "wrong-variant", "unexpected device on 0x70/3 at 0x54"):
            self.assertIn(word, p.stdout)


if __name__ == "__main__":
    unittest.main()
