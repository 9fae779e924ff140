"""End-to-end test harness: a private D-Bus, caracara-sim and caracarad in a temporary directory.

Every test talks to caracarad (org.caracara.Vehicle1) the way a user does, and checks the
result on the simulator's side (org.caracara.Simulator1), which plays the hardware and knows
nothing of what the daemon claims.

    rig = Rig(control={"arming_delay_ms": 300})
    rig.start()                      # dbus-daemon, caracara-sim, caracarad; waits for the name
    rig.arm()                        # it starts killed (source "start"): ClearKill, wait for ready
    rig.thrust([1000, 0, 0, 0, 0, 0, 0, 0])
    poll(lambda: rig.sim_speeds()[0] == speed_byte(1000))
    rig.stop_checked()               # SIGTERM, wait, SIGKILL fallback, directory removed;
                                     # fails if a process did not exit cleanly

VehicleTestCase starts one rig per test class (configured by class attributes) and tears it
down even when setUpClass fails. Binaries come from $CARACARA_BUILD_DIR (default
/tmp/build-e2e). Set CARACARA_KEEP_TEST_DIR=1 to keep the directories and logs.

Needs Debian's /usr/bin/python3 with python3-dbus and python3-gi.
"""

import atexit
import ctypes
import math
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from collections import namedtuple

import dbus
import dbus.mainloop.glib
from gi.repository import GLib

# The npm packages the Node tests pin (tests/bridge, tests/ros): tests/npm_packages.py.
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import npm_packages  # noqa: E402

CI_RUN = os.environ.get("CI") == "true"


def missing(what):
    """A tool a test needs is missing: fails under CI, skips elsewhere."""
    if CI_RUN:
        raise AssertionError("cannot run under CI: " + what)
    raise unittest.SkipTest(what)


def npm_ci(here):
    """Checks that node_modules in `here` are what its package-lock.json pins. Never installs: a test
    may run in a namespace without network (e2e_ros: unshare --net); CTest's setup tests npm_bridge
    and npm_ros install them beforehand (tests/npm_packages.py, FIXTURES_REQUIRED)."""
    if not shutil.which("node"):
        missing("node is needed (scripts/deps.sh)")
    why = npm_packages.stale(here)
    if why is None:
        return
    if not shutil.which("npm"):
        missing("npm is needed to install %s's packages (scripts/deps.sh)" % here)
    raise AssertionError("%s: the CTest setup test %s installs them (tests/npm_packages.py %s), outside any "
                         "network namespace; this test does not fetch" % (why, npm_packages.fixture(here), here))


# --- where things are -----------------------------------------------------------------------

BUILD_DIR = os.environ.get("CARACARA_BUILD_DIR") or "/tmp/build-e2e"
PYTHON = "/usr/bin/python3"
HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE_DIR = os.path.dirname(os.path.dirname(HERE))


def binary(name):
    """Path of a built program: caracarad, caracara-sim or caracaractl."""
    sub = {"caracarad": "daemon", "caracara-sim": "sim", "caracaractl": "tools"}[name]
    return os.path.join(BUILD_DIR, sub, name)


# A cross build's programs are foreign binaries: they run through the emulator ctest runs the
# tests with (CARACARA_TEST_EMULATOR, set by tests/CMakeLists.txt), while python3, busctl and
# dbus-daemon stay native.
EMULATOR = os.environ.get("CARACARA_TEST_EMULATOR", "").split()
# ASan+UBSan builds (CARACARA_SANITIZE): correct, but their CPU time is the instrumentation's.
SANITIZED = os.environ.get("CARACARA_TEST_SANITIZED") == "1"


def command(name):
    """The argv that starts a built program (before its arguments)."""
    return EMULATOR + [binary(name)]


# --- the D-Bus names -------------------------------------------------------------------------

VEHICLE = "org.caracara.Vehicle1"
ROOT = "/org/caracara/Vehicle1"
THRUSTER_IFACE = "org.caracara.Vehicle1.Thruster"
TEENSY_IFACE = "org.caracara.Vehicle1.Teensy"
BUS_IFACE = "org.caracara.Vehicle1.Bus"
TEENSY_PATH = ROOT + "/teensy"
BUS_PATH = ROOT + "/bus"
ERR = "org.caracara.Vehicle1.Error."
INVALID_ARGS = "org.freedesktop.DBus.Error.InvalidArgs"

SIM = "org.caracara.Simulator1"
SIM_ROOT = "/org/caracara/Simulator1"
SIM_THRUSTER_IFACE = "org.caracara.Simulator1.Thruster"
SIM_TEENSY_IFACE = "org.caracara.Simulator1.Teensy"
SIM_TEENSY_PATH = SIM_ROOT + "/teensy"

PROPS = "org.freedesktop.DBus.Properties"


def thruster_path(i):
    return "%s/thruster/%d" % (ROOT, i)


def sim_thruster_path(i):
    return "%s/thruster/%d" % (SIM_ROOT, i)


# --- the vehicle's facts, computed independently of the daemon -------------------------------

MOTORS = 8
MOTOR_MAX = 8850
DEFAULT_MT = [0x52, 0x56, 0x58, 0x5A, 0x5C, 0x5E, 0x60, 0x62]
INFO = 100
ZERO = 0x80

# The packet seed's axis table: axis -> {motor: sign}. Axes: x (+port), y (+forward),
# z (+deeper), yaw (+clockwise from above), pitch (+nose up), roll (+clockwise from behind).
AXES = ["x", "y", "z", "yaw", "pitch", "roll"]
SEED_AXIS_MOTORS = {
    "x": {2: +1, 6: +1, 0: -1, 4: -1},
    "y": {0: +1, 2: +1, 4: +1, 6: +1},
    "z": {1: +1, 3: +1, 5: +1, 7: +1},
    "yaw": {0: +1, 2: +1, 4: -1, 6: -1},
    "pitch": {3: +1, 5: +1, 1: -1, 7: -1},
    "roll": {5: +1, 7: +1, 1: -1, 3: -1},
}


def budget_limit(running):
    """The seed's absolute maximum for the number of running motors (stricter row in between)."""
    if running <= 0:
        return MOTOR_MAX
    if running <= 2:
        return 7850
    if running <= 4:
        return 5750
    return 4200


def speed_byte(value):
    """Motor value -> SEABOTIX SPEED byte: steps = round(|v| * 102 / 8850), half up."""
    steps = (abs(int(value)) * 102 + 4425) // 8850
    if steps == 0:
        return ZERO
    return 0x80 + steps if value > 0 else 0x7F - steps


def order_bytes(mt, value, info=INFO):
    """The three bytes of an order after the address: [SPEED, INFO, CSUM]."""
    s = speed_byte(value)
    return [s, info, (mt + s + info) & 0xFF]


def angle_diff(a, b):
    """a - b wrapped into [-pi, pi]."""
    d = (a - b) % (2 * math.pi)
    return d - 2 * math.pi if d > math.pi else d


# --- the contract: dbus/*.xml --------------------------------------------------------------

CONTRACT_DIR = os.path.join(SOURCE_DIR, "dbus")
EMITS = "org.freedesktop.DBus.Property.EmitsChangedSignal"


def parse_interfaces(xml_text):
    """{interface name: {"methods", "properties", "signals", "annotations"}} from introspection
    XML. Methods and signals keep their argument order; properties map to (type, access,
    {annotation: value})."""
    import xml.etree.ElementTree as ET
    root = ET.fromstring(xml_text)
    out = {}
    for iface in root.findall("interface"):
        def annotations(el):
            return {a.get("name"): a.get("value") for a in el.findall("annotation")}

        def args(el, default_dir):
            return [(a.get("name"), a.get("type"), a.get("direction", default_dir)) for a in el.findall("arg")]

        out[iface.get("name")] = {
            "methods": {m.get("name"): {"args": args(m, "in"), "annotations": annotations(m)}
                        for m in iface.findall("method")},
            "method_order": [m.get("name") for m in iface.findall("method")],
            "properties": {p.get("name"): {"type": p.get("type"), "access": p.get("access"),
                                           "annotations": annotations(p)}
                           for p in iface.findall("property")},
            "signals": {s.get("name"): {"args": args(s, "out"), "annotations": annotations(s)}
                        for s in iface.findall("signal")},
            "annotations": annotations(iface),
        }
    return out


def load_contract():
    """Every interface of the checked-in dbus/*.xml files, keyed by interface name."""
    import glob
    out = {}
    for path in sorted(glob.glob(os.path.join(CONTRACT_DIR, "*.xml"))):
        with open(path) as f:
            for name, iface in parse_interfaces(f.read()).items():
                iface["file"] = os.path.basename(path)
                out[name] = iface
    return out


def dbus_signature(v):
    """The D-Bus type signature of a value python-dbus unmarshalled."""
    simple = {dbus.Boolean: "b", dbus.Byte: "y", dbus.Int16: "n", dbus.UInt16: "q", dbus.Int32: "i",
              dbus.UInt32: "u", dbus.Int64: "x", dbus.UInt64: "t", dbus.Double: "d", dbus.String: "s",
              dbus.ObjectPath: "o", dbus.Signature: "g"}
    t = type(v)
    if t in simple:
        return simple[t]
    if t is dbus.Array:
        return "a" + str(v.signature)
    if t is dbus.Dictionary:
        return "a{" + str(v.signature) + "}"
    if t is dbus.Struct:
        return "(" + "".join(dbus_signature(x) for x in v) + ")"
    raise TypeError("unknown D-Bus value type %r" % (t,))


# A noisy, drifting orientation sensor for caracara-sim's [sim] table (commissioning's tests).
SIM_NOISE = {"orientation_noise_rad": 0.003, "yaw_drift_rad_s": 0.0005}

WireEntry = namedtuple("WireEntry", "index time_ns transaction bus addr read data miso result")


# --- small utilities -------------------------------------------------------------------------

class Timeout(AssertionError):
    pass


def poll(fn, timeout=10.0, interval=0.02, message=None, pump=None):
    """Calls fn until it returns something truthy; returns that. Raises Timeout with the last
    value (or exception) when the deadline passes. pump, if given, runs between attempts."""
    deadline = time.monotonic() + timeout
    last = None
    while True:
        try:
            last = fn()
            if last:
                return last
        except dbus.DBusException as e:  # a transient error is a "not yet"
            last = e
        if time.monotonic() >= deadline:
            raise Timeout("%s (last: %r)" % (message or "condition not met within %.1f s" % timeout, last))
        if pump:
            pump(interval)
        else:
            time.sleep(interval)


def error_name(fn, *args, **kwargs):
    """Runs fn; returns the D-Bus error name it raised, or None if it succeeded."""
    try:
        fn(*args, **kwargs)
    except dbus.DBusException as e:
        return e.get_dbus_name()
    return None


def pump_main_loop(seconds=0.0):
    """Dispatches GLib events (D-Bus signals and async replies) for about `seconds`."""
    ctx = GLib.MainContext.default()
    end = time.monotonic() + seconds
    while True:
        while ctx.pending():
            ctx.iteration(False)
        if time.monotonic() >= end:
            return
        time.sleep(min(0.005, max(0.0, end - time.monotonic())))


def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, dict):
        return "{ " + ", ".join("%s = %s" % (k, toml_value(x)) for k, x in v.items()) + " }"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    raise TypeError("cannot write %r to TOML" % (v,))


def toml_dumps(sections):
    """{section: {key: value}} -> TOML text (values may be scalars, lists or inline tables)."""
    out = []
    for name, table in sections.items():
        if not table:
            continue
        out.append("[%s]" % name)
        for k, v in table.items():
            out.append("%s = %s" % (k, toml_value(v)))
        out.append("")
    return "\n".join(out)


def _die_with_parent():
    # The processes must not outlive a test runner that is killed (e.g. by a ctest timeout).
    try:
        libc = ctypes.CDLL("libc.so.6", use_errno=True)
        libc.prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
    except OSError:
        pass


_live_rigs = set()


@atexit.register
def _stop_leftover_rigs():
    for rig in list(_live_rigs):
        rig.stop()


# --- the rig ---------------------------------------------------------------------------------

# The simulated GPIO chip's lines (sim/gpio_model.hpp); the kill switch is active high there.
SIM_GPIO = {
    "kill_switch": {"chip": "gpiochip0", "line": "KILL_SWITCH"},
    "kill_output": {"chip": "gpiochip0", "line": "KILL_OUT"},
    "power_off_output": {"chip": "gpiochip0", "line": "POWER_OFF"},
}

BUS_CONF = """<!DOCTYPE busconfig PUBLIC "-//freedesktop//DTD D-Bus Bus Configuration 1.0//EN"
 "http://www.freedesktop.org/standards/dbus/1.0/busconfig.dtd">
<busconfig>
  <type>session</type>
  <listen>unix:path={dir}/bus</listen>
  <auth>EXTERNAL</auth>
  <policy context="default">
    <allow send_destination="*" eavesdrop="true"/>
    <allow eavesdrop="true"/>
    <allow own="*"/>
{extra}
  </policy>
</busconfig>
"""


class Rig:
    """One private bus, one simulator and (optionally) one daemon."""

    START_TIMEOUT = 30.0  # generous: sanitizer builds on slow machines start slowly

    def __init__(self, control=None, gpio=True, extra_config=None, extra_toml="", bus_policy_extra="", sim_config=None,
                 sim_toml=""):
        self.control = dict(control or {})
        self.sim_config = dict(sim_config or {})  # caracara-sim's own [sim] table (--config), when not empty
        self.sim_toml = sim_toml  # appended to the simulator's file (e.g. [[thruster]] tables)
        self.gpio = gpio
        self.extra_config = dict(extra_config or {})
        self.extra_toml = extra_toml  # appended verbatim (e.g. [[thruster]] sections)
        self.bus_policy_extra = bus_policy_extra  # more <allow>/<deny> rules for the bus policy
        self.dir = None
        self.procs = {}
        self.logs = {}
        self.conn = None
        self.daemon_exit = None

    # -- lifecycle --

    @property
    def address(self):
        return "unix:path=%s/bus" % self.dir

    @property
    def sim_socket(self):
        return os.path.join(self.dir, "sim.sock")

    @property
    def config_path(self):
        return os.path.join(self.dir, "caracarad.toml")

    def config_text(self):
        sections = {"control": self.control}
        if self.gpio:
            sections["gpio"] = SIM_GPIO
        # The dive recorder writes into the rig's directory, not the host's /var/log/caracara.
        sections["recorder"] = {"directory": self.dives_dir}
        sections.update(self.extra_config)
        return toml_dumps(sections) + "\n" + self.extra_toml

    @property
    def dives_dir(self):
        path = os.path.join(self.dir, "dives")
        os.makedirs(path, exist_ok=True)
        return path

    def _spawn(self, name, argv):
        log_path = os.path.join(self.dir, name + ".log")
        log = open(log_path, "ab")
        self.logs[name] = log_path
        p = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                             preexec_fn=_die_with_parent, close_fds=True)
        log.close()
        self.procs[name] = p
        return p

    def start(self, daemon=True):
        _live_rigs.add(self)
        self.dir = tempfile.mkdtemp(prefix="caracara-e2e-")
        for name in ("caracarad", "caracara-sim"):
            if not os.access(binary(name), os.X_OK):
                raise RuntimeError("%s is not built (CARACARA_BUILD_DIR=%s)" % (binary(name), BUILD_DIR))
        with open(os.path.join(self.dir, "bus.conf"), "w") as f:
            f.write(BUS_CONF.format(dir=self.dir, extra=self.bus_policy_extra))
        # The socket file appears at bind(), before listen(): a connect in between is refused.
        # dbus-daemon prints its address (into its log) only once it listens.
        self._spawn("dbus-daemon", ["/usr/bin/dbus-daemon", "--nofork", "--print-address=1",
                                    "--config-file=" + os.path.join(self.dir, "bus.conf")])
        poll(lambda: self.address in self.log("dbus-daemon") or self._died("dbus-daemon"),
             self.START_TIMEOUT, message="dbus-daemon did not print its address")
        self._check_alive("dbus-daemon")
        self.conn = dbus.bus.BusConnection(self.address, mainloop=dbus.mainloop.glib.DBusGMainLoop())
        self.start_sim()
        with open(self.config_path, "w") as f:
            f.write(self.config_text())
        if daemon:
            self.start_daemon()
        return self

    def start_sim(self):
        """Starts caracara-sim (again, after a test ended it: the daemon is to pick it up)."""
        args = ["--socket", self.sim_socket, "--bus-address", self.address]
        if self.sim_config or self.sim_toml:
            path = os.path.join(self.dir, "sim.toml")
            with open(path, "w") as f:
                f.write(toml_dumps({"sim": self.sim_config}) + "\n" + self.sim_toml)
            args += ["--config", path]
        self._spawn("caracara-sim", command("caracara-sim") + args)
        poll(lambda: self.conn.name_has_owner(SIM) or self._died("caracara-sim"), self.START_TIMEOUT,
             message="caracara-sim did not take its name")
        self._check_alive("caracara-sim")

    def start_daemon(self):
        self.daemon_exit = None
        self._spawn("caracarad", command("caracarad") + ["--hardware=sim:" + self.sim_socket,
                                  "--bus-address", self.address, "--config", self.config_path])
        poll(lambda: self.conn.name_has_owner(VEHICLE) or self._died("caracarad"), self.START_TIMEOUT,
             message="caracarad did not take its name")
        self._check_alive("caracarad")

    def _died(self, name):
        p = self.procs.get(name)
        return p is not None and p.poll() is not None

    def _check_alive(self, name):
        if self._died(name):
            raise RuntimeError("%s exited with %s at start:\n%s" % (name, self.procs[name].returncode, self.log(name)))

    def terminate(self, name, timeout=15.0):
        """SIGTERM, wait, SIGKILL fallback; returns the exit status (negative: signal)."""
        p = self.procs.get(name)
        if p is None:
            return None
        if p.poll() is None:
            try:
                p.send_signal(signal.SIGTERM)
                p.wait(timeout)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
        return p.returncode

    def stop_daemon(self, timeout=15.0):
        self.daemon_exit = self.terminate("caracarad", timeout)
        return self.daemon_exit

    def stop(self, remove_dir=True):
        """Tears everything down; safe to call more than once and after a failed start."""
        _live_rigs.discard(self)
        for name in ("caracarad", "caracara-sim"):
            try:
                code = self.terminate(name)
                if name == "caracarad" and self.daemon_exit is None:
                    self.daemon_exit = code
            except Exception:  # keep tearing down
                pass
        if self.conn is not None:
            try:
                self.conn.close()
            except Exception:
                pass
            self.conn = None
        try:
            self.terminate("dbus-daemon")
        except Exception:
            pass
        self.procs.clear()
        if remove_dir:
            self.remove_dir()

    def remove_dir(self):
        if self.dir and not os.environ.get("CARACARA_KEEP_TEST_DIR"):
            shutil.rmtree(self.dir, ignore_errors=True)

    SANITIZER_MARKS = ("ERROR: AddressSanitizer", "ERROR: LeakSanitizer", "runtime error:")

    def stop_checked(self):
        """stop(), then fails if caracarad or caracara-sim did not exit with 0 on SIGTERM or
        a sanitizer reported a problem (the CI runs these tests under ASan/UBSan)."""
        procs = {name: self.procs.get(name) for name in ("caracarad", "caracara-sim")}
        self.stop(remove_dir=False)
        problems, logs = [], {}
        for name, p in procs.items():
            if p is None:
                continue
            logs[name] = self.log(name)
            if p.returncode != 0:
                problems.append("%s exited with %s" % (name, p.returncode))
            if any(mark in logs[name] for mark in self.SANITIZER_MARKS):
                problems.append("%s: sanitizer report" % name)
        self.remove_dir()
        if problems:
            raise AssertionError("; ".join(problems) + "".join(
                "\n--- %s log (end) ---\n%s" % (n, logs[n][-4000:]) for n in logs))

    def log(self, name="caracarad"):
        try:
            with open(self.logs[name], errors="replace") as f:
                return f.read()
        except (KeyError, OSError):
            return ""

    # -- generic D-Bus access --

    def obj(self, service, path):
        return self.conn.get_object(service, path, introspect=False)

    def get(self, service, path, iface, name):
        return self.obj(service, path).Get(iface, name, dbus_interface=PROPS)

    def get_all(self, service, path, iface):
        return self.obj(service, path).GetAll(iface, dbus_interface=PROPS)

    def call(self, service, path, iface, method, *args, signature=None, timeout=30.0):
        return self.obj(service, path).get_dbus_method(method, iface)(*args, signature=signature, timeout=timeout)

    # -- the daemon --

    def vget(self, name, path=ROOT, iface=VEHICLE):
        return self.get(VEHICLE, path, iface, name)

    def vcall(self, method, *args, signature=None, path=ROOT, iface=VEHICLE, timeout=30.0):
        return self.call(VEHICLE, path, iface, method, *args, signature=signature, timeout=timeout)

    def state(self):
        return str(self.vget("State"))

    def motor_values(self):
        return [int(v) for v in self.vget("MotorValues")]

    def thrust(self, values):
        return self.vcall("SetThrust", dbus.Array(values, signature="i"), signature="ai")

    def motion(self, x=0.0, y=0.0, z=0.0, yaw=0.0, pitch=0.0, roll=0.0):
        return self.vcall("SetMotion", float(x), float(y), float(z), float(yaw), float(pitch), float(roll),
                          signature="dddddd")

    def packet(self, words):
        return self.vcall("ApplyPacket", dbus.Array(words, signature="i"), signature="ai")

    def arm(self, timeout=20.0):
        """What a pilot does after a start: the daemon comes up killed (source "start");
        ClearKill arms it, and it is ready after the arming delay."""
        if self.state() == "killed" and self.vget("KillSource") == "start":
            self.vcall("ClearKill")
        self.wait_state("ready", timeout)

    def wait_state(self, state, timeout=20.0):
        return poll(lambda: self.state() == state, timeout, message="State never became %r" % state)

    # -- the simulator --

    def sim_get(self, name, path=SIM_ROOT, iface=SIM):
        return self.get(SIM, path, iface, name)

    def sim_call(self, method, *args, signature=None, path=SIM_ROOT, iface=SIM):
        return self.call(SIM, path, iface, method, *args, signature=signature)

    def sim_thruster(self, i, name):
        return self.get(SIM, sim_thruster_path(i), SIM_THRUSTER_IFACE, name)

    def sim_thruster_call(self, i, method, *args, signature=None):
        return self.call(SIM, sim_thruster_path(i), SIM_THRUSTER_IFACE, method, *args, signature=signature)

    def sim_thrusters(self, name):
        """One property of every simulated thruster, one GetAll each."""
        return [self.get_all(SIM, sim_thruster_path(i), SIM_THRUSTER_IFACE)[name] for i in range(MOTORS)]

    def sim_speeds(self):
        """OrderedSpeed of every simulated thruster: what the hardware was last told."""
        return [int(v) for v in self.sim_thrusters("OrderedSpeed")]

    def sim_last_orders(self):
        return [bytes(bytearray(v)) for v in self.sim_thrusters("LastOrder")]

    def sim_counters(self, name):
        return [int(v) for v in self.sim_thrusters(name)]

    def sim_snapshot(self):
        """(OrderedSpeed, LastOrder) of every thruster."""
        out = []
        for i in range(MOTORS):
            p = self.get_all(SIM, sim_thruster_path(i), SIM_THRUSTER_IFACE)
            out.append((int(p["OrderedSpeed"]), bytes(bytearray(p["LastOrder"]))))
        return out

    def sim_teensy(self, name):
        return self.get(SIM, SIM_TEENSY_PATH, SIM_TEENSY_IFACE, name)

    def sim_teensy_call(self, method, *args, signature=None):
        return self.call(SIM, SIM_TEENSY_PATH, SIM_TEENSY_IFACE, method, *args, signature=signature)

    def sim_yaw(self):
        return float(self.sim_teensy("Orientation")[0])

    def wire_log(self, since=0):
        """(next index, [WireEntry]) from the simulator's wire log."""
        nxt, entries = self.sim_call("GetWireLog", dbus.UInt64(since), signature="t")
        out = []
        for e in entries:
            out.append(WireEntry(int(e[0]), int(e[1]), int(e[2]), str(e[3]), int(e[4]), bool(e[5]),
                                 bytes(bytearray(e[6])), bytes(bytearray(e[7])), str(e[8])))
        return int(nxt), out

    def wire_next(self):
        return self.wire_log(2 ** 63)[0]

    def wait_orders_refreshed(self, count=2, timeout=10.0):
        """Waits until every simulated thruster has received `count` more orders (loop ticks)."""
        before = self.sim_counters("OrdersReceived")
        poll(lambda: all(a >= b + count for a, b in zip(self.sim_counters("OrdersReceived"), before)), timeout,
             message="the daemon stopped refreshing orders")

    def wait_sim_speeds(self, expected, timeout=10.0):
        return poll(lambda: self.sim_speeds() == list(expected), timeout,
                    message="simulated thrusters never reached %s" % [hex(s) for s in expected])

    def wait_sim_zero(self, timeout=10.0):
        return self.wait_sim_speeds([ZERO] * MOTORS, timeout)

    # -- command-line clients --

    def busctl(self, *args, timeout=60):
        return subprocess.run(["busctl", "--address=" + self.address] + [str(a) for a in args],
                              capture_output=True, text=True, timeout=timeout)

    def ctl(self, *args, timeout=90):
        return subprocess.run(command("caracaractl") + ["--bus-address", self.address] + [str(a) for a in args],
                              capture_output=True, text=True, timeout=timeout, stdin=subprocess.DEVNULL)

    # -- test conveniences --

    def reset(self, timeout=20.0):
        """Back to ready with zero thrust, whatever an earlier test left. The zeros make this
        connection a pilot: a test client that leaves the bus is then not the last pilot."""
        st = self.state()
        if st == "killed":
            if self.sim_get("KillSwitch"):
                self.sim_call("SetKillSwitch", False, signature="b")
            poll(lambda: error_name(self.vcall, "ClearKill") in (None, ERR + "NotKilled"), timeout,
                 message="cannot clear the kill")
        if self.state() != "ready":
            self.wait_state("ready", timeout)
        self.thrust([0] * MOTORS)
        self.wait_sim_zero(timeout)


    def rearm(self, timeout=20.0):
        """Back to ready with no pilot (killed if need be, then ClearKill): an earlier test's
        pilot that left cannot kill during the next (pilot-lost), and this connection, which
        only kills and clears, is no pilot."""
        if self.state() != "killed":
            self.vcall("Kill")
        if self.sim_get("KillSwitch"):
            self.sim_call("SetKillSwitch", False, signature="b")
        poll(lambda: error_name(self.vcall, "ClearKill") is None, timeout, message="cannot clear the kill")
        self.wait_state("ready", timeout)
        self.wait_sim_zero(timeout)


# A separate client process: connects, optionally sends SetThrust with the values given on
# its command line, prints its unique bus name, then stays connected until stdin closes.
CLIENT_SCRIPT = r"""
import sys, dbus
bus = dbus.bus.BusConnection(sys.argv[1])
vehicle = bus.get_object("org.caracara.Vehicle1", "/org/caracara/Vehicle1", introspect=False)
values = [int(x) for x in sys.argv[2:]]
if values:
    vehicle.SetThrust(dbus.Array(values, signature="i"), dbus_interface="org.caracara.Vehicle1")
print(bus.get_unique_name(), flush=True)
sys.stdin.read()
"""


def start_client(rig, values=()):
    """Starts a client process (see CLIENT_SCRIPT); returns (process, its unique name).
    Close process.stdin to make it leave the bus."""
    p = subprocess.Popen([PYTHON, "-c", CLIENT_SCRIPT, rig.address] + [str(v) for v in values],
                         stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         preexec_fn=_die_with_parent)
    name = p.stdout.readline().strip()
    if not name:
        p.stdin.close()
        p.wait(10)
        raise AssertionError("client failed: %s" % p.stderr.read())
    return p, name


class VehicleTestCase(unittest.TestCase):
    """One rig per test class. Override CONTROL (the [control] table) and friends."""

    CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 60000}
    GPIO = True
    EXTRA_CONFIG = {}
    EXTRA_TOML = ""
    SIM_TOML = ""  # the simulator's own file (--config), when not empty
    BUS_POLICY_EXTRA = ""
    WAIT_READY = True

    @classmethod
    def setUpClass(cls):
        cls.rig = Rig(control=cls.CONTROL, gpio=cls.GPIO, extra_config=cls.EXTRA_CONFIG,
                      extra_toml=cls.EXTRA_TOML, sim_toml=cls.SIM_TOML,
                      bus_policy_extra=cls.BUS_POLICY_EXTRA)
        cls.addClassCleanup(cls.rig.stop_checked)
        cls.rig.start()
        if cls.WAIT_READY:
            cls.rig.arm()

    def assertDBusError(self, expected, fn, *args, **kwargs):
        got = error_name(fn, *args, **kwargs)
        self.assertEqual(got, expected, "expected D-Bus error %s, got %s" % (expected, got or "success"))
