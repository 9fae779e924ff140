#!/usr/bin/python3
"""The layering rules, checked on the sources (.cpp, .hpp, .h):

- each layer includes only the layers before it in ORDER (core <- drivers/protocol <-
  drivers/platform <- drivers/sdbus <- drivers/devices <- daemon <- dbus); inside daemon/
  each subsystem's folder is a layer of its own, in DAEMON's order (loop <- interfaces <- bus
  <- teensy <- safety <- vehicle <- failsafe <- control <- recovery <- commissioning <- dive
  <- daemon/ itself, where VehicleDaemon puts them together);
- daemon/main.cpp, the composition root, is the one product file that may see every layer;
- sim/, tools/, bench/, tests/ and fuzz/ sit on top and may use any layer; nothing outside
  fuzz/ includes fuzz/;
- every project include is written from the repository root;
- no include cycle between files: a header and its source are one unit (x.hpp + x.cpp), and
  no chain of includes leads from a unit back to itself;
- no product source file (all but bench/, tests/ and fuzz/) is over 600 lines;
- CMake lists sources (no GLOB);
- the thruster controller variants are told apart under drivers/ alone (drivers/protocol's
  VariantFormat table and codec): no product file above drivers/ tests a `Variant::` value or
  reads a variant's own status fields (`.seabotix.`, `.legacy.`).
Prints each violation; exit 1 when there is one."""
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DAEMON = ["loop", "interfaces", "bus", "teensy", "safety", "vehicle", "failsafe", "control", "recovery", "commissioning", "dive"]
ORDER = (["core", "drivers/protocol", "drivers/platform", "drivers/sdbus", "drivers/devices"]
         + ["daemon/" + d for d in DAEMON] + ["daemon", "dbus"])
TOP = ["sim", "tools", "bench", "tests", "fuzz"]
COMPOSITION_ROOT = "daemon/main.cpp"
NOT_PRODUCT = ("bench", "tests", "fuzz")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
SOURCE = (".cpp", ".hpp", ".h")
VARIANT_TEST = re.compile(r"\bVariant::\w+|\.(?:seabotix|legacy)\.")


def layer_of(rel):
    """The longest layer or top folder that holds rel, or None."""
    best = None
    for name in ORDER + TOP:
        if rel.startswith(name + "/") and (best is None or len(name) > len(best)):
            best = name
    return best


def unit_of(rel):
    """A header and its source are one unit: drivers/devices/bus_gate.{hpp,cpp} -> .../bus_gate."""
    return os.path.splitext(rel)[0]


problems = []
edges = {}  # unit -> set of units it includes
for top in ["core", "drivers", "daemon", "dbus"] + TOP:
    for dirpath, _, files in os.walk(os.path.join(ROOT, top)):
        for name in sorted(files):
            if not name.endswith(SOURCE):
                continue
            path = os.path.join(dirpath, name)
            rel = os.path.relpath(path, ROOT)
            layer = layer_of(rel)
            if layer is None:
                problems.append("%s: in no layer (%s)" % (rel, ", ".join(ORDER)))
                continue
            text = open(path, encoding="utf-8", errors="replace").read()
            if layer.split("/")[0] not in NOT_PRODUCT and text.count("\n") > 600:
                problems.append("%s: %d lines (at most 600)" % (rel, text.count("\n")))
            if (layer in ORDER and ORDER.index(layer) > ORDER.index("drivers/devices")
                    and rel != COMPOSITION_ROOT):
                for m in VARIANT_TEST.finditer(text):
                    problems.append("%s:%d: %s above drivers/: read ThrusterStatus's common fields"
                                    % (rel, text.count("\n", 0, m.start()) + 1, m.group(0)))
            for inc in INCLUDE.findall(text):
                if not os.path.exists(os.path.join(ROOT, inc)):
                    problems.append("%s: #include \"%s\" is not a path from the repository root" % (rel, inc))
                    continue
                if unit_of(inc) != unit_of(rel):
                    edges.setdefault(unit_of(rel), set()).add(unit_of(inc))
                to = layer_of(inc)
                if to == "fuzz" and layer != "fuzz":
                    problems.append("%s: includes %s; nothing outside fuzz/ may" % (rel, inc))
                    continue
                if layer in TOP or rel == COMPOSITION_ROOT:
                    continue
                if to in ORDER and ORDER.index(to) > ORDER.index(layer):
                    problems.append("%s: includes %s, a layer above %s/ (only %s sees every layer)"
                                    % (rel, inc, layer, COMPOSITION_ROOT))
                elif to not in ORDER:
                    problems.append("%s: includes %s, outside the layers" % (rel, inc))


def cycles(graph):
    """Strongly connected components of more than one unit (Tarjan, iterative)."""
    index, low, on, stack, out = {}, {}, set(), [], []
    counter = [0]
    for start in sorted(graph):
        if start in index:
            continue
        work = [(start, iter(sorted(graph.get(start, ()))))]
        index[start] = low[start] = counter[0]; counter[0] += 1
        stack.append(start); on.add(start)
        while work:
            node, it = work[-1]
            nxt = next(it, None)
            if nxt is not None:
                if nxt not in index:
                    index[nxt] = low[nxt] = counter[0]; counter[0] += 1
                    stack.append(nxt); on.add(nxt)
                    work.append((nxt, iter(sorted(graph.get(nxt, ())))))
                elif nxt in on:
                    low[node] = min(low[node], index[nxt])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                comp = []
                while True:
                    n = stack.pop(); on.discard(n); comp.append(n)
                    if n == node:
                        break
                if len(comp) > 1:
                    out.append(sorted(comp))
    return out


for comp in cycles(edges):
    problems.append("include cycle between %d units: %s" % (len(comp), " <-> ".join(comp)))

for dirpath, _, files in os.walk(ROOT):
    if "/build" in dirpath or "/.git" in dirpath or "/node_modules" in dirpath:
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
