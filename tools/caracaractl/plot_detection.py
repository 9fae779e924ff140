"""Plots one direction detection run of a dive for `caracaractl plot DIVE --detection`
(docs/commissioning.md).

caracaractl decodes the dive (the one decoder) and hands this script its samples and events as
CSV, as `caracaractl export` prints them, and the dive's start on CLOCK_MONOTONIC. One panel per
thruster, around its pulse: the pulse as the dive recorded it (shaded), the pulse on the wire when
a wire log is given (the orders the simulator received, --wire), and the vehicle's attitude
change from the settled attitude before the pulse (yaw, pitch, roll from the Teensy, as the
detection measured it), with the verdict, its margin and the measured change in the title.

--wire takes CSV with the header `time_ns,thruster,speed`: every order a thruster received
(CLOCK_MONOTONIC ns, the thruster's number, the SEABOTIX SPEED byte; 0x80 is zero), as the
simulator's wire log holds them. Prints the thrusters pulsed (in the dive, and on the wire) and
each verdict, one line each, for whoever checks the plot against the run.
"""

import argparse
import csv
import io
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from PIL import Image  # noqa: E402  (python3-pil: python3-matplotlib depends on it)

THRUSTERS = 8
ZERO_SPEED = 0x80
BEFORE_S = 1.0  # the settled window before a pulse (the detection's detect_settle_ms default)
AFTER_S = 0.8   # shown after the pulse: the vehicle coasting on
VERDICT_COLOUR = {"ok": "#2ca02c", "reversed": "#d62728", "inconclusive": "#7f7f7f"}
AXES = (("yaw", "#1f77b4"), ("pitch", "#ff7f0e"), ("roll", "#9467bd"))


def fields(detail):
    return dict(p.split("=", 1) for p in detail.split(" ") if "=" in p)


def read_run(events_path, which):
    """The detection run `which` (-1: the last) of the dive: its start and end times, and per thruster
    its pulse (on, off) and result fields."""
    runs = []
    with open(events_path, newline="") as f:
        for r in csv.DictReader(f):
            t, kind, detail = float(r["t_s"]), r["kind"], r["detail"]
            if kind == "detection" and detail == "started":
                runs.append({"start": t, "end": None, "pulses": {}, "results": {}})
            elif not runs or runs[-1]["end"] is not None:
                continue
            elif kind == "detection":
                runs[-1]["end"] = t
            elif kind == "detection-pulse":
                f_ = fields(detail)
                k = int(f_["thruster"])
                pulses = runs[-1]["pulses"]
                if "value" in f_:
                    pulses[k] = [t, None, float(f_["value"])]
                elif k in pulses:
                    pulses[k][1] = t
            elif kind == "detection-result":
                f_ = fields(detail)
                runs[-1]["results"][int(f_["thruster"])] = f_
    if not runs:
        raise ValueError("the dive holds no direction detection run")
    try:
        return runs[which]
    except IndexError:
        raise ValueError("the dive holds %d detection run%s, not run %d" % (len(runs), "" if len(runs) == 1 else "s",
                                                                          which)) from None


def read_samples(path):
    t, att = [], {name: [] for name, _ in AXES}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            t.append(float(r["t_s"]))
            for name, _ in AXES:
                att[name].append(float(r[name]))
    return t, att


def read_wire(path, start_mono_ns):
    """Per thruster, (dive time s, speed byte) of every order it received."""
    orders = {k: [] for k in range(THRUSTERS)}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            k = int(r["thruster"])
            if 0 <= k < THRUSTERS:
                orders[k].append(((int(r["time_ns"]) - start_mono_ns) / 1e9, int(r["speed"])))
    return orders


def wire_pulse(orders, start, end):
    """The first and last non-zero order inside [start, end], or None."""
    on = [t for t, s in orders if start <= t <= end and s != ZERO_SPEED]
    return (on[0], on[-1]) if on else None


def unwrap_from(values, ref):
    """Angles as offsets from `ref`, wrapped to (-pi, pi] (a heading near +-pi stays continuous)."""
    return [math.remainder(v - ref, 2 * math.pi) for v in values]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", required=True)
    ap.add_argument("--events", required=True)
    ap.add_argument("--start-mono-ns", type=int, required=True)
    ap.add_argument("--wire")
    ap.add_argument("--run", type=int, default=-1, help="which detection run of the dive (0 the first; -1 the last)")
    ap.add_argument("--out", required=True)
    ap.add_argument("--title", default="direction detection")
    a = ap.parse_args()

    run = read_run(a.events, a.run)
    if not run["pulses"]:
        raise ValueError("the detection run holds no pulse")
    t, att = read_samples(a.samples)
    wire = read_wire(a.wire, a.start_mono_ns) if a.wire else None
    run_end = run["end"] if run["end"] is not None else t[-1]

    fig, axes = plt.subplots(4, 2, sharey=True, figsize=(10, 9.5), constrained_layout=True)
    fig.suptitle(a.title, fontsize=10)
    on_wire = []
    for k in range(THRUSTERS):
        ax = axes[k // 2][k % 2]
        ax.grid(True, alpha=0.3)
        ax.axhline(0, color="k", lw=0.5)
        if k not in run["pulses"]:
            ax.set_title("T%d: not pulsed" % k, fontsize=9)
            continue
        on, off, value = run["pulses"][k]
        off = off if off is not None else run_end
        lo, hi = on - BEFORE_S, off + AFTER_S
        idx = [i for i, x in enumerate(t) if lo <= x <= hi]
        before = [i for i in idx if t[i] < on]
        x = [t[i] - on for i in idx]
        for name, colour in AXES:
            v = [att[name][i] for i in idx]
            ref = v[0] if v else 0.0
            rel = unwrap_from(v, ref)
            base = sum(rel[: len(before)]) / len(before) if before else 0.0
            ax.plot(x, [1000 * (r - base) for r in rel], color=colour, lw=1.0, label=name)
        ax.axvspan(0, off - on, color="#bbbbbb", alpha=0.35, lw=0, label="pulse (dive)")
        if wire is not None:
            p = wire_pulse(wire[k], lo, hi)
            if p:
                on_wire.append(k)
                # A bar along the panel's foot: the first to the last non-zero order.
                ax.plot([p[0] - on, p[1] - on], [0.04, 0.04], transform=ax.get_xaxis_transform(), color="k", lw=4,
                        solid_capstyle="butt", label="pulse on the wire")
        r = run["results"].get(k)
        verdict = r["verdict"] if r else "not judged"
        title = "T%d pulsed at %.0f: %s" % (k, value, verdict)
        if r:
            title += " (margin %s)\nyaw %s  pitch %s  roll %s rad" % (r["margin"], r["yaw"], r["pitch"], r["roll"])
        ax.set_title(title, fontsize=8, color=VERDICT_COLOUR.get(verdict, "k"))
    for ax in axes[-1]:
        ax.set_xlabel("time from the pulse's start (s)")
    for row in axes:
        row[0].set_ylabel("attitude change (mrad)")
    axes[0][0].legend(fontsize=7, loc="upper left", ncol=2)

    pulsed = sorted(run["pulses"])
    print("pulses in the dive: %s" % " ".join(str(k) for k in pulsed))
    if wire is not None:
        print("pulses on the wire: %s" % " ".join(str(k) for k in on_wire))
    print("verdicts: %s" % ", ".join("%d %s" % (k, run["results"][k]["verdict"]) for k in sorted(run["results"])))

    if a.out.endswith(".png"):
        # A line plot needs few colours: a palette PNG is a third of the size (the image in the docs).
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=80)
        Image.open(buf).convert("RGB").quantize(colors=64).save(a.out, optimize=True)
    else:
        fig.savefig(a.out)


if __name__ == "__main__":
    try:
        main()
    except (OSError, ValueError, KeyError) as e:
        sys.exit("plot_detection.py: %s" % e)  # status 1, the problem on stderr
