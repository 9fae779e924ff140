#!/usr/bin/python3
"""The bounds file itself (CTest bounds_lint): tests/bounds.json is whole, every entry of it is used
by a test, and no test writes a literal timing (or memory) bound of its own.

    python3 tests/bounds_lint.py        exit 1 with one line per finding

What it checks:
  1. Each entry of tests/bounds.json has a number "promised", a number "slack" >= 0 with its
     "slack_why", a "unit", a "why" and "used_by"; "kind" is absent (a ceiling: promised + slack)
     or "min" (a floor: promised - slack).
  2. Each entry is used: its name appears, as a word, in a test file under tests/ (Python, Node,
     shell, CMake), not counting tests/bounds.json and this file.
  3. The entries that restate a figure of the product agree with it: PILOT_LOST_PERSISTENCE_MS
     with core/failsafe.hpp's kPilotLostPersistenceMs, ZERO_STEP_HELD_BUS_S_MAX's promise with
     the units' TimeoutStopSec (systemd/caracarad.service).
  4. No literal timing bound in tests/. A literal timing bound is a comparison a test asserts
     between a measured duration (or memory growth) and a number written in the test:
       - Python: the arguments of assertLess, assertLessEqual, assertGreater, assertGreaterEqual,
         and the comparisons inside an `assert` statement, assertTrue or assertFalse, where one
         side names a duration or a size (a name or text matching TIME_WORDS: took, elapsed,
         waited, late, silent, armed, *_ms, *_s, *_ns, *Ms, monotonic(), duration, grown..., or a
         name the file fills from such an expression) and the other side holds a number literal other than 0, 1 and the unit
         conversions (1000, 1e3, 1e6, 1e9 and their inverses, 1024);
       - Node (*.mjs): the same in the first argument of assert.ok(...) / assert(...), read as
         text: a comparison (<, <=, >, >=) between such a name and a number literal;
       - shell (*.sh): a test comparison ([ ... -le|-lt|-ge|-gt ... ]) between such a name and a
         number literal of two digits or more, or such a name (*_MS, *_S, *_US) set to one.
     Not bound: timeouts a test gives up after (poll(..., 10), wait_state(..., 30)), sleeps, counts,
     and a configured value the test sets and then names (CONTROL["command_timeout_ms"]): the
     bound is the comparison, and its margin must come from tests/bounds.json.
"""
import ast
import json
import os
import re
import sys

TESTS = os.path.dirname(os.path.abspath(__file__))
TOP = os.path.dirname(TESTS)
BOUNDS = os.path.join(TESTS, "bounds.json")
SELF = os.path.abspath(__file__)
SKIP_DIRS = {"node_modules", "__pycache__"}
TIME_WORDS = re.compile(r"(took|elapsed|waited|late|silent|armed|duration|monotonic|time_ns|seconds|grown"
                        r"|_ms\b|_s\b|_ns\b|_us\b|Ms\b|MS\b|\bms\b)", re.I)
CONVERSIONS = {0, 1, 1000, 1e3, 1e6, 1e9, 1e-3, 1e-6, 1e-9, 1024}
ORDER_ASSERTS = {"assertLess", "assertLessEqual", "assertGreater", "assertGreaterEqual"}


def files(exts):
    for root, dirs, names in os.walk(TESTS):
        dirs[:] = sorted(d for d in dirs if d not in SKIP_DIRS)
        for n in sorted(names):
            p = os.path.join(root, n)
            if n.endswith(exts) and p not in (BOUNDS, SELF):
                yield p


def literals(node):
    """The number literals of an expression, but the unit conversions."""
    out = []
    for n in ast.walk(node):
        if isinstance(n, ast.Constant) and isinstance(n.value, (int, float)) and not isinstance(n.value, bool):
            if n.value not in CONVERSIONS and -n.value not in CONVERSIONS:
                out.append(n.value)
    return out


def durations(src, tree):
    """Names a file fills with durations: assigned, or appended to, from an expression that names
    one (pings.append((time.monotonic_ns() - t0) / 1e6) makes pings a list of durations)."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and TIME_WORDS.search(ast.unparse(node.value) or ""):
            names |= {t.id for t in node.targets if isinstance(t, ast.Name)}
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "append"
              and isinstance(node.func.value, ast.Name) and node.args
              and TIME_WORDS.search(ast.unparse(node.args[0]) or "")):
            names.add(node.func.value.id)
    return {n for n in names if not NOT_DURATION.search(n)}


# Not durations: a rate (a quantity per second) or a count.
NOT_DURATION = re.compile(r"rate|per_|hz|count", re.I)
# A count or a size of something timed is not a duration: len(pings), os.path.getsize(out).
COUNTS = {"len", "getsize"}


def python_findings(path):
    with open(path) as f:
        src = f.read()
    tree = ast.parse(src, path)
    measured = durations(src, tree)
    found = []

    def timed(node):
        if isinstance(node, ast.Call) and getattr(node.func, "attr", getattr(node.func, "id", None)) in COUNTS:
            return False
        return bool(TIME_WORDS.search(ast.unparse(node) or "")) or any(
            isinstance(n, ast.Name) and n.id in measured for n in ast.walk(node))

    def pair(a, b, line):
        for x, y in ((a, b), (b, a)):
            if timed(x) and literals(y):
                found.append((line, "%s compared with the literal %s" % (
                    ast.unparse(x), ", ".join(repr(v) for v in literals(y)))))
                return

    def compares(node, line):
        for n in ast.walk(node):
            if isinstance(n, ast.Compare):
                sides = [n.left] + list(n.comparators)
                for op, a, b in zip(n.ops, sides, sides[1:]):
                    if isinstance(op, (ast.Lt, ast.LtE, ast.Gt, ast.GtE)):
                        pair(a, b, line)

    for node in ast.walk(tree):
        if isinstance(node, ast.Assert):
            compares(node.test, node.lineno)
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
            name = node.func.attr
            if name in ORDER_ASSERTS and len(node.args) >= 2:
                pair(node.args[0], node.args[1], node.lineno)
            elif name in ("assertTrue", "assertFalse") and node.args:
                compares(node.args[0], node.lineno)
    return sorted(found)


JS_ASSERT = re.compile(r"\bassert(?:\.ok)?\(")
JS_CMP = re.compile(r"([\w.$()\[\]\"' +\-*/]+?)\s*(<=|>=|<|>)\s*([\w.$()\[\]\"' +\-*/]+)")
NUMBER = re.compile(r"(?<![\w.])(\d+(?:\.\d+)?(?:e-?\d+)?)(?![\w.])")


def js_numbers(text):
    out = []
    for m in NUMBER.finditer(text):
        v = float(m.group(1))
        if v not in CONVERSIONS:
            out.append(m.group(1))
    return out


def js_findings(path):
    found = []
    with open(path) as f:
        for i, line in enumerate(f, 1):
            for m in JS_ASSERT.finditer(line):
                # The condition: its strings emptied, up to the message (a template literal) or
                # the line's end.
                cond = re.sub(r'"[^"]*"|\'[^\']*\'', '""', line[m.end():]).split("`", 1)[0]
                cond = re.sub(r"=>", " ", cond)
                for c in JS_CMP.finditer(cond):
                    a, b = c.group(1), c.group(3)
                    for x, y in ((a, b), (b, a)):
                        if TIME_WORDS.search(x) and js_numbers(y) and not js_numbers(x):
                            found.append((i, "%s compared with the literal %s" % (
                                (a + " " + c.group(2) + " " + b).strip(), ", ".join(js_numbers(y)))))
                            break
    return found


SH_CMP = re.compile(r"(\S+)\s+-(le|lt|ge|gt)\s+(\S+)")
# A duration given a number in a test's shell (PILOT_LOST_MS=5000), then compared.
SH_SET = re.compile(r"^\s*(?:local\s+|readonly\s+)?([A-Za-z_]*(?:_MS|_S|_US|_ms|_s|_us))=(\d{2,})\b")


def sh_findings(path):
    found = []
    with open(path) as f:
        for i, line in enumerate(f, 1):
            code = line.split("#", 1)[0] if not line.lstrip().startswith("#") else ""
            m = SH_SET.match(code)
            if m:
                found.append((i, "%s=%s: a duration written in the test" % (m.group(1), m.group(2))))
            for c in SH_CMP.finditer(code):
                a, b = c.group(1), c.group(3)
                for x, y in ((a, b), (b, a)):
                    nums = [n for n in re.findall(r"(?<![\w.$])(\d{2,})(?![\w.])", y) if float(n) not in CONVERSIONS]
                    if TIME_WORDS.search(x) and nums:
                        found.append((i, "%s -%s %s: the literal %s" % (a, c.group(2), b, ", ".join(nums))))
                        break
    return found


def check_entries(bounds):
    bad = []
    for name, e in bounds.items():
        for key, kind in (("promised", (int, float)), ("slack", (int, float)), ("slack_why", str), ("unit", str),
                          ("why", str), ("used_by", list)):
            if not isinstance(e.get(key), kind) or isinstance(e.get(key), bool) or e.get(key) in ("", []):
                bad.append("tests/bounds.json: %s has no %s" % (name, key))
        if isinstance(e.get("slack"), (int, float)) and e["slack"] < 0:
            bad.append("tests/bounds.json: %s: a negative slack (a floor is kind \"min\")" % name)
        if e.get("kind", "max") not in ("max", "min"):
            bad.append("tests/bounds.json: %s: kind %r (max or min)" % (name, e.get("kind")))
        if "value" in e:
            bad.append("tests/bounds.json: %s: a value of its own (the bound is promised + slack)" % name)
    return bad


def check_used(bounds):
    text = ""
    for p in files((".py", ".mjs", ".sh", ".cmake", ".txt")):
        with open(p, errors="replace") as f:
            text += f.read() + "\n"
    return ["tests/bounds.json: %s is used by no test" % n for n in bounds if not re.search(r"\b%s\b" % n, text)]


def check_product(bounds):
    bad = []
    with open(os.path.join(TOP, "core", "failsafe.hpp")) as f:
        m = re.search(r"kPilotLostPersistenceMs\s*=\s*(\d+)", f.read())
    e = bounds.get("PILOT_LOST_PERSISTENCE_MS")
    if e and (not m or int(m.group(1)) != e["promised"]):
        bad.append("tests/bounds.json: PILOT_LOST_PERSISTENCE_MS %s, core/failsafe.hpp kPilotLostPersistenceMs %s" %
                   (e["promised"], m.group(1) if m else "not found"))
    with open(os.path.join(TOP, "systemd", "caracarad.service")) as f:
        m = re.search(r"^TimeoutStopSec=(\d+)s?$", f.read(), re.M)
    e = bounds.get("ZERO_STEP_HELD_BUS_S_MAX")
    if e and (not m or int(m.group(1)) != e["promised"]):
        bad.append("tests/bounds.json: ZERO_STEP_HELD_BUS_S_MAX promises %s s, systemd/caracarad.service TimeoutStopSec %s" %
                   (e["promised"], m.group(1) if m else "not found"))
    return bad


def main():
    with open(BOUNDS) as f:
        bounds = json.load(f)["bounds"]
    bad = check_entries(bounds) + check_used(bounds) + check_product(bounds)
    for exts, find in ((".py", python_findings), (".mjs", js_findings), (".sh", sh_findings)):
        for p in files(exts):
            for line, what in find(p):
                bad.append("%s:%d: a literal timing bound (%s): name it in tests/bounds.json" % (
                    os.path.relpath(p, TOP), line, what))
    for b in bad:
        print(b)
    print("bounds_lint: %d entries, %s" % (len(bounds), "%d finding(s)" % len(bad) if bad else "every one used, no literal "
                                           "timing bound in tests/"))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
