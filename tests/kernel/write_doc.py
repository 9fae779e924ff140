"""One kernel test run's section of docs/kernel-bridge.md: written (a record), or checked against.

    python3 write_doc.py DOC LABEL SCENARIOS_TSV RESULTS COVERAGE_JSON KERNEL_VERSION
        writes the run's section into DOC (CARACARA_KERNEL_DOC=write records it so)
    python3 write_doc.py --check DOC LABEL SCENARIOS_TSV RESULTS COVERAGE_JSON KERNEL_VERSION
        judges the run against DOC's recorded section: exit 1, with each reason, when it fails

tests/kernel/run.sh calls it at the end of each run, for both of its callers: LABEL is debian12
(the host's root, libgpiod 1) or debian13 (tests/system/debian13.sh, libgpiod 2, Debian 13's
kernel). The section is the part between "<!-- kernel-run LABEL begin -->" and
"<!-- kernel-run LABEL end -->" (appended at the end of the document the first time); nothing
else in DOC is touched. It has no date.

The check judges what the project controls, not what a Debian mirror publishes; a run passes when
  - every scenario of the run passed,
  - the run's scenarios are the recorded ones (names, order and what each proves),
  - each kernel-facing file's line coverage is within COVERAGE_TOLERANCE_PP percentage points of
    its recorded figure (and a file measured, or of the other backend, as recorded), and
  - the booted kernel is of the recorded kernel's release series (KERNEL_SERIES: 6.1 for
    Debian 12, 6.12 for Debian 13): a new point release of the series (Debian's 6.1.0-56 ->
    6.1.0-57) passes, and the run says which kernel the section was measured on last.
The kernel is recorded as information ("Measured last on kernel ..."); line counts and the list
of functions never executed are shown where they differ, not judged.
"""
import json
import os
import re
import sys

# How far a file's line coverage may move from its recorded figure, in percentage points: the
# scenarios take some paths by timing (a retry, a second read), which moves a few lines a run.
COVERAGE_TOLERANCE_PP = 3.0
ROOTS = {"debian12": "Debian 12 root, libgpiod 1", "debian13": "Debian 13 root, libgpiod 2"}
OTHER_BACKEND = "the other backend: measured by the other run"


def kernel_series(kver):
    """'6.1' of '6.1.0-57-amd64', '6.12' of '6.12.117+deb13-amd64' (None when unreadable)."""
    m = re.match(r"(\d+)\.(\d+)", kver or "")
    return "%s.%s" % m.groups() if m else None


def run_data(label, tsv, results_path, cov_path, kver):
    """A run's section as data, from run.sh's outputs."""
    scenarios = []
    with open(tsv) as f:
        for line in f:
            if line.strip():
                name, _, what = line.rstrip("\n").partition("\t")
                scenarios.append((name, what))
    results = {}
    if os.path.exists(results_path):
        with open(results_path) as f:
            for line in f:
                m = re.match(r"(PASS|FAIL) (\S+?)(?::| \()", line)
                if m:
                    results[m.group(2)] = line.strip()
    rows = []
    for name, what in scenarios:
        # Without the seconds: the section changes when a result does, not at every run.
        r = results.get(name, "no result")
        rows.append((name, "pass" if r.startswith("PASS") else r.replace("|", "/"), what.replace("|", "/")))
    cov = None
    if cov_path and os.path.exists(cov_path):
        with open(cov_path) as f:
            c = json.load(f)
        files, never = [], []
        for f in c["files"]:
            if f["status"] == "other backend":
                files.append({"file": f["file"], "other": True})
            elif "percent" in f:
                files.append({"file": f["file"], "percent": float(f["percent"]), "lines": int(f["lines"]),
                              "ran": f["status"] == "ran"})
                never += [(f["file"], n["function"], n.get("why") or "") for n in f["never"]]
            else:
                files.append({"file": f["file"], "missing": f["status"]})
        cov = {"backend": c["backend"], "percent": float(c["total"]["percent"]), "lines": int(c["total"]["lines"]),
               "files": files, "never": never}
    return {"label": label, "root": ROOTS.get(label, label), "kernel": kver, "scenarios": rows, "coverage": cov}


def render(d):
    """The section's text."""
    series = kernel_series(d["kernel"])
    passed = sum(1 for _, r, _ in d["scenarios"] if r == "pass")
    out = ["<!-- kernel-run %s begin -->" % d["label"],
           "### Run: %s" % d["root"],
           "",
           "Written by `tests/kernel/run.sh` (`tests/kernel/write_doc.py`) from a run; not edited by hand "
           "(`CARACARA_KERNEL_DOC=write` records a run's section, every other run checks it).",
           "",
           "Measured last on kernel `%s` (release series %s). Every other run is judged against this "
           "record, not compared with it byte for byte: it passes when each of its scenarios passes, its "
           "scenarios are the ones below, each file's line coverage is within %s percentage points of its "
           "figure below, and its kernel is of the %s series (a later point release of it passes; the run "
           "names the kernel it booted)." % (d["kernel"], series, "±%g" % COVERAGE_TOLERANCE_PP, series),
           "",
           "**%d of %d scenarios passed.**" % (passed, len(d["scenarios"])),
           "",
           "| scenario | result | what it proves |",
           "| --- | --- | --- |"]
    for name, result, what in d["scenarios"]:
        out.append("| `%s` | %s | %s |" % (name, result, what))
    out.append("")
    cov = d["coverage"]
    if cov:
        out += ["Line coverage of the kernel-facing files in this run (%s build): **%.1f %% of %d lines**."
                % (cov["backend"], cov["percent"], cov["lines"]),
                "",
                "| file | lines executed |",
                "| --- | --- |"]
        for f in cov["files"]:
            if f.get("other"):
                cell = OTHER_BACKEND
            elif "percent" in f:
                cell = "%.1f %% of %d" % (f["percent"], f["lines"]) + ("" if f["ran"] else " (never ran)")
            else:
                cell = "**no coverage data** (%s)" % f["missing"]
            out.append("| `%s` | %s |" % (f["file"], cell))
        out += ["", "Functions never executed on the kernel in this run: %d." % len(cov["never"])]
        if cov["never"]:
            out.append("")
            for file, fn, why in cov["never"]:
                out.append("- `%s`: `%s`%s" % (file, fn, (" — " + why) if why else ""))
        out.append("")
    else:
        out += ["No coverage data from this run.", ""]
    out.append("<!-- kernel-run %s end -->" % d["label"])
    return "\n".join(out)


def section_pattern(label):
    return re.compile(r"<!-- kernel-run %s begin -->.*?<!-- kernel-run %s end -->" % (re.escape(label), re.escape(label)),
                      re.S)


def parse(text, label):
    """The recorded section of LABEL in a document's text, as data (None when it has none)."""
    m = section_pattern(label).search(text)
    if not m:
        return None
    lines = m.group(0).split("\n")
    d = {"label": label, "root": ROOTS.get(label, label), "kernel": None, "scenarios": [], "coverage": None}
    cov = None
    for line in lines:
        h = re.match(r"### Run: (.*)$", line)
        k = re.match(r"Measured last on kernel `([^`]+)`", line)
        s = re.match(r"\| `([^`]+)` \| (.*?) \| (.*) \|$", line)
        c = re.match(r"\| `([^`]+)` \| ([^|]*) \|$", line)
        t = re.match(r"Line coverage of the kernel-facing files in this run \((.*) build\): \*\*([\d.]+) % of (\d+) lines\*\*\.$",
                     line)
        n = re.match(r"- `([^`]+)`: `(.*?)`(?: — (.*))?$", line)
        if h:
            d["root"] = h.group(1)
        elif k:
            d["kernel"] = k.group(1)
        elif t:
            cov = {"backend": t.group(1), "percent": float(t.group(2)), "lines": int(t.group(3)), "files": [], "never": []}
            d["coverage"] = cov
        elif cov is None and s:
            d["scenarios"].append(s.groups())
        elif cov is not None and c:
            cell = c.group(2)
            p = re.match(r"([\d.]+) % of (\d+)( \(never ran\))?$", cell)
            miss = re.match(r"\*\*no coverage data\*\* \((.*)\)$", cell)
            if cell == OTHER_BACKEND:
                cov["files"].append({"file": c.group(1), "other": True})
            elif p:
                cov["files"].append({"file": c.group(1), "percent": float(p.group(1)), "lines": int(p.group(2)),
                                     "ran": not p.group(3)})
            else:
                cov["files"].append({"file": c.group(1), "missing": miss.group(1) if miss else cell})
        elif cov is not None and n:
            cov["never"].append((n.group(1), n.group(2), n.group(3) or ""))
    return d


def judge(recorded, run):
    """(failures, notes) of a run against the recorded section."""
    fail, note = [], []
    if recorded is None:
        return ["docs/kernel-bridge.md has no section for %s: record one with CARACARA_KERNEL_DOC=write" % run["label"]], note
    # The kernel: information, but of the recorded release series.
    want, got = kernel_series(recorded["kernel"]), kernel_series(run["kernel"])
    if not want:
        fail.append("the recorded section names no kernel it was measured on")
    elif got != want:
        fail.append("this run booted kernel %s, of the %s series; the record was measured on %s, of the %s series: "
                    "another Debian release's kernel, not a point release of this one (record a run on it with "
                    "CARACARA_KERNEL_DOC=write if that is the change)" % (run["kernel"], got, recorded["kernel"], want))
    elif run["kernel"] != recorded["kernel"]:
        note.append("this run booted kernel %s; the section was measured last on %s (same %s series: judged, not "
                    "compared; CARACARA_KERNEL_DOC=write records this run)" % (run["kernel"], recorded["kernel"], want))
    # Every scenario passed.
    for name, result, _ in run["scenarios"]:
        if result != "pass":
            fail.append("scenario %s did not pass: %s" % (name, result))
    # The scenarios are the recorded ones.
    rec = [(n, w) for n, _, w in recorded["scenarios"]]
    now = [(n, w) for n, _, w in run["scenarios"]]
    if rec != now:
        rn, nn = [n for n, _ in rec], [n for n, _ in now]
        missing = [n for n in rn if n not in nn]
        extra = [n for n in nn if n not in rn]
        if missing:
            fail.append("recorded scenarios this run did not run: %s" % ", ".join(missing))
        if extra:
            fail.append("scenarios this run ran that are not recorded: %s" % ", ".join(extra))
        if not missing and not extra and rn != nn:
            fail.append("the scenarios ran in another order than recorded")
        rw = dict(rec)
        changed = [n for n, w in now if n in rw and rw[n] != w]
        if changed:
            fail.append("what these scenarios prove is not what is recorded: %s" % ", ".join(changed))
    # Coverage of each kernel-facing file, within the tolerance.
    rc, nc = recorded["coverage"], run["coverage"]
    if rc and not nc:
        fail.append("this run has no coverage data; the record has")
    elif nc and not rc:
        fail.append("the record has no coverage figures; this run has (record them with CARACARA_KERNEL_DOC=write)")
    elif rc and nc:
        rf = {f["file"]: f for f in rc["files"]}
        nf = {f["file"]: f for f in nc["files"]}
        for name in sorted(set(rf) | set(nf)):
            a, b = rf.get(name), nf.get(name)
            if a is None or b is None:
                fail.append("%s: %s" % (name, "not in the record" if a is None else "not measured by this run"))
            elif a.get("other") or b.get("other"):
                if bool(a.get("other")) != bool(b.get("other")):
                    fail.append("%s: recorded as %s, this run has it as %s" % (
                        name, "the other backend's" if a.get("other") else "this backend's",
                        "the other backend's" if b.get("other") else "this backend's"))
            elif "percent" not in b:
                fail.append("%s: no coverage data in this run (%s)" % (name, b.get("missing")))
            elif "percent" not in a:
                fail.append("%s: the record has no coverage figure for it" % name)
            else:
                diff = b["percent"] - a["percent"]
                if abs(diff) > COVERAGE_TOLERANCE_PP + 1e-9:
                    fail.append("%s: line coverage %.1f %%, recorded %.1f %%: %+.1f points, outside ±%g" % (
                        name, b["percent"], a["percent"], diff, COVERAGE_TOLERANCE_PP))
                elif abs(diff) >= 0.05:
                    note.append("%s: line coverage %.1f %% (recorded %.1f %%, within ±%g points)" % (
                        name, b["percent"], a["percent"], COVERAGE_TOLERANCE_PP))
                if a["lines"] != b["lines"]:
                    note.append("%s: %d lines instrumented (recorded %d)" % (name, b["lines"], a["lines"]))
        gone = [x for x in nc["never"] if x not in rc["never"]]
        if gone:
            note.append("functions never executed in this run that the record has executed: %s" % (
                "; ".join("%s %s" % (f, fn) for f, fn, _ in gone)))
    return fail, note


def main(argv):
    check = argv[:1] == ["--check"]
    if check:
        argv = argv[1:]
    doc, label, tsv, results_path, cov_path, kver = argv[:6]
    run = run_data(label, tsv, results_path, cov_path, kver)
    with open(doc) as f:
        text = f.read()
    if check:
        fail, note = judge(parse(text, label), run)
        for n in note:
            print("kernel doc: note: %s" % n)
        for x in fail:
            print("kernel doc: FAIL: %s" % x)
        if not fail:
            print("kernel doc: the run holds against docs/kernel-bridge.md's %s section (kernel %s; every scenario "
                  "passed, the recorded scenarios, coverage within ±%g points)" % (label, kver, COVERAGE_TOLERANCE_PP))
        return 1 if fail else 0
    section = render(run)
    pat = section_pattern(label)
    if pat.search(text):
        text = pat.sub(lambda _: section, text)
    else:
        text = text.rstrip("\n") + "\n\n" + section + "\n"
    with open(doc, "w") as f:
        f.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
