"""[realtime]: the daemon's own threads at the configured real-time policy and priorities (the
loop above the bus and Teensy workers, the dive writer at the normal policy), its memory
locked, and where the kernel refuses real-time scheduling one clear warning and a daemon that
still kills. Judged from the kernel's side: /proc/<pid>/task/*/stat (policy, rt_priority).
"""

import os
import shutil
import time
import unittest

from harness import (EMULATOR, SANITIZED, Rig, command, poll)

# /proc/<pid>/task/<tid>/stat fields after the command (field 2): rt_priority is field 40 and
# policy field 41 (proc(5)).
SCHED_OTHER, SCHED_FIFO, SCHED_RR = 0, 1, 2


def thread_schedules(pid):
    """{tid: (policy, rt_priority)} for every thread of `pid`."""
    out = {}
    for tid in os.listdir("/proc/%d/task" % pid):
        with open("/proc/%d/task/%s/stat" % (pid, tid)) as f:
            rest = f.read().rsplit(")", 1)[1].split()
        # rest[0] is field 3 (state).
        out[int(tid)] = (int(rest[41 - 3]), int(rest[40 - 3]))
    return out


def status_kib(pid, key):
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1])
    raise AssertionError("%s not in /proc/%d/status" % (key, pid))


def mappings(pid):
    """/proc/<pid>/smaps as [{path, perms, size, rss (KiB), locked (VmFlags lo)}]."""
    out = []
    with open("/proc/%d/smaps" % pid) as f:
        for line in f:
            head = line.split()
            if "-" in head[0] and len(head) >= 5 and ":" not in head[0]:
                lo, hi = (int(x, 16) for x in head[0].split("-"))
                out.append({"path": head[5] if len(head) > 5 else "", "perms": head[1], "size": (hi - lo) // 1024,
                            "rss": 0, "locked": False})
            elif head[0] == "Rss:":
                out[-1]["rss"] = int(head[1])
            elif head[0] == "VmFlags:":
                out[-1]["locked"] = "lo" in head[1:]
    return out


def library(m, stem):
    return os.path.basename(m["path"]).startswith(stem + ".so")


def may_lock_memory():
    """As the daemon judges it (ThreadSchedule::lock_memory): RLIMIT_MEMLOCK unlimited, or
    CAP_IPC_LOCK (bit 14 of CapEff). Not so in a container that holds the limit (the Debian 13
    root under systemd-nspawn): the daemon then leaves memory unlocked and says why."""
    import resource
    if resource.getrlimit(resource.RLIMIT_MEMLOCK)[0] == resource.RLIM_INFINITY:
        return True
    with open("/proc/self/status") as f:
        caps = next(int(line.split()[1], 16) for line in f if line.startswith("CapEff:"))
    return bool(caps & (1 << 14))


def may_use_realtime():
    """Root with CAP_SYS_NICE (the tests' usual case) may take any real-time priority."""
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(1))
    except PermissionError:
        return False
    os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))
    return True


class RefusedRig(Rig):
    """The daemon without CAP_SYS_NICE and with RLIMIT_RTPRIO 0, as in a container."""

    def start_daemon(self):
        real = command

        def without_rt(name):
            argv = real(name)
            return ["setpriv", "--inh-caps=-sys_nice", "--bounding-set=-sys_nice", "--", "prlimit",
                    "--rtprio=0", "--"] + argv if name == "caracarad" else argv

        import harness
        harness.command = without_rt
        try:
            super().start_daemon()
        finally:
            harness.command = real


class RealtimeTest(unittest.TestCase):

    def setUp(self):
        if not may_use_realtime():
            if os.environ.get("CI") == "true":
                self.fail("this process may not use real-time scheduling: the test cannot judge [realtime]")
            self.skipTest("this process may not use real-time scheduling (run as root)")

    def start(self, rig):
        self.addCleanup(rig.stop_checked)
        rig.start()
        return rig.procs["caracarad"].pid

    def check_threads(self, pid, policy, loop, workers):
        sched = thread_schedules(pid)
        self.assertEqual(sched[pid], (policy, loop), "the loop thread (main) %r" % sched)
        others = sorted((s for tid, s in sched.items() if tid != pid), key=lambda s: -s[1])
        self.assertEqual([s for s in others if s[0] != SCHED_OTHER], [(policy, p) for p in workers],
                         "the bus and Teensy workers, nothing else real-time: %r" % sched)
        # The dive writer: file writes can wait, at the normal policy.
        self.assertIn((SCHED_OTHER, 0), others, "no thread at the normal policy: %r" % sched)

    def test_default_threads_fifo_loop_above_workers_memory_locked(self):
        rig = Rig()
        pid = self.start(rig)
        self.check_threads(pid, SCHED_FIFO, 40, [38, 36])
        if SANITIZED:
            pass  # ASan's shadow memory cannot be locked: the daemon says so and goes on
        elif may_lock_memory():
            self.assertGreater(status_kib(pid, "VmLck"), 1024, "memory not locked")
            self.assertIn("realtime: memory locked", rig.log())
            if EMULATOR:
                # qemu-user maps the arm64 daemon's code as data it translates (no r-xp mapping
                # of libc to look at): which libraries are locked is judged on the native builds.
                print("the cold libraries: not judged under %s" % " ".join(EMULATOR))
            else:
                self.check_cold_libraries_unlocked(rig, pid)
        else:
            self.assertEqual(status_kib(pid, "VmLck"), 0, "memory locked past RLIMIT_MEMLOCK")
            self.assertIn("realtime: memory not locked: RLIMIT_MEMLOCK", rig.log(),
                          "the daemon did not say why memory is not locked")
        self.assertIn("realtime: policy fifo, loop at 40, bus worker at 38, Teensy worker at 36", rig.log())
        # Still a vehicle: a kill reaches the kill output.
        rig.arm()
        rig.vcall("Kill")
        poll(lambda: rig.sim_get("KillOutput"), 5)

    def check_cold_libraries_unlocked(self, rig, pid):
        # The hot path's code (the daemon, libc, libstdc++, libsystemd) locked and resident
        # whole; libsystemd's journal-file dependencies and the TOML parser neither locked nor
        # faulted in; of libm, only the pages of lround() (docs/realtime.md).
        maps = mappings(pid)
        exe = os.path.realpath("/proc/%d/exe" % pid)
        for stem in ("libc", "libstdc++", "libsystemd", exe):
            text = [m for m in maps if (m["path"] == stem or library(m, stem)) and m["perms"] == "r-xp"]
            self.assertTrue(text, "%s not mapped" % stem)
            for m in text:
                self.assertTrue(m["locked"] and m["rss"] == m["size"], "%s's code not locked whole: %r" % (stem, m))
        cold = [m for m in maps if any(library(m, s) for s in ("libgcrypt", "libzstd", "libtomlplusplus"))
                and m["perms"] == "r-xp"]
        self.assertTrue(cold, "no cold library mapped: %r" % sorted({m["path"] for m in maps}))
        for m in cold:
            self.assertFalse(m["locked"], "a cold library locked: %r" % m)
            self.assertLess(m["rss"], m["size"] // 2, "a cold library faulted in: %r" % m)
        libm = [m for m in maps if library(m, "libm") and m["perms"] == "r-xp"]
        two_pages = 2 * os.sysconf("SC_PAGE_SIZE") // 1024
        self.assertEqual([(m["size"], m["rss"]) for m in libm if m["locked"]], [(two_pages, two_pages)],
                         "lround's two pages of libm, locked: %r" % libm)
        self.assertIn("KiB of libraries off the hot path left unlocked", rig.log())

    def test_configured_policy_and_priorities(self):
        rig = Rig(extra_config={"realtime": {"policy": "rr", "loop_priority": 21, "bus_priority": 12,
                                             "teensy_priority": 11, "lock_memory": False}})
        pid = self.start(rig)
        self.check_threads(pid, SCHED_RR, 21, [12, 11])
        self.assertEqual(status_kib(pid, "VmLck"), 0)

    def test_disabled_every_thread_normal(self):
        rig = Rig(extra_config={"realtime": {"enabled": False, "lock_memory": False}})
        pid = self.start(rig)
        sched = thread_schedules(pid)
        self.assertEqual(set(sched.values()), {(SCHED_OTHER, 0)}, sched)
        self.assertNotIn("realtime:", rig.log())

    @unittest.skipUnless(shutil.which("setpriv") and shutil.which("prlimit"), "needs util-linux")
    def test_refused_warns_once_and_runs_at_normal_policy(self):
        rig = RefusedRig(extra_config={"realtime": {"lock_memory": False}})
        pid = self.start(rig)
        sched = thread_schedules(pid)
        self.assertEqual(set(sched.values()), {(SCHED_OTHER, 0)}, sched)
        log = rig.log()
        self.assertEqual(log.count("realtime: the kernel refused policy fifo at priority 38"), 1, log)
        self.assertIn("every thread runs at the normal policy", log)
        self.assertEqual(log.count("realtime:"), 1, log)
        # A daemon without real-time scheduling still kills.
        rig.arm()
        rig.vcall("Kill")
        poll(lambda: rig.sim_get("KillOutput"), 5)
        time.sleep(0.1)
        self.assertEqual(rig.state(), "killed")


if __name__ == "__main__":
    unittest.main()
