"""Plots one dive for `caracaractl plot` (docs/dive-format.md).

caracaractl decodes the dive file (the one decoder, fuzzed) and hands this script the samples
and events as CSV (the same text `caracaractl export` prints). Four panels share the time
axis: the motor values (applied, solid; requested, dotted, where they differ) with the
current budget's limit, the thrusters' currents, their temperatures, and the Teensy's
orientation. Kills, faults and bus losses and recoveries are vertical lines on every panel,
labelled on the top one. PNG and SVG come from matplotlib; HTML is the SVG in a page.
"""

import argparse
import csv
import io
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

THRUSTERS = 8
MARKS = {  # event kind -> colour, line style
    "kill": ("#d62728", "-"),
    "fault": ("#ff7f0e", "--"),
    "fault-cleared": ("#2ca02c", ":"),
    "bus-lost": ("#9467bd", "-"),
    "bus-restored": ("#17becf", "-."),
    "power-off": ("#000000", "-"),
    "end": ("#7f7f7f", ":"),
}


def number(text):
    return float(text) if text != "" else math.nan


def read_samples(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise ValueError("no samples")
    cols = {}
    for key in rows[0]:
        if key == "distances_mm":
            continue
        cols[key] = [number(r[key]) for r in rows]
    return cols


def read_marks(path):
    """(time, kind, label) of what is marked."""
    marks = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            t, kind, detail = float(r["t_s"]), r["kind"], r["detail"]
            if kind == "state" and detail.startswith("killed"):
                src = detail.split("source=", 1)[1].split(" ", 1)[0] if "source=" in detail else "?"
                marks.append((t, "kill", "kill (%s)" % src))
            elif kind == "state" and detail.startswith("powered-off"):
                marks.append((t, "power-off", "power-off"))
            elif kind == "fault":
                parts = dict(p.split("=", 1) for p in detail.split(" ") if "=" in p)
                if parts.get("faults", "none") == "none":
                    marks.append((t, "fault-cleared", "T%s ok" % parts.get("thruster", "?")))
                else:
                    marks.append((t, "fault", "T%s %s" % (parts.get("thruster", "?"), parts["faults"])))
            elif kind in ("bus-lost", "bus-restored"):
                marks.append((t, kind, kind))
            elif kind == "end":
                marks.append((t, "end", "end"))
    return marks


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", required=True)
    ap.add_argument("--events", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--title", default="dive")
    a = ap.parse_args()

    s = read_samples(a.samples)
    marks = read_marks(a.events)
    t = s["t_s"]
    colours = plt.get_cmap("tab10").colors

    fig, axes = plt.subplots(4, 1, sharex=True, figsize=(12, 10), constrained_layout=True)
    fig.suptitle(a.title, fontsize=11)
    ax_m, ax_c, ax_t, ax_o = axes
    for i in range(THRUSTERS):
        c = colours[i % len(colours)]
        ax_m.plot(t, s["app_%d" % i], color=c, lw=1.2, label="T%d" % i)
        if s["req_%d" % i] != s["app_%d" % i]:
            ax_m.plot(t, s["req_%d" % i], color=c, lw=0.8, ls=":")
        ax_c.plot(t, s["current_a_%d" % i], color=c, lw=1.0)
        ax_t.plot(t, s["temp_c_%d" % i], color=c, lw=1.0)
    limit = s["budget_limit"]
    ax_m.plot(t, limit, color="k", lw=0.8, ls="--", label="budget")
    ax_m.plot(t, [-v for v in limit], color="k", lw=0.8, ls="--")
    ax_m.set_ylabel("motor value\n(applied; dotted: requested)")
    ax_m.legend(ncol=9, fontsize=7, loc="upper right")
    ax_c.set_ylabel("current (A)")
    ax_t.set_ylabel("temperature (°C)")
    for k, name in enumerate(("yaw", "pitch", "roll")):
        ax_o.plot(t, s[name], color=colours[k], lw=1.0, label=name)
    ax_o.set_ylabel("orientation (rad)")
    ax_o.legend(fontsize=7, loc="upper right")
    ax_o.set_xlabel("time since arming (s)")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        for when, kind, _ in marks:
            colour, style = MARKS[kind]
            ax.axvline(when, color=colour, ls=style, lw=1.0, alpha=0.8)
    for when, kind, label in marks:
        ax_m.annotate(label, (when, 0.98), xycoords=("data", "axes fraction"), xytext=(2, 0),
                      textcoords="offset points", rotation=90,
                      va="top", ha="left", fontsize=7, color=MARKS[kind][0])

    out = a.out
    if out.endswith(".html"):
        buf = io.StringIO()
        fig.savefig(buf, format="svg")
        with open(out, "w") as f:
            f.write("<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>%s</title></head><body>\n"
                    % a.title.replace("<", "&lt;"))
            svg = buf.getvalue()
            f.write(svg[svg.find("<svg"):])
            f.write("\n</body></html>\n")
    else:
        fig.savefig(out, dpi=100)
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except (OSError, ValueError, KeyError) as e:
        print("plot_dive.py: %s" % e, file=sys.stderr)
        sys.exit(1)
