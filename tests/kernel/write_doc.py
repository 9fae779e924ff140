"""Writes one kernel test run's scenario list and coverage table into a copy of docs/kernel-bridge.md.

    python3 write_doc.py DOC LABEL SCENARIOS_TSV RESULTS COVERAGE_JSON KERNEL_VERSION

tests/kernel/run.sh calls it at the end of each run on a copy in its work directory (the build
tree), then checks the tracked docs/kernel-bridge.md against that copy (CARACARA_KERNEL_DOC=write
records it instead): LABEL is debian12 (the host's root, libgpiod 1) or debian13
(tests/system/debian13.sh, libgpiod 2, Debian 13's kernel). The section between
"<!-- kernel-run LABEL begin -->" and "<!-- kernel-run LABEL end -->" is replaced (appended at
the end of the document the first time); nothing else in DOC is touched. The section has no
date: it changes when the run's kernel, a scenario, a result or the coverage does, so that a
run with none of those changed leaves it as it is.
"""
import json
import os
import re
import sys


def main():
    doc, label, tsv, results_path, cov_path, kver = sys.argv[1:7]
    scenarios = []
    with open(tsv) as f:
        for line in f:
            if line.strip():
                name, _, what = line.rstrip("\n").partition("\t")
                scenarios.append((name, what))
    results = {}
    with open(results_path) as f:
        for line in f:
            m = re.match(r"(PASS|FAIL) (\S+?)(?::| \()", line)
            if m:
                results[m.group(2)] = line.strip()
    cov = None
    if os.path.exists(cov_path):
        with open(cov_path) as f:
            cov = json.load(f)
    passed = sum(1 for n, _ in scenarios if results.get(n, "").startswith("PASS"))
    root = {"debian12": "Debian 12 root, libgpiod 1", "debian13": "Debian 13 root, libgpiod 2"}.get(label, label)
    out = ["<!-- kernel-run %s begin -->" % label,
           "### Run: %s (kernel %s)" % (root, kver),
           "",
           "Written by `tests/kernel/run.sh` (`tests/kernel/write_doc.py`) from a run; not edited by hand "
           "(`CARACARA_KERNEL_DOC=write` records a run's section, every other run checks it).",
           "",
           "**%d of %d scenarios passed.**" % (passed, len(scenarios)),
           "",
           "| scenario | result | what it proves |",
           "| --- | --- | --- |"]
    for name, what in scenarios:
        # Without the seconds: the section changes when a result does, not at every run.
        r = results.get(name, "no result")
        shown = "pass" if r.startswith("PASS") else r.replace("|", "/")
        out.append("| `%s` | %s | %s |" % (name, shown, what.replace("|", "/")))
    out.append("")
    if cov:
        t = cov["total"]
        out += ["Line coverage of the kernel-facing files in this run (%s build): **%.1f %% of %d lines**."
                % (cov["backend"], t["percent"], t["lines"]),
                "",
                "| file | lines executed |",
                "| --- | --- |"]
        never = []
        for f in cov["files"]:
            if f["status"] == "other backend":
                cell = "the other backend: measured by the other run"
            elif "percent" in f:
                cell = "%.1f %% of %d" % (f["percent"], f["lines"]) + ("" if f["status"] == "ran" else " (never ran)")
                never += [(f["file"], n) for n in f["never"]]
            else:
                cell = "**no coverage data** (%s)" % f["status"]
            out.append("| `%s` | %s |" % (f["file"], cell))
        out += ["", "Functions never executed on the kernel in this run: %d." % len(never)]
        if never:
            out.append("")
            for file, n in never:
                out.append("- `%s`: `%s`%s" % (file, n["function"], (" — " + n["why"]) if n["why"] else ""))
        out.append("")
    else:
        out += ["No coverage data from this run.", ""]
    out.append("<!-- kernel-run %s end -->" % label)
    section = "\n".join(out)
    with open(doc) as f:
        text = f.read()
    pat = re.compile(r"<!-- kernel-run %s begin -->.*?<!-- kernel-run %s end -->" % (re.escape(label), re.escape(label)),
                     re.S)
    if pat.search(text):
        text = pat.sub(lambda _: section, text)
    else:
        text = text.rstrip("\n") + "\n\n" + section + "\n"
    with open(doc, "w") as f:
        f.write(text)


if __name__ == "__main__":
    main()
