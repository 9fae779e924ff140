"""The SSH bridge of the benchmarks' ssh phase (bench/run.py --only ssh).

A private sshd on 127.0.0.1 (a free port, a host key and a client key made for the run, keys
only, no PAM) in a mount namespace of its own, where a copy of /etc/passwd names its
privilege-separation user and a tmpfs on /run holds /run/sshd: nothing of this machine's
configuration changes, and nothing listens beyond loopback. Clients reach the benchmark's
private bus the way caracaractl -H reaches a vehicle: ssh runs systemd-stdio-bridge on the far
end (here with --bus-path, since the benchmark's bus is not the system bus).

sshd is /usr/sbin/sshd when openssh-server is installed; otherwise openssh-server and libwrap0
are fetched with `apt-get download` and unpacked under /var/cache/caracara-bench (installing
the package would start a system sshd on port 22).
"""
import glob
import os
import re
import shutil
import socket
import subprocess
import time

CACHE = "/var/cache/caracara-bench"


def escape(value):
    """A value in a D-Bus address: bytes outside [-0-9A-Za-z_/.*] become %XX."""
    return "".join(chr(b) if re.fullmatch(rb"[-0-9A-Za-z_/.*]", bytes([b])) else "%%%02x" % b
                   for b in value.encode())


def find_sshd(log):
    """(path of sshd, extra environment)."""
    for path in (shutil.which("sshd"), "/usr/sbin/sshd"):
        if path and os.access(path, os.X_OK):
            return path, {}
    root = os.path.join(CACHE, "openssh-server")
    sshd = os.path.join(root, "usr", "sbin", "sshd")
    if not os.access(sshd, os.X_OK):
        debs = os.path.join(CACHE, "debs")
        os.makedirs(debs, exist_ok=True)
        log(f"   fetching openssh-server and libwrap0 with apt-get download into {CACHE}")
        cmd = ["apt-get", "download", "-q", "openssh-server", "libwrap0"]
        if subprocess.run(cmd, cwd=debs, capture_output=True).returncode != 0:
            subprocess.run(["apt-get", "update", "-qq"], check=True)
            subprocess.run(cmd, cwd=debs, check=True, capture_output=True)
        for deb in glob.glob(os.path.join(debs, "*.deb")):
            subprocess.run(["dpkg-deb", "-x", deb, root], check=True)
    libs = glob.glob(os.path.join(root, "lib", "*-linux-gnu")) + glob.glob(os.path.join(root, "usr", "lib", "*-linux-gnu"))
    return sshd, {"LD_LIBRARY_PATH": ":".join(libs)}


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def port_listens(port):
    """True when something accepts a connection on 127.0.0.1:port."""
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=0.5):
            return True
    except OSError:
        return False


def private_sshd(d, port, log):
    """Makes a private sshd's files in d (host and client keys, authorized_keys, sshd_config
    for 127.0.0.1:port, keys only, no PAM, stream-local forwarding allowed, a passwd with its
    privilege-separation user); returns (argv, extra environment) that run it in a mount
    namespace of its own (e2e_bridge runs it too)."""
    sshd, env = find_sshd(log)
    for key in ("host_key", "client_key"):
        subprocess.run(["ssh-keygen", "-q", "-t", "ed25519", "-N", "", "-f", os.path.join(d, key)], check=True)
    shutil.copy(os.path.join(d, "client_key.pub"), os.path.join(d, "authorized_keys"))
    with open(os.path.join(d, "sshd_config"), "w") as f:
        f.write(f"""ListenAddress 127.0.0.1
Port {port}
HostKey {d}/host_key
AuthorizedKeysFile {d}/authorized_keys
PermitRootLogin prohibit-password
PasswordAuthentication no
KbdInteractiveAuthentication no
UsePAM no
StrictModes no
PidFile none
AllowStreamLocalForwarding yes
""")
    with open("/etc/passwd") as src, open(os.path.join(d, "passwd"), "w") as dst:
        text = src.read()
        dst.write(text)
        if not re.search(r"^sshd:", text, re.M):
            dst.write("sshd:x:65534:65534::/run/sshd:/usr/sbin/nologin\n")
    script = (f"set -e; mount --bind {d}/passwd /etc/passwd; mount -t tmpfs -o mode=0755 tmpfs /run; "
              f"mkdir -m 0755 /run/sshd; exec {sshd} -D -e -f {d}/sshd_config")
    return ["unshare", "--mount", "--propagation", "private", "sh", "-c", script], env


class SshBridge:
    def __init__(self, bench, log):
        self.b = bench
        self.dir = os.path.join(bench.dir, "ssh")
        os.makedirs(self.dir, exist_ok=True)
        self.port = free_port()
        d = self.dir
        argv, env = private_sshd(d, self.port, log)
        with open(os.path.join(d, "ssh_config"), "w") as f:
            f.write(f"""Host bench
  HostName 127.0.0.1
  Port {self.port}
  User root
  IdentityFile {d}/client_key
  IdentitiesOnly yes
  UserKnownHostsFile /dev/null
  GlobalKnownHostsFile /dev/null
  StrictHostKeyChecking no
  BatchMode yes
  LogLevel ERROR
""")
        self.proc = bench.spawn(argv, "sshd", env={**os.environ, **env})
        bench.wait_for(self.listening, 10, "the benchmark's sshd")
        # What sd_bus_open_system_remote() runs, plus this run's ssh config and the private bus.
        argv = ["-F", os.path.join(d, "ssh_config"), "-xT", "--", "bench", "systemd-stdio-bridge",
                f"--bus-path={bench.bus}"]
        self.address = "unixexec:path=ssh," + ",".join(f"argv{i}={escape(a)}" for i, a in enumerate(argv, 1))

    def listening(self):
        if self.proc.poll() is not None:
            raise RuntimeError(f"sshd exited (status {self.proc.returncode}); see {self.b.dir}/sshd.log")
        try:
            with socket.create_connection(("127.0.0.1", self.port), timeout=0.5):
                return True
        except OSError:
            return False

    def connect_ms(self, samples=5):
        """Median time of a whole connection: ssh login, bridge, Hello, one Ping, close."""
        times = []
        for _ in range(samples):
            t0 = time.monotonic()
            r = subprocess.run(["busctl", f"--address={self.address}", "call", "org.freedesktop.DBus",
                                "/org/freedesktop/DBus", "org.freedesktop.DBus.Peer", "Ping"], capture_output=True,
                               text=True)
            if r.returncode != 0:
                raise RuntimeError(f"busctl over the SSH bridge: {r.stderr.strip()}")
            times.append((time.monotonic() - t0) * 1000)
        return sorted(times)[len(times) // 2]

    def stop(self):
        self.b.stop(self.proc)
