#!/usr/bin/python3
"""Reads bench/sequence_bench.py's runs.json files (one or more folders or files) and writes
sequence_scaling.png (frames/s against threads: fogcl solid, the OpenEXR-only peer dashed) and
sequence_table.md (one row per case and thread count) next to the first argument.
  bench/plot_sequence.py bench/results/device-16core/*.json"""
import json
import statistics
import sys
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

files = [Path(a) for a in sys.argv[1:]]
runs, metas = [], []
for f in files:
    d = json.loads(f.read_text())
    runs += d["runs"]
    metas.append(d["meta"])
seconds = defaultdict(list)
frames = {}
for r in runs:
    seconds[(r["case"], r["tool"], r["threads"])].append(r["seconds"])
    frames[r["case"]] = r["frames"]
fps = {k: frames[k[0]] / statistics.median(v) for k, v in seconds.items()}
cases = list(dict.fromkeys(r["case"] for r in runs))

fig, axes = plt.subplots(1, 2, figsize=(13, 5.5))
colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
for ax, prefix in zip(axes, ["1080p", "4k"]):
    for i, c in enumerate(x for x in cases if x.startswith(prefix)):
        for tool, style in (("fogcl", "-o"), ("peer", "--x")):
            pts = sorted((t, v) for (cc, tt, t), v in fps.items() if cc == c and tt == tool)
            if pts:
                ax.plot([p[0] for p in pts], [p[1] for p in pts], style, color=colors[i % len(colors)],
                        label=f"{c} {'fogcl apply' if tool == 'fogcl' else 'OpenEXR alone'}")
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_xticks([1, 2, 4, 8, 16])
    ax.set_xticklabels(["1", "2", "4", "8", "16"])
    ax.set_xlabel("threads (--threads N, pinned to N cores)")
    ax.set_ylabel("frames/s")
    ax.set_title(f"{'1080p, 24 frames' if prefix == '1080p' else '4K, 12 frames'}")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
m = metas[0]
fig.suptitle(f"fogcl apply on sequences vs OpenEXR alone: {m['cores']} cores, fog on {m['device']}, {m['time']}")
fig.tight_layout()
out = files[0].parent
fig.savefig(out / "sequence_scaling.png", dpi=110)

lines = ["| case | threads | OpenEXR alone (frames/s) | fogcl apply (frames/s) | ratio | before (frames/s) | fogcl / before |",
         "|---|---:|---:|---:|---:|---:|---:|"]
for c in cases:
    for t in sorted({k[2] for k in fps if k[0] == c}):
        p, f, b = fps.get((c, "peer", t)), fps.get((c, "fogcl", t)), fps.get((c, "before", t))
        if p is None or f is None:
            continue
        lines.append(f"| {c} | {t} | {p:.2f} | {f:.2f} | {f / p:.2f} | {f'{b:.2f}' if b else ''} | "
                     f"{f'{f / b:.2f}x' if b else ''} |")
(out / "sequence_table.md").write_text("\n".join(lines) + "\n")
print("\n".join(lines))
