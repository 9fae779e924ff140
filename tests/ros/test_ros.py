"""caracara-ros against a second DDS vendor: a Fast DDS peer (peer.cpp) whose types fastddsgen
generated from the ROS 2 message definitions as published (@foxglove/rosmsg-msgs-common), never
from the project's IDL; CDR bytes checked against @foxglove/rosmsg2-serialization (cdr.mjs).

Runs in a private network namespace (ros.cmake starts it under `unshare --net`): the loopback
interface with multicast on, and nothing else, so no packet leaves the machine. The vehicle is
the real caracara-sim and caracarad on a private bus (tests/e2e/harness.py); what moved is read
from the simulator's wire log, and where the simulated vehicle went and how it is turned from its
body (tests/e2e/vehicle_motion.py): REP 103 / 145's frames are judged by the motion and attitude,
never by the numbers SetMotion would take. Under CI (CI=true) a missing tool fails the test.
"""

import contextlib
import glob
import hashlib
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import unittest

try:
    import yaml  # python3-yaml: rosbag2 keeps a topic's QoS as YAML
except ImportError:
    yaml = None

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(SOURCE, "tests", "e2e"))

import harness  # noqa: E402
from harness import missing, npm_ci  # noqa: E402
from bounds import CLIENT_LOSS_ZERO_MS_MAX, ORIENTATION_TO_JUDGE_MIN_RAD, ROS_READING_STAMP_AGE_MS_MAX  # noqa: E402
from bounds import ROS_SENSOR_RATE_MAX_FRACTION, ROS_SENSOR_RATE_MIN_FRACTION, ROS_SENSOR_RATE_WINDOW_S  # noqa: E402
from bounds import ROS_NEWTON_ACCEL_ERROR_FRACTION_MAX, ROS_NEWTON_ACCEL_WINDOW_S, ROS_TAKEOVER_EARLY_MS_MAX  # noqa: E402
from harness import BUILD_DIR, MOTORS, ZERO, VehicleTestCase, angle_diff, poll, speed_byte  # noqa: E402
from test_failsafes import kill_edges, orders  # noqa: E402
from vehicle_motion import START_HEADING_RAD, body_motion, judge, place, pose, settle  # noqa: E402


# Every type caracara-ros speaks, with the topic it is on.
TYPES = ["sensor_msgs/Imu", "sensor_msgs/JointState", "sensor_msgs/Range", "diagnostic_msgs/DiagnosticArray",
         "std_msgs/Bool", "std_msgs/String", "std_msgs/Empty", "std_msgs/Float64MultiArray", "geometry_msgs/Wrench",
         "tf2_msgs/TFMessage", "rmw_dds_common/ParticipantEntitiesInfo"]
PUBLISHED = {"rt/caracara/imu": "sensor_msgs/Imu", "rt/caracara/joint_states": "sensor_msgs/JointState",
             "rt/caracara/thrusters/ordered": "sensor_msgs/JointState", "rt/caracara/range/0": "sensor_msgs/Range",
             "rt/diagnostics": "diagnostic_msgs/DiagnosticArray", "rt/caracara/killed": "std_msgs/Bool",
             "rt/caracara/state": "std_msgs/String", "rt/caracara/kill_source": "std_msgs/String",
             "rt/tf": "tf2_msgs/TFMessage", "rt/tf_static": "tf2_msgs/TFMessage"}
LATCHED = ("killed", "state", "kill_source", "tf_static")  # transient-local, as ROS latches them
DISCOVERY_INFO = {"ros_discovery_info": "rmw_dds_common/ParticipantEntitiesInfo"}
GID_BYTES = {"humble": 24, "jazzy": 16}  # rmw_dds_common's Gid: char[24] in Humble, char[16] since Iron
MOTOR_MAX = 8850
DAEMON_TELEMETRY_HZ = 5.0  # daemon/control/control_loop.cpp's kTelemetryPeriodNs: [ros] sensor_rate_hz's default
STEADY_TOPICS = {"rt/caracara/imu": "sensor_msgs/Imu", "rt/tf": "tf2_msgs/TFMessage",
                 "rt/caracara/joint_states": "sensor_msgs/JointState"}


def build_peer(distro):
    """The Fast DDS peer for one distro's definitions, built once per source (in the build tree).
    Fast DDS 2.9 and fastddsgen 2 on Debian 12, Fast DDS 3.1 and fastddsgen 4 on Debian 13."""
    for tool in ("fastddsgen", "g++", "node"):
        if not shutil.which(tool):
            missing(tool + " is needed (scripts/deps.sh: fastddsgen, libfastrtps-dev or libfastdds-dev, nodejs)")
    if not os.path.exists("/usr/include/fastdds/dds/domain/DomainParticipant.hpp"):
        missing("Fast DDS's headers are needed (scripts/deps.sh: libfastrtps-dev, Debian 13's libfastdds-dev)")
    # Fast DDS 3's version header (Debian puts it under the multiarch include directory).
    fastdds3 = bool(glob.glob("/usr/include/fastdds/config.hpp") + glob.glob("/usr/include/*/fastdds/config.hpp"))
    npm_ci(HERE)
    idl = subprocess.run(["node", "msg_to_idl.mjs", distro] + TYPES, cwd=HERE, check=True, capture_output=True,
                         text=True).stdout

    def make(out, exe):
        with open(os.path.join(out, "ros_h.idl"), "w") as f:
            f.write(idl)
        # fastddsgen 4 would add XTypes type objects: the peer matches by type name, as ROS 2 does.
        subprocess.run(["fastddsgen", "-replace"] + (["-no-typeobjectsupport"] if fastdds3 else []) +
                       ["-d", out, os.path.join(out, "ros_h.idl")], check=True, stdout=subprocess.DEVNULL)
        generated = sorted(os.path.join(out, n) for n in os.listdir(out) if n.endswith(".cxx"))
        subprocess.run(["g++", "-std=c++17", "-O1", "-I" + out, os.path.join(HERE, "peer.cpp")] + generated +
                       ["-lfastdds" if fastdds3 else "-lfastrtps", "-lfastcdr", "-o", exe], check=True)
    return built_once("peer-" + distro, "peer", idl + str(fastdds3), ["peer.cpp"], make)


def built_once(name, program, inputs, sources, make):
    """The test program `program` built into the build tree once per source: make(out, exe)
    builds it in the directory `out` (NAME-key), keyed by `inputs` and the text of `sources`
    (files of tests/ros)."""
    text = inputs
    for source in sources:
        with open(os.path.join(HERE, source)) as f:
            text += f.read()
    out = os.path.join(BUILD_DIR, "tests", "ros", "%s-%s" % (name, hashlib.sha256(text.encode()).hexdigest()[:16]))
    exe = os.path.join(out, program)
    if os.path.exists(exe):
        return exe
    os.makedirs(out, exist_ok=True)
    make(out, exe + ".tmp")
    os.rename(exe + ".tmp", exe)
    return exe


def security_plugins():
    """Where Debian puts Cyclone DDS's security plugins (libddsc0debian, Debian 12 and 13 alike)."""
    arch = subprocess.run(["gcc", "-print-multiarch"], capture_output=True, text=True).stdout.strip()
    plugins = "/usr/lib/%s/libddsc0debian" % arch  # this machine's, not a cross build's (:arm64)
    if not os.path.exists(os.path.join(plugins, "libdds_security_auth.so")):
        missing("Cyclone DDS's security plugins are needed (libddsc0debian: %s/libdds_security_auth.so)" % plugins)
    return plugins


def build_secure_peer():
    """The DDS Security peer (secure_peer.cpp): Cyclone DDS with the real security plugins, its
    types made by idlc from the ROS 2 definitions as published; with permissive_ac.c, the access
    control of a rogue stack that writes whatever its permissions say. Built once per source."""
    for tool in ("idlc", "gcc", "g++", "node"):
        if not shutil.which(tool):
            missing(tool + " is needed (scripts/deps.sh: cyclonedds-tools, cyclonedds-dev, nodejs)")
    plugins = security_plugins()
    npm_ci(HERE)
    idl = subprocess.run(["node", "msg_to_idl.mjs", "humble", "geometry_msgs/Wrench", "std_msgs/Empty"], cwd=HERE,
                         check=True, capture_output=True, text=True).stdout

    def make(out, exe):
        with open(os.path.join(out, "sp.idl"), "w") as f:
            f.write(idl)
        subprocess.run(["idlc", "sp.idl"], cwd=out, check=True)
        subprocess.run(["gcc", "-c", "-O1", "sp.c", "-o", "sp.o"], cwd=out, check=True)
        permissive = os.path.join(out, "libpermissive_ac.so")
        subprocess.run(["gcc", "-shared", "-fPIC", "-O1", '-DPLUGINS="%s"' % plugins,
                        os.path.join(HERE, "permissive_ac.c"), "-ldl", "-o", permissive], check=True)
        subprocess.run(["g++", "-std=c++17", "-O1", "-I" + out, '-DPLUGINS="%s"' % plugins,
                        '-DPERMISSIVE="%s"' % permissive, os.path.join(HERE, "secure_peer.cpp"),
                        os.path.join(out, "sp.o"), "-lddsc", "-o", exe], check=True)
    return built_once("secure-peer", "secure_peer", idl + plugins, ["secure_peer.cpp", "permissive_ac.c"], make)


def doc_blocks():
    """docs/ros2.md's blocks marked <!-- test_ros: NAME -->: the keystore as users make it."""
    with open(os.path.join(SOURCE, "docs", "ros2.md")) as f:
        return dict(re.findall(r"<!-- test_ros: (\w+) -->\n```\w+\n(.*?)```", f.read(), re.S))


def make_keystore(path, enclaves):
    """A keystore made with openssl alone, by docs/ros2.md's own commands: its CA, governance and
    one enclave per name, each with the <publish>/<subscribe> rules given."""
    blocks = doc_blocks()
    env = dict(os.environ, KEYSTORE=path)
    subprocess.run(["bash", "-e", "-c", blocks["keystore"]], env=env, check=True, capture_output=True)
    for name, allow in enclaves.items():
        subprocess.run(["bash", "-e", "-c", blocks["enclave"]], env=dict(env, ENCLAVE=name, ALLOW=allow), check=True,
                       capture_output=True)
    return blocks


class Codec:
    """cdr.mjs: @foxglove/rosmsg2-serialization, one request a line."""

    def __init__(self):
        self.lock = threading.Lock()  # one request and its answer at a time, whichever thread asks
        self.p = subprocess.Popen(["node", "cdr.mjs"], cwd=HERE, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                  text=True)

    def ask(self, req):
        with self.lock:
            self.p.stdin.write(json.dumps(req) + "\n")
            self.p.stdin.flush()
            return json.loads(self.p.stdout.readline(), parse_constant=lambda c: float(c))

    def encode(self, type_, msg, distro="humble"):
        return self.ask({"op": "encode", "distro": distro, "type": type_, "msg": msg})["hex"]

    def decode(self, type_, hex_, distro="humble"):
        return self.ask({"op": "decode", "distro": distro, "type": type_, "hex": hex_})["msg"]

    def close(self):
        self.p.stdin.close()
        self.p.wait(10)
        self.p.stdout.close()


_TYPE_HASHES = {}


def type_hash(distro, type_):
    """The type's RIHS01 hash as rosidl computes it from the distro's published definitions
    (type_hash.mjs), not from caracara-ros."""
    if (distro, type_) not in _TYPE_HASHES:
        _TYPE_HASHES[distro, type_] = subprocess.run(["node", "type_hash.mjs", distro, type_], cwd=HERE, check=True,
                                                     capture_output=True, text=True).stdout.strip()
    return _TYPE_HASHES[distro, type_]


def network_is_private():
    """Inside the namespace ros.cmake made: only the loopback interface, multicast on, routed."""
    links = subprocess.run(["ip", "-o", "link"], capture_output=True, text=True, check=True).stdout.splitlines()
    names = [line.split(":")[1].strip() for line in links]
    if names != ["lo"]:
        if harness.CI_RUN:
            raise AssertionError("not in a private network namespace (interfaces %s)" % names)
        raise unittest.SkipTest("run through ctest (ros.cmake starts it under unshare --net)")
    subprocess.run(["ip", "link", "set", "lo", "up", "multicast", "on"], check=True)
    subprocess.run(["ip", "route", "replace", "224.0.0.0/4", "dev", "lo"], check=True)


def fixed_sample(type_, distro="humble"):
    """A fixed sample of each type, every field set to something other than its default."""
    gid = {"data": list(range(1, GID_BYTES[distro] + 1))}
    h = {"stamp": {"sec": 1700000000, "nanosec": 123456789}, "frame_id": "base_link"}
    q = {"x": 0.1, "y": -0.2, "z": 0.3, "w": 0.9}
    v = {"x": 1.5, "y": -2.5, "z": 3.25}
    return {
        "sensor_msgs/Imu": {"header": h, "orientation": q, "orientation_covariance": [0.0] * 9,
                            "angular_velocity": v, "angular_velocity_covariance": [-1.0] + [0.0] * 8,
                            "linear_acceleration": v, "linear_acceleration_covariance": [-1.0] + [0.0] * 8},
        "sensor_msgs/JointState": {"header": h, "name": ["thruster_%d" % i for i in range(8)], "position": [],
                                   "velocity": [i / 8 - 0.5 for i in range(8)], "effort": [0.25 * i for i in range(8)]},
        "sensor_msgs/Range": {"header": h, "radiation_type": 0, "field_of_view": 0.5, "min_range": 0.0,
                              "max_range": 65.535, "range": 1.25, "variance": 0.0},
        "diagnostic_msgs/DiagnosticArray": {"header": h, "status": [
            {"level": 1, "name": "caracara: thruster_0", "message": "faults: overcurrent", "hardware_id": "seabotix@0x52",
             "values": [{"key": "current A", "value": "2.5"}]},
            {"level": 0, "name": "caracara: teensy", "message": "online", "hardware_id": "teensy", "values": []}]},
        "std_msgs/Bool": {"data": True},
        "std_msgs/String": {"data": "killed"},
        "std_msgs/Empty": {},
        "std_msgs/Float64MultiArray": {"layout": {"dim": [{"label": "thrusters", "size": 8, "stride": 8}],
                                                  "data_offset": 0}, "data": [0.125 * i - 0.5 for i in range(8)]},
        "geometry_msgs/Wrench": {"force": v, "torque": {"x": -0.25, "y": 0.5, "z": -0.75}},
        "tf2_msgs/TFMessage": {"transforms": [{"header": h, "child_frame_id": "base_link",
                                               "transform": {"translation": v, "rotation": q}}]},
        "rmw_dds_common/ParticipantEntitiesInfo": {"gid": gid, "node_entities_info_seq": [
            {"node_namespace": "/caracara", "node_name": "caracara_ros", "reader_gid_seq": [gid],
             "writer_gid_seq": [gid, gid]}]},
    }[type_]


def peer_exited(p, err):
    """A publishing peer that exited by itself before the test was done with it (no reader matched
    it in time, say): that, with what it said, is the failure."""
    if p.poll() is not None:
        err.seek(0)
        raise AssertionError("the publishing peer exited with %s: %s" % (p.returncode, err.read().strip()))


def nonzero_orders(log):
    """The thruster orders of the log that are not zero."""
    return [e for e, _, speed in orders(log) if speed != ZERO]


# REP 103's body FLU: each Wrench component and the motion it means (tests/e2e/vehicle_motion.py's
# words), + and -: force along x forward, y left, z up; torque right-handed about them.
WRENCH_MOTIONS = {("force", "x"): ("forward", "backward"), ("force", "y"): ("port", "starboard"),
                  ("force", "z"): ("up", "deeper"), ("torque", "z"): ("counter-clockwise", "clockwise"),
                  ("torque", "y"): ("nose down", "nose up"), ("torque", "x"): ("roll right", "roll left")}
ZERO_WRENCH = {"force": {"x": 0, "y": 0, "z": 0}, "torque": {"x": 0, "y": 0, "z": 0}}
ORIENTATION_TOPICS = {"rt/caracara/imu": "sensor_msgs/Imu", "rt/tf": "tf2_msgs/TFMessage"}


def rotate(q, v):
    """The vector v turned by the unit quaternion q ({x, y, z, w}, body to world): where the body's
    axis v points in the world frame."""
    u, w = (q["x"], q["y"], q["z"]), q["w"]

    def cross(a, b):
        return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
    t = tuple(2 * c for c in cross(u, v))
    return tuple(v[i] + w * t[i] + c for i, c in enumerate(cross(u, t)))


def quaternion_yaw(q):
    """The yaw of a body-to-world quaternion, right-handed about the world's z (tf2's getYaw)."""
    return math.atan2(2 * (q["w"] * q["z"] + q["x"] * q["y"]), 1 - 2 * (q["y"] ** 2 + q["z"] ** 2))


def expected_axes(attitude, convention):
    """Where the body's x and y axes point in the world frame, from the simulator's (the Teensy's)
    angles as the seed gives them: heading clockwise seen from above from the reference (north),
    pitch nose up, roll right side down. First in north, east, up; then in the convention's
    axes: "enu" (REP 103: x forward, y left in x east, y north, z up) or "ned" (x forward, y right
    in x north, y east, z down)."""
    h, p, r = attitude
    forward = (math.cos(p) * math.cos(h), math.cos(p) * math.sin(h), math.sin(p))
    right = (math.cos(h) * math.sin(p) * math.sin(r) - math.sin(h) * math.cos(r),
             math.sin(h) * math.sin(p) * math.sin(r) + math.cos(h) * math.cos(r), -math.cos(p) * math.sin(r))
    if convention == "enu":
        return (forward[1], forward[0], forward[2]), (-right[1], -right[0], -right[2])
    return (forward[0], forward[1], -forward[2]), (right[0], right[1], -right[2])


def sim_attitude(rig):
    """(CLOCK_REALTIME ns, [yaw, pitch, roll]): the simulator's attitude, timed at the middle of
    the call that read it (timed before it, a slow reply on the loaded machine made the simulator
    seem ahead of what it was at that time)."""
    before = time.time_ns()
    att = [float(x) for x in rig.sim_teensy("Orientation")]
    return ((before + time.time_ns()) // 2, att)


def stamp_of(topic, m):
    """A message's header stamp in ns (CLOCK_REALTIME); /tf's of its one transform."""
    head = m["transforms"][0]["header"] if topic == "rt/tf" else m["header"]
    return head["stamp"]["sec"] * 10 ** 9 + head["stamp"]["nanosec"]


def unwrap(angles):
    out = angles[:1]
    for a in angles[1:]:
        out.append(out[-1] + angle_diff(a, out[-1]))
    return out


class RosTestCase(VehicleTestCase):
    """One rig, one caracara-ros (commands as COMMANDS says) per class."""
    COMMANDS = False
    DISTRO = "humble"
    LAYOUT_IN_CONFIG = True  # range_layout = DISTRO; else caracara-ros finds the distro itself
    ROS_CONFIG = ""  # more [ros] lines
    EXTRA_CONFIG = {"failsafe": {"pilot-lost": {"action": "kill", "persistence_ms": 60000}}}

    @classmethod
    def setUpClass(cls):
        network_is_private()
        cls.peer = build_peer(cls.DISTRO)
        super().setUpClass()
        cls.codec = Codec()
        cls.addClassCleanup(cls.codec.close)
        conf = os.path.join(cls.rig.dir, "ros.toml")
        with open(conf, "w") as f:
            f.write('[ros]\nnamespace = "/caracara"\ncommands = %s\n%s%s[network]\ninterface = "lo"\n'
                    % ("true" if cls.COMMANDS else "false",
                       'range_layout = "%s"\n' % cls.DISTRO if cls.LAYOUT_IN_CONFIG else "",
                       cls.ROS_CONFIG.replace("{rig_dir}", cls.rig.dir)))
        cls.ros = cls.rig._spawn("caracara-ros", harness.EMULATOR + [
            os.path.join(BUILD_DIR, "tools", "ros", "caracara-ros"), "--bus-address", cls.rig.address, "--config", conf])
        cls.addClassCleanup(cls.stop_ros)
        poll(lambda: "commands" in cls.rig.log("caracara-ros") or cls.ros.poll() is not None, 20,
             message="caracara-ros did not start")
        if cls.ros.poll() is not None:
            raise AssertionError("caracara-ros exited: " + cls.rig.log("caracara-ros"))

    @classmethod
    def stop_ros(cls):
        code = cls.rig.terminate("caracara-ros")
        if code != 0:
            raise AssertionError("caracara-ros exited with %s on SIGTERM:\n%s" % (code, cls.rig.log("caracara-ros")))

    def listen(self, seconds, topics=PUBLISHED, during=None, distro=None, typehash=True):
        """The peer's view for `seconds`: (samples by topic, decoded, with time and the bytes as they
        came), participants, writers by topic, and every writer and reader discovered (a list).
        `during` is called every 20 ms while the peer listens. distro: the peer built from that
        distro's definitions (else the class's). typehash: its Range readers announce their type's
        hash in USER_DATA as Iron's and later rmw do ("typehash=RIHS01_...;", Jazzy's with
        variance), none for Humble's; False: none (a Humble peer, or a non-ROS reader, of Jazzy's type)."""
        distro = distro or self.DISTRO
        user_data = lambda t, ty: (  # noqa: E731
            "=typehash=%s;" % type_hash(distro, ty) if typehash and distro != "humble" and ty == "sensor_msgs/Range" else "")
        args = ["%s=%s%s" % (t, ty, user_data(t, ty)) for t, ty in topics.items()]
        # Into files, not pipes: nothing reads a pipe while `during` runs, and a full one would
        # stop the peer.
        with tempfile.TemporaryFile("w+") as out_f, tempfile.TemporaryFile("w+") as err_f:
            p = subprocess.Popen([build_peer(distro), "listen", str(seconds)] + args, stdout=out_f, stderr=err_f,
                                 text=True)
            while p.poll() is None:
                if during:
                    during()
                time.sleep(0.02)
            out_f.seek(0)
            err_f.seek(0)
            out, err = out_f.read(), err_f.read()
        self.assertEqual(p.returncode, 0, err)
        samples, participants, writers, endpoints = {}, [], {}, []
        for line in out.splitlines():
            o = json.loads(line)
            if "topic" in o:
                msg = self.codec.decode(topics[o["topic"]], o["cdr"], distro)
                samples.setdefault(o["topic"], []).append((o["t_ns"], msg, o["wire"]))
            elif "participant" in o:
                participants.append(o)
            elif "writer" in o:
                writers[o["writer"]] = o
                endpoints.append(o)
            elif "reader" in o:
                endpoints.append(o)
        return samples, participants, writers, endpoints

    def check_discovery_info(self, reader_topics):
        """ros_discovery_info as ROS 2's graph cache reads it: the participant's gid is the GUID the
        peer discovered (zeros after it to the distro's Gid size), one node caracara_ros in the
        namespace, and its writer and reader gids exactly the GUIDs of the writers and readers the
        peer discovered on that participant (the discovery info's own writer and reader are not the
        node's)."""
        samples, participants, writers, endpoints = self.listen(3, {**PUBLISHED, **DISCOVERY_INFO})
        # By GUID: a participant found again (after a lease lapse under load) is the same one.
        ros = {p["guid"] for p in participants if p["user_data"] == "enclave=/;"}
        self.assertEqual(len(ros), 1, participants)
        guid = ros.pop()
        prefix = guid[:24]
        self.assertIn("ros_discovery_info", samples, "no ros_discovery_info received")
        w = writers["ros_discovery_info"]
        self.assertEqual(w["type"], "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_")
        self.assertTrue(w["reliable"] and w["transient_local"] and w["xcdr1"], w)
        # caracara-ros's own (a test's peer may write one too): its gid begins with the GUID.
        info = [m for _, m, _ in samples["ros_discovery_info"] if bytes(m["gid"]["data"]).hex().startswith(prefix)][-1]
        pad = "00" * (GID_BYTES[self.DISTRO] - 16)
        gid_hex = lambda g: bytes(g["data"]).hex()  # noqa: E731
        self.assertEqual(gid_hex(info["gid"]), guid + pad)
        self.assertEqual(len(info["node_entities_info_seq"]), 1)
        node = info["node_entities_info_seq"][0]
        self.assertEqual((node["node_namespace"], node["node_name"]), ("/caracara", "caracara_ros"))
        listed_writers = [gid_hex(g) for g in node["writer_gid_seq"]]
        listed_readers = [gid_hex(g) for g in node["reader_gid_seq"]]
        for g in listed_writers + listed_readers:
            self.assertTrue(g.endswith(pad), g)
        ours = {o["guid"]: o for o in endpoints if o["guid"].startswith(prefix)}.values()
        seen_writers = [o["guid"] for o in ours if o.get("writer", "ros_discovery_info") != "ros_discovery_info"]
        # Nor is the participant's reader of the discovery info (rmw's graph cache has one too).
        seen_readers = [o for o in ours if o.get("reader", "ros_discovery_info") != "ros_discovery_info"]
        self.assertEqual(sorted(g[:32] for g in listed_writers), sorted(seen_writers))
        self.assertEqual(sorted(g[:32] for g in listed_readers), sorted(o["guid"] for o in seen_readers))
        self.assertEqual(sorted(o["reader"] for o in seen_readers), sorted(reader_topics))
        # Every published topic's writer is among them.
        self.assertLessEqual(set(PUBLISHED), {o["writer"] for o in ours if "writer" in o})

    def publish(self, topic, type_, msg, count=3, hz=2.0):
        """Sends `msg` `count` times, half a second apart: a volatile reader that matches this
        writer late skips what was written before it did, so one sample alone may be lost."""
        hex_ = self.codec.encode(type_, msg, self.DISTRO)
        r = subprocess.run([self.peer, "publish", topic, type_, hex_, str(count), str(hz)], capture_output=True,
                           text=True, timeout=60)
        self.assertEqual(r.returncode, 0, r.stderr)
        return r

    @contextlib.contextmanager
    def driving(self, topic, type_, msg, hz=50, short_lease=False, distro=None):
        """The peer publishing `msg` at `hz` (50: as a pilot's stack would) until the block ends,
        then SIGKILLed: a writer that goes away without a word. short_lease: its participant's
        lease 100 ms (peer.cpp), for a test that times how soon its death is noticed. distro: the
        peer built from that distro's definitions (else the class's)."""
        distro = distro or self.DISTRO
        hex_ = self.codec.encode(type_, msg, distro)
        env = dict(os.environ, PEER_SHORT_LEASE="1" if short_lease else "0")
        with tempfile.TemporaryFile("w+") as err:
            p = subprocess.Popen([build_peer(distro), "publish", topic, type_, hex_, "1000000", str(hz), "hold"],
                                 stdout=subprocess.DEVNULL, stderr=err, text=True, env=env)
            try:
                yield p
            except Exception:
                peer_exited(p, err)
                raise
            finally:
                p.send_signal(signal.SIGKILL)
                p.wait(10)

    @contextlib.contextmanager
    def steering(self, topic, type_, msg, hz=50):
        """The peer publishing `msg` at `hz` until the block ends, as a pilot's stack would;
        send(m) makes it publish m from then on (one writer throughout); send("stop") stops it
        sending, its writer still there. At the end it leaves in good order."""
        err = tempfile.TemporaryFile("w+")
        self.addCleanup(err.close)
        p = subprocess.Popen([self.peer, "publish", topic, type_, self.codec.encode(type_, msg, self.DISTRO), "1",
                              str(hz), "stdin"], stdin=subprocess.PIPE, stdout=subprocess.DEVNULL,
                             stderr=err, text=True)

        def send(m):  # "stop": the writer stops sending and stays
            p.stdin.write((m if m == "stop" else self.codec.encode(type_, m, self.DISTRO)) + "\n")
            p.stdin.flush()
        try:
            yield send
        except Exception:
            peer_exited(p, err)
            raise
        finally:
            p.stdin.close()
            try:
                p.wait(10)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait(10)

    def check_orientation(self, samples, attitude, convention, world, body, publish_tf=True, delta=0.03):
        """Every Imu (and /tf) orientation against the simulator's attitude about its stamp: the
        body's x and y axes where `convention` puts them; the frame names. The value was read from
        the Teensy a poll or two before the stamp, so the best match of the simulator's attitudes
        from 200 ms before the stamp to 50 ms after it counts (a wrong axis is off by far more)."""
        self.assertIn("rt/caracara/imu", samples, "no Imu received")
        self.assertEqual("rt/tf" in samples, publish_tf)
        self.assertGreater(len(attitude), 10)
        unjudged = {}
        for topic, msgs in samples.items():
            for _, m, _ in msgs:
                if topic == "rt/tf":
                    tf = m["transforms"][0]
                    self.assertEqual((tf["header"]["frame_id"], tf["child_frame_id"]), (world, body))
                    q = tf["transform"]["rotation"]
                else:
                    self.assertEqual(m["header"]["frame_id"], body)
                    q = m["orientation"]
                stamp = stamp_of(topic, m)
                if stamp + 50e6 < attitude[0][0]:
                    # A reading from before the record began (the first message of a steady
                    # stream may carry the reading of up to a second ago): nothing to judge it by.
                    unjudged[topic] = unjudged.get(topic, 0) + 1
                    continue
                near = [a for t, a in attitude if -200e6 <= t - stamp <= 50e6] or \
                    [min(attitude, key=lambda a: abs(a[0] - stamp))[1]]
                got = rotate(q, (1, 0, 0)), rotate(q, (0, 1, 0))

                def error(att):
                    want = expected_axes(att, convention)
                    return max(abs(got[axis][k] - want[axis][k]) for axis in range(2) for k in range(3))
                att = min(near, key=error)
                if error(att) > delta:
                    best_t, best = min(attitude, key=lambda a: error(a[1]))
                    self.fail("%s: body axes x, y in %s: got %s, the simulator's %s gives %s (error %.3f); the best "
                              "match of the whole record, %s (error %.3f), was %.0f ms from the stamp"
                              % (topic, world, got, att, expected_axes(att, convention), error(att), best,
                                 error(best), (best_t - stamp) / 1e6))
        for topic, n in unjudged.items():
            self.assertLessEqual(n, 2, "%s: %d of %d messages stamped before the record began" % (topic, n, len(samples[topic])))

    def hold_motion(self, seconds, **axes):
        """SetMotion(axes) over D-Bus, renewed within the command timeout, for `seconds`."""
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.rig.motion(**axes)
            time.sleep(0.1)

    def check_steady_rates(self, rate_hz, topics=STEADY_TOPICS):
        """A late subscriber on a still vehicle (placed at rest, no thrust: nothing changes, so
        caracarad announces only its counters, once a second) gets each of `topics` at `rate_hz`,
        each message stamped with the time of the reading it carries: at or before its arrival and
        at most ROS_READING_STAMP_AGE_MS_MAX older, never going back, and the same reading sent
        again carries the same stamp (so fewer stamps than messages: not the time of sending)."""
        rig = self.rig
        rig.reset()
        time.sleep(1.0)  # an earlier test's thrust fully died away: placed, the vehicle stays
        self.place_and_wait(0.4)
        time.sleep(1.5)  # this subscriber joins long after the values last changed
        realtime_minus_monotonic = time.time_ns() - time.monotonic_ns()
        # Counted from 2.5 s after the first message: the first one or two come as the peer's
        # readers match, then there may be a gap before the stream runs (1 s at 5 Hz and 2.4 s once
        # with the listening peer's old 100 ms lease; 0.2 s with its 2 s one); from then on the rate.
        samples, _, _, _ = self.listen(ROS_SENSOR_RATE_WINDOW_S + 3.5, topics)
        expected = rate_hz * ROS_SENSOR_RATE_WINDOW_S
        for topic in topics:
            with self.subTest(topic=topic):
                got = samples.get(topic, [])
                self.assertTrue(got, "nothing on " + topic)
                start = got[0][0] + 2.5e9
                startup_gap_ms = max((b[0] - a[0]) / 1e6 for a, b in zip(got, got[1:]) if a[0] < start)
                got = [(t, m) for t, m, _ in got if start <= t < start + ROS_SENSOR_RATE_WINDOW_S * 10 ** 9]
                stamps = []
                for t_ns, m in got:
                    stamp = stamp_of(topic, m)
                    age_ms = (t_ns + realtime_minus_monotonic - stamp) / 1e6
                    self.assertGreaterEqual(age_ms, 0, "%s stamped after it arrived" % topic)
                    self.assertLessEqual(age_ms, ROS_READING_STAMP_AGE_MS_MAX, "%s: a stamp %.0f ms old" % (topic, age_ms))
                    stamps.append(stamp)
                print("%s: %d messages in %.1f s on a still vehicle (%.1f Hz configured), %d distinct stamps; "
                      "before the window the longest gap %.0f ms" % (topic, len(got), ROS_SENSOR_RATE_WINDOW_S, rate_hz,
                                                                    len(set(stamps)), startup_gap_ms), file=sys.stderr)
                self.assertGreaterEqual(len(got), ROS_SENSOR_RATE_MIN_FRACTION * expected)
                self.assertLessEqual(len(got), ROS_SENSOR_RATE_MAX_FRACTION * expected)
                self.assertEqual(stamps, sorted(stamps), "stamps went back")
                self.assertLess(len(set(stamps)), len(stamps), "every message stamped anew: the time of sending")
        # The vehicle was still: the counts are the rate's, not the changes'.
        self.assertLess(abs(angle_diff(float(rig.sim_teensy("Orientation")[0]), 0.4)), 0.002, "the vehicle turned")

    def place_and_wait(self, heading):
        """The simulated vehicle placed (vehicle_motion.place), and caracarad's Teensy reading it:
        the Imu written before that (a poll or more behind) would be of the earlier place."""
        place(self.rig, heading=heading)
        poll(lambda: abs(angle_diff(float(self.rig.get(harness.VEHICLE, harness.TEENSY_PATH, harness.TEENSY_IFACE,
                                                                "Orientation")[0]), heading)) < 0.02, 10,
             message="caracarad's Teensy never read the placed heading")

    def check_attitude_and_turn(self, convention, world, body):
        """The orientation of `body` in `world`: a vehicle turned, nose up and rolled right (the
        thrusters hold it against the simulated body's restoring moment) reads as the simulator's
        attitude says; a clockwise turn reads as yaw decreasing in ENU, increasing in NED."""
        rig = self.rig
        rig.reset()
        self.place_and_wait(START_HEADING_RAD)
        self.hold_motion(2.5, pitch=0.5, roll=0.5)  # pitch and roll settle at about 0.25 rad
        attitude, last = [], [0.0]

        def during(**axes):
            if time.monotonic() - last[0] > 0.1:
                rig.motion(**axes)
                last[0] = time.monotonic()
            attitude.append(sim_attitude(rig))
        try:
            samples, _, _, _ = self.listen(2, ORIENTATION_TOPICS, during=lambda: during(pitch=0.5, roll=0.5))
        finally:
            rig.motion()
        self.assertGreater(min(a[1][1] for a in attitude), ORIENTATION_TO_JUDGE_MIN_RAD, "not nose up enough to judge")
        self.assertGreater(min(a[1][2] for a in attitude), ORIENTATION_TO_JUDGE_MIN_RAD, "not rolled right enough to judge")
        self.check_orientation(samples, attitude, convention, world, body)
        # A clockwise turn (the seed's yaw, + clockwise seen from above).
        rig.reset()
        self.place_and_wait(0.3)
        # A whole poll round (yaw, pitch, roll, a distance: one a cycle) and a telemetry tick: the
        # reading now held is all of the placed vehicle, not the heading alone.
        time.sleep(0.3)
        attitude.clear()
        try:
            samples, _, _, _ = self.listen(2.5, ORIENTATION_TOPICS, during=lambda: during(yaw=0.5))
        finally:
            rig.motion()
        turned = angle_diff(attitude[-1][1][0], attitude[0][1][0])
        self.assertGreater(turned, 0.5, "the simulated vehicle did not turn clockwise")
        # Turning at about 0.5 rad/s: the Teensy's poll and the stamp's nearest sample differ a little.
        self.check_orientation(samples, attitude, convention, world, body, delta=0.05)
        sign = -1 if convention == "enu" else 1
        for topic in ORIENTATION_TOPICS:
            # The turn's readings: not one from before the record began (check_orientation).
            msgs = [m for _, m, _ in samples[topic] if stamp_of(topic, m) + 50e6 >= attitude[0][0]]
            qs = [m["orientation"] if topic == "rt/caracara/imu" else m["transforms"][0]["transform"]["rotation"]
                  for m in msgs]
            yaws = unwrap([quaternion_yaw(q) for q in qs])
            # The simulator's turn between the first and the last message's stamps: the messages
            # come only once the peer's readers matched (late, under load), so they span less of
            # the turn than the whole record does.
            at = lambda stamp: min(attitude, key=lambda a: abs(a[0] - stamp))[1][0]  # noqa: E731
            span = angle_diff(at(stamp_of(topic, msgs[-1])), at(stamp_of(topic, msgs[0])))
            with self.subTest(topic=topic):
                self.assertGreater(span, ORIENTATION_TO_JUDGE_MIN_RAD, "the messages span too little of the turn")
                # Each reading matched the simulator within 0.05 (check_orientation): their turn, twice that.
                self.assertAlmostEqual(sign * (yaws[-1] - yaws[0]), span, delta=0.1,
                                       msg="a clockwise turn of %.2f rad (%.2f between the first and last message) "
                                       "read as yaw %+.2f rad" % (turned, span, yaws[-1] - yaws[0]))
                steps = [sign * (b - a) for a, b in zip(yaws, yaws[1:])]
                self.assertGreater(min(steps), -0.02, "yaw went the other way during the turn: %s" % steps)


class SecurePeer:
    """The DDS Security peer running (secure_peer.cpp) until the block ends (then SIGKILLed, if
    still running): WHO is an enclave directory, "rogue:" one, or "none". Its output: text(), and
    lines() as JSON, during the block and after it."""

    def __init__(self, exe, who, mode, *args):
        self.out = tempfile.TemporaryFile("w+")
        self.final = None
        self.p = subprocess.Popen([exe, who, mode] + [str(a) for a in args], stdout=self.out,
                                  stderr=subprocess.STDOUT, text=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        if self.p.poll() is None:
            self.p.send_signal(signal.SIGKILL)
        self.p.wait(10)
        self.final = self.text()
        self.out.close()

    def text(self):
        if self.final is not None:
            return self.final
        self.out.seek(0)
        return self.out.read()

    def lines(self):
        return [json.loads(line) for line in self.text().splitlines() if line.startswith("{")]


# An identity from another CA, refused by caracara-ros's side of the handshake (it replies, and
# finds the certificate not from its CA) or by the peer's (it gave up: caracara-ros's request
# goes unanswered). Which side replies follows from the certificates' subjects (Cyclone's
# adjusted GUIDs): with /caracara/ros's, /intruder's the first way, /pilot's the second.
OTHER_CA_REFUSED = (r"participant [0-9a-f]{24} refused: (not authenticated within|authentication failed: "
                    r"Certificate not valid)")


class SecurityTest(RosTestCase):
    """[ros] security = an SROS2 enclave (docs/ros2.md, DDS Security), commands on: two keystores
    made with openssl alone by the docs' own commands (two CAs), peers with Cyclone DDS's real
    security plugins. A permitted pilot drives and kills; a valid identity without publish
    permission (a rogue stack that writes anyway), an identity from the other CA and a peer with
    no security move nothing, their kills are not taken, and caracara-ros logs each. Judged by the
    simulator's wire log and caracara-ros's log. CommandsTest.test_cyclone_peer_without_security_drives
    is the control: the same unsecured peer drives a vehicle without security."""
    COMMANDS = True

    @classmethod
    def setUpClass(cls):
        network_is_private()
        cls.secure_peer = build_secure_peer()
        cls.keys = tempfile.mkdtemp(prefix="caracara-keystores-")
        cls.addClassCleanup(shutil.rmtree, cls.keys, True)
        blocks = doc_blocks()
        observer = "<publish><topics><topic>rt/caracara/kill</topic></topics></publish>"
        make_keystore(os.path.join(cls.keys, "a"), {"/caracara/ros": blocks["vehicle"], "/pilot": blocks["pilot"],
                                                    "/observer": observer})
        make_keystore(os.path.join(cls.keys, "b"), {"/pilot": blocks["pilot"], "/intruder": blocks["pilot"]})
        cls.ROS_CONFIG = 'security = "%s"\n' % os.path.join(cls.keys, "a", "enclaves", "caracara", "ros")
        super().setUpClass()

    def setUp(self):
        self.rig.rearm()

    def enclave(self, keystore, name):
        return os.path.join(self.keys, keystore, "enclaves", name.lstrip("/"))

    def secured(self, who, mode, *args):
        return SecurePeer(self.secure_peer, who, mode, *args)

    def test_permitted_pilot_drives(self):
        rig = self.rig
        self.assertIn("DDS Security on, enclave " + self.enclave("a", "/caracara/ros"), rig.log("caracara-ros"))
        since = rig.wire_next()
        with self.secured(self.enclave("a", "/pilot"), "wrench", 0.5, 0, 0, 0, 0, 0, 20):
            poll(lambda: nonzero_orders(rig.wire_log(since)[1]), 20, message="the permitted pilot's Wrench never moved a "
                 "thruster:\n" + rig.log("caracara-ros"))
        rig.wait_sim_zero()
        log = rig.log("caracara-ros")
        self.assertRegex(log, r"DDS Security: participant [0-9a-f]{24} authenticated")
        self.assertIn("commands as a pilot", log)

    def test_refused_peers_move_nothing_and_are_logged(self):
        rig = self.rig
        cases = [("valid identity, no publish permission (a rogue stack)", "rogue:" + self.enclave("a", "/observer"),
                  "on rt/caracara/cmd_wrench refused: its signed permissions do not allow publishing it"),
                 # The other CA's two identities: caracara-ros's side of the handshake refuses the
                 # first, the peer's side the second (OTHER_CA_REFUSED).
                 ("identity from another CA (refused by the vehicle's side)", self.enclave("b", "/intruder"),
                  "refused: authentication failed: Certificate not valid"),
                 ("identity from another CA (refused by the peer's side)", self.enclave("b", "/pilot"),
                  "refused: not authenticated within"),
                 ("no DDS Security", "none", "refused: it has no DDS Security")]
        for what, who, line in cases:
            with self.subTest(what):
                before = rig.log("caracara-ros")
                since = rig.wire_next()
                with self.secured(who, "wrench", 0.5, 0, 0, 0, 0, 0, 20) as p:
                    poll(lambda: len(re.findall(line, rig.log("caracara-ros"))) > len(re.findall(line, before)), 20,
                         message="no refusal logged for the peer with %s:\n%s" % (what, rig.log("caracara-ros")))
                    # It goes on writing meanwhile: nothing of it may move a thruster.
                    poll(lambda: sum(1 for o in p.lines() if o.get("ok")) >= 40, 10, message="the peer did not write")
                self.assertEqual(nonzero_orders(rig.wire_log(since)[1]), [], what)
                self.assertEqual(rig.motor_values(), [0] * MOTORS)
                after = rig.log("caracara-ros")
                self.assertEqual(after.count("commands as a pilot"), before.count("commands as a pilot"), what)
                # The peer made its writer and wrote all along: the refusal was the vehicle's (for
                # the rogue, its writer refused by the vehicle's access control: the line above).
                self.assertNotIn("no writer", p.text())
        self.assertEqual(rig.vget("State"), "ready")

    def test_kill_follows_the_governance(self):
        """A kill from a peer the governance refuses (another CA, no security) is not taken; one
        from a valid identity allowed to publish kill (and nothing else) is."""
        rig = self.rig
        for what, who, line in (("identity from another CA", self.enclave("b", "/pilot"), OTHER_CA_REFUSED),
                                ("no DDS Security", "none", "it has no DDS Security")):
            with self.subTest(what):
                before = len(re.findall(line, rig.log("caracara-ros")))
                since = rig.wire_next()
                with self.secured(who, "kill", 1000, 5):
                    poll(lambda: len(re.findall(line, rig.log("caracara-ros"))) > before, 20,
                         message="no refusal logged for the kill of the peer with " + what)
                    time.sleep(1)  # a few more of its kills
                self.assertEqual(rig.vget("State"), "ready", what)
                self.assertEqual(kill_edges(rig.wire_log(since)[1]), [], what)
        since = rig.wire_next()
        with self.secured(self.enclave("a", "/observer"), "kill", 1000, 5):
            rig.wait_state("killed")
        self.assertIn("kill from DDS", rig.log("caracara-ros"))
        poll(lambda: kill_edges(rig.wire_log(since)[1]), 5, message="no kill output edge")


class BytesTest(unittest.TestCase):
    """Fast CDR (the peer's generated types) and rosmsg2-serialization give the same bytes for a
    fixed sample of every type, for Humble's and Jazzy's definitions."""

    def test_every_type_same_bytes(self):
        for distro in ("humble", "jazzy"):
            peer = build_peer(distro)
            codec = Codec()
            try:
                for t in TYPES:
                    with self.subTest(distro=distro, type=t):
                        ref = codec.encode(t, fixed_sample(t, distro), distro)
                        fast = subprocess.run([peer, "roundtrip", t, ref], capture_output=True, text=True, check=True)
                        self.assertEqual(fast.stdout.strip(), ref)
                        self.assertTrue(ref.startswith("0001"), "CDR little-endian (XCDR1) encapsulation")
            finally:
                codec.close()


# rosbag2_storage's QoS profile (rosbag2_storage/src/rosbag2_storage/qos.cpp, the YAML it reads back
# from a channel's offered_qos_profiles): its field names, and rmw's policy numbers where a bag
# without serialized_metadata is read as version 8 (Humble reads numbers too).
ROSBAG2_QOS_KEYS = {"history", "depth", "reliability", "durability", "deadline", "lifespan", "liveliness",
                    "liveliness_lease_duration", "avoid_ros_namespace_conventions"}
RMW_KEEP_LAST, RMW_RELIABLE, RMW_TRANSIENT_LOCAL, RMW_VOLATILE, RMW_LIVELINESS_AUTOMATIC = 1, 1, 1, 2, 1
LATCHED_TOPICS = ("/caracara/state", "/caracara/killed", "/caracara/kill_source", "/tf_static")


class DiveExportTest(unittest.TestCase):
    """caracaractl export --format mcap --encoding cdr on the regression dives (tests/dives): read
    as rosbag2 would (mcap_ros_check.mjs: @mcap/core, ros2msg schemas, every message decoded by
    rosmsg2-serialization and written back to the same bytes), judged against the dive's CSV; each
    channel's offered_qos_profiles parsed as YAML against rosbag2's field names (the state topics
    transient-local, so they replay latched), the "rosbag2" record's ROS_DISTRO; with --distro
    jazzy, Range in Jazzy's layout."""

    def test_regression_dives(self):
        npm_ci(HERE)
        dives = os.path.join(SOURCE, "tests", "dives")
        ctl = harness.command("caracaractl")
        names = sorted(n for n in os.listdir(dives) if n.endswith(".cdive"))
        self.assertTrue(names)
        with tempfile.TemporaryDirectory() as d:
            for name in names:
                with self.subTest(dive=name):
                    path = os.path.join(dives, name)
                    out = os.path.join(d, name + ".mcap")
                    r = subprocess.run(ctl + ["export", path, "--format", "mcap", "--encoding", "cdr", "--out", out],
                                       capture_output=True, text=True)
                    self.assertEqual(r.returncode, 0, r.stderr)
                    check = subprocess.run(["node", "mcap_ros_check.mjs", out], cwd=HERE, capture_output=True,
                                           text=True)
                    self.assertEqual(check.returncode, 0, check.stderr)
                    self.judge(json.loads(check.stdout), path, ctl)
            # Jazzy's: the same topics, Range with its variance, ROS_DISTRO jazzy.
            path, out = os.path.join(dives, names[0]), os.path.join(d, "jazzy.mcap")
            r = subprocess.run(ctl + ["export", path, "--format", "mcap", "--encoding", "cdr", "--distro", "jazzy",
                                      "--out", out], capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)
            check = subprocess.run(["node", "mcap_ros_check.mjs", out], cwd=HERE, capture_output=True, text=True)
            self.assertEqual(check.returncode, 0, check.stderr)
            self.judge(json.loads(check.stdout), path, ctl, distro="jazzy")
            r = subprocess.run(ctl + ["export", path, "--format", "mcap", "--encoding", "cdr", "--distro", "iron",
                                      "--out", out], capture_output=True, text=True)
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("--distro takes humble or jazzy, not 'iron'", r.stderr)

    def test_config_namespace_and_frames(self):
        """--ros-config: the topics under the config's namespace, the frames its names in its
        convention (NED here: _ned / _frd), each Range in its mount's frame, /tf_static the mounts,
        as caracara-ros names them live; a bad config refused by name, no file written."""
        npm_ci(HERE)
        dives = os.path.join(SOURCE, "tests", "dives")
        ctl = harness.command("caracaractl")
        path = os.path.join(dives, sorted(n for n in os.listdir(dives) if n.endswith(".cdive"))[0])
        with tempfile.TemporaryDirectory() as d:
            conf, out = os.path.join(d, "ros.toml"), os.path.join(d, "dive.mcap")
            with open(conf, "w") as f:
                f.write('[ros]\nnamespace = "/fleet/auv2"\nworld_frame = "map"\nbase_frame = "hull"\n'
                        'frame_convention = "ned"\nrange_max_m = 30.0\n[ros.imu]\nframe = "ahrs"\nrpy = [0, 0, 1.5]\n'
                        '[[ros.range]]\nframe = "sonar_front"\nxyz = [0.4, 0, -0.1]\n')
            r = subprocess.run(ctl + ["export", path, "--format", "mcap", "--encoding", "cdr", "--ros-config", conf,
                                      "--out", out], capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)
            check = subprocess.run(["node", "mcap_ros_check.mjs", out], cwd=HERE, capture_output=True, text=True)
            self.assertEqual(check.returncode, 0, check.stderr)
            bag = json.loads(check.stdout)
            msgs = bag["messages"]
            ranges = sorted(t for t in bag["topics"] if "/range/" in t)
            self.assertTrue(ranges)
            self.assertEqual(set(bag["topics"]), {"/fleet/auv2/" + t for t in (
                "imu", "joint_states", "thrusters/ordered", "state", "killed", "kill_source")} |
                {"/tf", "/tf_static", "/diagnostics"} | set(ranges))
            self.assertEqual(ranges, ["/fleet/auv2/range/%d" % i for i in range(len(ranges))])
            self.assertEqual({m["header"]["frame_id"] for m in msgs["/fleet/auv2/imu"]}, {"hull_frd"})
            self.assertEqual({(t["header"]["frame_id"], t["child_frame_id"]) for m in msgs["/tf"] for t in m["transforms"]},
                             {("map_ned", "hull_frd")})
            self.assertEqual({m["header"]["frame_id"] for m in msgs["/fleet/auv2/joint_states"]}, {"hull"})
            for i, topic in enumerate(ranges):
                self.assertEqual({(m["header"]["frame_id"], m["max_range"]) for m in msgs[topic]},
                                 {("sonar_front" if i == 0 else "range_%d" % i, 30.0)})
            static = msgs["/tf_static"]
            self.assertEqual(len(static), 1)
            mounts = {t["child_frame_id"]: t for t in static[0]["transforms"]}
            self.assertEqual(set(mounts), {"ahrs", "sonar_front"} | {"range_%d" % i for i in range(1, len(ranges))})
            self.assertEqual({t["header"]["frame_id"] for t in mounts.values()}, {"hull"})
            self.assertEqual(mounts["sonar_front"]["transform"]["translation"], {"x": 0.4, "y": 0, "z": -0.1})
            q = mounts["ahrs"]["transform"]["rotation"]
            self.assertAlmostEqual(quaternion_yaw(q), 1.5, places=9)
            # A bad setting: refused by name, nothing written.
            with open(conf, "w") as f:
                f.write('[ros]\nbase_frame = "hull frame"\n')
            os.unlink(out)
            r = subprocess.run(ctl + ["export", path, "--format", "mcap", "--encoding", "cdr", "--ros-config", conf,
                                      "--out", out], capture_output=True, text=True)
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("ros.base_frame must be a frame name", r.stderr)
            self.assertFalse(os.path.exists(out))

    def judge_replay(self, bag, distro):
        """What `ros2 bag play` offers each topic with, and what `ros2 bag info` names the distro."""
        if yaml is None:
            missing("python3-yaml is needed to read the bag's QoS profiles as rosbag2 does (scripts/deps.sh)")
        self.assertEqual(bag["records"], [{"name": "rosbag2", "metadata": {"ROS_DISTRO": distro}}])
        for topic, t in bag["topics"].items():
            with self.subTest(topic=topic):
                profiles = yaml.safe_load(t["metadata"]["offered_qos_profiles"])
                self.assertEqual(len(profiles), 1, profiles)
                p = profiles[0]
                self.assertEqual(set(p), ROSBAG2_QOS_KEYS)
                latched = topic in LATCHED_TOPICS
                self.assertEqual((p["history"], p["depth"], p["reliability"], p["durability"], p["liveliness"]),
                                 (RMW_KEEP_LAST, 1 if latched else 10, RMW_RELIABLE,
                                  RMW_TRANSIENT_LOCAL if latched else RMW_VOLATILE, RMW_LIVELINESS_AUTOMATIC))
                for k in ("deadline", "lifespan", "liveliness_lease_duration"):
                    self.assertEqual(p[k], {"sec": 0, "nsec": 0})
                self.assertIs(p["avoid_ros_namespace_conventions"], False)
        self.assertLessEqual(set(LATCHED_TOPICS), set(bag["topics"]))

    def judge(self, bag, path, ctl, distro="humble"):
        self.judge_replay(bag, distro)
        csv = subprocess.run(ctl + ["export", path], capture_output=True, text=True, check=True).stdout.splitlines()
        cols = csv[0].split(",")
        rows = [dict(zip(cols, line.split(","))) for line in csv[1:]]
        events = subprocess.run(ctl + ["export", path, "--events"], capture_output=True, text=True,
                                check=True).stdout.splitlines()[1:]
        self.assertEqual(bag["profile"], "ros2")
        types = {t: v["type"] for t, v in bag["topics"].items()}
        self.assertEqual(types["/caracara/imu"], "sensor_msgs/msg/Imu")
        self.assertEqual(types["/caracara/joint_states"], "sensor_msgs/msg/JointState")
        self.assertEqual(types["/tf"], "tf2_msgs/msg/TFMessage")
        self.assertEqual(types["/diagnostics"], "diagnostic_msgs/msg/DiagnosticArray")
        for topic in ("/caracara/imu", "/tf", "/caracara/joint_states", "/caracara/thrusters/ordered"):
            self.assertEqual(bag["topics"][topic]["count"], len(rows), topic)
        msgs = bag["messages"]
        for n, (row, js, od, imu) in enumerate(zip(rows, msgs["/caracara/joint_states"],
                                                   msgs["/caracara/thrusters/ordered"], msgs["/caracara/imu"])):
            for i in range(MOTORS):
                speed = row["speed_%d" % i]
                self.assertAlmostEqual(js["velocity"][i] * MOTOR_MAX, int(speed) if speed else 0, places=6)
                self.assertAlmostEqual(od["velocity"][i] * MOTOR_MAX, int(row["app_%d" % i]), places=6)
            # base_link (FLU) in odom (ENU), as caracara-ros's defaults: the heading reference is
            # north, ENU's yaw pi/2 - the Teensy's clockwise heading.
            q = imu["orientation"]
            attitude = [float(row[k]) for k in ("yaw", "pitch", "roll")]
            self.assertAlmostEqual(angle_diff(quaternion_yaw(q), math.pi / 2 - attitude[0]), 0, delta=1e-3)
            want = expected_axes(attitude, "enu")
            for axis, v in enumerate(((1, 0, 0), (0, 1, 0))):
                for k, c in enumerate(rotate(q, v)):
                    self.assertAlmostEqual(c, want[axis][k], delta=1e-3)
            self.assertEqual(imu["header"]["frame_id"], "base_link")
            tf = msgs["/tf"][n]["transforms"][0]
            self.assertEqual((tf["header"]["frame_id"], tf["child_frame_id"]), ("odom", "base_link"))
            self.assertEqual(tf["transform"]["rotation"], q)
            distances = row["distances_mm"].split()
            for k, mm in enumerate(distances):
                r = msgs["/caracara/range/%d" % k][n]
                self.assertAlmostEqual(r["range"], int(mm) / 1000, places=4)
                self.assertEqual("variance" in r, distro == "jazzy")
        states = [e.split(",")[2].split()[0] for e in events if e.split(",")[1] == "state"]
        got = [m["data"] for m in msgs["/caracara/state"]]
        # The first state message is the dive's start (arming); each change after it follows the events.
        self.assertEqual(got, [s for k, s in enumerate(["arming"] + states) if k == 0 or s != (["arming"] + states)[k - 1]])
        self.assertEqual([m["data"] for m in msgs["/caracara/killed"]], [s in ("killed", "powered-off") for s in got])


class PublishedTest(RosTestCase):
    """Every topic's type name, QoS and values as the Fast DDS peer receives them, against the simulator."""

    def test_discovery_data(self):
        _, participants, writers, _ = self.listen(3)
        self.assertTrue(any(p["user_data"] == "enclave=/;" for p in participants), participants)
        for topic, type_ in PUBLISHED.items():
            with self.subTest(topic=topic):
                w = writers.get(topic)
                self.assertIsNotNone(w, "no writer on %s (saw %s)" % (topic, sorted(writers)))
                pkg, name = type_.split("/")
                self.assertEqual(w["type"], "%s::msg::dds_::%s_" % (pkg, name))
                self.assertTrue(w["reliable"])
                self.assertTrue(w["xcdr1"])
                self.assertEqual(w["transient_local"], topic.split("/")[-1] in LATCHED)

    def test_discovery_info_lists_the_node(self):
        """`ros2 node list` / `ros2 node info` see caracara_ros with its topics (Humble's 24-byte gid)."""
        self.check_discovery_info(["rt/caracara/kill"])

    def test_values_against_the_simulator(self):
        rig = self.rig
        rig.reset()
        values = [4425, -4425, 0, 0, 0, 0, 0, 0]
        rig.thrust(values)
        rig.wait_sim_speeds([speed_byte(v) for v in values])
        # The simulator's attitude through the window (the body turns under this thrust), to
        # compare each Imu sample with the simulator's attitude at its stamp.
        attitude = []
        samples, _, _, _ = self.listen(3, during=lambda: attitude.append(sim_attitude(rig)))
        for topic in PUBLISHED:
            self.assertIn(topic, samples, "nothing received on " + topic)
        last = {t: s[-1][1] for t, s in samples.items()}
        # Latched state: a late subscriber gets it.
        self.assertEqual(last["rt/caracara/state"]["data"], "ready")
        self.assertIs(last["rt/caracara/killed"]["data"], False)
        # JointState: names, actual speed as a fraction of full thrust, as the simulator reports it.
        js = last["rt/caracara/joint_states"]
        self.assertEqual(js["name"], ["thruster_%d" % i for i in range(MOTORS)])
        self.assertAlmostEqual(js["velocity"][0], 0.5, delta=0.02)
        self.assertAlmostEqual(js["velocity"][1], -0.5, delta=0.02)
        self.assertEqual(len(js["effort"]), MOTORS)
        ordered = last["rt/caracara/thrusters/ordered"]["velocity"]
        self.assertEqual([round(v * MOTOR_MAX) for v in ordered], rig.motor_values())
        # Imu and /tf: base_link (FLU) in odom (ENU) as the simulator's attitude says (REP 103 /
        # 145); REP 145's unknown fields.
        self.check_orientation({t: samples[t] for t in ORIENTATION_TOPICS}, attitude, "enu", "odom", "base_link")
        imu = last["rt/caracara/imu"]
        self.assertEqual(imu["angular_velocity_covariance"][0], -1)
        self.assertEqual(imu["linear_acceleration_covariance"][0], -1)
        # Range: the simulator's first distance in metres.
        mm = int(rig.sim_teensy("Distances")[0])
        self.assertAlmostEqual(last["rt/caracara/range/0"]["range"], mm / 1000, delta=0.002)
        # Diagnostics: each thruster, the bus, the Teensy, the failsafes, the vehicle.
        names = [s["name"] for s in last["rt/diagnostics"]["status"]]
        for n in ["caracara: thruster_%d" % i for i in range(MOTORS)] + ["caracara: i2c bus", "caracara: teensy",
                                                                         "caracara: failsafes", "caracara: vehicle"]:
            self.assertIn(n, names)
        # joint_states comes at the steady sensor rate (5 Hz: test_steady_rates_on_a_still_vehicle
        # counts it), not only with changes of state.
        self.assertGreaterEqual(len(samples["rt/caracara/joint_states"]), 5)

    def test_steady_rates_on_a_still_vehicle(self):
        """imu, /tf and joint_states at the daemon's telemetry rate (the default) to a late subscriber,
        though nothing changes."""
        self.check_steady_rates(DAEMON_TELEMETRY_HZ)

    def test_orientation_in_enu_flu(self):
        """REP 103 / 145: base_link (x forward, y left, z up) in odom (x east, y north, z up), the
        heading reference north; a clockwise turn reads as yaw decreasing."""
        self.check_attitude_and_turn("enu", "odom", "base_link")

    def test_kill_topic_with_commands_off(self):
        """Kill is always taken; the kill output's edge is on the wire."""
        rig = self.rig
        rig.reset()
        since = rig.wire_next()
        self.publish("rt/caracara/kill", "std_msgs/Empty", {})
        rig.wait_state("killed")
        self.assertEqual(rig.vget("KillSource"), "dbus")
        poll(lambda: kill_edges(rig.wire_log(since)[1]), 5, message="no kill output edge")
        samples, _, _, _ = self.listen(1.5, {"rt/caracara/killed": "std_msgs/Bool", "rt/caracara/kill_source": "std_msgs/String"})
        self.assertIs(samples["rt/caracara/killed"][-1][1]["data"], True)
        self.assertEqual(samples["rt/caracara/kill_source"][-1][1]["data"], "dbus")

    def test_commands_off_nothing_moves(self):
        rig = self.rig
        rig.rearm()
        since = rig.wire_next()
        # No reader: the peer's publish finds none to match and says so.
        hex_ = self.codec.encode("geometry_msgs/Wrench", {"force": {"x": 0.5, "y": 0, "z": 0},
                                                          "torque": {"x": 0, "y": 0, "z": 0}})
        r = subprocess.run([self.peer, "publish", "rt/caracara/cmd_wrench", "geometry_msgs/Wrench", hex_, "10", "20"],
                           capture_output=True, text=True, timeout=60)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("no reader matched", r.stderr)
        self.assertEqual(nonzero_orders(rig.wire_log(since)[1]), [])
        self.assertEqual(rig.motor_values(), [0] * MOTORS)
        self.assertNotIn("pilot", rig.log("caracara-ros"))


class JazzyRangeTest(RosTestCase):
    """range_layout = "jazzy": sensor_msgs/Range with Jazzy's variance, read by a peer built from
    Jazzy's definitions (a Humble-layout sample would be 4 bytes short for it)."""
    DISTRO = "jazzy"

    def test_range_in_jazzy_layout(self):
        samples, _, writers, _ = self.listen(2, {"rt/caracara/range/0": "sensor_msgs/Range"})
        self.assertEqual(writers["rt/caracara/range/0"]["type"], "sensor_msgs::msg::dds_::Range_")
        r = samples["rt/caracara/range/0"][-1][1]
        self.assertEqual(r["variance"], 0.0)
        self.assertAlmostEqual(r["range"], int(self.rig.sim_teensy("Distances")[0]) / 1000, delta=0.002)

    def test_discovery_info_with_jazzy_gids(self):
        """Jazzy's 16-byte Gid, read by the peer built from Jazzy's rmw_dds_common."""
        self.check_discovery_info(["rt/caracara/kill"])


def status_named(samples, name):
    """The last /diagnostics' status `name`, its values as a dict."""
    msgs = samples.get("rt/diagnostics")
    assert msgs, "no /diagnostics received"
    st = [s for s in msgs[-1][1]["status"] if s["name"] == name]
    assert len(st) == 1, [s["name"] for s in msgs[-1][1]["status"]]
    return {**st[0], "values": {kv["key"]: kv["value"] for kv in st[0]["values"]}}


def distro_status(samples):
    return status_named(samples, "caracara: ros distro")


class AutoDistroTest(RosTestCase):
    """No range_layout in the config: caracara-ros speaks what the ROS 2 machines around speak, read
    from their ros_discovery_info (Jazzy's 16-byte Gid or Humble's 24, told apart by size). A
    Jazzy node appears (the peer built from Jazzy's definitions writes its ParticipantEntitiesInfo,
    transient-local as rmw does): Range and caracara-ros's own ros_discovery_info turn to Jazzy's
    layouts, read by that peer. A Humble node joins: both are about, caracara-ros keeps Jazzy (a
    tie keeps what it speaks) and says so in the journal and on /diagnostics (WARN)."""
    DISTRO = "jazzy"
    LAYOUT_IN_CONFIG = False
    DIAGNOSTICS = {"rt/diagnostics": "diagnostic_msgs/DiagnosticArray"}

    def ros_node(self, distro, name):
        """A peer built from `distro`'s definitions writing a ROS 2 node's ros_discovery_info in
        that distro's layout (2 Hz) until the block ends."""
        gid = {"data": list(range(0x40, 0x50)) + [0] * (GID_BYTES[distro] - 16)}
        msg = {"gid": gid, "node_entities_info_seq": [{"node_namespace": "/", "node_name": name,
                                                       "reader_gid_seq": [gid], "writer_gid_seq": []}]}
        return self.driving("ros_discovery_info", "rmw_dds_common/ParticipantEntitiesInfo", msg, hz=2, distro=distro)

    def test_speaks_what_the_peers_speak(self):
        rig = self.rig
        status = distro_status(self.listen(2.5, self.DIAGNOSTICS)[0])
        self.assertEqual((status["values"]["speaking"], status["level"]), ("humble", 0), status)
        self.assertIn("no ROS 2 peer seen yet", status["message"])
        log_start = len(rig.log("caracara-ros"))
        with self.ros_node("jazzy", "talker"):
            poll(lambda: "speaking jazzy" in rig.log("caracara-ros")[log_start:], 20,
                 message="caracara-ros never turned to Jazzy")
            self.assertIn("speaking jazzy: the peers' ros_discovery_info: 1 participant, all jazzy",
                          rig.log("caracara-ros"))
            # Range in Jazzy's layout, read by the peer built from Jazzy's definitions.
            samples, _, _, _ = self.listen(2.5, {"rt/caracara/range/0": "sensor_msgs/Range", **self.DIAGNOSTICS})
            r = samples["rt/caracara/range/0"][-1][1]
            self.assertEqual(r["variance"], 0.0)
            self.assertAlmostEqual(r["range"], int(rig.sim_teensy("Distances")[0]) / 1000, delta=0.002)
            status = distro_status(samples)
            self.assertEqual((status["values"]["speaking"], status["values"]["jazzy peers"], status["level"]),
                             ("jazzy", "1", 0), status)
            # caracara-ros's own ros_discovery_info with Jazzy's 16-byte gids, its Range writers
            # those listed (the Humble-layout ones are gone).
            self.check_discovery_info(["rt/caracara/kill"])
            log_start = len(rig.log("caracara-ros"))
            with self.ros_node("humble", "listener"):
                poll(lambda: "peers of both distros" in rig.log("caracara-ros")[log_start:], 20,
                     message="caracara-ros never said it found both distros")
                self.assertIn("speaking jazzy: peers of both distros (humble 1 participant, jazzy 1 participant): "
                              "jazzy, spoken already", rig.log("caracara-ros"))
                status = distro_status(self.listen(2.5, self.DIAGNOSTICS)[0])
                self.assertEqual((status["values"]["speaking"], status["values"]["humble peers"],
                                  status["values"]["jazzy peers"], status["level"]), ("jazzy", "1", "1", 1), status)
                self.assertIn("set range_layout to choose", status["message"])


class RangeSubscriberTest(RosTestCase):
    """No range_layout, and no ROS 2 node about (the distro stays Humble's): each subscriber of
    range/N gets the Range it asks for, told by the type hash in its reader's USER_DATA as Jazzy's
    rmw announces it ("typehash=RIHS01_...;", here computed from Jazzy's published definitions by
    rosidl's rule, type_hash.mjs), none from Humble. The bytes as they came are read by the
    reference deserializer with the subscriber's definition and written back the same: a Humble
    sample is 4 bytes short for Jazzy's, a Jazzy one leaves 4 over for Humble's. The journal and
    /diagnostics ("caracara: ros range layout") say which and why."""
    DISTRO = "humble"
    LAYOUT_IN_CONFIG = False
    TOPICS = {"rt/caracara/range/0": "sensor_msgs/Range", "rt/diagnostics": "diagnostic_msgs/DiagnosticArray"}

    def judge_range(self, samples, distro):
        got = samples.get("rt/caracara/range/0")
        self.assertTrue(got, "no Range the peer built from %s's definitions could read" % distro)
        wire = got[-1][2]
        r = self.codec.decode("sensor_msgs/Range", wire, distro)
        self.assertEqual(self.codec.encode("sensor_msgs/Range", r, distro), wire)
        self.assertEqual("variance" in r, distro == "jazzy")
        self.assertAlmostEqual(r["range"], int(self.rig.sim_teensy("Distances")[0]) / 1000, delta=0.002)

    def subscriber(self, distro, seconds=4):
        """A subscriber of range/0 (and /diagnostics) built from `distro`'s definitions for
        `seconds`: its samples and what caracara-ros's journal said meanwhile."""
        log_start = len(self.rig.log("caracara-ros"))
        samples = self.listen(seconds, self.TOPICS, distro=distro)[0]
        return samples, self.rig.log("caracara-ros")[log_start:]

    def test_each_subscriber_gets_the_range_it_asks_for(self):
        samples, log = self.subscriber("jazzy")
        self.assertRegex(log, r"Range subscriber [0-9a-f.]+ on /caracara/range/0 asks for jazzy: typehash %s: "
                              r"Range with variance \(Jazzy's\)" % type_hash("jazzy", "sensor_msgs/Range"))
        self.assertIn("Range in jazzy's layout: the Range subscribers' types: 1 subscriber, all asking for jazzy", log)
        self.judge_range(samples, "jazzy")
        status = status_named(samples, "caracara: ros range layout")
        self.assertEqual((status["values"]["layout"], status["values"]["jazzy subscribers"], status["level"]),
                         ("jazzy", "1", 0), status)
        self.assertEqual(distro_status(samples)["values"]["speaking"], "humble")  # not from ros_discovery_info
        samples, log = self.subscriber("humble")
        self.assertRegex(log, r"Range subscriber [0-9a-f.]+ on /caracara/range/0 asks for humble: no typehash")
        self.assertIn("Range in humble's layout: the Range subscribers' types: 1 subscriber, all asking for humble", log)
        self.judge_range(samples, "humble")
        status = status_named(samples, "caracara: ros range layout")
        self.assertEqual((status["values"]["layout"], status["values"]["humble subscribers"],
                          status["values"]["jazzy subscribers"], status["level"]), ("humble", "1", "0", 0), status)

    def test_subscribers_of_both_layouts(self):
        """A Jazzy subscriber, then a Humble one beside it: one writer reaches both, so caracara-ros
        keeps the layout it writes (a tie) and says in the journal and on /diagnostics (WARN) that
        the other cannot read it; the Humble subscriber does get Jazzy's bytes, 4 over its type."""
        log_start = len(self.rig.log("caracara-ros"))
        jazzy = {}
        t = threading.Thread(target=lambda: jazzy.update(self.listen(9, self.TOPICS, distro="jazzy")[0]))
        t.start()
        try:
            poll(lambda: "Range in jazzy's layout" in self.rig.log("caracara-ros")[log_start:], 20,
                 message="the Jazzy subscriber was not taken")
            samples, log = self.subscriber("humble", seconds=3)
        finally:
            t.join(60)
        self.assertIn("Range in jazzy's layout: Range subscribers asking for both (humble 1, jazzy 1): jazzy, written "
                      "already; the others cannot read Range (set range_layout to choose)", log)
        status = status_named(samples, "caracara: ros range layout")
        self.assertEqual((status["values"]["layout"], status["values"]["humble subscribers"],
                          status["values"]["jazzy subscribers"], status["level"]), ("jazzy", "1", "1", 1), status)
        wire = samples["rt/caracara/range/0"][-1][2]
        humble = self.codec.encode("sensor_msgs/Range", self.codec.decode("sensor_msgs/Range", wire, "humble"), "humble")
        self.assertEqual(len(wire) - len(humble), 8, "not Jazzy's 4 bytes of variance over Humble's Range")
        self.judge_range(jazzy, "jazzy")


class NedFrdTest(RosTestCase):
    """frame_convention = "ned": base_link_frd (x forward, y right, z down) in odom_ned (x north,
    y east, z down); a clockwise turn reads as yaw increasing."""
    ROS_CONFIG = 'frame_convention = "ned"\nsensor_rate_hz = 10\n'

    def test_orientation_in_ned_frd(self):
        self.check_attitude_and_turn("ned", "odom_ned", "base_link_frd")

    def test_configured_sensor_rate(self):
        """[ros] sensor_rate_hz = 10: imu, /tf and joint_states at 10 Hz on a still vehicle."""
        self.check_steady_rates(10.0)


class NoOdomTfTest(RosTestCase):
    """publish_odom_tf = false: the vehicle's localization publishes odom -> base_link, so
    caracara-ros has no /tf writer at all; the Imu is still there."""
    ROS_CONFIG = 'publish_odom_tf = false\n'

    def test_no_odom_to_base_link(self):
        rig = self.rig
        rig.reset()
        attitude, last = [], [0.0]

        def turning():  # the Imu is written when the attitude changes
            if time.monotonic() - last[0] > 0.1:
                rig.motion(yaw=0.3)
                last[0] = time.monotonic()
            attitude.append(sim_attitude(rig))
        try:
            samples, _, writers, _ = self.listen(2, {"rt/caracara/imu": "sensor_msgs/Imu"}, during=turning)
        finally:
            rig.motion()
        # Every other writer was discovered, so the missing /tf is not discovery still under way.
        self.assertLessEqual(set(PUBLISHED) - {"rt/tf"}, set(writers))
        self.assertNotIn("rt/tf", writers)
        self.check_orientation(samples, attitude, "enu", "odom", "base_link", publish_tf=False, delta=0.05)


def quaternion_from_rpy(roll, pitch, yaw):
    """URDF's rpy (fixed axes x, y, z) as a quaternion, the test's own: q = qz(yaw) qy(pitch) qx(roll)."""
    def mul(a, b):
        ax, ay, az, aw = a
        bx, by, bz, bw = b
        return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
                aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)
    qx = (math.sin(roll / 2), 0, 0, math.cos(roll / 2))
    qy = (0, math.sin(pitch / 2), 0, math.cos(pitch / 2))
    qz = (0, 0, math.sin(yaw / 2), math.cos(yaw / 2))
    x, y, z, w = mul(qz, mul(qy, qx))
    return {"x": x, "y": y, "z": z, "w": w}


def ros_gid(guid_hex, distro):
    """A 16-byte DDS GUID (32 hex digits) as `ros2 topic info -v` prints the GID (rclpy: each byte
    as two hex digits, dotted), zero-padded to the distro's Gid size."""
    data = bytes.fromhex(guid_hex) + bytes(GID_BYTES[distro] - 16)
    return ".".join("%02x" % b for b in data)


def commands_status(samples):
    """The last /diagnostics' "caracara: ros commands" status, its values as a dict."""
    msgs = samples.get("rt/diagnostics")  # once a second: a listen of 2.5 s or more gets one
    assert msgs, "no /diagnostics received"
    return commands_status_of(msgs[-1][1])


def commands_status_of(msg):
    st = [s for s in msg["status"] if s["name"] == "caracara: ros commands"]
    assert len(st) == 1, [s["name"] for s in msg["status"]]
    return {**st[0], "values": {kv["key"]: kv["value"] for kv in st[0]["values"]}}


class OneWriterTest(RosTestCase):
    """One commanding writer: the first writer of cmd_wrench / cmd_thrust that commands holds the
    vehicle until it stops for the command timeout (the vehicle's, 500 ms here) or leaves; a second
    writer's samples are refused by name, move nothing (the simulator's wire log), are logged with
    its GID as `ros2 topic info -v` prints it and counted on /diagnostics, which name the holder."""
    COMMANDS = True
    CONTROL = {"arming_delay_ms": 300, "command_timeout_ms": 500}
    DIAGNOSTICS = {"rt/diagnostics": "diagnostic_msgs/DiagnosticArray"}

    def test_second_writer_refused_until_the_first_stops(self):
        rig = self.rig
        rig.rearm()
        timeout_s = int(rig.vget("CommandTimeoutMs")) / 1000
        thrust = lambda d: {"layout": {"dim": [], "data_offset": 0}, "data": d}  # noqa: E731
        first, second = [0.3, 0.3] + [0] * 6, [0] * 6 + [0.4, 0.4]  # different thrusters each
        speeds = lambda d: [speed_byte(round(v * MOTOR_MAX)) for v in d]  # noqa: E731
        with self.steering("rt/caracara/cmd_thrust", "std_msgs/Float64MultiArray", thrust(first)) as send_first:
            rig.wait_sim_speeds(speeds(first))
            # The first writer's GUID as the peer discovered it: the one cmd_thrust writer so far.
            samples, _, writers, _ = self.listen(2.5, self.DIAGNOSTICS)
            first_guid = writers["rt/caracara/cmd_thrust"]["guid"]
            first_gid = ros_gid(first_guid, self.DISTRO)
            status = commands_status(samples)
            self.assertEqual(status["values"]["holder"], first_gid)
            self.assertEqual(status["message"], "held by writer " + first_gid)
            since = rig.wire_next()
            log_start = len(rig.log("caracara-ros"))
            with self.driving("rt/caracara/cmd_thrust", "std_msgs/Float64MultiArray", thrust(second)):
                try:
                    poll(lambda: "(not-holder)" in rig.log("caracara-ros")[log_start:], 20)
                except harness.Timeout:
                    self.fail("the second writer was never refused; caracara-ros's log since it began:\n" +
                              rig.log("caracara-ros")[log_start:])
                samples, _, _, endpoints = self.listen(3.5, self.DIAGNOSTICS)
                # Nothing of the second writer's moved: the wire carried the first's orders only.
                log = rig.wire_log(since)[1]
                self.assertEqual([(i, sp) for e, i, sp in orders(log) if i >= 2 and sp != ZERO], [])
                self.assertEqual({sp for e, i, sp in orders(log) if i < 2}, set(speeds(first)[:2]))
                self.assertEqual(rig.motor_values(), [round(v * MOTOR_MAX) for v in first])
                second_guids = {o["guid"] for o in endpoints if o.get("writer") == "rt/caracara/cmd_thrust"} - {first_guid}
                self.assertEqual(len(second_guids), 1, endpoints)
                second_gid = ros_gid(second_guids.pop(), self.DISTRO)
                # Refused by name, logged with its GID, the holder named.
                self.assertIn("cmd_thrust from writer %s refused (not-holder): the vehicle is held by writer %s"
                              % (second_gid, first_gid), rig.log("caracara-ros"))
                # On /diagnostics: the holder, the refusals counted and growing, message by message
                # (a refusal is there within a second: the diagnostics come at 1 Hz), the last named.
                counts = []
                for t_ns, m, _ in samples["rt/diagnostics"]:
                    st = commands_status_of(m)
                    self.assertEqual(st["values"]["holder"], first_gid)
                    self.assertEqual(st["level"], 1, "a recent refusal is a WARN")
                    counts.append((t_ns, int(st["values"]["refused not-holder"])))
                self.assertGreaterEqual(len(counts), 2, counts)
                for (t0, c0), (t1, c1) in zip(counts, counts[1:]):
                    self.assertLessEqual(t1 - t0, 1.5e9, "diagnostics more than a second apart")
                    self.assertGreater(c1, c0, "refusals not counted on /diagnostics as they came: %s" % counts)
                self.assertIn("not-holder from writer " + second_gid, st["values"]["last refusal"])
                # The first stops (its writer stays): past the command timeout the second takes over.
                send_first("stop")
                stopped = time.monotonic()
                rig.wait_sim_speeds(speeds(second), 20)
                took_s = time.monotonic() - stopped
                print("first writer stopped -> second writer's thrust on the thrusters: %.2f s (command timeout %.1f s)"
                      % (took_s, timeout_s), file=sys.stderr)
                # Not before the timeout ran out from the first writer's last sample, which went out
                # up to one of its 50 Hz periods before "stop" reached it (0.49 s once, in a whole run).
                self.assertGreaterEqual(took_s * 1000, timeout_s * 1000 - ROS_TAKEOVER_EARLY_MS_MAX)
                self.assertIn("writer %s holds the vehicle" % second_gid, rig.log("caracara-ros"))
                status = commands_status(self.listen(2.5, self.DIAGNOSTICS)[0])
                self.assertEqual(status["values"]["holder"], second_gid)
        rig.wait_sim_zero()


class StaticFramesTest(RosTestCase):
    """/tf_static as tf2's static broadcaster sends it (transient-local, one TFMessage holding every
    static transform): the IMU's and each distance sensor's mount from the config, in base_link
    (REP 103 body FLU); each Range in its own frame."""
    MOUNTS = {"imu_link": ((0.12, -0.05, 0.03), (0.0, 0.0, math.pi / 2)),
              "sonar_front": ((0.45, 0.0, -0.1), (0.0, 0.2, 0.0))}
    ROS_CONFIG = ('[ros.imu]\nframe = "imu_link"\nxyz = [0.12, -0.05, 0.03]\nrpy = [0.0, 0.0, %r]\n'
                  '[[ros.range]]\nframe = "sonar_front"\nxyz = [0.45, 0.0, -0.1]\nrpy = [0.0, 0.2, 0.0]\n' % (math.pi / 2))

    def test_late_subscriber_gets_the_mounts(self):
        time.sleep(1.0)  # joins late: caracara-ros sent /tf_static long before
        samples, _, writers, _ = self.listen(2, {"rt/tf_static": "tf2_msgs/TFMessage",
                                                 "rt/caracara/range/0": "sensor_msgs/Range"})
        w = writers["rt/tf_static"]
        self.assertTrue(w["reliable"] and w["transient_local"], w)
        # Keep-last 1: the one (last) message, holding every static transform.
        self.assertEqual(len(samples.get("rt/tf_static", [])), 1, samples.get("rt/tf_static"))
        transforms = {t["child_frame_id"]: t for t in samples["rt/tf_static"][0][1]["transforms"]}
        distances = len(self.rig.sim_teensy("Distances"))
        # The config's two, and range_N for each distance sensor beyond the config's one.
        self.assertEqual(set(transforms), set(self.MOUNTS) | {"range_%d" % i for i in range(1, distances)})
        for frame, t in transforms.items():
            with self.subTest(frame=frame):
                xyz, rpy = self.MOUNTS.get(frame, ((0, 0, 0), (0, 0, 0)))
                self.assertEqual(t["header"]["frame_id"], "base_link")
                tr, q = t["transform"]["translation"], t["transform"]["rotation"]
                for k, axis in enumerate("xyz"):
                    self.assertAlmostEqual(tr[axis], xyz[k], places=9)
                want = quaternion_from_rpy(*rpy)
                for c in "xyzw":
                    self.assertAlmostEqual(q[c], want[c], places=9)
        # The IMU turned a quarter left (yaw pi/2): its x axis is base_link's left (+y).
        imu_x = rotate(transforms["imu_link"]["transform"]["rotation"], (1, 0, 0))
        for got, want in zip(imu_x, (0, 1, 0)):
            self.assertAlmostEqual(got, want, places=6)
        # The Range is in its sensor's own frame.
        self.assertEqual(samples["rt/caracara/range/0"][-1][1]["header"]["frame_id"], "sonar_front")


class ConfigTest(unittest.TestCase):
    """The [ros] keys of the frames and rates: a bad value is refused at start, by name, before any DDS."""

    def test_bad_frame_options_refused_by_name(self):
        exe = os.path.join(BUILD_DIR, "tools", "ros", "caracara-ros")
        cases = [('frame_convention = "nwu"', 'ros.frame_convention must be "enu" or "ned" ("nwu")'),
                 ('frame_convention = 1', 'ros.frame_convention must be "enu" or "ned"'),
                 ('publish_odom_tf = "no"', "ros.publish_odom_tf must be true or false"),
                 ('commands = "true"', "ros.commands must be true or false"),
                 ('odom_tf = false', "unknown key ros.odom_tf"),
                 ('sensor_rate_hz = 0', "ros.sensor_rate_hz must be a number of Hz above 0 and at most 50"),
                 ('sensor_rate_hz = 51.5', "ros.sensor_rate_hz must be a number of Hz above 0 and at most 50"),
                 ('sensor_rate_hz = "5"', "ros.sensor_rate_hz must be a number of Hz above 0 and at most 50"),
                 ('[ros.imu]\nxyz = [0.1, 0.2]', "ros.imu.xyz must be 3 numbers, metres from the base frame "
                  "(x forward, y left, z up), each within 10"),
                 ('[ros.imu]\nxyz = [0.1, 0.2, 120]', "ros.imu.xyz must be 3 numbers"),
                 ('[ros.imu]\nrpy = [0, 0, 90]', "ros.imu.rpy must be 3 numbers, radians (roll, pitch, yaw about "
                  "x, y, z), each within 2 pi"),
                 ('[ros.imu]\nframe = "/imu"', 'ros.imu.frame must be a frame name (words of letters, digits and _ joined by /) ("/imu")'),
                 ('[ros.imu]\nplace = [0, 0, 0]', "unknown key ros.imu.place"),
                 ('[[ros.range]]\nxyz = [0, 0, 0]\n[[ros.range]]\nrpy = ["a", 0, 0]', "ros.range[1].rpy must be 3 numbers"),
                 ('[[ros.range]]\nframe = "base_link"', 'sensor frame "base_link" is the vehicle\'s own'),
                 ('[[ros.range]]\nframe = "imu_link"', 'sensor frame "imu_link" is named twice')]
        with tempfile.TemporaryDirectory() as d:
            conf = os.path.join(d, "ros.toml")
            for line, message in cases:
                with self.subTest(line=line):
                    with open(conf, "w") as f:
                        f.write("[ros]\n%s\n" % line)
                    r = subprocess.run(harness.EMULATOR + [exe, "--config", conf, "--bus-address", "unix:path=" +
                                       os.path.join(d, "none")], capture_output=True, text=True, timeout=30)
                    self.assertEqual(r.returncode, 2, r.stderr)
                    self.assertIn(conf + ": " + message, r.stderr)

    def run_ros(self, d, toml, *args):
        """caracara-ros with the config `toml`: its exit status and stderr; one still running after
        a few seconds (it started) is stopped with SIGTERM and reported as None."""
        exe = os.path.join(BUILD_DIR, "tools", "ros", "caracara-ros")
        conf = os.path.join(d, "ros.toml")
        with open(conf, "w") as f:
            f.write(toml)
        p = subprocess.Popen(harness.EMULATOR + [exe, "--config", conf, "--bus-address", "unix:path=" +
                             os.path.join(d, "none")] + list(args), stderr=subprocess.PIPE, text=True)
        try:
            return p.wait(5), p.communicate()[1]
        except subprocess.TimeoutExpired:
            p.terminate()
            return None, p.communicate(timeout=15)[1]

    def test_commands_without_security_refused_off_loopback(self):
        """commands = true (or --commands) with no DDS Security on an interface other than loopback
        is refused at start, naming the interface, before any DDS; insecure_commands = true in so
        many words lets it run, with a warning; on loopback it runs."""
        network_is_private()
        # A tether of the namespace's own (a veth pair, nothing outside it), gone after the test.
        subprocess.run(["ip", "link", "add", "tether0", "type", "veth", "peer", "name", "tether1"], check=True)
        self.addCleanup(subprocess.run, ["ip", "link", "del", "tether0"])
        subprocess.run(["ip", "addr", "add", "10.99.0.1/24", "dev", "tether0"], check=True)
        for link in ("tether0", "tether1"):
            subprocess.run(["ip", "link", "set", link, "up", "multicast", "on"], check=True)
        with tempfile.TemporaryDirectory() as d:
            for toml, args, iface in (('[ros]\ncommands = true\n[network]\ninterface = "tether0"\n', [], "tether0"),
                                      ('[ros]\n[network]\ninterface = "tether0"\n', ["--commands"], "tether0"),
                                      ('[ros]\ncommands = true\n[network]\ninterface = ""\n', [], "(any: none named)")):
                with self.subTest(toml=toml, args=args):
                    code, err = self.run_ros(d, toml, *args)
                    self.assertEqual(code, 2, err)
                    self.assertIn("commands are refused without DDS Security on interface %s: set ros.security" % iface,
                                  err)
                    self.assertNotIn("domain 0", err)
            with self.subTest("insecure_commands = true"):
                code, err = self.run_ros(d, '[ros]\ncommands = true\ninsecure_commands = true\n[network]\n'
                                         'interface = "tether0"\n')
                self.assertIsNone(code, err)
                self.assertIn("commands on, DDS Security off", err)
                self.assertIn("warning: commands from anyone who reaches interface tether0: no DDS Security", err)
            with self.subTest("loopback"):
                code, err = self.run_ros(d, '[ros]\ncommands = true\n[network]\ninterface = "lo"\n')
                self.assertIsNone(code, err)
                self.assertNotIn("warning", err)

    def test_open_governance_refused(self):
        """A keystore whose governance admits unauthenticated participants, or does not control who
        writes, leaves the command topics open: caracara-ros refuses to start with it, naming the
        topic and the rule, though every file is signed as it should be."""
        network_is_private()
        blocks = doc_blocks()
        for rule, bad, why in (("allow_unauthenticated_participants", "true", "it admits unauthenticated participants"),
                               ("enable_write_access_control", "false", "it does not control who writes on it")):
            with self.subTest(rule=rule), tempfile.TemporaryDirectory() as d:
                ks = os.path.join(d, "keystore")
                make_keystore(ks, {"/caracara/ros": blocks["vehicle"]})
                gov = os.path.join(ks, "enclaves", "governance.xml")
                with open(gov) as f:
                    text = f.read()
                with open(gov, "w") as f:
                    f.write(re.sub(r"<%s>\w+</%s>" % (rule, rule), "<%s>%s</%s>" % (rule, bad, rule), text))
                # Signed again by the permissions CA, as the keystore's owner would.
                subprocess.run(["openssl", "smime", "-sign", "-text", "-in", gov, "-out", gov[:-4] + ".p7s", "-signer",
                                os.path.join(ks, "public", "permissions_ca.cert.pem"), "-inkey",
                                os.path.join(ks, "private", "permissions_ca.key.pem")], check=True, capture_output=True)
                code, err = self.run_ros(d, '[ros]\nsecurity = "%s"\n' % os.path.join(ks, "enclaves", "caracara", "ros"))
                self.assertEqual(code, 1, err)
                self.assertIn("ros.security: the enclave's governance leaves rt/caracara/kill open: " + why, err)

    def test_bad_security_settings_refused_by_name(self):
        """A relative enclave path is refused by name; an enclave with a file missing stops it at
        start, naming the file; insecure_commands must be a boolean."""
        with tempfile.TemporaryDirectory() as d:
            code, err = self.run_ros(d, '[ros]\nsecurity = "keystore/enclaves/x"\n')
            self.assertEqual(code, 2, err)
            self.assertIn('ros.security must be the absolute path of an SROS2 enclave directory ("keystore/enclaves/x")',
                          err)
            code, err = self.run_ros(d, '[ros]\ninsecure_commands = "yes"\n')
            self.assertEqual(code, 2, err)
            self.assertIn("ros.insecure_commands must be true or false", err)
            enclave = os.path.join(d, "enclaves", "caracara", "ros")
            os.makedirs(enclave)
            for f in ("identity_ca.cert.pem", "cert.pem", "key.pem", "permissions_ca.cert.pem", "governance.p7s"):
                open(os.path.join(enclave, f), "w").close()
            code, err = self.run_ros(d, '[ros]\nsecurity = "%s"\n' % enclave)
            self.assertEqual(code, 1, err)
            self.assertIn("ros.security: %s/permissions.p7s is missing or unreadable" % enclave, err)


class CommandsTest(RosTestCase):
    COMMANDS = True

    def setUp(self):
        self.rig.rearm()

    def test_discovery_info_lists_the_command_readers(self):
        self.check_discovery_info(["rt/caracara/kill", "rt/caracara/cmd_wrench", "rt/caracara/cmd_thrust"])

    def wrench_hold(self, wrench):
        """judge()'s hold: the peer publishes `wrench` at 50 Hz; from the daemon's first order,
        for `seconds`; then a zero Wrench from the same writer, and it leaves."""
        def hold(seconds):
            rig = self.rig
            with self.steering("rt/caracara/cmd_wrench", "geometry_msgs/Wrench", wrench) as send:
                poll(lambda: rig.motor_values() != [0] * MOTORS, 20, message="the Wrench never reached the thrusters")
                time.sleep(seconds)
                send(ZERO_WRENCH)
                poll(lambda: rig.motor_values() == [0] * MOTORS, 10, message="a zero Wrench left the thrust on")
        return hold

    def test_wrench_moves_the_vehicle_as_rep_103_says(self):
        """Each Wrench component, + and -, moves the simulated vehicle as REP 103's body FLU means
        (judged by where it went, not by SetMotion's numbers); the depth axis from below the surface."""
        for (part, comp), (plus, minus) in WRENCH_MOTIONS.items():
            for demand, motion in ((0.5, plus), (-0.5, minus)):
                with self.subTest(wrench="%s.%s" % (part, comp), demand=demand):
                    w = json.loads(json.dumps(ZERO_WRENCH))
                    w[part][comp] = demand
                    judge(self, self.rig, motion, self.wrench_hold(w), "Wrench %s.%s=%+.1f" % (part, comp, demand))

    def test_cyclone_peer_without_security_drives(self):
        """The control of SecurityTest: the Cyclone peer it refuses when it has no security drives
        the vehicle here (no security), and kills it: what SecurityTest sees is the security."""
        rig = self.rig
        peer = build_secure_peer()
        since = rig.wire_next()
        with SecurePeer(peer, "none", "wrench", 0.5, 0, 0, 0, 0, 0, 20):
            poll(lambda: nonzero_orders(rig.wire_log(since)[1]), 20, message="the unsecured Cyclone peer did not drive")
        rig.wait_sim_zero()
        with SecurePeer(peer, "none", "kill", 20, 5):
            rig.wait_state("killed")

    def test_per_thruster_values(self):
        rig = self.rig
        data = [0.5, -0.5, 0, 0, 0.2, 0, 0, -0.2]  # whole motor values: 4425, 1770
        with self.driving("rt/caracara/cmd_thrust", "std_msgs/Float64MultiArray",
                          {"layout": {"dim": [], "data_offset": 0}, "data": data}):
            rig.wait_sim_speeds([speed_byte(round(v * MOTOR_MAX)) for v in data])
        rig.wait_sim_zero()

    def test_bad_messages_refused_by_name(self):
        rig = self.rig
        since = rig.wire_next()
        cases = [([0.1] * 7, "org.caracara.Vehicle1.Error."), ([1.5] + [0] * 7, "OutOfRange"),
                 ([float("nan")] + [0] * 7, "InvalidValue")]

        def refused_by_name(topic, type_, msg, name):
            # Sent at 2 Hz until its refusal is logged: a reader that matches the writer late skips
            # what came before (Fast DDS 3.1 to Cyclone, once in CI even 3 s after the writer's own
            # match). A late sample of the case before may still be refused meanwhile: this case's
            # name among the refusals since it began is what counts.
            before = rig.log("caracara-ros").count("refused")

            def named():
                lines = [r.splitlines()[0] for r in rig.log("caracara-ros").split("refused")[before + 1:]]
                return lines if any(name in r for r in lines) else None
            with self.driving(topic, type_, msg, hz=2):
                poll(named, 15, message="no refusal naming %s logged" % name)

        for data, name in cases:
            with self.subTest(data=data):
                refused_by_name("rt/caracara/cmd_thrust", "std_msgs/Float64MultiArray",
                                {"layout": {"dim": [], "data_offset": 0}, "data": ["NaN" if d != d else d for d in data]},
                                name)
        for x, name in ((2.0, "OutOfRange"), ("NaN", "InvalidValue")):
            with self.subTest(wrench_force_x=x):
                refused_by_name("rt/caracara/cmd_wrench", "geometry_msgs/Wrench",
                                {"force": {"x": x, "y": 0, "z": 0}, "torque": {"x": 0, "y": 0, "z": 0}}, name)
        # The daemon names SetMotion's (the seed's) axis: the log says which Wrench field that is.
        self.assertIn("(cmd_wrench in SetMotion's axes: x = force.y, y = force.x, z = -force.z, yaw = -torque.z, "
                      "pitch = -torque.y, roll = torque.x) refused: org.caracara.Vehicle1.Error.OutOfRange: y: must be "
                      "between -1 and 1, got 2", rig.log("caracara-ros"))
        self.assertEqual(nonzero_orders(rig.wire_log(since)[1]), [])
        self.assertEqual(rig.motor_values(), [0] * MOTORS)
        # Every refusal is on /diagnostics too, counted by kind (the 5 cases, each once at least).
        status = commands_status(self.listen(2.5, {"rt/diagnostics": "diagnostic_msgs/DiagnosticArray"})[0])
        self.assertGreaterEqual(int(status["values"]["refused bad-value"]), 5, status)
        self.assertIn("bad-value from writer ", status["values"]["last refusal"])

    def test_peer_killed_zeros_within_the_client_loss_bound(self):
        rig = self.rig
        data = [0.3] * 2 + [0] * 6
        with self.driving("rt/caracara/cmd_thrust", "std_msgs/Float64MultiArray",
                          {"layout": {"dim": [], "data_offset": 0}, "data": data}, short_lease=True):
            rig.wait_sim_speeds([speed_byte(round(v * MOTOR_MAX)) for v in data])
            since = rig.wire_next()
            killed_at = time.monotonic_ns()  # the block's end SIGKILLs the peer
        rig.wait_sim_zero()
        log = rig.wire_log(since)[1]
        # The first order of zero to each thruster that was moving: the last of them is when the
        # thrust was gone.
        firsts = {}
        for e, i, speed in orders(log):
            if speed == ZERO and data[i] != 0 and i not in firsts:
                firsts[i] = e.time_ns
        self.assertEqual(sorted(firsts), [0, 1])
        firsts = list(firsts.values())
        ms = (max(firsts) - killed_at) / 1e6
        print("peer SIGKILL -> zeros on the wire: %.1f ms" % ms, file=sys.stderr)
        self.assertLess(ms, CLIENT_LOSS_ZERO_MS_MAX)
        self.assertIn("gone", rig.log("caracara-ros"))


# The vehicle's description for NewtonWrenchTest: the simulator's file, which caracara-ros reads too.
NEWTON_MASS_KG = 11.5
SIM_DRAG_PER_S = 1.0  # sim/vehicle_body.hpp's k_drag: v' = F / m - k_drag * v


class NewtonWrenchTest(RosTestCase):
    """[ros] wrench_units = "newton": a Wrench in newtons through the vehicle's description (its
    thrusters' positions and directions, the BTD150 force curve) to motor values; the simulator
    moves by the same description's mass, so 10 N forward is 10 / mass m/s^2, along REP 103's +x."""
    COMMANDS = True
    SIM_TOML = "[vehicle]\nmass_kg = %s\n" % NEWTON_MASS_KG
    ROS_CONFIG = 'wrench_units = "newton"\nvehicle_config = "{rig_dir}/sim.toml"\n'

    def setUp(self):
        self.rig.rearm()

    def velocity_forward(self, heading):
        """The simulator's velocity (its world: x port and y forward at yaw 0) along the body's
        forward and port axes at `heading`, and the time it was read."""
        vx, vy, _ = (float(v) for v in self.rig.sim_teensy("Velocity"))
        t = time.monotonic()
        c, s = math.cos(heading), math.sin(heading)
        return -vx * s + vy * c, vx * c + vy * s, t

    def test_ten_newtons_forward_accelerate_by_the_mass(self):
        rig = self.rig
        self.assertIn("cmd_wrench in newtons", rig.log("caracara-ros"))
        settle(rig)
        place(rig)
        start = pose(rig)
        wrench = json.loads(json.dumps(ZERO_WRENCH))
        wrench["force"]["x"] = 10.0
        with self.steering("rt/caracara/cmd_wrench", "geometry_msgs/Wrench", wrench) as send:
            # The four horizontal thrusters, forward, and the thrust ramp done: from here on the
            # thrust is steady and the body's acceleration is F / m less the drag.
            def steady():
                ordered = [int(v) for v in rig.sim_thrusters("OrderedSpeed")]
                actual = [int(v) for v in rig.sim_thrusters("ActualSpeed")]
                horizontal = (0, 2, 4, 6)
                return all(ordered[i] > ZERO and actual[i] == ordered[i] for i in horizontal) and ordered
            ordered = poll(steady, 20, message="the 10 N Wrench never reached the thrusters")
            f1, p1, t1 = self.velocity_forward(START_HEADING_RAD)
            time.sleep(ROS_NEWTON_ACCEL_WINDOW_S)
            f2, p2, t2 = self.velocity_forward(START_HEADING_RAD)
            send(ZERO_WRENCH)
            poll(lambda: rig.motor_values() == [0] * MOTORS, 10, message="a zero Wrench left the thrust on")
        end = pose(rig)
        dt = t2 - t1
        forward = (f2 - f1) / dt + SIM_DRAG_PER_S * (f1 + f2) / 2
        port = (p2 - p1) / dt + SIM_DRAG_PER_S * (p1 + p2) / 2
        want = 10.0 / NEWTON_MASS_KG
        print("10 N forward: %.4f m/s^2 (10 / %.1f kg = %.4f), sideways %.4f; speeds %s" %
              (forward, NEWTON_MASS_KG, want, port, ordered), file=sys.stderr)
        self.assertLessEqual(abs(forward - want), ROS_NEWTON_ACCEL_ERROR_FRACTION_MAX * want)
        self.assertLessEqual(abs(port), ROS_NEWTON_ACCEL_ERROR_FRACTION_MAX * want)
        # REP 103's +x is forward: the vehicle went forward in its own frame, not to a side.
        moved = body_motion(start, end)["translation"]
        self.assertGreater(moved[1], 0, moved)
        self.assertLess(abs(moved[0]), 0.1 * moved[1], moved)
        # The vertical thrusters stay still: 10 N forward needs none of them.
        self.assertEqual([ordered[i] for i in (1, 3, 5, 7)], [ZERO] * 4)


if __name__ == "__main__":
    unittest.main()
