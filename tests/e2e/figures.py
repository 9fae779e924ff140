"""A figure a test measured, printed so that the run keeps it: scripts/doc_figures.py collects
every `FIGURE:` line of the normal step's passed tests into a record
(bench/figures.json, after scripts/test.sh's normal step) and writes the figures README.md
and docs/ quote from that record (CTest doc_figures fails when a quoted figure and its record
differ). The same key printed more than once (several runs, several cases) is kept as a list; a
document quotes its range, maximum or median.

    figure("pilot_lost.kill_after_ms", 1031.4, "ms", "last pilot left -> kill output edge")

Shell tests print the same line (tests/system/helpers.sh `figure`).
"""
import re

KEY = re.compile(r"^[a-z0-9_]+(\.[a-z0-9_]+)*$")
UNITS = ("ms", "us", "s", "KiB", "MiB", "%", "count")


def figure(key, value, unit, what):
    """Prints `FIGURE: KEY VALUE UNIT  # WHAT` (one line; the key and unit checked here, so that a
    misspelt one fails the test that prints it, not the record's reader)."""
    if not KEY.match(key):
        raise ValueError(f"figure key {key!r}: lowercase words joined by dots")
    if unit not in UNITS:
        raise ValueError(f"figure {key}: unit {unit!r} is none of {UNITS}")
    print(f"\nFIGURE: {key} {float(value):.6g} {unit}  # {what}", flush=True)
