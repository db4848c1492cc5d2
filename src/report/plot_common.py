# What both report plots share (plot_report.py, plot_volume_report.py): run_plot_script
# (report_common.cpp) sends this text first, then the plot's own, to `python3 - DIR` on stdin.
# Exit code 3: matplotlib is missing.
import csv
import math
import os
import sys

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    sys.stderr.write("matplotlib is missing\n")
    sys.exit(3)

folder = sys.argv[1]


def read_rows(name):
    """The rows of FOLDER/name and its scenes in their first order."""
    with open(os.path.join(folder, name), newline="") as f:
        rows = list(csv.DictReader(f))
    scenes = []
    for r in rows:
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
    return rows, scenes


def clipped_error(value, floor):
    """An error for a log axis: None for NaN/Inf, else at least floor (zero errors drawn there)."""
    v = float(value)
    if math.isnan(v) or math.isinf(v):
        return None
    return max(v, floor)


def pareto_front(points):
    """The (time, error) points nothing else beats in both: faster and more accurate."""
    front, best = [], float("inf")
    for t, e in sorted(points):
        if e < best:
            front.append((t, e))
            best = e
    return front


def save_png(fig, name, dpi):
    """FOLDER/name, written whole (a temporary, then renamed)."""
    tmp = os.path.join(folder, "." + name + ".tmp")
    fig.savefig(tmp, dpi=dpi, format="png")
    os.replace(tmp, os.path.join(folder, name))

