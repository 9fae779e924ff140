"""Fault soak: caracarad against caracara-sim under a steady 50 Hz SetThrust stream with client
churn, while faults are injected at random through the simulator; at the end the books are
checked from the simulator's wire log (the vehicle's side), the daemon's fds and RSS.

    soak.py [--seconds S] [--transactions N] [--seed K] [--loop-rate HZ]

Stops after S seconds or once the daemon's bus has carried N transactions, whichever is first.
Exit status 0 when every check holds. Needs what the e2e tests need (tests/e2e/harness.py).

The books:
  * lost commands: an accepted SetThrust whose orders did not all reach the wire before the
    next command (+ a grace of two loop periods), unless a fault, a kill or a bus outage
    overlapped it. Target 0.
  * killed orders: a non-zero order to a thruster after the kill output's asserting edge and
    after that thruster's zero order, before the output was released. Target 0. (A non-zero
    order already on its way when the kill came is counted apart, as in flight.)
  * timed-out orders: a non-zero order later than the command timeout (+ a grace) after the
    stream paused, before it resumed. Target 0.
  * the daemon's pid unchanged, its fds and RSS flat (start vs end).
"""
import argparse
import bisect
import json
import os
import random
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "e2e"))
import dbus  # noqa: E402

import harness  # noqa: E402
from harness import MOTORS, SIM, SIM_GPIO, SIM_ROOT, Rig, command, poll, speed_byte  # noqa: E402

KILL_OUT = 27
TIMEOUT_MS = 300
PERIOD = 0.02
GRACE = 0.06
GPIO = dict(SIM_GPIO, scl={"chip": "gpiochip0", "line": "GPIO3"}, sda={"chip": "gpiochip0", "line": "GPIO2"})
# What the soak holds the daemon to at the end of a run, besides the books (no lost command, no
# non-zero order after a kill's zero, none in flight at a kill that reached the wire after it,
# none past the command timeout): its fds do not grow at all, its RSS by at most this much
# (the allocator's arenas settling; a leak of one small allocation per transaction would pass
# it within the first hundred thousand transactions).
FD_GROWTH_MAX = 0
RSS_GROWTH_KIB_MAX = 2048
RECOVERY = {"enabled": True, "driver_id": "fe804000.i2c", "attempts": 3, "backoff_ms": 50}
# The wire log is read in pages of this many entries (GetWireLogPage), one page per turn of the
# main loop, so that the 50 Hz command stream never waits long behind a read: at loop rate 0
# the bus carries tens of thousands of messages a second, and one unbounded read of them all
# took seconds, grew with each turn and at last exceeded the bus's message limit.
PAGE = 2000
VEHICLE = "org.caracara.Vehicle1"
PATH = "/org/caracara/Vehicle1"


# The soak's books are the bus's: every accepted command on the wire. Its fault bits are noise
# for the bus to carry (a latched ground fault would otherwise exclude its thruster for good);
# the failsafes' own actions are e2e_failsafes' to judge.
FAILSAFE_WARN = {c: {"action": "warn"} for c in ("water-detect", "ground-fault", "overtemp", "stall", "hall")}


class SoakRig(Rig):
    """The simulator with a wire log large enough for the soak's drains to keep up."""

    def start_sim(self):
        conf = os.path.join(self.dir, "sim.toml")
        with open(conf, "w") as f:
            f.write("[sim]\nwire_log_entries = 2000000\n")
        self._spawn("caracara-sim", command("caracara-sim") + ["--socket", self.sim_socket,
                                                               "--bus-address", self.address, "--config", conf])
        poll(lambda: self.conn.name_has_owner(SIM) or self._died("caracara-sim"), self.START_TIMEOUT,
             message="caracara-sim did not take its name")
        self._check_alive("caracara-sim")


def rss_kib(pid):
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return 0


def fds(pid):
    return len(os.listdir("/proc/%d/fd" % pid))


class Soak:
    def __init__(self, args):
        self.args = args
        self.rng = random.Random(args.seed)
        self.rig = SoakRig(control={"arming_delay_ms": 100, "command_timeout_ms": TIMEOUT_MS, "loop_rate_hz": args.loop_rate},
                       gpio=False, extra_config={"gpio": GPIO, "recovery": RECOVERY, "failsafe": FAILSAFE_WARN})
        self.commands = []   # (t_sent, speeds) of accepted SetThrust calls
        self.excused = []    # (t0, t1, thruster or None): faults during which orders may not arrive
        self.pauses = []     # (t_pause, t_resume)
        self.wire = []       # (time_ns, index, kind, addr, data0, result) of orders and kill output edges
        self.since = 0
        self.caught_up = True  # the last page read reached the log's end
        self.read_to_ns = 0    # the wire time of the last entry read
        self.entries_read = 0
        self.max_lag = 0.0     # the longest the reader fell behind the wire (s)
        self.faults = {}
        self.sim_restarts = 0
        self.wire_gaps = 0
        self.calls = 0
        self.refused = 0
        self.refused_by = {}   # error name (last part) -> refused SetThrust calls
        self.churn = 0
        self.kill_level = None
        self.killed = False    # between an asserting and a releasing kill output edge
        self.zeroed = set()
        self.first_after_kill = False

    # --- the vehicle's side -------------------------------------------------------------------
    def read_page(self):
        """Reads the next page of the wire log into the books; True once it reached the log's end."""
        nxt, entries = self.rig.conn.call_blocking(SIM, SIM_ROOT, SIM, "GetWireLogPage", "tu",
                                                   (dbus.UInt64(self.since), dbus.UInt32(PAGE)), byte_arrays=True)
        if entries and self.since and int(entries[0][0]) > self.since:
            # The ring dropped entries before this drain read them: what happened then is unknown,
            # so no command of that stretch is judged (counted, and excused).
            self.wire_gaps += 1
            self.excused.append((self.read_to_ns / 1e9, int(entries[0][1]) / 1e9, None))
        for idx, t, _txn, bus, addr, read, data, _miso, result in entries:
            if bus == "i2c":
                self.judge_killed(int(t), int(idx), int(addr), int(data[0]) if not read and len(data) == 3 else -1)
            elif bus == "gpio" and addr == KILL_OUT and len(data) == 1:
                self.wire.append((int(t), int(idx), "kill", 0, data[0], "edge"))
                self.killed = data[0] == self.kill_level
                self.zeroed, self.first_after_kill = set(), self.killed
        self.caught_up = len(entries) < PAGE
        if entries:
            self.read_to_ns = max(self.read_to_ns, int(entries[-1][1]))
            if not self.caught_up:  # a full page: the reader is behind by at least this
                self.max_lag = max(self.max_lag, time.monotonic() - self.read_to_ns / 1e9)
        self.entries_read += len(entries)
        self.since = max(self.since, int(nxt))
        return self.caught_up

    def drain_wire(self):
        """Reads the log up to its end as it is now (the wire goes on meanwhile)."""
        end = int(self.rig.conn.call_blocking(SIM, SIM_ROOT, SIM, "GetWireLogPage", "tu",
                                              (dbus.UInt64(2 ** 63), dbus.UInt32(1)))[0])
        while self.since < end and not self.read_page():
            pass

    def judge_killed(self, t, idx, addr, speed):
        """One I2C message, in the order of the log. Between a kill output's asserting edge and
        its release: the simulator logs a transfer when it ends and serves the kill output's GPIO
        write while an I2C transfer is on the wire (as the kernel does), so the first I2C transfer
        logged after the kill edge is the one that was on the wire then, which nothing can take
        back (the zeros follow it). Any later non-zero order before that thruster's zero reached
        the wire after the kill: in_flight_at_kill, a failure."""
        if speed >= 0:
            self.wire.append((t, idx, "order", addr, speed, "ack"))
        if not self.killed:
            return
        on_the_wire_at_kill, self.first_after_kill = self.first_after_kill, False
        if speed < 0:
            return
        b = self.books
        if speed == 0x80:
            self.zeroed.add(addr)
        elif addr in self.zeroed:
            b["killed_orders"] += 1
        elif on_the_wire_at_kill:
            b["on_wire_at_kill"] += 1
        else:
            b["in_flight_at_kill"] += 1

    # --- faults -------------------------------------------------------------------------------
    def inject(self, now):
        rig, rng = self.rig, self.rng
        kind = rng.choice(["nack", "corrupt", "fault-bit", "hang-sda", "hold-scl", "teensy-busy", "teensy-garbage",
                           "hang", "kill-switch", "sim-restart" if rng.random() < 0.15 else "nack"])
        self.faults[kind] = self.faults.get(kind, 0) + 1
        i = rng.randrange(MOTORS)
        dur = rng.uniform(0.1, 0.6)
        if kind == "nack":
            rig.sim_thruster_call(i, "SetNack", True, signature="b")
            time.sleep(dur)
            rig.sim_thruster_call(i, "SetNack", False, signature="b")
            self.excused.append((now, time.monotonic(), i))
        elif kind == "corrupt":
            rig.sim_thruster_call(i, "CorruptReplies", dbus.UInt32(rng.randint(1, 5)),
                                  rng.choice(["checksum", "first-byte"]), signature="us")
        elif kind == "fault-bit":
            f = rng.choice(["overtemp", "stall", "hall", "ground-fault", "water-detect"])
            rig.sim_thruster_call(i, "SetFault", f, True, signature="sb")
            time.sleep(dur)
            rig.sim_thruster_call(i, "SetFault", f, False, signature="sb")
        elif kind == "hang-sda":
            rig.sim_call("HangBus", dbus.UInt32(rng.randint(1, 9)), signature="u")
            time.sleep(0.3)
            self.excused.append((now, time.monotonic() + 0.3, None))
        elif kind == "hold-scl":
            rig.sim_call("HoldScl")
            time.sleep(dur)
            rig.sim_call("ReleaseBus")
            self.excused.append((now, time.monotonic() + 1.5, None))
        elif kind in ("teensy-busy", "teensy-garbage"):
            rig.sim_teensy_call("InjectFault", "busy" if kind == "teensy-busy" else "garbage-ack",
                                dbus.UInt32(rng.randint(1, 10)), signature="su")
        elif kind == "hang":
            rig.sim_thruster_call(i, "SetHang", dbus.UInt32(rng.choice([5, 30, 1000])), signature="u")
            time.sleep(dur)
            rig.sim_thruster_call(i, "SetHang", dbus.UInt32(0), signature="u")
            self.excused.append((now, time.monotonic() + 0.1, None))
        elif kind == "kill-switch":
            rig.sim_call("SetKillSwitch", True, signature="b")
            time.sleep(dur)
            rig.sim_call("SetKillSwitch", False, signature="b")
        elif kind == "sim-restart":
            # The wire log starts again with the new simulator: the books so far are closed, and
            # the commands just before the restart are excused (their orders may never go out).
            self.excused.append((now - 0.3, now + 60, None))
            self.drain_wire()
            self.check_books()
            self.wire, self.commands, self.excused, self.pauses, self.since = [], [], [], [], 0
            self.read_to_ns, self.killed = 0, False
            sim = self.rig.procs.pop("caracara-sim")
            sim.kill()
            sim.wait(10)
            time.sleep(dur)
            self.rig.start_sim()
            self.sim_restarts += 1
        return kind

    # --- the books ----------------------------------------------------------------------------
    def check_books(self, cutoff=None):
        """Judges the commands sent and the pauses ended before `cutoff` (all of them when None),
        and forgets them. (Orders after a kill are judged as they are read: judge_killed.)"""
        b = self.books
        by_addr = {}
        for w in sorted(w for w in self.wire if w[2] == "order"):
            times, speeds = by_addr.setdefault(w[3], ([], []))
            times.append(w[0])
            speeds.append(w[4])
        self.by_addr = by_addr
        # Timed out: the stream paused.
        for t0, t1 in self.pauses:
            if cutoff is not None and t1 >= cutoff:
                continue
            lo, hi = int((t0 + TIMEOUT_MS / 1000 + GRACE) * 1e9), int(t1 * 1e9)
            for times, speeds in by_addr.values():
                b["timed_out_orders"] += sum(1 for sp in speeds[bisect.bisect_right(times, lo):bisect.bisect_left(times, hi)]
                                             if sp != 0x80)
        self.pauses = [p for p in self.pauses if cutoff is not None and p[1] >= cutoff]
        # Lost: each accepted command's eight orders reach the wire before the next (+ grace).
        kills = [w[0] for w in self.wire if w[2] == "kill"]
        judged = 0
        for k, (t, speeds) in enumerate(self.commands):
            if cutoff is not None and t >= cutoff:
                break
            judged = k + 1
            end = self.commands[k + 1][0] if k + 1 < len(self.commands) else t + 0.2
            lo, hi = int(t * 1e9), int((end + GRACE) * 1e9)
            if any(lo <= kt <= hi for kt in kills):
                b["superseded_by_kill"] += 1
                continue
            missing = [i for i in range(MOTORS) if not self.reached(i, speeds[i], lo, hi)]
            if not missing:
                b["reached"] += 1
                continue
            # Superseded: the thruster got a newer command's value instead (the stream moved on
            # before this one's turn on the bus came).
            later = self.commands[k + 1:k + 6]
            if all(any(sp in {c[1][i] for c in later} for sp in self.window(i, lo, hi, lo_open=True)) for i in missing):
                b["superseded"] += 1
                continue
            if all(any(a - 0.05 <= t <= c + 0.05 and (th is None or th == i) for a, c, th in self.excused)
                   for i in missing):
                b["excused"] += 1
            else:
                b["lost"] += 1
                if b["lost"] <= 5:
                    print("soak: LOST command at %.3f..%.3f (thrusters %s, wanted %s)" %
                          (t, end, missing, [hex(speeds[i]) for i in missing]), flush=True)
                    for i in missing:
                        times, sps = by_addr.get(self.addrs[i], ([], []))
                        near = [(round(wt / 1e9 - t, 4), hex(sp)) for wt, sp in zip(times, sps)
                                if t - 0.1 <= wt / 1e9 <= end + 0.3]
                        print("soak:   thruster %d orders around it (s from the call, speed): %s" % (i, near))
                    print("soak:   faults around it: %s" % [(round(a0 - t, 3), round(c - t, 3), th)
                                                           for a0, c, th in self.excused if a0 - 1 < t < c + 1])
        del self.commands[:judged]

    def window(self, i, lo, hi, lo_open=False):
        """The speeds ordered to thruster i in [lo, hi] ((lo, hi] with lo_open)."""
        times, speeds = self.by_addr.get(self.addrs[i], ([], []))
        start = (bisect.bisect_right if lo_open else bisect.bisect_left)(times, lo)
        return speeds[start:bisect.bisect_right(times, hi)]

    def reached(self, i, want, lo, hi):
        """The thruster stood at `want` at some moment of [lo, hi]: an order of it in the window,
        or the order standing when the window opened (an unchanged value is not sent again at once)."""
        if want in self.window(i, lo, hi):
            return True
        times, speeds = self.by_addr.get(self.addrs[i], ([], []))
        before = bisect.bisect_left(times, lo)
        return before > 0 and speeds[before - 1] == want

    # --- the run ------------------------------------------------------------------------------
    def run(self):
        a, rig, rng = self.args, self.rig, self.rng
        rig.start()
        self.addrs = [int(rig.sim_thruster(i, "Address")) >> 1 for i in range(MOTORS)]
        self.kill_level = None
        rig.arm()
        pid = rig.procs["caracarad"].pid
        time.sleep(1)
        fd0, rss0 = fds(pid), rss_kib(pid)
        self.books = dict(reached=0, superseded=0, superseded_by_kill=0, excused=0, lost=0, killed_orders=0, in_flight_at_kill=0, on_wire_at_kill=0,
                          timed_out_orders=0)
        # The level the kill output takes when asserted: what it shows while the vehicle is killed.
        rig.vcall("Kill")
        self.drain_wire()
        self.kill_level = next(w[4] for w in reversed(self.wire) if w[2] == "kill")
        rig.vcall("ClearKill")
        rig.wait_state("ready")
        self.wire, self.entries_read, self.max_lag = [], 0, 0.0
        client = dbus.bus.BusConnection(rig.address)
        t_start = time.monotonic()
        next_cmd = next_fault = next_drain = next_churn = next_check = t_start
        paused_until = 0
        tx0 = int(rig.vget("Transactions", path=PATH + "/bus", iface=VEHICLE + ".Bus"))
        last_report = t_start
        tx, next_tx = 0, t_start
        while True:
            now = time.monotonic()
            if now >= next_tx:
                tx = int(rig.vget("Transactions", path=PATH + "/bus", iface=VEHICLE + ".Bus")) - tx0
                next_tx = now + 1
            if now - t_start >= a.seconds or (a.transactions and tx >= a.transactions):
                break
            if now >= next_drain or not self.caught_up:
                # A page a turn until the reader has caught up with the wire, then every 0.2 s.
                self.read_page()
                next_drain = now + 0.2
            if now >= next_check:
                # Close the books up to a second before the last entry read; keep the orders of a
                # second before that (the order standing when a later command's window opens).
                cutoff = min(now, self.read_to_ns / 1e9) - 1.0
                self.check_books(cutoff)
                self.wire = [w for w in self.wire if w[0] >= int((cutoff - 1) * 1e9)]
                next_check = now + 1
            if now >= next_fault:
                self.inject(now)
                next_fault = time.monotonic() + rng.uniform(0.3, 1.5)
            if now >= next_churn:
                client.close()
                client = dbus.bus.BusConnection(rig.address)  # the old client left: the daemon zeroes
                self.churn += 1
                next_churn = now + rng.uniform(1, 4)
                if rng.random() < 0.3:  # a silent stream, past the command timeout
                    paused_until = now + TIMEOUT_MS / 1000 + rng.uniform(0.1, 0.5)
                    self.pauses.append((now, paused_until))
            if now >= next_cmd and now >= paused_until:
                vals = [rng.randrange(-500, 501) for _ in range(MOTORS)]
                t = time.monotonic()
                try:
                    client.call_blocking(VEHICLE, PATH, VEHICLE, "SetThrust", "ai", ([dbus.Int32(v) for v in vals],))
                    self.commands.append((t, [speed_byte(v) for v in vals]))
                except dbus.DBusException as e:
                    self.refused += 1
                    name = e.get_dbus_name() or ""
                    why = name.rsplit(".", 1)[-1]
                    self.refused_by[why] = self.refused_by.get(why, 0) + 1
                    if name.endswith(".Killed"):
                        try:
                            client.call_blocking(VEHICLE, PATH, VEHICLE, "ClearKill", "", ())
                        except dbus.DBusException:
                            pass
                self.calls += 1
                next_cmd += PERIOD
                if next_cmd < now:
                    next_cmd = now + PERIOD  # after a stall the stream goes on at its rate, no burst
            if now - last_report > 30:
                print("soak: %.0f s, %d transactions, %d calls, %d wire log entries read, %.1f s behind" %
                      (now - t_start, tx, self.calls, self.entries_read,
                       now - self.read_to_ns / 1e9 if self.read_to_ns else 0), flush=True)
                last_report = now
            time.sleep(0.002)
        time.sleep(0.3)
        self.drain_wire()
        self.check_books()
        client.close()
        elapsed = time.monotonic() - t_start
        tx = int(rig.vget("Transactions", path=PATH + "/bus", iface=VEHICLE + ".Bus")) - tx0
        time.sleep(1)
        fd1, rss1 = fds(pid), rss_kib(pid)
        same_pid = rig.procs["caracarad"].poll() is None and rig.procs["caracarad"].pid == pid
        recov = int(rig.vget("Recoveries", path=PATH + "/bus", iface=VEHICLE + ".Bus"))
        b = self.books
        print("soak: %.0f s, %d bus transactions, %d SetThrust calls (%d refused), %d client changes, "
              "%d simulator restarts, %d recoveries" % (elapsed, tx, self.calls, self.refused, self.churn,
                                                         self.sim_restarts, recov))
        print("soak: SetThrust refused with: " + ", ".join("%s %d" % kv for kv in sorted(self.refused_by.items())))
        print("soak: faults injected: " + ", ".join("%s %d" % kv for kv in sorted(self.faults.items())))
        print("soak: commands reached the wire %d, superseded by a newer one %d, by a kill %d, excused by a "
              "fault %d, LOST %d" % (b["reached"], b["superseded"], b["superseded_by_kill"], b["excused"], b["lost"]))
        print("soak: non-zero orders after a kill's zero %d, reaching the wire after the kill %d (on the wire "
              "at the kill, not judged: %d), after a timeout %d" %
              (b["killed_orders"], b["in_flight_at_kill"], b["on_wire_at_kill"], b["timed_out_orders"]))
        print("soak: wire log entries read %d (the reader at most %.1f s behind the wire); stretches dropped "
              "before they were read: %d" % (self.entries_read, self.max_lag, self.wire_gaps))
        # Under an emulator (the arm64 tests under qemu-user) the RSS is qemu's, whose translation
        # cache grows with every code path first run: shown, judged only natively.
        emulated = bool(harness.EMULATOR)
        print("soak: daemon pid unchanged %s; fds %d -> %d; RSS %d -> %d KiB%s" %
              (same_pid, fd0, fd1, rss0, rss1, " (qemu's, not judged)" if emulated else ""))
        failures = [what for what, bad in (
            ("a lost command", b["lost"] > 0),
            ("a non-zero order after a kill's zero", b["killed_orders"] > 0),
            ("an order in flight at a kill that reached the wire after it", b["in_flight_at_kill"] > 0),
            ("a non-zero order past the command timeout", b["timed_out_orders"] > 0),
            ("the daemon restarted", not same_pid),
            ("fd growth %d -> %d" % (fd0, fd1), fd1 > fd0 + FD_GROWTH_MAX),
            ("RSS growth %d -> %d KiB" % (rss0, rss1), not emulated and rss1 > rss0 + RSS_GROWTH_KIB_MAX),
            ("no command reached the wire", b["reached"] == 0)) if bad]
        for f in failures:
            print("soak: FAIL: %s" % f)
        self.results = dict(seconds=round(elapsed, 1), transactions=tx, setthrust_calls=self.calls,
                            refused=self.refused, refused_by=dict(self.refused_by), client_changes=self.churn,
                            simulator_restarts=self.sim_restarts,
                            recoveries=recov, faults=dict(self.faults), books=dict(b), wire_gaps=self.wire_gaps,
                            wire_entries_read=self.entries_read, reader_lag_max_s=round(self.max_lag, 2),
                            fds=[fd0, fd1], rss_kib=[rss0, rss1], rss_judged=not emulated, seed=a.seed,
                            loop_rate_hz=a.loop_rate, failures=failures, passed=not failures)
        rig.stop_checked()
        return not failures


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=60)
    ap.add_argument("--transactions", type=int, default=0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--loop-rate", type=int, default=50,
                    help="the daemon's loop_rate_hz (0: the bus flat out, for a million transactions in minutes)")
    ap.add_argument("--results", help="write the run's counts to this JSON file (scripts/soak.sh)")
    args = ap.parse_args()
    soak = Soak(args)
    try:
        ok = soak.run()
    except Exception:
        for name in ("caracara-sim", "caracarad"):
            try:
                print("---- %s log (last 20 lines)\n%s" % (name, "\n".join(soak.rig.log(name).splitlines()[-20:])))
            except Exception:  # noqa: BLE001 - the log may be gone with the rig
                pass
        soak.rig.stop()
        raise
    if args.results:
        top = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))) + os.sep
        with open(args.results, "w") as f:
            json.dump(dict(soak.results, command="tests/soak/soak.py " + " ".join(a.replace(top, "") for a in sys.argv[1:]),
                           cpus=os.cpu_count(),
                           finished=time.strftime("%Y-%m-%dT%H:%M:%S%z")), f, indent=1, sort_keys=True)
            f.write("\n")
        print("soak: counts written to %s" % args.results)
    print("soak: %s" % ("PASS" if ok else "FAIL"))
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
