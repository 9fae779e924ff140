"""caracara-bridge end to end: a private bus, caracara-sim, caracarad (tests/e2e/harness.py), the
bridge on a Unix socket, a private sshd and a real `ssh -L PORT:SOCKET` forward, then the
reference client's tests (bridge.test.mjs, node --test) through it; the socket's group rule;
a recorded dive exported to MCAP and read back by the reference reader (mcap_check.mjs); the
token on TCP; /command/motion's Twist judged by where the simulated vehicle went
(tests/e2e/vehicle_motion.py, issue 43) and a clockwise turn read back from /tf; and the bridge's bounds (issue 35): a Kill and a close while another client lists
a full dive directory, floods from a client that does not read (bounds.test.mjs, on a second
bridge on TCP), and stalled tokenless connections beside the pilots.

The npm packages are pinned in package-lock.json and installed with `npm ci` (cached under
/var/cache/caracara-npm) by CTest's setup test npm_bridge (tests/npm_packages.py) before this
test starts; the test only checks them. Under CI (CI=true) a missing node, npm or sshd fails it.
"""
import json
import math
import os
import re
import select
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(SOURCE, "tests", "e2e"))
sys.path.insert(0, os.path.join(SOURCE, "bench"))

import bounds  # noqa: E402
from bounds import BRIDGE_REQUEST_TIMEOUT_LATENESS_S_MAX  # noqa: E402
import harness  # noqa: E402
from harness import missing, npm_ci  # noqa: E402
from full_dive_dir import fill  # noqa: E402
from harness import BUILD_DIR, Rig, angle_diff, poll  # noqa: E402
from vehicle_motion import START_HEADING_RAD, describe, judge  # noqa: E402
from ssh_bridge import free_port, port_listens, private_sshd  # noqa: E402

# [failsafe.pilot-lost] persistence_ms of the rig: a closed tab, the last pilot, kills this long
# after (5 s by default; shorter here, the tests wait for it).
PILOT_LOST_MS = 1000
# [failsafe.surface] duration_ms of the rig: the ascent the cockpit's banner shows.
SURFACE_MS = 3000
# /tf's angles against the simulated attitude read just after it: the attitude comes at the daemon's
# telemetry rate, and a turn of 0.5 demand runs at about 0.5 rad/s (tests/bounds.json
# MOTION_ROTATION_MIN_RAD's note).
TF_YAW_TOLERANCE_RAD = 0.15


class Sshd:
    """The private sshd of bench/ssh_bridge.py (127.0.0.1, keys made for the run, no PAM, a
    mount namespace of its own); ssh -L forwards a local port to the bridge's socket through it."""

    def __init__(self, d):
        self.dir = d
        self.port = free_port()
        argv, env = private_sshd(d, self.port, lambda m: print(m, file=sys.stderr))
        self.log = open(os.path.join(d, "sshd.log"), "ab")
        self.proc = subprocess.Popen(argv, stdout=self.log, stderr=subprocess.STDOUT, env={**os.environ, **env})
        poll(self.listening, 10, message="the private sshd to listen")

    def listening(self):
        if self.proc.poll() is not None:
            raise AssertionError("sshd exited; see %s/sshd.log" % self.dir)
        try:
            with socket.create_connection(("127.0.0.1", self.port), timeout=0.5):
                return True
        except OSError:
            return False

    def forward(self, local_port, socket_path):
        """ssh -N -L local_port:socket_path, as caracaractl bridge runs it."""
        argv = ["ssh", "-N", "-o", "ExitOnForwardFailure=yes", "-o", "BatchMode=yes", "-o", "StrictHostKeyChecking=no",
                "-o", "UserKnownHostsFile=/dev/null", "-o", "LogLevel=ERROR", "-i", os.path.join(self.dir, "client_key"),
                "-p", str(self.port), "-L", f"127.0.0.1:{local_port}:{socket_path}", "root@127.0.0.1"]
        return subprocess.Popen(argv, stdin=subprocess.DEVNULL, stderr=self.log)

    def stop(self):
        self.proc.terminate()
        self.proc.wait(10)
        self.log.close()


def connect_as(path, *setpriv):
    """Connects to a Unix socket as another user; the errno name or 'ok'."""
    code = ("import socket,sys\ns=socket.socket(socket.AF_UNIX)\n"
            "try:\n s.connect(sys.argv[1]); print('ok')\nexcept OSError as e:\n import errno; print(errno.errorcode[e.errno])")
    r = subprocess.run(["setpriv", *setpriv, "/usr/bin/python3", "-c", code, path], capture_output=True, text=True,
                       timeout=30)
    return r.stdout.strip() or r.stderr.strip()


class HeldPilot:
    """tests/bridge/hold_motion.mjs (the cockpit in chromium, or the Foxglove reference client):
    hold(seconds=S, ...) commands a motion for S seconds, then stops it, and returns its answer."""

    def __init__(self, rig, mode, **env):
        self.mode = mode
        self.log_path = os.path.join(rig.dir, "hold_motion-%s.log" % mode)
        self.log = open(self.log_path, "w")
        self.proc = subprocess.Popen(["node", "hold_motion.mjs", mode], cwd=HERE, stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=self.log, text=True,
                                     env={**os.environ, "CARACARA_BUILD_DIR": BUILD_DIR,
                                          "CARACARA_BUS_ADDRESS": rig.address, **env})
        if self.answer(60) != "ready":
            raise AssertionError("hold_motion.mjs %s did not start" % mode)

    def answer(self, timeout=30):
        ready, _, _ = select.select([self.proc.stdout], [], [], timeout)
        line = self.proc.stdout.readline() if ready else ""
        if not line:
            self.log.flush()
            with open(self.log_path, errors="replace") as f:
                raise AssertionError("hold_motion.mjs %s gave no answer: %s" % (self.mode, f.read()[-3000:]))
        return json.loads(line)

    def hold(self, **request):
        try:
            self.proc.stdin.write(json.dumps(request) + "\n")
            self.proc.stdin.flush()
        except BrokenPipeError:
            self.answer(0)  # says why it ended
        return self.answer(request.get("seconds", 0) + 30)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        try:
            self.proc.stdin.close()
        except BrokenPipeError:
            pass  # it ended already: its log says why
        try:
            code = self.proc.wait(60)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            code = self.proc.wait()
        self.proc.stdout.close()
        self.log.close()
        if exc[0] is None and code != 0:
            with open(self.log_path, errors="replace") as f:
                raise AssertionError("hold_motion.mjs %s exited %d: %s" % (self.mode, code, f.read()[-3000:]))


def quaternion_yaw(q):
    """The yaw about the world's z of a body-to-world rotation (foxglove.FrameTransform's)."""
    return math.atan2(2 * (q["w"] * q["z"] + q["x"] * q["y"]), 1 - 2 * (q["y"] ** 2 + q["z"] ** 2))

# The bridge's request timeout (kRequestTimeout in tools/bridge/session.cpp).
REQUEST_TIMEOUT_S = 3


class BridgeRig:
    """The rig, the bridge on a Unix socket (serving the cockpit's files from the source tree), the
    private sshd and an ssh -L forward to it at cls.port; shared with test_cockpit.py."""
    SIM_CONFIG = {}     # caracara-sim's [sim] (test_cockpit.py: a thruster mounted reversed)
    COMMISSIONING = {}  # caracarad's [commissioning] (test_cockpit.py: a short detection)

    @classmethod
    def setUpClass(cls):
        npm_ci(HERE)
        if not os.access(os.path.join(BUILD_DIR, "tools", "bridge", "caracara-bridge"), os.X_OK):
            raise AssertionError("caracara-bridge is not built in %s" % BUILD_DIR)
        if not shutil.which("ssh") or not shutil.which("ssh-keygen"):
            missing("the OpenSSH client is needed")
        # Water detect surfaces and overtemp excludes soon, and the ascent is short: the cockpit's
        # banner test (cockpit.test.mjs) raises both.
        cls.rig = Rig(control={"arming_delay_ms": 300}, extra_config={
            "failsafe": {"pilot-lost": {"action": "kill", "persistence_ms": PILOT_LOST_MS},
                         "water-detect": {"action": "surface", "persistence_ms": 300},
                         "overtemp": {"action": "exclude", "persistence_ms": 300},
                         "surface": {"heave": -0.5, "duration_ms": SURFACE_MS}},
            **({"commissioning": cls.COMMISSIONING} if cls.COMMISSIONING else {})}, sim_config=cls.SIM_CONFIG)
        cls.procs = []
        cls.sshd = None
        try:
            cls.rig.start()
            cls.rig.arm()
            # The socket's directory is open to all (0755): only the socket's own mode decides.
            cls.sockdir = tempfile.mkdtemp(prefix="caracara-bridge-")
            os.chmod(cls.sockdir, 0o755)
            cls.socket = os.path.join(cls.sockdir, "bridge.sock")
            cls.bridge_log = open(os.path.join(cls.rig.dir, "caracara-bridge.log"), "ab")
            # One more origin than the bridge's own may connect (issue 46): a page the tests serve there.
            cls.allowed_port = free_port()
            cls.bridge = subprocess.Popen(harness.EMULATOR + [os.path.join(BUILD_DIR, "tools", "bridge", "caracara-bridge"),
                                           "--listen", "unix:" + cls.socket, "--bus-address", cls.rig.address,
                                           "--cockpit-dir", os.path.join(SOURCE, "tools", "cockpit"),
                                           "--dives-dir", cls.rig.dives_dir,
                                           "--allow-origin", "http://localhost:%d" % cls.allowed_port],
                                          stdout=cls.bridge_log, stderr=subprocess.STDOUT)
            cls.procs.append(cls.bridge)
            poll(lambda: os.path.exists(cls.socket) or cls.bridge.poll() is not None, 10, message="the bridge's socket")
            if cls.bridge.poll() is not None:
                raise AssertionError("caracara-bridge exited: " + cls.bridge_output())
            cls.sshd = Sshd(tempfile.mkdtemp(prefix="caracara-bridge-sshd-"))
            cls.port = free_port()
            cls.procs.append(cls.sshd.forward(cls.port, cls.socket))
            poll(cls.forwarding, 15, message="the ssh -L forward")
        except BaseException:
            cls.tearDownClass()
            raise

    @classmethod
    def bridge_output(cls):
        with open(os.path.join(cls.rig.dir, "caracara-bridge.log"), errors="replace") as f:
            return f.read()[-3000:]

    @classmethod
    def forwarding(cls):
        return cls.listening(cls.port)

    @classmethod
    def tearDownClass(cls):
        for p in reversed(cls.procs):
            p.terminate()
            try:
                p.wait(10)
            except subprocess.TimeoutExpired:
                p.kill()
        if cls.sshd:
            cls.sshd.stop()
        cls.rig.stop()

    @staticmethod
    def listening(port):
        return port_listens(port)

    def ssh_config(self):
        """An ssh config naming the private sshd "vehicle", as a pilot's ~/.ssh/config would."""
        cfg = os.path.join(self.sshd.dir, "ssh_config")
        if not os.path.exists(cfg):
            with open(cfg, "w") as f:
                f.write(f"Host vehicle\n  HostName 127.0.0.1\n  Port {self.sshd.port}\n  User root\n"
                        f"  IdentityFile {self.sshd.dir}/client_key\n  IdentitiesOnly yes\n  UserKnownHostsFile /dev/null\n"
                        "  StrictHostKeyChecking no\n  BatchMode yes\n  LogLevel ERROR\n")
        return cfg

    def caracaractl_bridge(self, port):
        """`caracaractl -H vehicle bridge --port PORT` held until the test's end (its stderr in the
        rig's directory; $XDG_RUNTIME_DIR a directory of the test's, to find its private one):
        (process, ws:// address, http:// address, key, stderr path, runtime directory)."""
        runtime = tempfile.mkdtemp(prefix="caracaractl-runtime-")
        os.chmod(runtime, 0o755)  # open to all, as /tmp: only the private directory's mode decides
        self.addCleanup(shutil.rmtree, runtime, True)
        err_path = os.path.join(self.rig.dir, "caracaractl-bridge-%d.log" % port)
        err = open(err_path, "w")
        p = subprocess.Popen(harness.EMULATOR + [os.path.join(BUILD_DIR, "tools", "caracaractl"), "-H", "vehicle",
                              "bridge", "--port", str(port), "--socket", self.socket, "--ssh-config", self.ssh_config()],
                             stdout=subprocess.PIPE, stderr=err, text=True, env={**os.environ, "XDG_RUNTIME_DIR": runtime})

        def stop():
            if p.poll() is None:
                p.send_signal(2)
                self.assertEqual(p.wait(15), 0, "caracaractl bridge on ^C")
            p.stdout.close()
            err.close()
        self.addCleanup(stop)
        ws_url, http_url = p.stdout.readline().strip(), p.stdout.readline().strip()
        m = re.fullmatch(r"ws://localhost:%d/\?key=([0-9a-f]{64})" % port, ws_url)
        self.assertTrue(m, "caracaractl bridge printed %r" % ws_url)
        self.assertEqual(http_url, "http://localhost:%d/?key=%s" % (port, m.group(1)))
        return p, ws_url, http_url, m.group(1), err_path, runtime

    def check_bridge_stops_cleanly(self):
        # SIGTERM: exit status 0, its socket removed (under ASan: no leak, which would make it non-zero).
        self.bridge.terminate()
        self.assertEqual(self.bridge.wait(20), 0, "caracara-bridge: " + self.bridge_output())
        self.assertFalse(os.path.exists(self.socket))

    def rearm(self):
        """Ready again, whatever an earlier test left (killed, or a restarted daemon)."""
        if self.rig.state() != "killed":
            self.rig.vcall("Kill")
        self.rig.vcall("ClearKill")
        self.rig.wait_state("ready")

    def node(self, script, **env):
        r = subprocess.run(["node", "--test", "--test-reporter=spec", script], cwd=HERE, capture_output=True, text=True,
                           timeout=300, env={**os.environ, "CARACARA_BUILD_DIR": BUILD_DIR,
                                             "CARACARA_BUS_ADDRESS": self.rig.address,
                                             "CARACARA_PILOT_LOST_MS": str(PILOT_LOST_MS),
                                             "CARACARA_SURFACE_MS": str(SURFACE_MS), **env})
        print(r.stdout, r.stderr, sep="\n", file=sys.stderr)
        self.assertEqual(r.returncode, 0, "node --test %s failed" % script)
        return r.stdout


class BridgeTest(BridgeRig, unittest.TestCase):
    def test_1_reference_client_through_ssh_forward(self):
        self.node("bridge.test.mjs", CARACARA_WS_URL="ws://127.0.0.1:%d" % self.port)
        self.assertIsNone(self.bridge.poll(), "the bridge survived every test")

    def test_2_caracaractl_bridge_forwards_and_prints_the_address(self):
        port = free_port()
        p, ws_url, http_url, key, err_path, runtime = self.caracaractl_bridge(port)
        upgrade = (b"GET %s HTTP/1.1\r\nHost: localhost:%d\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                   b"Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n"
                   b"Sec-WebSocket-Protocol: foxglove.websocket.v1\r\n%s\r\n")

        def ask(request):
            with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
                s.sendall(request)
                got = b""
                while chunk := s.recv(65536):
                    got += chunk
                    if b"\r\n\r\n" in got and b" 101 " in got.split(b"\r\n")[0]:
                        break  # an open WebSocket: its head is enough
                return got.decode(errors="replace")
        # The forward without its key, with a wrong one, or with another port's cookie: 403, the
        # reason in the body, the refusal on caracaractl's stderr; nothing reaches the bridge.
        for target, extra, why in ((b"/", b"", "needs the key of its session"),
                                   (b"/?key=" + b"0" * 64, b"", "wrong key"),
                                   (b"/", b"Cookie: caracara_key_%d=%s\r\n" % (port + 1, key.encode()),
                                    "needs the key of its session")):
            answer = ask(upgrade % (target, port, extra))
            self.assertIn("403", answer.splitlines()[0], answer)
            self.assertIn(why, answer)
        for target in (b"/", b"/dives/"):
            answer = ask(b"GET %s HTTP/1.1\r\nHost: localhost:%d\r\n\r\n" % (target, port))
            self.assertIn("403", answer.splitlines()[0], answer)
        # With it: a WebSocket upgrade with the Foxglove subprotocol (the key in the query, as
        # Foxglove's URL carries it); a page load is redirected without the key, setting the cookie
        # that then lets the page and its requests through.
        answer = ask(upgrade % (b"/?key=" + key.encode(), port, b""))
        self.assertIn("101", answer.splitlines()[0])
        self.assertIn("sec-websocket-protocol: foxglove.websocket.v1", answer.lower())
        answer = ask(b"GET /?key=%s HTTP/1.1\r\nHost: localhost:%d\r\n\r\n" % (key.encode(), port))
        self.assertIn("303", answer.splitlines()[0], answer)
        self.assertIn("\r\nLocation: /\r\n", answer)
        self.assertIn("\r\nSet-Cookie: caracara_key_%d=%s; Path=/; HttpOnly; SameSite=Strict\r\n" % (port, key), answer)
        cookie = b"Cookie: caracara_key_%d=%s\r\n" % (port, key.encode())
        answer = ask(b"GET / HTTP/1.1\r\nHost: localhost:%d\r\n%s\r\n" % (port, cookie))
        self.assertIn("200", answer.splitlines()[0])
        self.assertIn("<title>Caracara cockpit</title>", answer)
        self.assertIn("101", ask(upgrade % (b"/", port, cookie)).splitlines()[0])
        with open(err_path) as f:
            said = f.read()
        self.assertIn("caracaractl: refused a connection to localhost:%d without the key" % port, said)
        self.assertIn("caracaractl: refused a connection to localhost:%d with a wrong key" % port, said)
        # The reference client, which sends no Origin (as Foxglove desktop), through the forward
        # with the printed address.
        script = ("import { connect } from './lib.mjs';"
                  "const c = await connect(process.env.CARACARA_WS_URL); c.subscribeAll();"
                  "const s = await c.waitFor('/vehicle/state'); await c.close(); console.log(s.state);")
        r = subprocess.run(["node", "--input-type=module", "-e", script], cwd=HERE, capture_output=True, text=True,
                           timeout=60, env={**os.environ, "CARACARA_WS_URL": ws_url})
        self.assertEqual(r.returncode, 0, r.stderr)
        # ssh's end is a socket in a directory of the pilot's alone: another local user cannot
        # go round the key.
        (private,) = [d for d in os.listdir(runtime) if d.startswith("caracaractl-bridge.")]
        private = os.path.join(runtime, private)
        self.assertEqual(os.stat(private).st_mode & 0o777, 0o700)
        self.assertEqual(connect_as(os.path.join(private, "bridge.sock"), "--reuid=nobody", "--regid=nogroup",
                                    "--clear-groups"), "EACCES")
        p.send_signal(2)
        self.assertEqual(p.wait(15), 0)
        self.assertFalse(os.path.exists(private), "the private directory outlived the forward")
        cfg = self.ssh_config()
        # SSH refuses the login (no key of nobody's is authorized): 4, as the help says; the
        # host not reached (nothing listens on the port): 3.
        with open(cfg, "a") as f:
            f.write(f"Host refused\n  HostName 127.0.0.1\n  Port {self.sshd.port}\n  User nobody\n"
                    f"  IdentityFile {self.sshd.dir}/client_key\n  IdentitiesOnly yes\n  UserKnownHostsFile /dev/null\n"
                    "  StrictHostKeyChecking no\n  BatchMode yes\n"
                    f"Host unreached\n  HostName 127.0.0.1\n  Port {free_port()}\n  BatchMode yes\n")
        for host, want in (("refused", 4), ("unreached", 3)):
            r = subprocess.run(harness.EMULATOR + [os.path.join(BUILD_DIR, "tools", "caracaractl"), "-H", host, "bridge",
                                "--port", str(free_port()), "--socket", self.socket, "--ssh-config", cfg],
                               capture_output=True, text=True, timeout=60)
            self.assertEqual(r.returncode, want, host + ": " + r.stderr)
        self.assertIn("SSH refused the login", subprocess.run(
            harness.EMULATOR + [os.path.join(BUILD_DIR, "tools", "caracaractl"), "-H", "refused", "bridge", "--port",
                                str(free_port()), "--socket", self.socket, "--ssh-config", cfg],
            capture_output=True, text=True, timeout=60).stderr)

    def test_2_pages_of_other_origins_are_refused(self):
        # What a browser sends (issue 46): a page's WebSocket and fetch carry its Origin; the
        # bridge's own page is http://<Host>. Through the rig's plain ssh -L forward.
        def ask(origin, host="127.0.0.1:%d" % self.port, target=b"/", upgrade=True):
            head = b"GET %s HTTP/1.1\r\nHost: %s\r\n" % (target, host.encode())
            if upgrade:
                head += (b"Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
                         b"Sec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: foxglove.websocket.v1\r\n")
            if origin is not None:
                head += b"Origin: %s\r\n" % origin.encode()
            with socket.create_connection(("127.0.0.1", self.port), timeout=10) as s:
                s.sendall(head + b"\r\n")
                got = s.recv(65536).decode(errors="replace")
            return got.split("\r\n")[0], got.split("\r\n\r\n", 1)[-1]
        own = "http://127.0.0.1:%d" % self.port
        self.assertIn("101", ask(None)[0])                       # no Origin: not a browser page
        self.assertIn("101", ask(own)[0])                        # the cockpit the bridge serves
        self.assertIn("101", ask("http://localhost:%d" % self.port, "localhost:%d" % self.port)[0])
        self.assertIn("101", ask("http://localhost:%d" % self.allowed_port)[0])  # --allow-origin
        refused = [("http://localhost:%d" % (self.allowed_port + 1), "127.0.0.1:%d" % self.port),
                   ("http://127.0.0.1:%d" % (self.port + 1), "127.0.0.1:%d" % self.port),
                   ("https://evil.example", "127.0.0.1:%d" % self.port), ("null", "127.0.0.1:%d" % self.port),
                   # DNS rebinding: a name resolving to 127.0.0.1 matches its own Host.
                   ("http://rebind.example:%d" % self.port, "rebind.example:%d" % self.port)]
        for origin, host in refused:
            line, body = ask(origin, host)
            self.assertIn("403", line, origin)
            self.assertIn("caracara-bridge: a page from %s may not use this bridge" % origin, body)
        # The recorded dives too; the cockpit's files are the same for everyone.
        self.assertIn("403", ask("https://evil.example", target=b"/dives/", upgrade=False)[0])
        self.assertIn("200", ask(None, target=b"/dives/", upgrade=False)[0])
        self.assertIn("200", ask(own, target=b"/dives/", upgrade=False)[0])
        self.assertIn("200", ask("https://evil.example", target=b"/", upgrade=False)[0])
        with open(os.path.join(self.rig.dir, "caracara-bridge.log"), errors="replace") as f:
            log = f.read()
        for origin, _ in refused:
            self.assertIn("caracara-bridge: refused a WebSocket upgrade from origin '%s'" % origin, log)
        self.assertIn("caracara-bridge: refused a request for dives from origin 'https://evil.example'", log)
        self.assertIn("caracara-bridge: pages from http://localhost:%d may connect (--allow-origin)" % self.allowed_port,
                      log)
        # An allow-list entry that is not an origin stops the bridge at its start.
        exe = harness.EMULATOR + [os.path.join(BUILD_DIR, "tools", "bridge", "caracara-bridge")]
        for bad in ("app.foxglove.dev", "https://app.foxglove.dev/", "null"):
            r = subprocess.run(exe + ["--listen", "unix:" + os.path.join(self.rig.dir, "x.sock"), "--allow-origin", bad,
                                      "--bus-address", self.rig.address], capture_output=True, text=True, timeout=30)
            self.assertEqual(r.returncode, 2, r.stderr)
            self.assertIn("--allow-origin takes an origin, scheme://host[:port]", r.stderr)

    def test_2_socket_is_for_the_group_only(self):
        st = os.stat(self.socket)
        self.assertEqual(st.st_mode & 0o777, 0o660)
        self.assertEqual(connect_as(self.socket, "--reuid=nobody", "--regid=nogroup", "--clear-groups"), "EACCES")
        # The same user in the socket's group gets in.
        self.assertEqual(connect_as(self.socket, "--reuid=nobody", "--regid=nogroup", "--groups=%d" % st.st_gid), "ok")

    def test_4_a_restarted_daemon_is_followed(self):
        # The bridge keeps its socket; the new daemon's objects are loaded again (it starts killed).
        self.rig.stop_daemon()
        self.rig.start_daemon()
        script = ("import { connect } from './lib.mjs';"
                  "const c = await connect(process.env.CARACARA_WS_URL); c.subscribeAll();"
                  "const s = await c.waitFor('/vehicle/state', (m) => m.state === 'killed' && m.kill_source === 'start');"
                  "await c.close(); console.log(JSON.stringify(s));")
        r = subprocess.run(["node", "--input-type=module", "-e", script], cwd=HERE, capture_output=True, text=True,
                           timeout=60, env={**os.environ, "CARACARA_WS_URL": "ws://127.0.0.1:%d" % self.port})
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIsNone(self.bridge.poll())

    def test_3_dive_exported_to_mcap_reads_back(self):
        # test_1 armed and killed: the first dive of the rig is closed by that kill.
        self.rig.vcall("Kill")
        dives = sorted(f for f in os.listdir(self.rig.dives_dir) if f.endswith(".cdive"))
        self.assertTrue(dives, "no dive recorded")
        dive = os.path.join(self.rig.dives_dir, dives[0])
        out = os.path.join(self.rig.dir, "dive.mcap")
        ctl = harness.EMULATOR + [os.path.join(BUILD_DIR, "tools", "caracaractl")]
        r = subprocess.run(ctl + ["export", dive, "--format", "mcap", "--out", out], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        samples = subprocess.run(ctl + ["export", dive], capture_output=True, text=True, check=True).stdout
        events = subprocess.run(ctl + ["export", dive, "--events"], capture_output=True, text=True, check=True).stdout
        n_samples = len(samples.strip().splitlines()) - 1
        n_events = len(events.strip().splitlines()) - 1
        self.assertGreater(n_samples, 0)
        self.node("mcap_check.mjs", CARACARA_MCAP=out, CARACARA_SAMPLES=str(n_samples), CARACARA_EVENTS=str(n_events))

    def test_5_tcp_needs_its_token(self):
        exe = harness.EMULATOR + [os.path.join(BUILD_DIR, "tools", "bridge", "caracara-bridge")]
        port = free_port()
        token_file = os.path.join(self.rig.dir, "token")
        with open(token_file, "w") as f:
            f.write("short\n")
        for args in ([], ["--token-file", token_file]):  # no token; a token under 16 characters
            r = subprocess.run(exe + ["--listen", "tcp:127.0.0.1:%d" % port, "--bus-address", self.rig.address] + args,
                               capture_output=True, text=True, timeout=30)
            self.assertEqual(r.returncode, 2, r.stderr)
        token = "0123456789abcdef0123456789abcdef"
        with open(token_file, "w") as f:
            f.write(token + "\n")
        p = subprocess.Popen(exe + ["--listen", "tcp:127.0.0.1:%d" % port, "--token-file", token_file,
                                    "--bus-address", self.rig.address, "--dives-dir", self.rig.dives_dir,
                                    "--cockpit-dir", os.path.join(SOURCE, "tools", "cockpit")], stderr=subprocess.DEVNULL)
        try:
            poll(lambda: self.listening(port), 10, message="the TCP listener")

            def status(target, header=b""):
                with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
                    s.sendall(b"GET " + target + b" HTTP/1.1\r\nHost: x\r\nUpgrade: websocket\r\n"
                              b"Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
                              b"Sec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: foxglove.websocket.v1\r\n" +
                              header + b"\r\n")
                    return s.recv(4096).split(b"\r\n")[0].decode()
            self.assertIn("401", status(b"/"))
            self.assertIn("401", status(b"/?token=" + token[:-1].encode() + b"x"))
            self.assertIn("401", status(b"/?token=" + token.encode() + b"0"))
            self.assertIn("101", status(b"/?token=" + token.encode()))
            self.assertIn("101", status(b"/", b"Authorization: Bearer " + token.encode() + b"\r\n"))
            # The scheme is case-insensitive (RFC 7235 2.1); the token is not.
            self.assertIn("101", status(b"/", b"Authorization: bearer " + token.encode() + b"\r\n"))
            self.assertIn("101", status(b"/", b"Authorization: BEARER " + token.encode() + b"\r\n"))
            self.assertIn("401", status(b"/", b"Authorization: bearer " + token.upper().encode() + b"\r\n"))
            # With the token, the page the bridge serves under any name is its own (a rebinding page
            # has no token); another page is refused even with the token.
            self.assertIn("101", status(b"/?token=" + token.encode(), b"Origin: http://x\r\n"))
            self.assertIn("403", status(b"/?token=" + token.encode(), b"Origin: http://localhost:1\r\n"))

            def plain(target):
                with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
                    s.sendall(b"GET " + target + b" HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n")
                    return s.recv(4096).split(b"\r\n")[0].decode()
            # The cockpit's files are the same for everyone; the dives are vehicle data: the token.
            self.assertIn("200", plain(b"/"))
            self.assertIn("401", plain(b"/dives/"))
            self.assertIn("200", plain(b"/dives/?token=" + token.encode()))
        finally:
            p.terminate()
            self.assertEqual(p.wait(20), 0)

    def tcp_bridge(self, dives_dir, log_name):
        """A second bridge on TCP with a token, serving dives_dir; (process, port, token, log path)."""
        port = free_port()
        token = "fedcba9876543210fedcba9876543210"
        token_file = os.path.join(self.rig.dir, "token-" + log_name)
        with open(token_file, "w") as f:
            f.write(token + "\n")
        log_path = os.path.join(self.rig.dir, log_name)
        with open(log_path, "ab") as log:
            p = subprocess.Popen(harness.EMULATOR + [os.path.join(BUILD_DIR, "tools", "bridge", "caracara-bridge"),
                                  "--listen", "tcp:127.0.0.1:%d" % port, "--token-file", token_file,
                                  "--bus-address", self.rig.address, "--dives-dir", dives_dir,
                                  "--cockpit-dir", os.path.join(SOURCE, "tools", "cockpit")],
                                 stdout=log, stderr=subprocess.STDOUT)
        self.addCleanup(lambda: p.poll() is not None or (p.terminate(), p.wait(20)))
        poll(lambda: self.listening(port) or p.poll() is not None, 10, message="the TCP listener")
        self.assertIsNone(p.poll(), "the TCP bridge exited")
        return p, port, token, log_path

    def test_6_bounds_kill_during_listing_and_floods(self):
        # A full dive directory (the recorder's default bound, 256 MB) for the bridge to list.
        full = os.path.join(self.rig.dir, "full-dives")
        count, size = fill(full)
        print("# %d dives, %.0f MB" % (count, size / 1e6), file=sys.stderr)
        p, port, token, log_path = self.tcp_bridge(full, "caracara-bridge-full.log")
        self.node("bounds.test.mjs", CARACARA_TCP_URL="ws://127.0.0.1:%d/?token=%s" % (port, token),
                  CARACARA_BRIDGE_PID=str(p.pid), CARACARA_BRIDGE_LOG=log_path,
                  CARACARA_KILL_OUTPUT_LISTING_MS_MAX=str(bounds.BRIDGE_KILL_OUTPUT_DURING_LISTING_MS_MAX),
                  CARACARA_KILL_HELD_BY_LISTING_MS=str(bounds.BRIDGE_KILL_HELD_BY_LISTING_MS),
                  CARACARA_CLIENT_LOSS_ZERO_MS_MAX=str(bounds.CLIENT_LOSS_ZERO_MS_MAX))
        self.assertIsNone(p.poll(), "the bridge survived")

    def test_7_stalled_tokenless_connections_never_lock_out_a_pilot(self):
        p, port, token, _ = self.tcp_bridge(self.rig.dives_dir, "caracara-bridge-stalled.log")
        upgrade = (b"GET /%s HTTP/1.1\r\nHost: x\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                   b"Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n"
                   b"Sec-WebSocket-Protocol: foxglove.websocket.v1\r\n\r\n")

        def connect(first_bytes=b""):
            s = socket.create_connection(("127.0.0.1", port), timeout=10)
            self.addCleanup(s.close)
            if first_bytes:
                s.sendall(first_bytes)
            return s

        def pilot():
            s = connect(upgrade % (b"?token=" + token.encode()))
            return s, s.recv(4096).split(b"\r\n")[0].decode()

        # 16 tokenless connections that never finish their request (the max-clients default), and
        # 16 that say nothing, held open; then the pilots with the token, all 16 of them.
        stalled = [connect(b"GET / HTTP/1.1\r\nHost: x\r\n") for _ in range(16)] + [connect() for _ in range(16)]
        t0 = time.monotonic()
        pilots = [pilot() for _ in range(16)]
        self.assertEqual([line for _, line in pilots], ["HTTP/1.1 101 Switching Protocols"] * 16)
        # A 17th is refused with the reason: the slots are the pilots'.
        s17, line = pilot()
        self.assertIn("503", line)
        # The stalled ones are closed after the request timeout (3 s), never the pilots.
        for s in stalled:
            s.settimeout(10)
            try:
                self.assertEqual(s.recv(4096), b"")
            except ConnectionResetError:
                pass
        waited = time.monotonic() - t0
        print("# stalled connections closed %.1f s after the pilots connected" % waited, file=sys.stderr)
        self.assertLess(waited, REQUEST_TIMEOUT_S + BRIDGE_REQUEST_TIMEOUT_LATENESS_S_MAX)
        for s, _ in pilots:
            s.setblocking(False)
            try:
                self.assertNotEqual(s.recv(65536), b"", "a pilot's connection was closed")
            except BlockingIOError:
                pass  # open, nothing to read
        # More connections without a request than the bridge keeps apart (64): the oldest go, and
        # a pilot still gets in once a slot is free.
        s17.close()
        for s, _ in pilots[:1]:
            s.close()
        flood = [connect() for _ in range(100)]
        time.sleep(0.5)  # well inside the request timeout: only the bound closed any

        def is_closed(s):
            s.setblocking(False)
            try:
                return s.recv(1) == b""
            except BlockingIOError:
                return False
            except ConnectionResetError:
                return True
        self.assertEqual([is_closed(s) for s in flood[:30]], [True] * 30, "the oldest were not closed")
        self.assertEqual([is_closed(s) for s in flood[-30:]], [False] * 30, "the newest were closed")
        _, line = pilot()
        self.assertIn("101", line)
        self.assertIsNone(p.poll())

    def test_8_a_twist_on_command_motion_moves_the_vehicle_in_body_flu(self):
        # REP 103 body FLU (x forward, y left, z up, right-handed rotations), each way; the
        # simulated vehicle is the referee. A clockwise turn reads on /tf as the ENU yaw decreasing.
        twist = [("linear", "x", "forward", "backward"), ("linear", "y", "port", "starboard"),
                 ("linear", "z", "up", "deeper"), ("angular", "z", "counter-clockwise", "clockwise"),
                 ("angular", "y", "nose down", "nose up"), ("angular", "x", "roll right", "roll left")]
        self.rearm()
        with HeldPilot(self.rig, "foxglove", CARACARA_WS_URL="ws://127.0.0.1:%d" % self.port) as pilot:
            for part, axis, plus, minus in twist:
                for demand, motion in ((0.5, plus), (-0.5, minus)):
                    what = "/command/motion %s.%s=%+.1f" % (part, axis, demand)
                    with self.subTest(what):
                        answer = {}

                        def hold(seconds):
                            answer.update(pilot.hold(seconds=seconds, topic="/command/motion",
                                                     message={part: {axis: demand}}))
                        m = judge(self, self.rig, motion, hold, what)
                        # /tf's last rotation (the Teensy's angles come at the daemon's telemetry
                        # rate) against the simulated heading now: ENU yaw = pi/2 - heading.
                        heading, pitch, roll = (float(v) for v in self.rig.sim_teensy("Orientation"))
                        q = answer["tf"][1]
                        enu_yaw = quaternion_yaw(q)
                        # The body's forward (x) and left (y) axes in the world: their heights are
                        # the sines of nose up and of roll right (right side down raises the left).
                        nose_up = math.asin(max(-1, min(1, 2 * (q["x"] * q["z"] - q["w"] * q["y"]))))
                        roll_right = math.asin(max(-1, min(1, 2 * (q["y"] * q["z"] + q["w"] * q["x"]))))
                        for name, tf_angle, sim_angle in (("nose up", nose_up, pitch), ("roll right", roll_right, roll)):
                            self.assertLessEqual(abs(tf_angle - sim_angle), TF_YAW_TOLERANCE_RAD,
                                                 "%s: /tf's %s %.3f, the simulator's %.3f" % (what, name, tf_angle,
                                                                                            sim_angle))
                        off = angle_diff(enu_yaw, math.pi / 2 - heading)
                        turned = angle_diff(enu_yaw, math.pi / 2 - START_HEADING_RAD)
                        print("# %s: %s; /tf's yaw turned %+.3f rad from the start, %+.3f rad off the "
                              "simulator's" % (what, describe(m), turned, off), file=sys.stderr)
                        self.assertLessEqual(abs(off), TF_YAW_TOLERANCE_RAD, "%s: /tf's yaw %.3f, the simulated "
                                             "heading %.3f" % (what, enu_yaw, heading))
                        if (part, axis) == ("angular", "z"):
                            # Counter-clockwise is ENU's positive yaw: the sign of the demand.
                            self.assertGreaterEqual(turned * math.copysign(1, demand), bounds.MOTION_ROTATION_MIN_RAD,
                                                    "%s: /tf's yaw turned %+.3f rad" % (what, turned))

    def test_9_bridge_stops_cleanly(self):
        self.check_bridge_stops_cleanly()


if __name__ == "__main__":
    unittest.main()
