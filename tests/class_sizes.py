#!/usr/bin/python3
"""Classes over a size, counted as their header plus their source (one class per file, named
after it: x.hpp + x.cpp), in the product. CTest `class_sizes` runs it.

    tests/class_sizes.py            the limits below, with their named exceptions
    tests/class_sizes.py LIMIT      every unit over LIMIT, no exceptions (a survey)

The vehicle's own code (core/, drivers/, daemon/, dbus/) keeps to 250 lines a unit; the
simulator and the topside tools (sim/, tools/), where a model or a client's command table is one
piece, to 450. EXCEPTIONS names each unit allowed past its limit, with why. Prints each unit
over its limit, largest first, with the classes its header declares; exit 1 when there is one."""
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LIMITS = {"core": 250, "drivers": 250, "daemon": 250, "dbus": 250, "sim": 450, "tools": 450}
PRODUCT = list(LIMITS)
EXCEPTIONS = {
    # Plain structs and their defaults, one per config section: splitting them scatters the
    # one place a reader looks up a key.
    "core/config": "the configuration's structs, one per section",
    # Codec tables: every field and fault bit of the SeaBotix IDS section 8 / the Teensy
    # protocol's command table, with encode and decode side by side.
    "drivers/protocol/seabotix": "the SeaBotix order/status codec and its fault table",
    "drivers/protocol/teensy_codec": "the Teensy frames' codec and its command table",
    # One state machine playing the firmware: frames, busy, the Confirm handshake, motion.
    "sim/teensy_model": "the simulated Teensy's firmware, one state machine",
}
# Not yet split (issue 38 stays open until this is empty): each names its size when it was
# listed, and fails again if it grows past it.
NOT_YET_SPLIT = {
}

survey = int(sys.argv[1]) if len(sys.argv) > 1 else None
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

def limit_of(unit):
    if survey is not None:
        return survey
    return NOT_YET_SPLIT.get(unit, LIMITS[unit.split("/")[0]])


over = sorted(((lines, unit, classes) for unit, (lines, classes) in units.items()
               if lines > limit_of(unit) and (survey is not None or unit not in EXCEPTIONS)), reverse=True)
for lines, unit, classes in over:
    print("%5d  %s  (%s): over %d" % (lines, unit, ", ".join(classes) or "no class", limit_of(unit)))
for unit, why in sorted(EXCEPTIONS.items()):
    if survey is None:
        if unit not in units:
            print("exception %s names no unit: remove it" % unit)
            over.append(unit)
        else:
            print("%5d  %s: allowed past %d (%s)" % (units[unit][0], unit, limit_of(unit), why))
for unit, size in sorted(NOT_YET_SPLIT.items()):
    if survey is None:
        print("%5d  %s: not yet split (limit %d, held at %d)" % (units.get(unit, [0])[0], unit,
                                                                LIMITS[unit.split("/")[0]], size))
print("%d unit(s) over their limit (header + source)" % len(over))
sys.exit(1 if over else 0)
