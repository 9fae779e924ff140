#!/usr/bin/python3
"""The layering rules, checked on the sources: each folder includes only the folders before it
(core <- protocol <- platform <- devices <- daemon <- dbus), the fuzz harnesses (fuzz/) may use
any layer but nothing includes them, every project include is written
from the repository root, no product source file (all but bench/, tests/ and fuzz/) is over 600 lines,
and CMake lists sources (no GLOB).
Prints each violation; exit 1 when there is one."""
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ORDER = ["core", "protocol", "platform", "devices", "daemon", "dbus"]
# What sits on top may use any layer; main.cpp is the composition root.
TOP = {"sim", "tools", "bench", "tests", "fuzz"}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)

problems = []
for top in ORDER + sorted(TOP):
    for dirpath, _, files in os.walk(os.path.join(ROOT, top)):
        for name in files:
            if not name.endswith((".cpp", ".hpp")):
                continue
            path = os.path.join(dirpath, name)
            rel = os.path.relpath(path, ROOT)
            text = open(path, encoding="utf-8", errors="replace").read()
            if top not in ("bench", "tests", "fuzz") and text.count("\n") > 600:
                problems.append("%s: %d lines (at most 600)" % (rel, text.count("\n")))
            for inc in INCLUDE.findall(text):
                if not os.path.exists(os.path.join(ROOT, inc)):
                    problems.append("%s: #include \"%s\" is not a path from the repository root" % (rel, inc))
                    continue
                if inc.split("/")[0] == "fuzz" and top != "fuzz":
                    problems.append("%s: includes %s; nothing outside fuzz/ may" % (rel, inc))
                    continue
                if top in TOP or rel == "daemon/main.cpp":
                    continue
                to = inc.split("/")[0]
                if to in ORDER and ORDER.index(to) > ORDER.index(top):
                    problems.append("%s: includes %s, a layer above %s/" % (rel, inc, top))
                elif to not in ORDER:
                    problems.append("%s: includes %s, outside the layers" % (rel, inc))
for dirpath, _, files in os.walk(ROOT):
    if "/build" in dirpath or "/.git" in dirpath:
        continue
    for name in files:
        if name == "CMakeLists.txt" or name.endswith(".cmake"):
            p = os.path.join(dirpath, name)
            if re.search(r"file\s*\(\s*GLOB", open(p).read(), re.I):
                problems.append("%s: file(GLOB) for sources" % os.path.relpath(p, ROOT))
for p in problems:
    print(p)
print("layers: %d violations" % len(problems))
sys.exit(1 if problems else 0)
