#!/usr/bin/python3
"""Classes over a size, counted as their header plus their source (one class per file, named
after it: x.hpp + x.cpp), in the product. CTest `class_sizes` runs it.

    tests/class_sizes.py            the limits below, with their named exceptions
    tests/class_sizes.py LIMIT      every unit over LIMIT, no exceptions (a survey)

The vehicle's own code (core/, drivers/, daemon/, dbus/) keeps to 250 lines a unit; the
simulator and the topside tools (sim/, tools/), where a model or a client's command table is one
piece, to 450. EXCEPTIONS names each unit allowed past its limit, with why. Prints each unit
over its limit, largest first, with the classes its header declares.

It also counts each class's public member functions in the vehicle's headers (core/, drivers/,
daemon/, dbus/): none may have more than 20 (issue 45 item 4), and those above 15 are printed as
a survey. Constructors, the destructor, operators and deleted functions are not counted, nor
data members, nested types or using/friend declarations; overloads of one name (a const and a
mutable accessor, a call with and without its completion) count once; a nested class is
counted on its own. tests/test_class_sizes.py pins the counter on a small header.
Exit 1 when a unit is over its size or a class over 20 public methods."""
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

# --- Public methods a class declares (issue 45 item 4) -------------------------------------------
METHOD_LIMIT = 20   # fails above it
METHOD_SURVEY = 15  # printed above it
METHOD_TOPS = ["core", "drivers", "daemon", "dbus"]
_COMMENT = re.compile(r"//[^\n]*|/\*.*?\*/", re.S)
_LITERAL = re.compile(r'R"(\w*)\(.*?\)\1"|"(?:\\.|[^"\\\n])*"|\'(?:\\.|[^\'\\\n])\'', re.S)
_PREPROCESSOR = re.compile(r"^[ \t]*#[^\n]*(?:\\\n[^\n]*)*", re.M)
_CLASS_HEAD = re.compile(r"(?<![\w:])(enum\s+)?\b(class|struct)\s+(?:\[\[[^\]]*\]\]\s*)?(\w+)"
                         r"(\s+final)?\s*(:[^;{}()]*)?\{")
_INIT_LIST = re.compile(r"[^(]*\(.*\)\s*:(?!:)", re.S)
_ACCESS = re.compile(r"\s*(public|protected|private)\s*:(?!:)")


def _clean(text):
    """The text with comments, string and character literals and preprocessor lines blanked
    (same length and lines), so that braces and parentheses inside them do not count."""
    blank = lambda m: re.sub(r"[^\n]", " ", m.group(0))
    out, pos = [], 0
    # One pass for comments and literals together: a "//" inside a string is not a comment.
    for m in re.finditer(_COMMENT.pattern + "|" + _LITERAL.pattern, text, re.S):
        out.append(text[pos:m.start()])
        out.append(blank(m))
        pos = m.end()
    out.append(text[pos:])
    return _PREPROCESSOR.sub(blank, "".join(out))


def _skip_braces(text, i):
    """The index just past the brace block that opens at text[i]."""
    depth = 0
    while i < len(text):
        if text[i] == "{":
            depth += 1
        elif text[i] == "}":
            depth -= 1
            if depth == 0:
                return i + 1
        i += 1
    return i


def _function_name(stmt):
    """The member function a declaration at class level declares, or None (a data member, a
    type, a using or friend declaration). Constructors, the destructor and operators give ""."""
    s = stmt.strip()
    if not s or re.match(r"(using|typedef|friend|static_assert|template\s*<[^()]*>\s*(class|struct|using))\b", s):
        return None
    angle, paren, equals = 0, None, None
    for i, c in enumerate(s):
        if c == "<":
            angle += 1
        elif c == ">" and angle:
            angle -= 1
        elif angle == 0 and c == "(" and paren is None:
            paren = i
        elif angle == 0 and c == "=" and equals is None and paren is None:
            equals = i
    if re.search(r"\boperator\b", s[:paren] if paren is not None else s):
        return ""
    if paren is None or equals is not None:
        return None  # a data member (initialised or not)
    if re.search(r"=\s*delete\s*$", s):
        return ""
    m = re.search(r"(~?\s*\w+)\s*$", s[:paren])
    return m.group(1).replace(" ", "") if m else None


def public_methods(text):
    """{class name: set of its public member function names}, for each class or struct defined
    in `text` (nested ones too). Constructors, the destructor, operators and deleted functions
    are not counted; overloads of one name (a const and a mutable accessor, a call with and
    without its completion) count once."""
    text = _clean(text)
    found = {}
    for head in _CLASS_HEAD.finditer(text):
        if head.group(1):
            continue  # enum class
        name = head.group(3)
        access = "public" if head.group(2) == "struct" else "private"
        end = _skip_braces(text, head.end() - 1) - 1
        methods = set()
        i, stmt = head.end(), ""
        while i < end:
            c = text[i]
            m = _ACCESS.match(text, i) if not stmt.strip() else None
            if m:
                access, i = m.group(1), m.end()
                continue
            if c == "{" and _INIT_LIST.match(stmt) and re.search(r"[\w>]\s*$", stmt):
                # A member's brace initialiser in a constructor's initialiser list.
                j = _skip_braces(text, i)
                stmt, i = stmt + text[i:j], j
                continue
            if c == "{":
                nested = _CLASS_HEAD.search(stmt + "{")
                fn = None if nested else _function_name(re.sub(r"\)\s*(const|noexcept|override|final|\s)*(->[^{]*)?$", ")", stmt))
                j = _skip_braces(text, i)
                if nested or fn is not None:
                    # A nested type's body or a function's body: the declaration ends here.
                    if fn and access == "public" and fn.lstrip("~") != name and not fn.startswith("~"):
                        methods.add(fn)
                    stmt, i = "", j
                    while i < end and text[i] in " \t\n;":
                        i += 1
                    continue
                stmt += text[i:j]  # a brace initialiser: the declaration goes on to its ';'
                i = j
                continue
            if c == ";":
                fn = _function_name(stmt)
                if fn and access == "public" and fn.lstrip("~") != name and not fn.startswith("~"):
                    methods.add(fn)
                stmt = ""
            else:
                stmt += c
            i += 1
        found.setdefault(name, set()).update(methods)
    return found


def method_counts(root=ROOT):
    """[(count, 'path: Class')] for each class in the vehicle's headers."""
    counts = []
    for top in METHOD_TOPS:
        for dirpath, _, files in os.walk(os.path.join(root, top)):
            for name in sorted(files):
                if not name.endswith((".hpp", ".h")):
                    continue
                path = os.path.join(dirpath, name)
                text = open(path, encoding="utf-8", errors="replace").read()
                for cls, methods in public_methods(text).items():
                    counts.append((len(methods), "%s: %s" % (os.path.relpath(path, root), cls)))
    return sorted(counts, reverse=True)


def main():
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

    # Public methods: the survey above METHOD_SURVEY, a failure above METHOD_LIMIT.
    counts = method_counts()
    crowded = [(n, where) for n, where in counts if n > METHOD_LIMIT]
    for n, where in counts:
        if n > METHOD_SURVEY:
            print("%5d  public methods  %s%s" % (n, where, ": over %d" % METHOD_LIMIT if n > METHOD_LIMIT else ""))
    print("%d class(es) over %d public methods" % (len(crowded), METHOD_LIMIT))
    sys.exit(1 if over or crowded else 0)


if __name__ == "__main__":
    main()
