#!/usr/bin/python3
"""From one fogcl_bench JSON (repetitions, random interleaving): per case (frame, mode, metric,
storage) the median ms of the Halide peer, the OpenCL kernel (default stores; ordinary; streaming)
and the host call, the copy ceiling (median over the rows' interleaved ceilings) and its way, and
the ratios Halide / fogcl (>= 1: fogcl at or ahead) and ceiling / path (vs copy). Writes CSV to
stdout and a Markdown table to argv[2]."""
import csv, json, statistics, sys
from collections import defaultdict
d = json.load(open(sys.argv[1]))
runs = defaultdict(list)
for b in d["benchmarks"]:
    if b.get("run_type") == "aggregate" or b.get("error_occurred"):
        continue
    runs[b["run_name"].split("/min_time")[0]].append(b)
def med(name, key="real_time"):
    v = [b[key] for b in runs.get(name, []) if key in b]
    return statistics.median(v) if v else None
MODES = {"0": "linear", "1": "exp", "2": "exp2", "3": "height valley", "4": "height haze"}
WAYS = {0: "memcpy", 1: "loop", 2: "stream", 3: "Halide"}
cases = sorted({tuple(a.split(":")[1] for a in n.split("/")[1:6]) for n in runs if n.startswith("BM_OpenCLHostCall/")},
               key=lambda c: (int(c[0]) * int(c[1]), int(c[2]), c[3], c[4]))
w = csv.writer(sys.stdout)
hdr = ["frame", "mode", "metric", "storage", "halide_ms", "device_ms", "device_plain_ms", "device_nt_ms", "hostcall_ms",
       "halide_over_device", "halide_over_hostcall", "ceiling_ms", "ceiling_way", "device_vs_copy", "hostcall_vs_copy",
       "halide_vs_copy", "n_reps"]
w.writerow(hdr)
md = ["| frame | fog | storage | Halide ms | kernel ms (default) | ordinary | streaming | host call ms | Halide / kernel | Halide / call | ceiling ms (way) | kernel vs copy | call vs copy | Halide vs copy |",
      "|---|---|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|"]
for c in cases:
    base = f"w:{c[0]}/h:{c[1]}/mode:{c[2]}/dist:{c[3]}/f16:{c[4]}"
    hal, dev = med("BM_Halide/" + base), med(f"BM_OpenCLDevice/{base}/nt:2")
    plain, nt = med(f"BM_OpenCLDevice/{base}/nt:0"), med(f"BM_OpenCLDevice/{base}/nt:1")
    call = med("BM_OpenCLHostCall/" + base)
    ceils = [b["ceiling_ms"] for n in ("BM_Halide/" + base, f"BM_OpenCLDevice/{base}/nt:2", "BM_OpenCLHostCall/" + base)
             for b in runs.get(n, []) if "ceiling_ms" in b]
    ways = [int(b["ceiling_way"]) for n in ("BM_Halide/" + base, f"BM_OpenCLDevice/{base}/nt:2", "BM_OpenCLHostCall/" + base)
            for b in runs.get(n, []) if "ceiling_way" in b]
    ceil = statistics.median(ceils) if ceils else None
    way = WAYS.get(max(set(ways), key=ways.count)) if ways else "-"
    r = lambda a, b: a / b if a and b else None
    row = [f"{c[0]}x{c[1]}", MODES[c[2]], "distance" if c[3] == "1" else "depth", "f16" if c[4] == "1" else "f32",
           hal, dev, plain, nt, call, r(hal, dev), r(hal, call), ceil, way, r(ceil, dev), r(ceil, call), r(ceil, hal),
           len(runs.get("BM_OpenCLHostCall/" + base, []))]
    w.writerow([f"{x:.4f}" if isinstance(x, float) else x for x in row])
    f = lambda x, p=2: f"{x:.{p}f}" if x else "-"
    md.append(f"| {row[0]} | {row[1]} {row[2]} | {row[3]} | {f(hal)} | {f(dev)} | {f(plain)} | {f(nt)} | {f(call)} | "
              f"{f(row[9])} | {f(row[10])} | {f(ceil)} ({way}) | {f(row[13])} | {f(row[14])} | {f(row[15])} |")
# The copy ways per frame.
md += ["", "| copy of the pass's bytes | threads | memcpy ms | loop ms | stream ms | Halide ms | pass bytes / LLC |",
       "|---|--:|--:|--:|--:|--:|--:|"]
for size in ("512/h:256", "1280/h:720", "1920/h:1080", "3840/h:2160"):
    for t in ("1", "2"):
        names = [f"{k}/w:{size}/threads:{t}" for k in ("BM_Memcpy", "BM_CopyLoop", "BM_CopyStream", "BM_CopyHalide")]
        if not any(n in runs for n in names):
            continue
        llc = next((b.get("frame_vs_llc") for n in names for b in runs.get(n, [])), None)
        md.append(f"| {size.replace('/h:', 'x')} | {t} | " + " | ".join(f(med(n), 3) for n in names) + f" | {f(llc, 3)} |")
open(sys.argv[2], "w").write("\n".join(md) + "\n")
