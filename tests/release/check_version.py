#!/usr/bin/python3
"""The one version: CMake's project(VERSION), given as the first argument, is what
caracarad, caracaractl, caracara-sim, caracara-bridge and caracara-ros --version print, what the
manual pages' .TH lines carry, the newest released debian/changelog entry and the newest
CHANGELOG.md section.

    check_version.py VERSION SOURCE_DIR BUILD_DIR
"""
import os
import re
import shlex
import subprocess
import sys

version, src, build = sys.argv[1:4]
emulator = shlex.split(os.environ.get("CARACARA_TEST_EMULATOR", ""))
problems = []

for program, path in (("caracarad", "daemon/caracarad"), ("caracaractl", "tools/caracaractl"),
                      ("caracara-sim", "sim/caracara-sim"), ("caracara-bridge", "tools/bridge/caracara-bridge"),
                      ("caracara-ros", "tools/ros/caracara-ros")):
    r = subprocess.run(emulator + [os.path.join(build, path), "--version"], capture_output=True,
                       text=True, timeout=60)
    want = f"{program} {version}\n"
    if r.returncode != 0 or r.stdout != want:
        problems.append(f"{program} --version: exit {r.returncode}, {r.stdout!r} (want {want!r})")

for page in ("caracarad.8", "caracaractl.1", "caracara-sim.1", "caracara-bridge.1", "caracara-ros.1"):
    with open(os.path.join(build, "docs/man", page)) as f:
        th = f.readline()
    if f'"caracarad {version}"' not in th:
        problems.append(f"{page}: {th.strip()!r} does not name caracarad {version}")

with open(os.path.join(src, "debian/changelog")) as f:
    head = f.readline()
m = re.match(r"caracarad \(([^)]+)\) (\S+);", head)
if not m or m.group(1) != version or m.group(2) == "UNRELEASED":
    problems.append(f"debian/changelog: {head.strip()!r} is not a released {version} entry")

with open(os.path.join(src, "CHANGELOG.md")) as f:
    sections = re.findall(r"^## (\S+)", f.read(), re.M)
if not sections or sections[0] != version:
    problems.append(f"CHANGELOG.md: newest section {sections[:1]}, not {version}")

with open(os.path.join(src, "README.md")) as f:
    if version not in f.read():
        problems.append(f"README.md does not name {version}")

for p in problems:
    print("FAIL:", p)
print(f"version {version}: {'ok' if not problems else f'{len(problems)} problem(s)'}")
sys.exit(1 if problems else 0)
