#!/usr/bin/python3
"""Classes over a size, counted as their header plus their source (one class per file, named
after it: x.hpp + x.cpp), in the product: core/, drivers/, daemon/, dbus/, sim/, tools/.

    tests/class_sizes.py [LIMIT]     LIMIT defaults to 250 lines

Prints each unit over LIMIT, largest first, with the classes its header declares; exit 1 when
there is one."""
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PRODUCT = ["core", "drivers", "daemon", "dbus", "sim", "tools"]

limit = int(sys.argv[1]) if len(sys.argv) > 1 else 250
units = {}  # unit -> [lines, classes]
for top in PRODUCT:
    for dirpath, _, files in os.walk(os.path.join(ROOT, top)):
        for name in files:
            stem, ext = os.path.splitext(name)
            if ext not in (".cpp", ".hpp", ".h"):
                continue
            text = open(os.path.join(dirpath, name), encoding="utf-8", errors="replace").read()
            unit = units.setdefault(os.path.relpath(os.path.join(dirpath, stem), ROOT), [0, []])
            unit[0] += text.count("\n")
            if ext != ".cpp":
                # Top-level classes only: those declared at the start of a line.
                unit[1] += [c for c in re.findall(r"^(?:class|struct)\s+(\w+)[^;]*$", text, re.M)]

over = sorted(((lines, unit, classes) for unit, (lines, classes) in units.items() if lines > limit), reverse=True)
for lines, unit, classes in over:
    print("%5d  %s  (%s)" % (lines, unit, ", ".join(classes) or "no class"))
print("%d unit(s) over %d lines (header + source)" % (len(over), limit))
sys.exit(1 if over else 0)
