#!/usr/bin/python3
"""The one table scripts/test.sh ends with: each suite, ran or not, its counts and its time.

    suite_table.py RESULTS_DIR

RESULTS_DIR holds what scripts/test.sh recorded: steps.txt (one "STEP SELECTED EXIT SECONDS"
line per step of test.sh), and for each ctest run STEP.xml (ctest --output-junit, passed tests'
output kept whole) and STEP.json (ctest --show-only=json-v1: the labels). The counts are read
from the suites' own last words:
  Catch2            "All tests passed (A assertions in N test cases)" / "test cases: N | P passed | F failed"
  python unittest   "Ran N tests" and "OK (skipped=K)"
  system test       "system: P of N checks passed"       (tests/system/run.sh)
  kernel test       "kernel: P of N scenarios passed"    (tests/kernel/run.sh)
  a skipped suite   "system: not run (REASON)", "kernel: not run (REASON)", "debian13: not run (REASON)"
  Debian 13 ctest   "X% tests passed, F tests failed out of N"
  libFuzzer         "stat::number_of_executed_units: N" and "#N DONE cov: C ft: F"

Exit status 1 when a suite failed, or did not run although this machine can run it; under CI
(CI=true) every skip is a failure too (a suite that cannot run there fails), and so is a python
test skipped inside a suite. Outside CI a skip stays a skip, shown with its reason.
"""
import json
import os
import re
import sys
import xml.etree.ElementTree as ET

CI = os.environ.get("CI") == "true"
ROOT = os.geteuid() == 0
AMD64 = os.uname().machine == "x86_64"


class Suite:
    def __init__(self, name, step, can_run=True, why_not=""):
        self.name, self.step, self.can_run, self.why_not = name, step, can_run, why_not
        self.tests = []          # (name, status, seconds, output)
        self.status = None       # forced status: a suite with no ctest test of its own
        self.counts = []
        self.seconds = 0.0
        self.skip_reason = ""
        self.inner_skips = 0

    def verdict(self, selected):
        if not selected:
            return "not selected", False
        if self.status:
            return self.status
        if not self.tests:
            if not self.can_run:
                return "not run (%s)" % self.why_not, CI
            return "NOT RUN", True
        st = [t[1] for t in self.tests]
        if "failed" in st:
            return "FAILED (%d of %d tests)" % (st.count("failed"), len(st)), True
        # Every scenario or none: a count short of its plan fails whatever the exit status said.
        short = [(what, got, of) for what, got, of in self.counts
                 if what in ("checks", "scenarios") and of is not None and got != of]
        if short:
            return "FAILED (%s)" % ", ".join("%d of %d %s" % (g, o, w) for w, g, o in short), True
        if "skipped" in st:
            why = self.skip_reason or "skipped"
            return "skipped: %s" % why, CI or self.can_run and not self.skip_reason
        if self.inner_skips:
            return "passed, %d python test(s) skipped" % self.inner_skips, CI
        return "passed", False


def read_junit(path):
    """[(name, status, seconds, output)] from ctest's JUnit file."""
    out = []
    if not os.path.exists(path):
        return out
    for case in ET.parse(path).getroot().iter("testcase"):
        status = case.get("status", "run")
        if case.find("failure") is not None or status == "fail":
            status = "failed"
        elif case.find("skipped") is not None or status in ("notrun", "disabled"):
            status = "skipped"
        else:
            status = "passed"
        text = "".join((e.text or "") for e in case.iter("system-out"))
        out.append((case.get("name"), status, float(case.get("time") or 0), text))
    return out


def read_labels(path):
    if not os.path.exists(path):
        return {}
    with open(path) as f:
        data = json.load(f)
    labels = {}
    for t in data.get("tests", []):
        ls = []
        for p in t.get("properties", []):
            if p.get("name") == "LABELS":
                ls = p.get("value", [])
        labels[t["name"]] = ls
    return labels


def inner_counts(text):
    """What a suite's own output says it counted."""
    counts, skips, reason = [], 0, ""
    text = re.sub(r"\x1b\[[0-9;]*m", "", text)
    for m in re.finditer(r"All tests passed \((\d+) assertions? in (\d+) test cases?\)", text):
        counts.append(("test cases", int(m.group(2)), int(m.group(2))))
    for m in re.finditer(r"test cases:\s+(\d+) \|\s+(\d+) passed", text):
        counts.append(("test cases", int(m.group(2)), int(m.group(1))))
    for m in re.finditer(r"^Ran (\d+) tests? in", text, re.M):
        counts.append(("python tests", int(m.group(1)), int(m.group(1))))
    for m in re.finditer(r"^(?:OK|FAILED) \(.*skipped=(\d+)", text, re.M):
        skips += int(m.group(1))
    for m in re.finditer(r"^(system|kernel)(?: \(debian13\))?: (\d+) of (\d+) (checks|scenarios) passed", text, re.M):
        counts.append((m.group(4), int(m.group(2)), int(m.group(3))))
    for m in re.finditer(r"^(system|kernel|debian13): not run \((.*)\)", text, re.M):
        reason = m.group(2)
    for m in re.finditer(r"tests passed, (\d+) tests failed out of (\d+)", text):
        counts.append(("Debian 13 ctest tests", int(m.group(2)) - int(m.group(1)), int(m.group(2))))
    for m in re.finditer(r"^stat::number_of_executed_units:\s*(\d+)", text, re.M):
        counts.append(("executions", int(m.group(1)), None))
    for m in re.finditer(r"^#\d+\s+DONE\s+cov: (\d+) ft: (\d+)", text, re.M):
        counts.append(("cov", int(m.group(1)), None))
    return counts, skips, reason


def section(text, start, end=None):
    """The part of debian13.sh's output between two of its step lines."""
    i = text.find(start)
    if i < 0:
        return ""
    j = text.find(end, i) if end else -1
    return text[i:j if j >= 0 else len(text)]


def main():
    results = sys.argv[1]
    steps = {}
    with open(os.path.join(results, "steps.txt")) as f:
        for line in f:
            name, selected, rc, secs = line.split()
            steps[name] = (selected == "1", int(rc), int(secs))

    need_root = "needs root (not root)" if not ROOT else "needs amd64"
    systemable = ROOT and AMD64
    suites = [Suite("unit", "normal"), Suite("integration", "normal"), Suite("e2e", "normal"),
              Suite("soak", "normal"), Suite("layers", "normal"), Suite("release (version)", "normal"),
              Suite("system Debian 12", "normal", systemable, need_root),
              Suite("kernel Debian 12", "normal", systemable, need_root),
              Suite("Debian 13 build+ctest", "normal", systemable, need_root),
              Suite("system Debian 13", "normal", systemable, need_root),
              Suite("kernel Debian 13", "normal", systemable, need_root),
              Suite("ASan+UBSan", "sanitize"), Suite("arm64", "cross"), Suite("fuzz", "fuzz")]
    by = {s.name: s for s in suites}

    def add(suite, t, counts_from=None):
        name, status, secs, text = t
        suite.tests.append(t)
        suite.seconds += secs
        c, skips, reason = inner_counts(text if counts_from is None else counts_from)
        suite.counts += c
        suite.inner_skips += skips
        if status == "skipped" and reason:
            suite.skip_reason = reason

    labels = read_labels(os.path.join(results, "normal.json"))
    for t in read_junit(os.path.join(results, "normal.xml")):
        name, status, secs, text = t
        ls = labels.get(name, [])
        if name == "system_debian13":
            # One ctest test, three suites: the build and ctest, the system checks, the kernel.
            b = section(text, "debian13: building", "debian13: system test")
            s13 = section(text, "debian13: system test", "debian13: kernel test")
            k13 = section(text, "debian13: kernel test")
            _, _, reason = inner_counts(text)
            # debian13.sh's last line: "system test exit R (S s); kernel test exit R (S s)".
            took = {k: float(v) for k, v in re.findall(r"(system|kernel) test exit \S+ \((\d+) s\)", text)}
            for sname, part in (("Debian 13 build+ctest", b), ("system Debian 13", s13),
                                ("kernel Debian 13", k13 or text)):
                st = status
                if sname == "kernel Debian 13" and "kernel: not run" in text:
                    st = "skipped"
                part_secs = {"Debian 13 build+ctest": secs - sum(took.values()),
                             "system Debian 13": took.get("system", 0.0), "kernel Debian 13": took.get("kernel", 0.0)}
                add(by[sname], (name, st, part_secs[sname], part), part)
                if st == "skipped" and reason:
                    by[sname].skip_reason = reason
            continue
        if name in ("system_debs", "system_nspawn"):
            suite = by["system Debian 12"]
        elif "kernel" in ls:
            suite = by["kernel Debian 12"]
        elif "integration" in ls:
            suite = by["integration"]
        elif "e2e" in ls:
            suite = by["e2e"]
        elif "soak" in ls:
            suite = by["soak"]
        elif "release" in ls:
            suite = by["release (version)"]
        elif name == "layers":
            suite = by["layers"]
        else:
            suite = by["unit"]
        add(suite, t)
    for step, sname in (("sanitize", "ASan+UBSan"), ("cross", "arm64"), ("fuzz", "fuzz")):
        for t in read_junit(os.path.join(results, step + ".xml")):
            add(by[sname], t)
        sel, rc, _ = steps.get(step, (False, 0, 0))
        if sel and rc != 0 and not by[sname].tests:
            by[sname].status = ("FAILED (exit %d before its tests)" % rc, True)
    # A step that failed before ctest (build, packages) fails its suites.
    sel, rc, _ = steps.get("normal", (False, 0, 0))
    if sel and rc != 0 and not any(s.tests for s in suites if s.step == "normal"):
        for s in suites:
            if s.step == "normal":
                s.status = ("FAILED (exit %d before its tests)" % rc, True)
    sel, rc, _ = steps.get("arm64-packages", (False, 0, 0))
    if sel and rc != 0:
        by["arm64"].status = ("FAILED (arm64 packages: exit %d)" % rc, True)

    failed = False
    rows = []
    for s in suites:
        selected = steps.get(s.step, (False, 0, 0))[0]
        verdict, bad = s.verdict(selected)
        failed |= bad
        st = [t[1] for t in s.tests]
        counts = []
        if s.tests:
            counts.append("%d/%d ctest" % (st.count("passed"), len(st)))
        agg = {}
        for what, got, of in s.counts:
            a = agg.setdefault(what, [0, 0, of is None])
            a[0] += got
            a[1] += of or 0
        for what, (got, of, single) in agg.items():
            counts.append("%d %s" % (got, what) if single else "%d/%d %s" % (got, of, what))
        rows.append((s.name, verdict + (" <-" if bad else ""), ", ".join(counts) or "-",
                     "%.0f s" % s.seconds if s.tests else "-"))
    w = [max(len(r[i]) for r in rows + [("suite", "result", "counts", "time")]) for i in range(4)]
    print("== suites (CI=%s)" % ("true" if CI else "unset"))
    for r in [("suite", "result", "counts", "time")] + rows:
        print("  %-*s  %-*s  %-*s  %*s" % (w[0], r[0], w[1], r[1], w[2], r[2], w[3], r[3]))
    print("== steps: " + ", ".join("%s %s (exit %d, %d s)" % (n, "ran" if v[0] else "not selected", v[1], v[2])
                                   for n, v in steps.items()))
    if failed:
        print("suites: FAIL (a suite failed, or did not run where it can%s)" % (", or skipped under CI" if CI else ""))
    else:
        print("suites: every selected suite ran and held")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
