#!/usr/bin/python3
"""The one table scripts/test.sh ends with: each suite, ran or not, its counts and its time.

    suite_table.py RESULTS_DIR [--record FILE]    the table; --record also writes it as JSON
    suite_table.py --readme [--check] [--record FILE] [--readme-file README.md]
        README's CI table (between "<!-- suite-table begin -->" and "<!-- suite-table end -->")
        written from the committed record, bench/suite-results.json by default; --check writes
        nothing and exits 1 when README is not what the record gives (CTest readme_suites).

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
test skipped inside a suite. Outside CI a skip stays a skip, shown with its reason. A suite left
out of a run by design (the bridge and cockpit suites under arm64 and in the Debian 13 root,
LEFT_OUT below) is shown as "not run here" with why, and fails nothing.
"""
import argparse
import datetime
import json
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET

CI = os.environ.get("CI") == "true"
ROOT = os.geteuid() == 0
AMD64 = os.uname().machine == "x86_64"
TOP = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RECORD = os.path.join(TOP, "bench", "suite-results.json")
README = os.path.join(TOP, "README.md")

# The bridge's and the cockpit's end-to-end tests (CTest e2e_bridge, e2e_cockpit, label bridge)
# run in the normal build only, caracara-ros's (e2e_ros, label ros) in every build but arm64;
# where a run leaves them out, why (the script that does it says the same where it does it).
# Shown unless that run's tests include them after all.
LEFT_OUT = {
    "arm64": "scripts/cross_test.sh runs ctest -LE 'bridge|ros': under qemu-user their timing-bound "
             "steps time out; the arm64 bridge's protocol, MCAP and file serving run in test_foxglove",
    "ros arm64": "scripts/cross_test.sh runs ctest -LE 'bridge|ros': e2e_ros holds caracara-ros to the "
                 "250 ms client-loss bound through a Fast DDS peer on the host, not under qemu-user; "
                 "the arm64 caracara-ros is built",
    "Debian 13": "tests/system/debian13.sh runs ctest -LE 'system|kernel|bridge' in the Debian 13 root: "
                 "their npm packages come from the registry, which the root has no network for; "
                 "the Debian 12 run's suites run them",
}
# Those tests' rows in the arm64 run, should it run them after all.
ARM64_ROW = {"e2e_bridge": "bridge arm64", "e2e_cockpit": "cockpit arm64", "e2e_ros": "ros arm64"}


class Suite:
    def __init__(self, name, step, can_run=True, why_not="", left_out=""):
        self.name, self.step, self.can_run, self.why_not = name, step, can_run, why_not
        self.left_out = left_out  # why this run leaves the suite out by design
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
            if self.left_out:
                return "not run here: %s" % self.left_out, False
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


def table(results):
    """The table's rows [(suite, result, counts, time, bad)], the steps and whether any failed."""
    steps = {}
    with open(os.path.join(results, "steps.txt")) as f:
        for line in f:
            name, selected, rc, secs = line.split()
            steps[name] = (selected == "1", int(rc), int(secs))

    need_root = "needs root (not root)" if not ROOT else "needs amd64"
    systemable = ROOT and AMD64
    suites = [Suite("unit", "normal"), Suite("integration", "normal"), Suite("e2e", "normal"),
              Suite("bridge Debian 12", "normal"), Suite("cockpit Debian 12", "normal"),
              Suite("soak", "normal"), Suite("layers", "normal"), Suite("docs from records", "normal"),
              Suite("release (version)", "normal"),
              Suite("system Debian 12", "normal", systemable, need_root),
              Suite("kernel Debian 12", "normal", systemable, need_root),
              Suite("Debian 13 build+ctest", "normal", systemable, need_root),
              Suite("system Debian 13", "normal", systemable, need_root),
              Suite("kernel Debian 13", "normal", systemable, need_root),
              Suite("bridge Debian 13", "normal", left_out=LEFT_OUT["Debian 13"]),
              Suite("cockpit Debian 13", "normal", left_out=LEFT_OUT["Debian 13"]),
              Suite("ASan+UBSan", "sanitize"), Suite("arm64", "cross"),
              Suite("bridge arm64", "cross", left_out=LEFT_OUT["arm64"]),
              Suite("cockpit arm64", "cross", left_out=LEFT_OUT["arm64"]),
              Suite("ros arm64", "cross", left_out=LEFT_OUT["ros arm64"]), Suite("fuzz", "fuzz")]
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
                # The Debian 13 ctest's count is the build+ctest row's (debian13.sh's last line
                # repeats it, in the kernel part).
                c13 = [c for c in inner_counts(text)[0] if c[0] == "Debian 13 ctest tests"][-1:]
                by[sname].counts = [c for c in by[sname].counts if c[0] != "Debian 13 ctest tests"]
                if sname == "Debian 13 build+ctest":
                    by[sname].counts += c13
                if st == "skipped" and reason:
                    by[sname].skip_reason = reason
            # The bridge and cockpit tests, should the Debian 13 ctest have run them after all.
            for m in re.finditer(r"Test\s+#\d+: (e2e_bridge|e2e_cockpit) \.+\s*(\*+)?\s*(\w+)", b):
                which = "bridge" if m.group(1) == "e2e_bridge" else "cockpit"
                by[which + " Debian 13"].tests.append((m.group(1), "passed" if m.group(3) == "Passed" else "failed", 0.0, ""))
            continue
        if name in ("e2e_bridge", "e2e_cockpit"):
            add(by["bridge Debian 12" if name == "e2e_bridge" else "cockpit Debian 12"], t)
            continue
        if name == "npm_bridge":
            # The setup test that installs the bridge's and the cockpit's npm packages
            # (FIXTURES_SETUP, label bridge): the bridge row's; npm_ros is e2e_ros's, in e2e.
            add(by["bridge Debian 12"], t)
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
        elif name in ("layers", "bounds_lint", "bounds_lint_test"):
            # The lints on the sources: the layering rules, and the bounds file (tests/bounds_lint.py).
            suite = by["layers"]
        elif name in ("readme_suites", "doc_figures", "bench_report"):
            # README's CI table, the quoted figures and the benchmark tables against their records.
            suite = by["docs from records"]
        else:
            suite = by["unit"]
        add(suite, t)
    for step, sname in (("sanitize", "ASan+UBSan"), ("cross", "arm64"), ("fuzz", "fuzz")):
        for t in read_junit(os.path.join(results, step + ".xml")):
            if step == "cross" and t[0] in ARM64_ROW:
                add(by[ARM64_ROW[t[0]]], t)
            else:
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
        rows.append((s.name, verdict, ", ".join(counts) or "-", "%.0f s" % s.seconds if s.tests else "-", bad))
    return rows, steps, failed


def git(*args):
    try:
        return subprocess.run(["git", "-C", TOP] + list(args), capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return ""


def print_table(rows, steps, failed, ci):
    head = ("suite", "result", "counts", "time")
    shown = [(r[0], r[1] + (" <-" if r[4] else ""), r[2], r[3]) for r in rows]
    w = [max(len(r[i]) for r in shown + [head]) for i in range(4)]
    print("== suites (CI=%s)" % ("true" if ci else "unset"))
    for r in [head] + shown:
        print("  %-*s  %-*s  %-*s  %*s" % (w[0], r[0], w[1], r[1], w[2], r[2], w[3], r[3]))
    print("== steps: " + ", ".join("%s %s (exit %d, %d s)" % (n, "ran" if v[0] else "not selected", v[1], v[2])
                                   for n, v in steps.items()))
    if failed:
        print("suites: FAIL (a suite failed, or did not run where it can%s)" % (", or skipped under CI" if ci else ""))
    else:
        print("suites: every selected suite ran and held")


def run_summary(rec):
    """What a record keeps of a whole run for the runs beside it: when, what, how long."""
    return {k: rec.get(k) for k in ("finished", "commit", "ci", "machine", "caches", "seconds", "failed")} | \
        {"steps": {n: v["seconds"] for n, v in (rec.get("steps") or {}).items() if v.get("selected")}}


def record(rows, steps, failed, record_path):
    """The run as a record: what README's CI table is written from (--readme). It keeps the last
    run with warm caches and the last with cold ones (scripts/test.sh says which this one was:
    CARACARA_SUITE_CACHES) under "runs", so that both times stay in view."""
    commit = git("rev-parse", "HEAD")
    caches = os.environ.get("CARACARA_SUITE_CACHES", "warm")
    seconds = int(os.environ.get("CARACARA_SUITE_SECONDS", "0")) or sum(v[2] for v in steps.values())
    runs = {}
    if os.path.exists(record_path):
        try:
            with open(record_path) as f:
                old = json.load(f)
            runs = old.get("runs") or {old.get("caches", "warm"): run_summary(old)}
        except (OSError, ValueError):
            runs = {}
    rec = {
        "written_by": "scripts/suite_table.py --record (scripts/test.sh)",
        "finished": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%MZ"),
        "commit": commit,
        # The records this run rewrites are left out: this one and the figures' (bench/figures.json).
        "tree_clean": all(line.split(maxsplit=1)[-1] in (os.path.relpath(record_path, TOP),
                                                         os.path.join("bench", "figures.json"))
                          for line in git("status", "--porcelain", "--untracked-files=no").splitlines())
        if commit else None,
        "ci": CI,
        "machine": "%s, %d CPUs" % (os.uname().machine, os.cpu_count() or 0),
        "steps": {n: {"selected": v[0], "exit": v[1], "seconds": v[2]} for n, v in steps.items()},
        "suites": [{"suite": r[0], "result": r[1], "counts": r[2], "time": r[3], "failed": r[4]} for r in rows],
        "failed": failed,
        "caches": caches,
        "seconds": seconds,
    }
    if all(v[0] for v in steps.values()):
        runs[caches] = run_summary(rec)
    rec["runs"] = runs
    return rec


BEGIN, END = "<!-- suite-table begin -->", "<!-- suite-table end -->"


def runs_line(rec):
    """The whole runs' times, warm caches and cold (every cache of the suite emptied first)."""
    def one(kind, r):
        if not r:
            return "%s caches: none recorded yet" % kind
        steps = ", ".join("%s %d min" % (n, round(s / 60)) for n, s in r["steps"].items())
        return "%s caches: **%d min %d s** (%s, commit %s%s; %s)" % (
            kind, r["seconds"] // 60, r["seconds"] % 60, r["finished"], (r["commit"] or "?")[:12],
            ", failed" if r["failed"] else "", steps)
    runs = rec.get("runs") or {}
    return "Whole runs of `scripts/test.sh` (CI's command), the last with each kind of cache: " + \
        "; ".join(one(k, runs.get(k)) for k in ("warm", "cold")) + "."


def readme_section(rec):
    """README's CI table from the record, or what is missing when there is none."""
    out = [BEGIN]
    if rec is None:
        out += ["No suite record is committed yet (`bench/suite-results.json`): a full `scripts/test.sh` "
                "run writes it; `scripts/suite_table.py --readme` then writes this table from it."]
    else:
        steps = ", ".join(n for n, v in rec["steps"].items() if v["selected"])
        everything = all(v["selected"] for v in rec["steps"].values())
        out += ["The suite table of the last recorded `scripts/test.sh` run (`bench/suite-results.json`, "
                "written by `scripts/suite_table.py --record`; this table by `scripts/suite_table.py --readme`): "
                "finished %s on %s, commit %s%s, CI=%s, steps run: %s%s. %s" % (
                    rec["finished"], rec["machine"], (rec["commit"] or "?")[:12],
                    "" if rec.get("tree_clean") in (True, None) else " with uncommitted changes",
                    "true" if rec["ci"] else "unset", steps or "none",
                    "" if everything else " (not a full run)",
                    "Every selected suite ran and held." if not rec["failed"] else
                    "**It failed** (the rows marked failed)."),
                "",
                runs_line(rec),
                "",
                "| suite | result | counts | time |",
                "| --- | --- | --- | --- |"]
        for r in rec["suites"]:
            cells = [r["suite"], r["result"] + (" **(failed)**" if r["failed"] else ""), r["counts"], r["time"]]
            out.append("| " + " | ".join(c.replace("|", "/") for c in cells) + " |")
    out.append(END)
    return "\n".join(out)


def readme(args):
    rec = None
    if os.path.exists(args.record):
        with open(args.record) as f:
            rec = json.load(f)
    with open(args.readme_file) as f:
        text = f.read()
    pat = re.compile(re.escape(BEGIN) + ".*?" + re.escape(END), re.S)
    if not pat.search(text):
        print("suite_table: %s has no %s ... %s section" % (args.readme_file, BEGIN, END), file=sys.stderr)
        return 1
    new = pat.sub(lambda _: readme_section(rec), text)
    if args.check:
        if new != text:
            print("suite_table: %s's CI table is not what %s gives (scripts/suite_table.py --readme writes it)"
                  % (args.readme_file, args.record), file=sys.stderr)
            return 1
        return 0
    if new != text:
        with open(args.readme_file, "w") as f:
            f.write(new)
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("results", nargs="?", help="scripts/test.sh's results directory")
    ap.add_argument("--record", help="the record to write (with RESULTS_DIR) or read (--readme)")
    ap.add_argument("--readme", action="store_true")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--readme-file", default=README)
    args = ap.parse_args()
    if args.readme:
        args.record = args.record or RECORD
        return readme(args)
    if not args.results:
        ap.error("RESULTS_DIR is needed (or --readme)")
    rows, steps, failed = table(args.results)
    print_table(rows, steps, failed, CI)
    if args.record:
        # Read the tree before the file is opened: opening truncates it (it used to make every
        # record say "with uncommitted changes").
        rec = record(rows, steps, failed, os.path.abspath(args.record))
        with open(args.record, "w") as f:
            json.dump(rec, f, indent=1)
            f.write("\n")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
