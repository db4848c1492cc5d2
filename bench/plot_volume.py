#!/usr/bin/env python3
"""Draws how the volumetric pass's cost grows with its work, from a fogcl_volume_bench JSON:
   bench/plot_volume.py VOLUME.json [MORE.json ...] OUT.png   (a later file's rows replace an earlier's)
Left: device time against the march's work (steps x volumes entered, summed over target pixels)
for the BM_VolumeScaling sweeps (step count, resolution, number of volumes); a cost that grows as
the work does lies on one line through the origin. Right: the march's steps x pixels per second
of the OpenCL pass, the OpenMP-SIMD C++ peer and the scalar path (1080p, half resolution)."""
import json
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def rows(path):
    with open(path) as f:
        data = json.load(f)
    out = []
    for b in data["benchmarks"]:
        if b.get("run_type") == "aggregate" and b.get("aggregate_name") != "median":
            continue
        b["args"] = dict((k, int(v)) for k, v in re.findall(r"(\w+):(\d+)", b.get("run_name", b["name"])))
        out.append(b)
    return out, data.get("context", {})


def ms(b):
    return b["real_time"] * {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b["time_unit"]]


def main():
    dst = sys.argv[-1]
    by_name, ctx = {}, {}
    for src in sys.argv[1:-1]:
        found, ctx = rows(src)
        by_name.update((b["name"].replace("/real_time", ""), b) for b in found)
    bench = list(by_name.values())
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.8))

    scaling = [b for b in bench if b["name"].startswith("BM_VolumeScaling/")]
    sweeps = {
        "steps 8-256 (half, 4 volumes)": lambda a: a["divisor"] == 2 and a["volumes"] == 4,
        "full / half / quarter (64 steps, 4 volumes)": lambda a: a["steps"] == 64 and a["volumes"] == 4,
        "1-16 volumes (64 steps, half)": lambda a: a["steps"] == 64 and a["divisor"] == 2,
    }
    for (label, keep), marker in zip(sweeps.items(), "osD"):
        pts = sorted((b["work"], ms(b), b["args"]) for b in scaling if keep(b["args"]))
        if not pts:
            continue
        left.plot([p[0] for p in pts], [p[1] for p in pts], marker=marker, linestyle="-", label=label, alpha=0.8)
    if scaling:
        per = sorted(b["ns_per_work"] for b in scaling)
        median = per[len(per) // 2]
        top = max(b["work"] for b in scaling)
        left.plot([0, top], [0, top * median * 1e-6], "k:", label=f"{median:.0f} ns per unit of work (median)")
    left.set_xlabel("work: steps x volumes entered, summed over target pixels")
    left.set_ylabel("device time [ms]")
    left.set_title("480x270, stylized, noise buffer: cost against work")
    left.legend(fontsize=8)
    left.grid(alpha=0.3)

    names, rates, colors = [], [], []
    palette = {"OpenCL (PoCL)": "tab:blue", "OpenMP-SIMD peer": "tab:orange", "scalar, 1 thread": "tab:gray"}
    for integ, label in ((0, "stylized"), (1, "physical")):
        for prefix, path in (("BM_VolumeDevice/", "OpenCL (PoCL)"), ("BM_VolumeOpenMP/", "OpenMP-SIMD peer"),
                             ("BM_VolumeScalar/", "scalar, 1 thread")):
            for b in bench:
                a = b["args"]
                if (b["name"].startswith(prefix) and a.get("integrator") == integ and a.get("width") == 1920
                        and a.get("divisor", 2) == 2 and a.get("noise_image", 0) == 0):
                    names.append(f"{label}\n{path}")
                    rates.append(b["steps_x_pixels_per_s"] / 1e6)
                    colors.append(palette[path])
    right.barh(names[::-1], rates[::-1], color=colors[::-1])
    for y, r in enumerate(rates[::-1]):
        right.text(r, y, f" {r:.1f}", va="center", fontsize=8)
    right.set_xlabel("march: million steps x target pixels per second")
    right.set_title("1920x1080, half resolution, 64 steps, 4 volumes")
    right.grid(alpha=0.3, axis="x")
    fig.suptitle(f"fogcl volumetric pass, {ctx.get('num_cpus', '?')} CPUs, {ctx.get('date', '')}", fontsize=9)
    fig.tight_layout()
    fig.savefig(dst, dpi=110)


if __name__ == "__main__":
    main()
