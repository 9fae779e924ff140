#!/usr/bin/python3
"""caracara-ros's bench row (docs/ros2.md). It prints figures and never fails on time.

  latency  a geometry_msgs/Wrench published by the Fast DDS peer (tests/ros/peer.cpp) to the
           first order on the wire that carries it, p50/p99. Beside it, in the same run and on
           the same rig, SetMotion over D-Bus (python3-dbus, synchronous) to its first order.
           Both clocks are CLOCK_MONOTONIC: the peer's at each write, the simulator's wire log
           at the end of each transfer.
  cost     caracara-ros's CPU (utime+stime over the window) and RSS (VmRSS, VmHWM) while
           caracarad announces at its 50 Hz loop rate (a pilot sweeps the thrust at 50 Hz), with
           the peer subscribed to every topic. Also the samples per second the peer got on joint_states.

    bench/ros_bench.py [--samples N] [--cost-seconds S] [--out FILE]

It needs a build (CARACARA_BUILD_DIR, default build/ in the repository) and the test peer's
tools (scripts/deps.sh). Like tests/ros, it runs in a private network namespace (it re-runs
itself under `unshare --net`), so nothing leaves the machine.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(HERE)
os.environ.setdefault("CARACARA_BUILD_DIR", os.path.join(SOURCE, "build"))
sys.path.insert(0, os.path.join(SOURCE, "tests", "e2e"))
sys.path.insert(0, os.path.join(SOURCE, "tests", "ros"))


def in_private_namespace():
    links = subprocess.run(["ip", "-o", "link"], capture_output=True, text=True, check=True).stdout.splitlines()
    return [line.split(":")[1].strip() for line in links] == ["lo"]


if not in_private_namespace():
    os.execvp("unshare", ["unshare", "--net", sys.executable] + sys.argv)

import harness  # noqa: E402
from harness import BUILD_DIR, MOTORS, ZERO, Rig, poll  # noqa: E402
from test_failsafes import orders  # noqa: E402
from test_ros import Codec, build_peer, network_is_private  # noqa: E402


def percentile(values, p):
    s = sorted(values)
    return s[min(len(s) - 1, int(round(p / 100 * (len(s) - 1))))]


def summary(values_ms):
    return {"n": len(values_ms), "p50_ms": round(percentile(values_ms, 50), 3),
            "p99_ms": round(percentile(values_ms, 99), 3), "max_ms": round(max(values_ms), 3)}


def latencies(rig, sends, expected, thruster, since):
    """For each (t_ns, sample index), the first order to `thruster` after it with the byte that sample gives."""
    log = [(e.time_ns, speed) for e, i, speed in orders(rig.wire_log(since)[1]) if i == thruster]
    out = []
    for t, k in sends:
        hit = next((when for when, speed in log if when >= t and speed == expected[k % 2]), None)
        if hit is not None:
            out.append((hit - t) / 1e6)
    return out


def start_ros(rig, commands):
    conf = os.path.join(rig.dir, "ros.toml")
    with open(conf, "w") as f:
        f.write('[ros]\ncommands = %s\n[network]\ninterface = "lo"\n' % ("true" if commands else "false"))
    name = "caracara-ros"
    p = rig._spawn(name, harness.EMULATOR + [os.path.join(BUILD_DIR, "tools", "ros", "caracara-ros"),
                                             "--bus-address", rig.address, "--config", conf])
    poll(lambda: "commands" in rig.log(name) or p.poll() is not None, 20, message="caracara-ros did not start")
    return p


DRIVER = """
import math, sys, time, dbus, dbus.bus
bus = dbus.bus.BusConnection(sys.argv[1])
v = dbus.Interface(bus.get_object("org.caracara.Vehicle1", "/org/caracara/Vehicle1"), "org.caracara.Vehicle1")
end = time.monotonic() + float(sys.argv[2])
k = 0
while time.monotonic() < end:
    x = int(3000 * math.sin(k / 10))
    v.SetThrust(dbus.Array([x, -x, x, -x, x, -x, x, -x], signature="i"))
    k += 1
    time.sleep(0.02)
"""


def proc_cpu_s(pid):
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def proc_kb(pid, key):
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1])
    return 0


def bench_latency(peer, codec, n):
    rig = Rig(control={"arming_delay_ms": 0, "command_timeout_ms": 60000},
              extra_config={"failsafe": {"pilot-lost": {"action": "kill", "persistence_ms": 60000}}})
    rig.start()
    try:
        rig.arm()
        start_ros(rig, True)
        values = (0.3, 0.5)
        # The bytes each value gives on the thruster that moves most (the daemon's mixing), for
        # forward: SetMotion's y in the seed's axes, a Wrench's force.x in REP 103's (docs/frames.md).
        expected = []
        for v in values:
            rig.motion(y=v)
            expected.append(poll(lambda: rig.sim_speeds() if rig.sim_speeds() != [ZERO] * MOTORS else None, 10))
        thruster = max(range(MOTORS), key=lambda i: abs(expected[0][i] - ZERO))
        assert expected[0][thruster] != expected[1][thruster]
        expected = [e[thruster] for e in expected]
        rig.motion()
        rig.wait_sim_zero()
        # SetMotion over D-Bus, alternating, 20 per second.
        since = rig.wire_next()
        sends = []
        for k in range(n):
            t = time.monotonic_ns()
            rig.motion(y=values[k % 2])
            sends.append((t, k))
            time.sleep(0.05)
        dbus_ms = latencies(rig, sends, expected, thruster, since)
        rig.rearm()  # this connection is no pilot any more; the peer's is the next
        rig.arm()
        # The same through DDS: the peer's writes, its own pilot connection in caracara-ros.
        hexes = [codec.encode("geometry_msgs/Wrench", {"force": {"x": v, "y": 0, "z": 0},
                                                       "torque": {"x": 0, "y": 0, "z": 0}}) for v in values]
        since = rig.wire_next()
        r = subprocess.run([peer, "publish", "rt/caracara/cmd_wrench", "geometry_msgs/Wrench", ",".join(hexes),
                            str(n), "20"], capture_output=True, text=True, timeout=n + 60)
        if r.returncode != 0:
            raise RuntimeError(r.stderr)
        sends = [(json.loads(line)["t_ns"], json.loads(line)["sent"]) for line in r.stdout.splitlines()]
        dds_ms = latencies(rig, sends, expected, thruster, since)
        rig.terminate("caracara-ros")
        # The writer's first sample also opens its pilot connection to the bus: reported apart.
        return {"dbus_setmotion": summary(dbus_ms), "dds_wrench": summary(dds_ms[1:]),
                "dds_first_wrench_ms": round(dds_ms[0], 3)}
    finally:
        rig.stop()


def bench_cost(peer, seconds):
    rig = Rig(control={"arming_delay_ms": 0, "command_timeout_ms": 60000})
    rig.start()
    try:
        rig.arm()
        ros = start_ros(rig, False)
        # A pilot sweeping the thrust at 50 Hz, so that the values change on every loop cycle and
        # the daemon announces them at its 50 Hz (a constant thrust announces little).
        driver = subprocess.Popen([harness.PYTHON, "-c", DRIVER, rig.address, str(seconds + 4)])
        time.sleep(1)
        topics = ["rt/caracara/imu=sensor_msgs/Imu", "rt/caracara/joint_states=sensor_msgs/JointState",
                  "rt/caracara/thrusters/ordered=sensor_msgs/JointState", "rt/caracara/range/0=sensor_msgs/Range",
                  "rt/diagnostics=diagnostic_msgs/DiagnosticArray", "rt/tf=tf2_msgs/TFMessage",
                  "rt/caracara/state=std_msgs/String"]
        listener = subprocess.Popen([peer, "listen", str(seconds + 2)] + topics, stdout=subprocess.PIPE, text=True)
        time.sleep(1)
        cpu0, t0 = proc_cpu_s(ros.pid), time.monotonic()
        time.sleep(seconds)
        cpu1, t1 = proc_cpu_s(ros.pid), time.monotonic()
        rss, hwm = proc_kb(ros.pid, "VmRSS"), proc_kb(ros.pid, "VmHWM")
        out = listener.communicate(timeout=seconds + 30)[0]
        joint = sum(1 for line in out.splitlines() if '"rt/caracara/joint_states"' in line)
        loop_hz = float(rig.vget("LoopRateHz"))
        driver.wait(30)
        rig.terminate("caracara-ros")
        return {"window_s": round(t1 - t0, 2), "cpu_percent_of_one_core": round(100 * (cpu1 - cpu0) / (t1 - t0), 2),
                "rss_kb": rss, "hwm_kb": hwm, "joint_states_per_s": round(joint / (seconds + 1), 1),
                "daemon_loop_rate_hz": round(loop_hz, 1)}
    finally:
        rig.stop()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--samples", type=int, default=200)
    ap.add_argument("--cost-seconds", type=float, default=20.0)
    ap.add_argument("--out")
    a = ap.parse_args()
    network_is_private()
    peer = build_peer("humble")
    codec = Codec()
    try:
        results = {"latency": bench_latency(peer, codec, a.samples), "cost": bench_cost(peer, a.cost_seconds)}
    finally:
        codec.close()
    lat, cost = results["latency"], results["cost"]
    print("caracara-ros bench (%s)" % time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()))
    print("  to the first order on the wire    n     p50 ms   p99 ms   max ms")
    for name, label in (("dbus_setmotion", "SetMotion over D-Bus"), ("dds_wrench", "Wrench over DDS (Fast DDS peer)")):
        s = lat[name]
        print("  %-32s %4d  %8.3f %8.3f %8.3f" % (label, s["n"], s["p50_ms"], s["p99_ms"], s["max_ms"]))
    print("  the writer's first Wrench (opens its pilot connection): %.3f ms" % lat["dds_first_wrench_ms"])
    print("  caracara-ros at the daemon's %.0f Hz: CPU %.2f %% of one core over %.0f s, RSS %d kB (peak %d kB), "
          "joint_states %.1f/s" % (cost["daemon_loop_rate_hz"], cost["cpu_percent_of_one_core"], cost["window_s"],
                                    cost["rss_kb"], cost["hwm_kb"], cost["joint_states_per_s"]))
    if a.out:
        with open(a.out, "w") as f:
            json.dump(results, f, indent=1)
            f.write("\n")


if __name__ == "__main__":
    main()
