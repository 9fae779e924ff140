#!/usr/bin/python3
"""Caracara benchmarks: latency to the wire, kill latency, loop rate, CPU and memory.

Benchmarks print figures; they never fail on time. Every figure is measured next to its
floor in the same run. See bench/README.md for what each figure and floor is.

    bench/run.py --build DIR [--quick] [--out FILE] [--rss-seconds S]

bench/run.sh builds the programs and calls this with the right interpreter (/usr/bin/python3).
"""
import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))


def log(msg):
    print(f"[bench {time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr, flush=True)


class Bench:
    def __init__(self, build, quick, keep):
        self.build = build
        self.quick = quick
        self.keep = keep
        self.dir = tempfile.mkdtemp(prefix="caracara-bench.")
        self.procs = []
        self.rt = False
        self.rt_active = True
        self.loaded = None  # during the loaded phase: {role: SCHED_FIFO priority} (LOADED_PRIORITIES)
        self.bus = None
        self.sock = os.path.join(self.dir, "sim.sock")
        self.daemon = None
        self.sim = None
        self.dbusd = None
        self.exe = {
            "daemon": os.path.join(build, "daemon", "caracarad"),
            "sim": os.path.join(build, "sim", "caracara-sim"),
            "client": os.path.join(build, "bench", "caracara-bench"),
            "floor": os.path.join(build, "bench", "caracara-bench-floor"),
        }
        for name, path in self.exe.items():
            if not os.access(path, os.X_OK):
                sys.exit(f"bench: {path} is missing; build first (bench/run.sh does)")

    # --- processes --------------------------------------------------------------------

    def prefix(self, role=None):
        if self.loaded is not None:
            prio = self.loaded.get(role)
            return ["chrt", "-f", str(prio)] if prio else []
        return ["chrt", "-f", "10"] if self.rt and self.rt_active else []

    def spawn(self, argv, name, **kw):
        argv = [*self.prefix(name), *argv]
        out = open(os.path.join(self.dir, f"{name}.log"), "ab")
        p = subprocess.Popen(argv, stdout=kw.pop("stdout", out), stderr=out, **kw)
        self.procs.append(p)
        return p

    def stop(self, p, sig=signal.SIGTERM, timeout=20):
        if p is None or p.poll() is not None:
            return
        try:
            p.send_signal(signal.SIGCONT)
            p.send_signal(sig)
            p.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()

    def cleanup(self):
        for p in reversed(self.procs):
            self.stop(p, timeout=5)
        self.procs = []
        if not self.keep:
            shutil.rmtree(self.dir, ignore_errors=True)

    def start_bus(self):
        conf = os.path.join(self.dir, "bus.conf")
        path = os.path.join(self.dir, "bus")
        with open(conf, "w") as f:
            f.write(f"""<!DOCTYPE busconfig PUBLIC "-//freedesktop//DTD D-Bus Bus Configuration 1.0//EN"
 "http://www.freedesktop.org/standards/dbus/1.0/busconfig.dtd">
<busconfig><type>session</type><listen>unix:path={path}</listen><auth>EXTERNAL</auth>
<policy context="default"><allow send_destination="*" eavesdrop="true"/><allow eavesdrop="true"/><allow own="*"/></policy>
</busconfig>
""")
        # The socket file appears before dbus-daemon listens; its printed address means it does.
        self.dbusd = self.spawn(["dbus-daemon", "--nofork", "--print-address=1", f"--config-file={conf}"],
                                "dbus-daemon")
        self.bus = f"unix:path={path}"
        log = os.path.join(self.dir, "dbus-daemon.log")
        self.wait_for(lambda: self.bus in open(log).read(), 10, "the private dbus-daemon")

    def wait_for(self, pred, timeout, what):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if pred():
                return
            time.sleep(0.02)
        raise RuntimeError(f"timed out waiting for {what}")

    def busctl(self, *args, check=True):
        r = subprocess.run(["busctl", f"--address={self.bus}", *args], capture_output=True, text=True)
        if check and r.returncode != 0:
            raise RuntimeError(f"busctl {' '.join(args)}: {r.stderr.strip()}")
        return r

    def rearm(self):
        """Kill and ClearKill (busctl: no pilot), then ready: a bench client that drove and left
        was the last pilot, and pilot-lost would kill after its persistence (5 s), in the middle
        of whatever comes next."""
        for method in ("Kill", "ClearKill"):
            self.busctl("call", "org.caracara.Vehicle1", "/org/caracara/Vehicle1", "org.caracara.Vehicle1", method)
        r = subprocess.run([self.exe["client"], "wait-ready", "--bus", self.bus, "--timeout-ms", "20000"],
                           capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError(f"caracarad did not become ready again: {r.stderr.strip()}")

    def sim_call(self, method, sig="", *args):
        return self.busctl("call", "org.caracara.Simulator1", "/org/caracara/Simulator1", "org.caracara.Simulator1",
                           method, *([sig, *map(str, args)] if sig else []))

    def start_sim(self, realistic):
        self.stop_sim()
        if os.path.exists(self.sock):
            os.unlink(self.sock)
        argv = [self.exe["sim"], "--socket", self.sock, "--bus-address", self.bus]
        if realistic:
            argv.append("--realistic-timing")
        self.sim = self.spawn(argv, "sim")

        def up():
            return os.path.exists(self.sock) and self.busctl(
                "get-property", "org.caracara.Simulator1", "/org/caracara/Simulator1", "org.caracara.Simulator1",
                "ClockHz", check=False).returncode == 0
        self.wait_for(up, 10, "caracara-sim")

    def stop_sim(self):
        self.stop(self.sim)
        self.sim = None

    def sim_has_kill_switch(self):
        r = self.busctl("introspect", "--xml-interface", "org.caracara.Simulator1", "/org/caracara/Simulator1",
                        check=False)
        return r.returncode == 0 and re.search(r'<method name="SetKillSwitch"', r.stdout) is not None

    def daemon_config(self, rate, reads=1, kill_switch=False, extra="", realtime=True):
        path = os.path.join(self.dir, f"caracarad-{rate}-{int(kill_switch)}-{len(extra)}-{int(realtime)}.toml")
        with open(path, "w") as f:
            f.write(f"""# generated by bench/run.py
[control]
loop_rate_hz = {rate}
status_reads_per_tick = {reads}
command_timeout_ms = 500
arming_delay_ms = 0
""")
            # The dive recorder, on by default as in the product; CARACARA_BENCH_RECORDER=off for the
            # comparison in docs/dive-format.md.
            dives = os.path.join(self.dir, "dives")
            os.makedirs(dives, exist_ok=True)
            on = os.environ.get("CARACARA_BENCH_RECORDER", "on") != "off"
            f.write(f'[recorder]\nenabled = {"true" if on else "false"}\ndirectory = "{dives}"\n')
            # CARACARA_BENCH_REALTIME=off: the daemon's threads at the normal policy, memory unlocked
            # (the figures before [realtime], docs/realtime.md).
            if not realtime or os.environ.get("CARACARA_BENCH_REALTIME", "on") == "off":
                f.write("[realtime]\nenabled = false\nlock_memory = false\n")
            if kill_switch:
                f.write('[gpio]\nkill_switch = { chip = "gpiochip0", line = "KILL_SWITCH" }\n'
                        'kill_output = { chip = "gpiochip0", line = "KILL_OUT" }\n')
            f.write(extra)
        return path

    def start_daemon(self, config, wrapper=(), ready_timeout=20):
        self.stop_daemon()
        argv = [*wrapper, self.exe["daemon"], f"--hardware=sim:{self.sock}", "--bus-address", self.bus,
                "--config", config]
        self.daemon = self.spawn(argv, "caracarad")
        r = subprocess.run([self.exe["client"], "wait-ready", "--bus", self.bus,
                            "--timeout-ms", str(ready_timeout * 1000)], capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError(f"caracarad did not become ready: {r.stderr.strip()}")
        return self.daemon

    def stop_daemon(self):
        self.stop(self.daemon, timeout=60)
        self.daemon = None

    def client(self, *args, timeout=None, bus=None):
        r = subprocess.run([*self.prefix("client"), self.exe["client"], *map(str, args), "--bus", bus or self.bus],
                           capture_output=True, text=True,
                           timeout=timeout)
        if r.returncode != 0:
            raise RuntimeError(f"caracara-bench {' '.join(map(str, args))}: {r.stderr.strip()}")
        if r.stderr.strip():
            log(r.stderr.strip())
        return json.loads(r.stdout)

    def floor(self, *args, config=None, wrapper=()):
        argv = [*self.prefix("floor"), *wrapper, self.exe["floor"], "--socket", self.sock, *map(str, args)]
        if config:
            argv += ["--config", config]
        r = subprocess.run(argv, capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError(f"caracara-bench-floor {' '.join(map(str, args))}: {r.stderr.strip()}")
        return json.loads(r.stdout.strip().splitlines()[-1])


# --- /proc helpers --------------------------------------------------------------------------

def cpu_ns(pid):
    with open(f"/proc/{pid}/schedstat") as f:
        return int(f.read().split()[0])


def status_kib(pid, key):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1])
    return 0


def callgrind_total(path):
    """Total Ir of a callgrind output file (its 'totals:' or 'summary:' line)."""
    total = None
    with open(path) as f:
        for line in f:
            if line.startswith("totals:") or line.startswith("summary:"):
                total = int(line.split()[1])
    if total is None:
        raise RuntimeError(f"no totals in {path}")
    return total


def callgrind_calls(path, names):
    """How many times each function in `names` was called (the 'calls=' lines of the file; the
    file names a function once in full, then by its number)."""
    ids, counts, callee = {}, {n: 0 for n in names}, None
    with open(path) as f:
        for line in f:
            m = re.match(r"c?fn=\((\d+)\)(?: (.*))?$", line.rstrip("\n"))
            if m:
                if m.group(2):
                    ids[m.group(1)] = m.group(2)
                callee = ids.get(m.group(1)) if line.startswith("cfn=") else None
            elif line.startswith("calls=") and callee in counts:
                counts[callee] += int(line.split()[0][6:])
    return counts


ALLOCATORS = ("malloc", "calloc", "realloc", "operator new(unsigned long)")


def callgrind_inclusive(path, patterns):
    """Inclusive Ir of the functions whose names match `patterns` (callgrind_annotate)."""
    r = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100", path], capture_output=True,
                       text=True)
    out = {}
    for line in r.stdout.splitlines():
        m = re.match(r"\s*([\d,]+)\s+(?:\([^)]*\)\s+)?(\S.*)$", line)
        if not m:
            continue
        ir = int(m.group(1).replace(",", ""))
        name = m.group(2)
        for key, pat in patterns.items():
            if key not in out and re.search(pat, name):
                out[key] = ir
    return out


# --- the figures ------------------------------------------------------------------------------

def phase_dbus(b, p, res):
    log("1. SetThrust round trip vs Peer.Ping (simulator answers at once, loop at 50 Hz)")
    b.start_sim(realistic=False)
    b.start_daemon(b.daemon_config(50))
    res["rtt"] = b.client("rtt", "--calls", p["rtt_calls"], "--warmup", p["rtt_warmup"])
    b.stop_daemon()
    # The same on the 100 kHz wire (a diagnostic): each call may wait for the transaction in
    # flight, and the settle gap covers an eight-order burst.
    log("   and with realistic timing at 100 kHz")
    b.start_sim(realistic=True)
    b.start_daemon(b.daemon_config(50))
    res["rtt_realistic"] = b.client("rtt", "--calls", max(1, p["rtt_calls"] // 4), "--warmup", p["rtt_warmup"],
                                    "--settle-us", 5000)
    b.stop_daemon()
    b.stop_sim()


def phase_ssh(b, p, res):
    log("7. SetThrust round trip over an SSH bridge on loopback vs Peer.Ping over the same bridge")
    from ssh_bridge import SshBridge
    bridge = SshBridge(b, log)
    try:
        b.start_sim(realistic=False)
        b.start_daemon(b.daemon_config(50))
        res["ssh_connect_ms"] = bridge.connect_ms()
        res["rtt_ssh"] = b.client("rtt", "--calls", max(1, p["rtt_calls"] // 4), "--warmup", p["rtt_warmup"],
                                  bus=bridge.address)
        b.stop_daemon()
        b.stop_sim()
    finally:
        bridge.stop()


def phase_bridge(b, p, res):
    log("8. caracara-bridge: a property change to a client, a published motion to the wire vs SetMotion, CPU and RSS")
    bridge_exe = os.path.join(b.build, "tools", "bridge", "caracara-bridge")
    node_dir = os.path.join(os.path.dirname(HERE), "tests", "bridge")
    if not shutil.which("node"):
        raise RuntimeError("node is needed (scripts/deps.sh)")
    # The packages tests/bridge/package-lock.json pins, as the tests have them (tests/npm_packages.py:
    # npm ci from the lock file unless node_modules already holds exactly that), never whatever an
    # older node_modules holds.
    npm = subprocess.run([sys.executable, os.path.join(os.path.dirname(HERE), "tests", "npm_packages.py"), node_dir],
                         capture_output=True, text=True)
    if npm.returncode != 0:
        raise RuntimeError("tests/bridge's npm packages: %s" % (npm.stdout + npm.stderr).strip())
    b.start_sim(realistic=False)
    b.start_daemon(b.daemon_config(50))
    sock = os.path.join(b.dir, "bridge.sock")
    br = b.spawn([bridge_exe, "--listen", "unix:" + sock, "--bus-address", b.bus], "caracara-bridge")
    b.wait_for(lambda: os.path.exists(sock), 10, "the bridge's socket")
    env = {**os.environ, "CARACARA_WS_URL": f"ws+unix://{sock}:/", "CARACARA_BUS_ADDRESS": b.bus,
           "CARACARA_BENCH_SAMPLES": str(p["bridge_samples"])}

    def node(*args, **kw):
        return subprocess.Popen(["node", os.path.join(HERE, "bridge_bench.mjs"), *map(str, args)], env=env,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)

    def run(*args):
        n = node(*args)
        out, err = n.communicate(timeout=600)
        if n.returncode != 0:
            raise RuntimeError(f"bridge_bench.mjs {' '.join(map(str, args))}: {err.strip()}")
        return json.loads(out.strip().splitlines()[-1])

    # start_daemon's wait-ready cleared the start kill: the vehicle is ready.
    res["bridge"] = {**run("latency"), **run("motion"), "load": {}}
    b.rearm()  # the motion run's pilots left: no pilot-lost kill during the load windows
    for k in (1, 4):
        seconds = p["cpu_warm"] + p["cpu_window"]
        n = node("load", k, seconds)
        n.stderr.readline()  # "# loaded"
        time.sleep(p["cpu_warm"])
        c0, t0 = cpu_ns(br.pid), time.monotonic()
        time.sleep(p["cpu_window"])
        c1, t1 = cpu_ns(br.pid), time.monotonic()
        rss = status_kib(br.pid, "VmRSS")
        out, err = n.communicate(timeout=120)
        if n.returncode != 0:
            raise RuntimeError(f"bridge_bench.mjs load {k}: {err.strip()}")
        res["bridge"]["load"][str(k)] = {"cpu_percent": 100.0 * (c1 - c0) / 1e9 / (t1 - t0), "rss_kib": rss,
                                         **json.loads(out.strip().splitlines()[-1])}
    res["bridge"]["rss_peak_kib"] = status_kib(br.pid, "VmHWM")
    b.stop(br)
    # The cockpit in chromium: it needs TCP (a browser has no Unix sockets), so a second bridge
    # on loopback with a token, the page served from the source tree.
    if os.access("/usr/bin/chromium", os.X_OK):
        from ssh_bridge import free_port, port_listens
        port, token_file = free_port(), os.path.join(b.dir, "bridge.token")
        token = os.urandom(16).hex()
        with open(token_file, "w") as f:
            f.write(token + "\n")
        tcp = b.spawn([bridge_exe, "--listen", f"tcp:127.0.0.1:{port}", "--token-file", token_file, "--bus-address",
                       b.bus, "--cockpit-dir", os.path.join(os.path.dirname(HERE), "tools", "cockpit")],
                      "caracara-bridge (tcp)")
        b.wait_for(lambda: port_listens(port), 10, "the bridge's TCP port")
        env["CARACARA_HTTP_URL"] = f"http://127.0.0.1:{port}/?token={token}"
        b.rearm()
        res["bridge"].update(run("cockpit"))
        b.stop(tcp)
    else:
        log("   no /usr/bin/chromium: the cockpit row is left out (apt-get install chromium)")
    # A Kill, and a client's close, while another client lists a full dive directory (issue 35):
    # a bridge on loopback with a token, its dive directory at the recorder's default bound.
    from ssh_bridge import free_port, port_listens
    sys.path.insert(0, node_dir)
    from full_dive_dir import fill
    count, size = fill(os.path.join(b.dir, "full-dives"))
    log(f"   {count} dives, {size / 1e6:.0f} MB, for the listing row")
    port, token_file = free_port(), os.path.join(b.dir, "bridge-full.token")
    token = os.urandom(16).hex()
    with open(token_file, "w") as f:
        f.write(token + "\n")
    full = b.spawn([bridge_exe, "--listen", f"tcp:127.0.0.1:{port}", "--token-file", token_file, "--bus-address", b.bus,
                    "--dives-dir", os.path.join(b.dir, "full-dives")], "caracara-bridge (full dives)")
    b.wait_for(lambda: port_listens(port), 10, "the bridge's TCP port")
    env["CARACARA_TCP_URL"] = f"ws://127.0.0.1:{port}/?token={token}"
    b.start_daemon(b.daemon_config(50, kill_switch=True))  # with the kill output, whose edge is timed
    b.rearm()
    res["bridge"].update(run("listing"))
    b.stop(full)
    b.stop_daemon()
    b.stop_sim()


def pstats(v):
    """The same nearest-rank statistics as bench_common.hpp's stats_json."""
    if not v:
        return {"n": 0, "min": 0, "p50": 0, "p90": 0, "p99": 0, "max": 0, "mean": 0}
    s = sorted(v)

    def pct(q):
        rank = -(-q * len(s) // 100)  # ceil
        return s[min(max(int(rank), 1), len(s)) - 1]
    return {"n": len(s), "min": s[0], "p50": pct(50), "p90": pct(90), "p99": pct(99), "max": s[-1],
            "mean": sum(s) / len(s)}


def merge(parts):
    """Merges the JSON of several runs of one measurement: raw samples, tallies, counts."""
    out = dict(parts[0])
    raw = {k: [x for q in parts for x in q["raw"][k]] for k in parts[0]["raw"]}
    for k, v in raw.items():
        out[k] = pstats(v)
    out["raw"] = raw
    for k in ("samples", "missing", "missing_edge", "not_holding"):
        if k in out:
            out[k] = sum(q[k] for q in parts)
    if "tally" in out:
        t = {}
        for q in parts:
            for group, counts in q["tally"].items():
                for name, n in counts.items():
                    t.setdefault(group, {}).setdefault(name, 0)
                    t[group][name] += n
        out["tally"] = t
    out["blocks"] = len(parts)
    return out


def phase_wire(b, p, res):
    log("2./3. command and kill to the wire (realistic timing at 100 kHz)")
    b.start_sim(realistic=True)
    ks = b.sim_has_kill_switch()
    res["kill_switch_available"] = ks
    if not ks:
        log("kill switch edge: not available in this build")
    res["wire"] = {}
    nb = p["wire_blocks"]
    for rate in (50, 0):
        cfg = b.daemon_config(rate, kill_switch=ks)
        try:
            d = b.start_daemon(cfg)
        except RuntimeError as e:
            if not ks:
                raise
            # A simulator with a kill switch but a daemon that cannot use one (gpio.kill_switch).
            log(f"caracarad refused gpio.kill_switch ({e}); kill switch edge: not available in this build")
            ks = res["kill_switch_available"] = False
            cfg = b.daemon_config(rate)
            d = b.start_daemon(cfg)
        parts = {"seam": [], "cmd": [], "kill_dbus": [], "kill_switch": []}
        log(f"   loop_rate_hz={rate}: {nb} blocks of seam floor / command / Kill(){' / kill switch' if ks else ''}")
        # Blocks interleave the measurements so that they share the machine's drift. The seam
        # floor (a program sending eight orders back to back through the same seam to the same
        # simulator) runs while the daemon is stopped.
        for blk in range(nb):
            d.send_signal(signal.SIGSTOP)
            try:
                parts["seam"].append(b.floor("--burst", max(1, p["burst_samples"] // nb)))
            finally:
                d.send_signal(signal.SIGCONT)
            parts["cmd"].append(b.client("cmd2wire", "--samples", max(1, p["cmd_samples"] // nb),
                                         "--seed", 1000 * rate + blk + 11))
            parts["kill_dbus"].append(b.client("kill2wire", "--samples", max(1, p["kill_samples"] // nb),
                                               "--source", "dbus", "--seed", 1000 * rate + blk + 5))
            if ks:
                parts["kill_switch"].append(b.client("kill2wire", "--samples", max(1, p["kill_samples"] // nb),
                                                     "--source", "switch", "--seed", 1000 * rate + blk + 9))
        res["wire"][str(rate)] = {k: merge(v) for k, v in parts.items() if v}
        b.stop_daemon()
    b.stop_sim()


def phase_faults(b, p, res):
    log("6. kill to the kill output: healthy, one thruster holding every transfer 0.9 s, the Teensy holding every frame 0.5 s")
    b.start_sim(realistic=True)
    ks = b.sim_has_kill_switch()
    # i2c.timeout_ms = 1000: the adapter waits as long as a Raspberry Pi's kernel does by default.
    # The thruster answers each transfer after 0.9 s, just inside it: the bus is held that long
    # per transfer, yet the thruster stays reachable (three timeouts in a row would kill the
    # vehicle as unreachable, and the kill-and-clear cycle measured here could not re-arm).
    # spi.silence_ms a minute: the Teensy held 0.5 s per frame is measured here as a slow link
    # that must not hold the loop, not as the silent Teensy the failsafe kills for (e2e
    # test_teensy_silence).
    cfg = b.daemon_config(50, kill_switch=ks, extra="[i2c]\ntimeout_ms = 1000\n[spi]\nsilence_ms = 60000\n")
    b.start_daemon(cfg)
    n = max(4, p["kill_samples"] // 4)
    out = {}
    thruster = ("/org/caracara/Simulator1/thruster/3", "org.caracara.Simulator1.Thruster")
    teensy = ("/org/caracara/Simulator1/teensy", "org.caracara.Simulator1.Teensy")
    # healthy; thruster 3 holding each transfer 0.9 s; the Teensy answering each SPI frame
    # 0.5 s late (its worker is stuck that long, the loop must not be).
    for seed, (key, hang) in enumerate((("healthy", None), ("hung", (thruster, "900")), ("teensy_hung", (teensy, "500")))):
        if hang:
            b.busctl("call", "org.caracara.Simulator1", hang[0][0], hang[0][1], "SetHang", "u", hang[1])
        out[key] = {"dbus": b.client("kill2output", "--samples", n, "--source", "dbus", "--seed", 61 + seed)}
        if ks:
            out[key]["switch"] = b.client("kill2output", "--samples", n, "--source", "switch", "--seed", 71 + seed)
        if hang:
            b.busctl("call", "org.caracara.Vehicle1", "/org/caracara/Vehicle1", "org.caracara.Vehicle1", "ClearKill",
                     check=False)
            out[key]["rtt"] = b.client("rtt", "--calls", max(200, p["rtt_calls"] // 4), "--warmup", 50)
            b.busctl("call", "org.caracara.Simulator1", hang[0][0], hang[0][1], "SetHang", "u", "0")
    res["faults"] = out
    b.stop_daemon()
    b.stop_sim()


def phase_kill_floor(b, p, res):
    """The floor of the kill switch's path: caracara-bench-floor --kill-seconds follows the switch with
    the kill output through the same GPIO seam, nothing else; timed by the same client as row 6."""
    log("6. kill switch edge to kill output: the floor program (edge read, output written, nothing else)")
    b.start_sim(realistic=True)
    if not b.sim_has_kill_switch():
        b.stop_sim()
        return
    cfg = b.daemon_config(50, kill_switch=True)
    out = os.path.join(b.dir, "kill-floor.out")
    with open(out, "wb") as f:
        fl = b.spawn([b.exe["floor"], "--socket", b.sock, "--config", cfg, "--kill-seconds", "3600"], "floor",
                     stdout=f)
    try:
        b.wait_for(lambda: "ready" in open(out).read() or fl.poll() is not None, 10, "the kill floor program")
        if fl.poll() is not None:
            raise RuntimeError("caracara-bench-floor --kill-seconds ended: see floor.log")
        n = max(4, p["kill_samples"] // 4)
        res["kill_floor"] = b.client("kill2output", "--samples", n, "--source", "switch", "--floor", 1, "--seed", 81)
    finally:
        b.stop(fl)
        b.procs.remove(fl)
    b.stop_sim()


# The loaded phase's priorities (SCHED_FIFO). The daemon takes its own from [realtime] (loop 40,
# bus worker 38, Teensy worker 36). The simulator plays hardware, which does not share the
# vehicle's CPUs: above the daemon, so that the thrusters and the Teensy never answer late
# because the daemon or the load holds the CPU. The client is the stopwatch and the operator's
# hand (it flips the kill switch): beside the simulator. The floor programs stand in for the
# daemon: at its loop's priority. The bus daemon carries Kill(): at 30 for the phase, as a
# vehicle's dbus.service would be given in a drop-in (docs/realtime.md).
LOADED_PRIORITIES = {"sim": 45, "client": 45, "floor": 40}
DBUS_DAEMON_PRIORITY = 30


def stress_argv():
    n = os.cpu_count() or 1
    return ["stress-ng", "--cpu", str(n), "--vm", "1", "--vm-bytes", "256M", "--io", "1", "--quiet"]


def tick_lateness(times_ns, period_ns):
    """Each loop tick's lateness, seen on the wire: a tick is a burst of transfers (the next one
    starts a period later; a gap over half a period separates them), its time the end of its first
    transfer. The daemon's schedule is a fixed grid (ControlLoop::on_tick: the next tick a period
    after the last one's due time) until a tick comes more than a period late: then it skips ahead
    and the grid starts again from that tick. Within each stretch of the grid, a tick's lateness is
    its distance behind it, the grid's phase the stretch's earliest tick (the constant handoff and
    transfer time taken out); a missed tick is a period with no burst in it."""
    starts, last = [], None
    for t in sorted(times_ns):
        if last is None or t - last > period_ns // 2:
            starts.append(t)
        last = t
    stretches, missed = [[]], 0
    for i, t in enumerate(starts):
        gap = t - starts[i - 1] if i else period_ns
        if gap > period_ns * 3 // 2:
            missed += round(gap / period_ns) - 1
            stretches.append([])
        stretches[-1].append(t)
    late = []
    for st in stretches:
        offsets = [(t - st[0]) - k * period_ns for k, t in enumerate(st)]
        late += [(o - min(offsets)) / 1000 for o in offsets]
    return {"ticks": len(starts), "missed": missed, "stretches": len(stretches), "lateness_us": pstats(late)}


def phase_ticks(b, p, res):
    """4b. The loop's tick lateness at 50 Hz, judged on the wire (realistic 100 kHz timing, no commands)."""
    log(f"4b. loop tick lateness at loop_rate_hz=50 for {p['tick_seconds']} s, from the wire log")
    b.start_sim(realistic=True)
    b.start_daemon(b.daemon_config(50))
    time.sleep(1)  # the first ticks after ready are the start's
    nxt = int(b.sim_call("GetWireLog", "t", 2 ** 63).stdout.split()[1])
    time.sleep(p["tick_seconds"])
    r = b.busctl("--json=short", "call", "org.caracara.Simulator1", "/org/caracara/Simulator1",
                 "org.caracara.Simulator1", "GetWireLog", "t", str(nxt))
    entries = json.loads(r.stdout)["data"][1]
    b.stop_daemon()
    b.stop_sim()
    res["ticks"] = dict(tick_lateness([int(e[1]) for e in entries if e[3] == "i2c"], 20_000_000),
                        seconds=p["tick_seconds"])


def phase_loaded(b, p, res):
    """The wire and kill phases and the kill floor with every core loaded by stress-ng at the normal
    policy (as vision would load them), beside the same phases without the load, in the same run
    and at the same priorities (LOADED_PRIORITIES): the load is the only difference."""
    if not shutil.which("stress-ng"):
        raise RuntimeError("stress-ng is not installed (scripts/deps.sh)")
    phases = (phase_wire, phase_faults, phase_kill_floor, phase_ticks)
    out = {"stress": stress_argv(), "priorities": dict(LOADED_PRIORITIES, **{"dbus-daemon": DBUS_DAEMON_PRIORITY})}
    subprocess.run(["chrt", "-a", "-f", "-p", str(DBUS_DAEMON_PRIORITY), str(b.dbusd.pid)], check=True)
    b.loaded = LOADED_PRIORITIES
    stress = None
    try:
        log("9. wire, kill and the kill floor without stress-ng, at the loaded phase's priorities")
        out["quiet"] = {}
        for fn in phases:
            fn(b, p, out["quiet"])
        log(f"9. the same, loaded: {' '.join(out['stress'])}")
        stress = subprocess.Popen(out["stress"], stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                  stderr=subprocess.DEVNULL, start_new_session=True)
        time.sleep(2)  # every stressor running
        if stress.poll() is not None:
            raise RuntimeError(f"stress-ng ended at once (status {stress.returncode})")
        out["loaded"] = {}
        for fn in phases:
            fn(b, p, out["loaded"])
    finally:
        b.loaded = None
        subprocess.run(["chrt", "-a", "-o", "-p", "0", str(b.dbusd.pid)], check=False)
        if stress is not None:
            os.killpg(stress.pid, signal.SIGTERM)
            try:
                stress.wait(20)
            except subprocess.TimeoutExpired:
                os.killpg(stress.pid, signal.SIGKILL)
                stress.wait()
    for half in ("quiet", "loaded"):
        out[half].pop("kill_switch_available", None)
    res["loaded"] = out


def phase_loop(b, p, res):
    log("4. loop rate at loop_rate_hz=0 against the floor program (alternating windows)")
    b.start_sim(realistic=False)
    cfg = b.daemon_config(0)
    d = b.start_daemon(cfg)
    res["loop"] = {}
    for realistic in (True, False):
        b.sim_call("SetRealisticTiming", "b", "true" if realistic else "false")
        rows = {"daemon": [], "floor": []}
        ratios = []
        # Adjacent windows, daemon then floor (the daemon stopped meanwhile), several rounds:
        # the machine's speed drifts, so each round's ratio compares like with like.
        for _ in range(p["loop_rounds"]):
            dw = b.client("cycles", "--seconds", p["loop_window"])
            d.send_signal(signal.SIGSTOP)
            try:
                fw = b.floor("--seconds", p["loop_window"], config=cfg)
            finally:
                d.send_signal(signal.SIGCONT)
            rows["daemon"].append(dw)
            rows["floor"].append(fw)
            ratios.append(dw["rate_hz"] / fw["rate_hz"])
            time.sleep(0.2)
        key = "realistic" if realistic else "immediate"
        dc = sum(r["cycles"] for r in rows["daemon"]) / sum(r["seconds"] for r in rows["daemon"])
        fc = sum(r["cycles"] for r in rows["floor"]) / sum(r["seconds"] for r in rows["floor"])
        ratios.sort()
        res["loop"][key] = {"daemon_hz": dc, "floor_hz": fc, "median_round_ratio": ratios[len(ratios) // 2],
                            "round_ratios": ratios, "windows": rows}
    b.stop_daemon()
    b.stop_sim()


def callgrind_window(b, pid, seconds, name):
    """Zeroes callgrind's counters, counts Cycles over `seconds`, dumps; returns (dump path, window)."""
    before = set(f for f in os.listdir(b.dir) if f.startswith("cg-daemon.out."))
    subprocess.run(["callgrind_control", "--zero", str(pid)], capture_output=True, check=True)
    win = b.client("cycles", "--seconds", seconds)
    r = subprocess.run(["callgrind_control", f"--dump={name}", str(pid)], capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"callgrind_control --dump: {r.stderr}")
    for _ in range(100):
        new = set(f for f in os.listdir(b.dir) if f.startswith("cg-daemon.out.")) - before
        if new:
            return os.path.join(b.dir, sorted(new)[0]), win
        time.sleep(0.1)
    raise RuntimeError("callgrind wrote no dump")


CG_FUNCTIONS = {
    "on_tick": r"ControlLoop::on_tick\(",
    "on_work (bus transactions)": r"BusWorkDispatch::on_work\(",
    "deadline timer": r"DeadlineTimer::on_time\(",
    "telemetry": r"VehicleService::telemetry\(",
    "vehicle_changed": r"VehicleService::vehicle_changed\(",
    "SetThrust handler": r"m_set_thrust\(",
    "sd_bus_emit_properties_changed_strv": r"sd_bus_emit_properties_changed_strv",
    "sd_event_prepare": r"\bsd_event_prepare\b",
    "sd_event_wait": r"\bsd_event_wait\b",
    "malloc": r":malloc \[",
    "free": r":free \[",
}


def phase_cost(b, p, res):
    log("5. cost: instructions per tick (callgrind), CPU at 50 Hz, RSS")
    b.rt_active = False  # cost is counted, not timed: normal scheduling like a default unit
    b.start_sim(realistic=False)
    cfg50 = b.daemon_config(50)
    cost = res["cost"] = {}

    # Floor instructions per cycle: two runs of different lengths, the difference divided by
    # the difference in cycles (start-up cancels out).
    totals = []
    for n in p["cg_floor_cycles"]:
        out = os.path.join(b.dir, f"cg-floor-{n}.out")
        b.floor("--cycles", n, config=cfg50,
                wrapper=("valgrind", "--tool=callgrind", f"--callgrind-out-file={out}"))
        totals.append(callgrind_total(out))
    n0, n1 = p["cg_floor_cycles"]
    cost["floor_ir_per_cycle"] = (totals[1] - totals[0]) / (n1 - n0)

    # The daemon under callgrind at 50 Hz: zero the counters after start-up, count the Cycles
    # property over a window, dump: Ir(window) / cycles. Once without commands, once with a
    # steady SetThrust stream.
    out = os.path.join(b.dir, "cg-daemon.out")
    log("   callgrind: caracarad at 50 Hz")
    # Under valgrind without [realtime]: a policy changes no instruction count, and mlockall
    # would lock valgrind's own memory.
    d = b.start_daemon(b.daemon_config(50, realtime=False), wrapper=("valgrind", "--tool=callgrind", f"--callgrind-out-file={out}"),
                       ready_timeout=120)
    time.sleep(p["cg_warm"])
    def window(label):
        dump, win = callgrind_window(b, d.pid, p["cg_window"], label)
        ir = callgrind_total(dump)
        ticks = max(1, win["cycles"])
        return {"window_cycles": win["cycles"], "window_seconds": win["seconds"], "ir": ir,
                "ir_per_tick": ir / ticks,
                "inclusive_per_tick": {k: v / ticks for k, v in callgrind_inclusive(dump, CG_FUNCTIONS).items()},
                # Allocations on the loop and the workers: the hot path's page faults and
                # allocator time start here (docs/realtime.md).
                "allocations_per_tick": {k: v / ticks for k, v in callgrind_calls(dump, ALLOCATORS).items()}}

    cg = cost["callgrind"] = {"stream_hz": p["stream_hz"]}
    cg["idle"] = window("idle")
    stream = b.spawn([b.exe["client"], "stream", "--bus", b.bus, "--hz", str(p["stream_hz"]),
                      "--seconds", str(p["cg_window"] + 60)], "stream-cg", stdout=subprocess.PIPE)
    time.sleep(2)
    cg["stream"] = window("stream")
    b.stop(stream)
    b.stop_daemon()

    # Native run at 50 Hz: CPU over a window without commands and over one with the stream;
    # the floor program over the same windows (its own CPU clock); RSS sampled every second
    # for the whole run.
    log(f"   CPU and RSS: caracarad at 50 Hz for {p['rss_seconds']:.0f} s")
    d = b.start_daemon(cfg50)
    pid = d.pid
    total = p["rss_seconds"]
    W = p["cpu_window"]
    t_start = time.monotonic()
    samples = []
    state = {"stream": None}

    def sample():
        samples.append((time.monotonic() - t_start, status_kib(pid, "VmRSS")))

    def daemon_cpu_window():
        c0, t0 = cpu_ns(pid), time.monotonic()
        cyc = subprocess.Popen([b.exe["client"], "cycles", "--bus", b.bus, "--seconds", str(W)],
                               stdout=subprocess.PIPE, text=True)
        while cyc.poll() is None:
            sample()
            time.sleep(1.0)
        c1, t1 = cpu_ns(pid), time.monotonic()
        w = json.loads(cyc.communicate()[0])
        return {"percent": 100.0 * (c1 - c0) / ((t1 - t0) * 1e9), "seconds": t1 - t0,
                "tick_rate_hz": w["rate_hz"], "ticks": w["cycles"]}

    def floor_cpu_window(*extra):
        fp = subprocess.Popen([b.exe["floor"], "--socket", b.sock, "--config", cfg50, "--seconds", str(W),
                               "--rate", "50", *extra], stdout=subprocess.PIPE, text=True)
        b.procs.append(fp)
        while fp.poll() is None:
            sample()
            time.sleep(1.0)
        fo = json.loads(fp.communicate()[0].strip().splitlines()[-1])
        return {"percent": 100.0 * fo["cpu_s"] / fo["seconds"], "rate_hz": fo["rate_hz"],
                "vmhwm_kib": fo.get("vmhwm_kib")}

    while time.monotonic() - t_start < p["cpu_warm"]:
        sample()
        time.sleep(1.0)
    cost["cpu_idle"] = daemon_cpu_window()
    state["stream"] = b.spawn([b.exe["client"], "stream", "--bus", b.bus, "--hz", str(p["stream_hz"]),
                               "--seconds", str(total + 60)], "stream", stdout=subprocess.PIPE)
    time.sleep(1.0)
    cost["cpu_stream"] = daemon_cpu_window()
    cost["floor_cpu_idle"] = floor_cpu_window()
    cost["floor_cpu_stream"] = floor_cpu_window("--burst-hz", str(p["stream_hz"]))
    while time.monotonic() - t_start < total:
        sample()
        time.sleep(1.0)
    sample()
    hwm = status_kib(pid, "VmHWM")
    b.stop(state["stream"])
    b.stop_daemon()
    b.stop_sim()
    warm_from = max(p["cpu_warm"], 0.1 * total)
    warm = [s for s in samples if s[0] >= warm_from] or samples
    tail = sorted(s[1] for s in samples if s[0] >= 0.9 * total) or [samples[-1][1]]
    cost["rss"] = {"peak_kib": hwm, "steady_kib": tail[len(tail) // 2], "after_warmup_kib": warm[0][1],
                   "end_kib": samples[-1][1], "seconds": samples[-1][0], "warmup_seconds": warm_from,
                   "growth_kib": samples[-1][1] - warm[0][1], "max_sampled_kib": max(s[1] for s in samples),
                   "samples": [[round(t, 1), v] for t, v in samples[::max(1, len(samples) // 120)]]}


# --- the table ----------------------------------------------------------------------------------

def rows_from(res, p):
    rows = []

    def row(fig, value, floor, ratio, target, met, unit=""):
        rows.append({"figure": fig, "value": value, "floor": floor, "ratio": ratio, "target": target, "met": met,
                     "unit": unit})

    if "rtt" in res:
        st, pg = res["rtt"]["setthrust_us"], res["rtt"]["ping_us"]
        r50, r99 = st["p50"] / pg["p50"], st["p99"] / pg["p99"]
        row("1. SetThrust round trip p50 (vs Peer.Ping)", st["p50"], pg["p50"], r50, "<= 1.2x", r50 <= 1.2, "us")
        row("1. SetThrust round trip p99 (vs Peer.Ping)", st["p99"], pg["p99"], r99, "<= 2x", r99 <= 2.0, "us")
        rf, pk = res["rtt"].get("refused_setthrust_us"), res["rtt"].get("ping_while_killed_us")
        if rf and rf["n"]:
            row("   diagnostic: SetThrust refused while killed, p50", rf["p50"], pk["p50"], rf["p50"] / pk["p50"],
                "info", None, "us")
        bs, bp = res["rtt"].get("back_to_back_setthrust_us"), res["rtt"].get("back_to_back_ping_us")
        if bs and bs["n"]:
            row("   diagnostic: back to back, no settle gap, p50", bs["p50"], bp["p50"], bs["p50"] / bp["p50"],
                "info", None, "us")
        rr = res.get("rtt_realistic")
        if rr and rr["setthrust_us"]["n"]:
            s2, p2 = rr["setthrust_us"], rr["ping_us"]
            row("   diagnostic: realistic 100 kHz wire, p50", s2["p50"], p2["p50"], s2["p50"] / p2["p50"],
                "info", None, "us")
            row("   diagnostic: realistic 100 kHz wire, p99", s2["p99"], p2["p99"], s2["p99"] / p2["p99"],
                "info", None, "us")
    if "wire" in res:
        for rate in ("50", "0"):
            w = res["wire"].get(rate)
            if not w:
                continue
            label = "50 Hz" if rate == "50" else "rate 0"
            c = w["cmd"]
            fl = c["floor_us"]
            row(f"2. command to wire p50, {label}", c["last_us"]["p50"], fl, c["last_us"]["p50"] / fl,
                "info", None, "us")
            # Issue 25's goal: the seam floor measured in the same blocks, plus 0.5 ms.
            seam99 = w["seam"]["burst_us"]["p99"] if "seam" in w else fl
            row(f"2. command to wire p99, {label}", c["last_us"]["p99"], fl, c["last_us"]["p99"] / fl,
                "<= seam p99 + 0.5 ms", c["last_us"]["p99"] <= seam99 + 500, "us")
            if "seam" in w:
                sb = w["seam"]["burst_us"]
                row(f"   seam floor p50 (floor program, 8 orders), {label}", sb["p50"], fl, sb["p50"] / fl,
                    "info", None, "us")
                row(f"   seam floor p99 (floor program, 8 orders), {label}", sb["p99"], fl, sb["p99"] / fl,
                    "info", None, "us")
            k = w["kill_dbus"]
            row(f"3. Kill() to wire p99, {label}", k["all_zero_us"]["p99"], k["floor_us"],
                k["all_zero_us"]["p99"] / k["floor_us"], "<= 1.25x", k["all_zero_us"]["p99"] <= 1.25 * k["floor_us"],
                "us")
            if "kill_switch" in w:
                k = w["kill_switch"]
                # From the simulator's kill switch edge (its "gpio" wire-log entry); a simulator
                # that does not log the edge leaves the client's clock before SetKillSwitch.
                fig = ("3. kill switch edge to wire p99" if k.get("start") == "edge"
                       else "3. SetKillSwitch call to wire p99 (no edge in the wire log)")
                row(f"{fig}, {label}", k["all_zero_us"]["p99"], k["floor_us"],
                    k["all_zero_us"]["p99"] / k["floor_us"], "<= 1.25x",
                    k["all_zero_us"]["p99"] <= 1.25 * k["floor_us"], "us")
                v = k.get("edge_via_dbus_us")
                if v and v["n"]:
                    hop = k["dbus_to_edge_us"]["p50"]
                    row(f"   diagnostic: from before SetKillSwitch p99 (hop p50 {hop:.0f} us), {label}", v["p99"],
                        k["floor_us"], v["p99"] / k["floor_us"], "info", None, "us")
        if not res.get("kill_switch_available"):
            rows.append({"figure": "3. kill switch edge: not available in this build", "value": None, "floor": None,
                         "ratio": None, "target": "", "met": None, "unit": ""})
    if "faults" in res:
        for key, label in (("healthy", "healthy bus"), ("hung", "a thruster holding each transfer 0.9 s"),
                           ("teensy_hung", "the Teensy holding each SPI frame 0.5 s")):
            f = res["faults"].get(key, {})
            for src, name in (("dbus", "Kill()"), ("switch", "kill switch edge")):
                k = f.get(src)
                if not k:
                    continue
                v = k["kill_output_us"]
                row(f"6. {name} to kill output p50, {label}", v["p50"], None, None, "info", None, "us")
                row(f"6. {name} to kill output p99, {label} ({k['missing']} missing)", v["p99"], None, None,
                    "<= 500 us", v["p99"] <= 500 and k["missing"] == 0, "us")
            r = f.get("rtt")
            if r:
                pg = r["ping_us"]
                row(f"6. Peer.Ping p99 with {label}", pg["p99"], None, None, "info", None, "us")
    kf = (res.get("kill_floor") or {}).get("kill_output_us")
    if kf:
        row("6. kill switch edge to kill output p99, the floor program (edge read, output written)", kf["p99"],
            None, None, "info", None, "us")
        sw = ((res.get("faults") or {}).get("healthy") or {}).get("switch")
        if sw:
            v = sw["kill_output_us"]["p99"]
            row("6. kill switch edge to kill output p99, healthy, vs the floor program", v, kf["p99"], v / kf["p99"],
                "<= 1.5x floor", v <= 1.5 * kf["p99"], "us")
    tick_row(res, "4b. ", row)
    loaded_rows(res, row)
    if "loop" in res:
        for key, label in (("realistic", "realistic 100 kHz"), ("immediate", "sim answers at once")):
            l = res["loop"].get(key)
            if l:
                r = l["median_round_ratio"]
                row(f"4. loop rate, rate 0, {label}", l["daemon_hz"], l["floor_hz"], r, ">= 0.95x", r >= 0.95, "Hz")
    if "cost" in res:
        c = res["cost"]
        cg = c.get("callgrind", {})
        for key, label, goal in (("idle", "no commands", 25000),
                                 ("stream", f"{cg.get('stream_hz', 20)} Hz SetThrust stream", 55000)):
            if key in cg:
                v = cg[key]["ir_per_tick"]
                row(f"5. instructions per tick, 50 Hz, {label}", v, c["floor_ir_per_cycle"],
                    v / c["floor_ir_per_cycle"], f"<= {goal}", v <= goal, "Ir")
        for key, label in (("idle", "no commands"), ("stream", f"{cg.get('stream_hz', 20)} Hz SetThrust stream")):
            al = (cg.get(key) or {}).get("allocations_per_tick")
            if al is not None:
                row(f"5. allocations per tick (malloc, calloc, realloc, new), 50 Hz, {label}", sum(al.values()), None,
                    None, "info", None, "")
        for key, fkey, label in (("cpu_idle", "floor_cpu_idle", "no commands"),
                                 ("cpu_stream", "floor_cpu_stream", f"{cg.get('stream_hz', 20)} Hz stream")):
            if c.get(key):
                fl = (c.get(fkey) or {}).get("percent")
                v = c[key]["percent"]
                row(f"5. CPU at 50 Hz, {label} (% of a core)", v, fl, v / fl if fl else None, "<= 1.2x floor",
                    bool(fl) and v <= 1.2 * fl, "%")
        if c.get("cpu_idle"):
            v = c["cpu_idle"]["tick_rate_hz"]
            row("   achieved tick rate at loop_rate_hz=50", v, 50.0, v / 50.0, ">= 0.99x", v >= 49.5, "Hz")
        if c.get("rss"):
            fl = (c.get("floor_cpu_idle") or {}).get("vmhwm_kib")
            rs = c["rss"]
            row(f"5. RSS peak over {rs['seconds']:.0f} s", rs["peak_kib"], fl, rs["peak_kib"] / fl if fl else None,
                "< 8 MiB", rs["peak_kib"] < 8192, "KiB")
            row("5. RSS steady (median of the last 10%)", rs["steady_kib"], fl, None, "< 8 MiB",
                rs["steady_kib"] < 8192, "KiB")
            row(f"5. RSS growth from {rs['warmup_seconds']:.0f} s to the end", rs["growth_kib"], 0, None,
                "flat (<= 64 KiB)", rs["growth_kib"] <= 64, "KiB")
    rs = res.get("rtt_ssh")
    if rs and rs["setthrust_us"]["n"]:
        st, pg = rs["setthrust_us"], rs["ping_us"]
        row("7. SSH bridge: SetThrust round trip p50 (vs Peer.Ping, same bridge)", st["p50"], pg["p50"],
            st["p50"] / pg["p50"], "info", None, "us")
        row("7. SSH bridge: SetThrust round trip p99 (vs Peer.Ping, same bridge)", st["p99"], pg["p99"],
            st["p99"] / pg["p99"], "info", None, "us")
        if "rtt" in res:
            lp = res["rtt"]["ping_us"]
            row("   diagnostic: Peer.Ping p50, SSH bridge vs local", pg["p50"], lp["p50"], pg["p50"] / lp["p50"],
                "info", None, "us")
        if "ssh_connect_ms" in res:
            row("   diagnostic: a whole busctl -H call (login, bridge, Hello, Ping), median", res["ssh_connect_ms"],
                None, None, "info", None, "ms")
    br = res.get("bridge")
    if br:
        lt = br["leds_to_state_us"]
        row("8. bridge: property change to the client's message p50 (publish leds to /vehicle/state)", lt["p50"],
            None, None, "info", None, "us")
        row("8. bridge: property change to the client's message p99", lt["p99"], None, None, "info", None, "us")
        mb, md = br["bridge_motion_to_wire_us"], br["dbus_setmotion_to_wire_us"]
        row("8. bridge: published motion to the wire p50 (vs SetMotion over D-Bus)", mb["p50"], md["p50"],
            mb["p50"] / md["p50"], "info", None, "us")
        row("8. bridge: published motion to the wire p99 (vs SetMotion over D-Bus)", mb["p99"], md["p99"],
            mb["p99"] / md["p99"], "info", None, "us")
        if "cockpit_pad_to_wire_us" in br:
            cp, cd = br["cockpit_pad_to_wire_us"], br["dbus_setmotion_to_wire_us_cockpit_run"]
            for q in ("p50", "p99"):
                row(f"8. cockpit: gamepad sample in the page to the wire {q} (vs SetMotion over D-Bus; clock "
                    f"+-{br['clock_uncertainty_us']:.0f} us)", cp[q], cd[q], cp[q] / cd[q], "info", None, "us")
        for k, v in sorted(br["load"].items()):
            row(f"8. bridge CPU, {k} client(s) subscribed to everything", v["cpu_percent"], None, None, "info", None,
                "%")
            row(f"8. bridge RSS, {k} client(s) subscribed to everything", v["rss_kib"], None, None, "info", None, "KiB")
        if "kill_during_listing_ms" in br:
            kl, kn = br["kill_during_listing_ms"], br["kill_no_listing_ms"]
            for q in ("p50", "p99"):
                row(f"8. bridge: Kill to the kill output {q} while another client lists 256 MB of dives (vs no "
                    f"listing)", kl[q], kn[q], kl[q] / kn[q], "info", None, "ms")
            row("8. bridge: a client's close to zeros, max, while another client lists 256 MB of dives",
                br["close_during_listing_ms"]["max"], None, None, "info", None, "ms")
    return rows


# One status read at 100 kHz that may be on the wire ahead of the zeros (issue 25).
STATUS_READ_US = 740


def tick_row(h, prefix, row):
    tk = h.get("ticks")
    if tk:
        v = tk["lateness_us"]["p99"]
        row(f"{prefix}loop tick lateness p99, 50 Hz, on the wire ({tk['ticks']} ticks, {tk['missed']} missed)",
            v, None, None, "<= 500 us, none missed", v <= 500 and tk["missed"] == 0, "us")


def loaded_rows(res, row):
    """Row 9: the loaded phase beside its quiet half (same run, same priorities)."""
    ld = res.get("loaded")
    if not ld or "loaded" not in ld:
        return
    qt, lo = ld["quiet"], ld["loaded"]
    for key, label in (("healthy", "healthy bus"), ("hung", "a thruster hung"), ("teensy_hung", "the Teensy hung")):
        for src, name in (("dbus", "Kill()"), ("switch", "kill switch edge")):
            lk = ((lo.get("faults") or {}).get(key) or {}).get(src)
            qk = ((qt.get("faults") or {}).get(key) or {}).get(src)
            if not lk or not qk:
                continue
            v, q = lk["kill_output_us"]["p99"], qk["kill_output_us"]["p99"]
            row(f"9. {name} to kill output p99, {label}: loaded ({lk['missing']} missing) vs quiet", v, q, v / q,
                "<= 1.5x quiet", v <= 1.5 * q and lk["missing"] == 0, "us")
    for half, h in (("quiet", qt), ("loaded", lo)):
        tick_row(h, f"9. {half}: ", row)
        fl = (h.get("kill_floor") or {}).get("kill_output_us")
        sw = (((h.get("faults") or {}).get("healthy") or {}).get("switch") or {}).get("kill_output_us")
        if fl and sw:
            row(f"9. {half}: kill switch edge to kill output p99, healthy, vs the floor program", sw["p99"],
                fl["p99"], sw["p99"] / fl["p99"], "<= 1.5x floor", sw["p99"] <= 1.5 * fl["p99"], "us")
        for rate in ("50", "0"):
            w = (h.get("wire") or {}).get(rate)
            if not w or "seam" not in w:
                continue
            label = "50 Hz" if rate == "50" else "rate 0"
            seam = w["seam"]["burst_us"]["p99"]
            c = w["cmd"]["last_us"]["p99"]
            row(f"9. {half}: command to wire p99, {label}, vs seam floor p99", c, seam, c / seam,
                "<= seam p99 + 0.5 ms", c <= seam + 500, "us")
            for src, name in (("kill_dbus", "Kill()"), ("kill_switch", "kill switch edge")):
                k = w.get(src)
                if k:
                    v = k["all_zero_us"]["p99"]
                    row(f"9. {half}: {name} to last zero on the wire p99, {label}, vs seam floor p99", v, seam,
                        v / seam, "<= seam p99 + 740 us", v <= seam + STATUS_READ_US, "us")


def strip_raw(obj):
    """Drops the per-sample arrays (kept with --raw)."""
    if isinstance(obj, dict):
        obj.pop("raw", None)
        for v in obj.values():
            strip_raw(v)
    elif isinstance(obj, list):
        for v in obj:
            strip_raw(v)


def fmt(v, unit=""):
    if v is None:
        return "-"
    if isinstance(v, bool):
        return "yes" if v else "NO"
    if unit == "%":
        return f"{v:.3f}"
    if abs(v) >= 1000:
        return f"{v:,.0f}"
    return f"{v:.1f}" if abs(v) >= 10 else f"{v:.3f}"


def print_table(rows, out=sys.stdout):
    hdr = ("figure", "value", "floor", "ratio", "target", "met?")
    lines = []
    for r in rows:
        if r["value"] is None:
            lines.append((r["figure"], "", "", "", "", ""))
            continue
        ratio = "-" if r["ratio"] is None else f"{r['ratio']:.2f}x"
        met = "-" if r["met"] is None else ("yes" if r["met"] else "NO")
        lines.append((r["figure"], f"{fmt(r['value'], r['unit'])} {r['unit']}", f"{fmt(r['floor'], r['unit'])}",
                      ratio, r["target"], met))
    widths = [max(len(hdr[i]), *(len(l[i]) for l in lines)) for i in range(6)]
    print("  ".join(h.ljust(widths[i]) for i, h in enumerate(hdr)), file=out)
    print("  ".join("-" * w for w in widths), file=out)
    for l in lines:
        print("  ".join((l[i].ljust(widths[i]) if i in (0, 4) else l[i].rjust(widths[i])) for i in range(6)),
              file=out)


# Every phase, in the order a full run takes them (bench/report.py: a record missing one is partial).
ALL_PHASES = ["dbus", "wire", "faults", "kill_floor", "loop", "cost", "ssh", "bridge", "loaded"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", required=True, help="build tree with caracarad, caracara-sim and bench/")
    ap.add_argument("--out", default=os.path.join(HERE, "results.json"), help="JSON results (default bench/results.json)")
    ap.add_argument("--quick", action="store_true", help="shorten every phase (smoke run)")
    ap.add_argument("--rss-seconds", type=float, default=None, help="length of the RSS run (default 600, quick 20)")
    ap.add_argument("--only", default=",".join(ALL_PHASES),
                    help="comma-separated phases: " + ",".join(ALL_PHASES) +
                         " (loaded: wire, faults and kill_floor without and with stress-ng, at the same priorities)")
    ap.add_argument("--keep", action="store_true", help="keep the temporary directory (logs, callgrind files)")
    ap.add_argument("--raw", action="store_true", help="keep every latency sample in the JSON (large)")
    ap.add_argument("--rt", action="store_true",
                    help="run the bus, simulator, daemon, client and floor of the latency and loop-rate phases "
                         "under SCHED_FIFO (chrt -f 10), shielding them from other load on the machine")
    a = ap.parse_args()

    if a.quick:
        p = dict(rtt_calls=2000, rtt_warmup=200, cmd_samples=100, kill_samples=40, burst_samples=40, wire_blocks=2,
                 loop_rounds=2, loop_window=2, cg_floor_cycles=(50, 250), cg_warm=3, cg_window=4, stream_hz=20,
                 cpu_warm=3, cpu_window=5, rss_seconds=30, bridge_samples=100, tick_seconds=10)
    else:
        p = dict(rtt_calls=10000, rtt_warmup=500, cmd_samples=1000, kill_samples=300, burst_samples=300, wire_blocks=10,
                 loop_rounds=6, loop_window=5, cg_floor_cycles=(200, 1200), cg_warm=5, cg_window=20, stream_hz=20,
                 cpu_warm=10, cpu_window=30, rss_seconds=600, bridge_samples=1000, tick_seconds=60)
    if a.rss_seconds is not None:
        p["rss_seconds"] = a.rss_seconds
    p["rss_seconds"] = max(p["rss_seconds"], p["cpu_warm"] + p["cpu_window"] * 4 + 10)

    b = Bench(os.path.abspath(a.build), a.quick, a.keep)
    b.rt = a.rt

    def on_signal(signum, _frame):
        b.cleanup()
        sys.exit(128 + signum)
    signal.signal(signal.SIGTERM, on_signal)
    signal.signal(signal.SIGINT, on_signal)

    res = {"quick": a.quick, "rt": a.rt, "params": p, "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
           "host": {"nproc": os.cpu_count(), "uname": " ".join(os.uname())}}
    phases = {"dbus": phase_dbus, "wire": phase_wire, "faults": phase_faults, "loop": phase_loop, "cost": phase_cost,
              "ssh": phase_ssh, "bridge": phase_bridge, "kill_floor": phase_kill_floor, "loaded": phase_loaded,
              "ticks": phase_ticks}  # ticks alone: the loaded phase runs it in both halves
    try:
        b.start_bus()
        for name in a.only.split(","):
            t0 = time.monotonic()
            try:
                phases[name](b, p, res)
            except Exception as e:  # a broken phase must not hide the others' figures
                log(f"phase {name} failed: {e}")
                res.setdefault("errors", {})[name] = str(e)
                b.stop_daemon()
                b.stop_sim()
            res.setdefault("phase_seconds", {})[name] = round(time.monotonic() - t0, 1)
    finally:
        if a.keep:
            log(f"logs kept in {b.dir}")
        b.cleanup()
    rows = rows_from(res, p)
    if not a.raw:
        strip_raw(res)
    res["table"] = rows
    res["finished"] = time.strftime("%Y-%m-%dT%H:%M:%S%z")
    with open(a.out, "w") as f:
        json.dump(res, f, indent=1)
    print()
    print_table(rows)
    if res.get("kill_switch_available") is False:
        print("\nkill switch edge: not available in this build")
    print(f"\nfigures written to {a.out}")


if __name__ == "__main__":
    main()
