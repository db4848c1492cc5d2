#!/usr/bin/python3
"""Summarises bench/halide_schedule_sweep.sh's JSON: per schedule and benchmark row, the median ms
over the rounds, and each schedule's median over rows relative to the first schedule given."""
import json
import statistics
import sys
from collections import defaultdict
from pathlib import Path

out = Path(sys.argv[1])
times = defaultdict(lambda: defaultdict(list))  # schedule index -> row -> [ms]
names = dict(enumerate((out / "schedules.txt").read_text().splitlines()))
for p in sorted(out.glob("s*-r*.json")):
    index = int(p.name[1:p.name.index("-")])
    data = json.loads(p.read_text())
    for b in data["benchmarks"]:
        unit = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b["time_unit"]]
        row = b["name"].split("/min_time")[0].replace("BM_Halide/", "")
        times[index][row].append(b["real_time"] * unit)
rows = sorted({r for s in times.values() for r in s})
print("| schedule | " + " | ".join(rows) + " | vs first |")
print("|---|" + "---|" * (len(rows) + 1))
base = {r: statistics.median(times[0][r]) for r in rows if times[0].get(r)}
for index in sorted(times):
    med = {r: statistics.median(times[index][r]) for r in rows if times[index].get(r)}
    rel = statistics.median([med[r] / base[r] for r in med if r in base]) if base else float("nan")
    print(f"| `{names[index] or 'default'}` | " + " | ".join(f"{med[r]:.3f}" if r in med else "-" for r in rows) +
          f" | {rel:.3f} |")
