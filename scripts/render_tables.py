#!/usr/bin/env python3
"""Renders the result tables of README.md and docs/*.md from the files under bench/results/.

Each generated table sits between two markers in the Markdown:

    <!-- table:NAME -->
    ...generated, do not edit...
    <!-- /table:NAME -->

and NAME is one of the renderers below. `render_tables.py` rewrites every such block in place;
`render_tables.py --check` changes nothing and exits 1 (printing a diff) when a committed block
differs from what the results render, when a marker names no renderer, or when a renderer's
table appears nowhere. Python 3 standard library only.

Every table says where its figures come from (machine, date, result file); a figure that is not
in a result file is not in a generated table.
"""
import argparse
import csv
import difflib
import json
import re
import statistics
import sys
from pathlib import Path

RESULTS = "bench/results"
MARKER = re.compile(r"<!-- table:([a-z0-9-]+) -->\n(.*?)<!-- /table:\1 -->", re.S)
OPEN_MARKER = re.compile(r"<!-- table:([a-z0-9-]+) -->")

# The machines, as the tables name them.
TWO_CORE_EPYC = "2-core EPYC VM, PoCL 3.1, 2 threads"
H100 = "NVIDIA H100, driver 580.159.04"
XEON16 = "16-core Xeon VM, PoCL 5.0"


# ---------------------------------------------------------------------------------------------
# Reading results


class Bench:
    """A Google Benchmark JSON file: the median of each run (aggregates, or the repetitions)."""

    def __init__(self, root, rel):
        self.rel = rel
        data = json.loads((root / RESULTS / rel).read_text())
        self.date = data["context"]["date"][:10]
        runs = {}
        for b in data["benchmarks"]:
            name = b.get("run_name", b["name"])
            if b.get("run_type") == "aggregate":
                if b.get("aggregate_name") == "median":
                    runs[name] = ("median", b)
            elif runs.get(name, ("", None))[0] != "median":
                runs.setdefault(name, ("reps", []))[1].append(b)
        self.rows = []
        for name, (kind, b) in runs.items():
            if kind == "reps":  # no aggregate: the median of the repetitions, key by key
                keys = [k for k, v in b[0].items() if isinstance(v, (int, float)) and not isinstance(v, bool)]
                b = {k: statistics.median(x[k] for x in b if k in x) for k in keys}
            parts = name.split("/")
            params = dict(p.split(":", 1) for p in parts[1:] if ":" in p)
            self.rows.append((parts[0], params, b))

    def get(self, family, **params):
        want = {k: str(v) for k, v in params.items()}
        found = [b for f, p, b in self.rows if f == family and all(p.get(k) == v for k, v in want.items())]
        if len(found) != 1:
            raise KeyError(f"{self.rel}: {family} {want}: {len(found)} matches")
        return found[0]


def sequence_fps(root, rel):
    """bench/sequence_bench.py's runs.json: frames/s per (case, tool, threads), as plot_sequence.py."""
    data = json.loads((root / RESULTS / rel).read_text())
    seconds, frames = {}, {}
    for r in data["runs"]:
        seconds.setdefault((r["case"], r["tool"], r["threads"]), []).append(r["seconds"])
        frames[r["case"]] = r["frames"]
    fps = {k: frames[k[0]] / statistics.median(v) for k, v in seconds.items()}
    count = {k: len(v) for k, v in seconds.items()}
    return data["meta"], fps, count


def volume_report(root):
    with open(root / RESULTS / "volume-report-2core/volume-report.csv", newline="") as f:
        return list(csv.DictReader(f))


# ---------------------------------------------------------------------------------------------
# Formatting


def g3(x):
    """Errors: three significant digits, as fogcl report prints them."""
    return f"{float(x):.3g}"


def ms(x, digits=2):
    return f"{x:.{digits}f}"


def ratio(x):
    return f"{x:.2f}"


def rng(values, fmt):
    lo, hi = fmt(min(values)), fmt(max(values))
    return lo if lo == hi else f"{lo}-{hi}"


def table(header, rows, align):
    out = ["| " + " | ".join(header) + " |", "|" + "|".join(align) + "|"]
    out += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(out) + "\n"


def src(rel):
    return f"[`{rel}`](../{RESULTS}/{rel})"


FOGS = [(0, 0, "linear depth"), (0, 1, "linear distance"), (1, 0, "exp depth"), (1, 1, "exp distance"),
        (2, 0, "exp2 depth"), (2, 1, "exp2 distance")]
FRAMES = [(1920, 1080, "1080p"), (3840, 2160, "4K")]


# ---------------------------------------------------------------------------------------------
# Renderers: each returns the Markdown between its markers.


def deferred_2core(root):
    b = Bench(root, "local-2core-streaming/hostcall-halide-device-final.json")
    rows = []
    for f16 in (0, 1):
        for w, h, frame in FRAMES:
            for mode, dist, fog in FOGS:
                key = dict(w=w, h=h, mode=mode, dist=dist, f16=f16)
                dev = b.get("BM_OpenCLDevice", nt=2, **key)
                call = b.get("BM_OpenCLHostCall", **key)
                hal = b.get("BM_Halide", **key)
                ordinary = ms(b.get("BM_OpenCLDevice", nt=0, **key)["real_time"]) if not f16 else "-"
                rows.append([frame, fog, "f16" if f16 else "f32", ms(call["memcpy2_ms"]), ms(dev["real_time"]),
                             ordinary, ms(call["real_time"]), f"{call['call_vs_kernel']:.3f}", ms(hal["real_time"]),
                             ratio(call["real_time"] / hal["real_time"]), ratio(call["vs_memcpy2"]),
                             ratio(hal["vs_memcpy2"]), f"{dev['max_err']:.1e}", f"{hal['max_err']:.1e}"])
    header = ["frame", "fog", "storage", "memcpy2 ms", "device ms", "device, ordinary stores ms", "host call ms",
              "call / own kernel", "Halide ms", "call / Halide", "call vs memcpy2", "Halide vs memcpy2",
              "max err OpenCL", "max err Halide"]
    note = (f"{TWO_CORE_EPYC} (Halide too), medians of 3, {b.date}, {src(b.rel)}.\n\n")
    return note + table(header, rows, ["---"] * 3 + ["--:"] * 11)


def startup_2core(root):
    b = Bench(root, "local-2core-streaming/fog.json")
    cold = Bench(root, "local-2core-streaming/start-cold.json")
    warm = Bench(root, "local-2core-streaming/start-warm.json")
    start = lambda x: x.get("BM_StartToFirstFrame")["real_time"] / 1000
    rows = [
        ["program build, cold (an option string PoCL never saw)", f"{b.get('BM_ProgramBuild', cold=1)['real_time']:.0f} ms", ""],
        ["program build, warm (PoCL's disk cache)", f"{b.get('BM_ProgramBuild', cold=0)['real_time']:.0f} ms", ""],
        ["first dispatch of a new pass (kernel + first launch)", f"{b.get('BM_FirstDispatch')['real_time']:.1f} ms", ""],
        ["process start to first fogged 1080p frame, cold cache", f"{start(cold):.2f} s", "≤ 1.5 s"],
        ["process start to first fogged 1080p frame, warm cache", f"{start(warm):.3f} s", "≤ 0.2 s"],
        ["steady dispatch overhead, 1×1 frame (enqueue to completion)", f"{b.get('BM_DispatchOverhead')['real_time']:.0f} µs", "≤ 50 µs"],
    ]
    dens = " / ".join(ms(b.get("BM_OpticalDepth", log10_density_d=k)["real_time"]) for k in (0, 2, 3, 20))
    rows.append(["exp fog at density·d ≈ 1 / 1e2 / 1e3 / 1e20 (1080p)", dens + " ms", "no denormal cliff"])
    note = (f"{TWO_CORE_EPYC}, medians, {b.date}: {src(b.rel)}, "
            f"{src(cold.rel)}, {src(warm.rel)}.\n\n")
    return note + table(["start-up and overhead (1080p, exp2)", "median", "target"], rows, ["---", "---", "---"])


def composite_2core(root):
    b = Bench(root, "volume-composite-own-2026-11-24/fresh.json")
    cases = [(0, 0, "RGBA32F depth-aware"), (1, 0, "RGBA16F depth-aware"), (0, 1, "RGBA32F bilinear"),
             (1, 1, "RGBA16F bilinear")]
    cell = lambda r: f"{r['composite_ms']:.2f} ({r['composite_vs_memcpy2']:.2f}×)"
    rows = []
    for f16, bil, name in cases:
        pas = [cell(b.get("BM_VolumeComposite", integrator=i, f16=f16, bilinear=bil, sparse=0)) for i in (0, 1)]
        k = b.get("BM_VolumeCompositeKernel", f16=f16, bilinear=bil)
        rows.append([name] + pas + [cell(k)])
    sp = " / ".join(cell(b.get("BM_VolumeComposite", integrator=0, f16=f16, bilinear=0, sparse=1)) for f16 in (0, 1))
    rows.append(["depth-aware, sparse: RGBA32F / RGBA16F", sp, "—", "—"])
    note = (f"1080p, half-resolution target, ms (× a 2-thread memcpy of the frame's color and depth), "
            f"{TWO_CORE_EPYC}, medians of 3, {b.date}, {src(b.rel)}.\n\n")
    return note + table(["1080p half", "stylized", "physical", "kernel alone (`BM_VolumeCompositeKernel`)"], rows,
                        ["---", "--:", "--:", "--:"])


def _sequence_rows(root, files, threads):
    fps, count, metas = {}, {}, []
    for rel in files:
        meta, f, c = sequence_fps(root, rel)
        fps.update(f)
        count.update(c)
        metas.append(meta)
    cases = ["1080p-half-zip", "1080p-half-piz", "4k-half-zip", "4k-half-piz",
             "1080p-float-zip", "1080p-float-piz", "4k-float-zip", "4k-float-piz"]
    rows = []
    for case in cases:
        row = [case.replace("-", " ").replace("4k", "4K").replace("zip", "ZIP").replace("piz", "PIZ")]
        for t in threads:
            p, q = fps[(case, "peer", t)], fps[(case, "fogcl", t)]
            n = min(count[(case, "peer", t)], count[(case, "fogcl", t)])
            mark = "" if n >= 3 else f" ({n} rep{'s' if n > 1 else ''})"
            row += [f"{p:.2f} / {q:.2f}{mark}", ratio(q / p)]
        rows.append(row)
    return rows


def sequence_16core(root):
    d = "device-16core-2026-11-24/"
    files = [d + f for f in ("t1-half.json", "t1-float.json", "t2-half-19of24.json", "t2-float.json", "t16.json")]
    rows = _sequence_rows(root, files, (1, 2, 16))
    header = ["case", "1 thread", "ratio", "2 threads", "ratio", "16 threads", "ratio"]
    note = (f"OpenEXR alone (the peer) / `fogcl apply` in frames/s, and fogcl / peer; {XEON16}, N threads pinned "
            f"to N cores, medians of 3 repetitions unless a cell says fewer, 2026-11-24, "
            f"[`{d}`](../{RESULTS}/{d}).\n\n")
    return note + table(header, rows, ["---"] + ["--:"] * 6)


def sequence_2core(root):
    rel = "local-2core-2026-11-24/runs-baseline.json"
    meta, fps, _ = sequence_fps(root, rel)
    k = ("1080p-float-zip", "{}", 2)
    f = {t: fps[("1080p-float-zip", t, 2)] for t in ("peer", "fogcl", "before")}
    rows = [["1080p float ZIP, 24 frames", ms(f["peer"]), ms(f["fogcl"]), ms(f["before"]),
             ratio(f["fogcl"] / f["peer"]), ratio(f["fogcl"] / f["before"])]]
    note = (f"2-core EPYC VM, `--threads 2`, PoCL, medians of 3, {meta['time']}, {src(rel)}; "
            f"\"before\" is `fogcl apply` without the pipeline (one thread, no pool).\n\n")
    return note + table(["case", "OpenEXR alone (frames/s)", "fogcl (frames/s)", "before (frames/s)", "fogcl / peer",
                         "fogcl / before"], rows, ["---"] + ["--:"] * 5)


def deferred_h100(root):
    b = Bench(root, "gpu-h100-2026-11-26-chunks/fog-gpu.json")
    rows = []
    for w, h, frame in FRAMES:
        row = [frame.replace("1080p", "1920×1080").replace("4K", "3840×2160")]
        for f16 in (0, 1):
            dev = [b.get("BM_OpenCLDevice", w=w, h=h, mode=m, dist=d, f16=f16, nt=2) for m, d, _ in FOGS]
            row += [rng([x["real_time"] for x in dev], lambda v: f"{v:.3f}"),
                    rng([x["bw_vs_copy"] for x in dev], ratio)]
        copy = [b.get("BM_DeviceCopy", w=w, h=h, f16=f16)["bytes_per_second"] / 1e9 for f16 in (0, 1)]
        trip = [rng([b.get("BM_OpenCLHostCall", w=w, h=h, mode=m, dist=d, f16=f16)["real_time"] for m, d, _ in FOGS],
                    lambda v: f"{v:.2f}") for f16 in (0, 1)]
        row += [f"{copy[0]:.0f} / {copy[1]:.0f}", f"{trip[0]} / {trip[1]}"]
        rows.append(row)
    header = ["frame", "RGBA32F device ms", "bw_vs_copy", "RGBA16F device ms", "bw_vs_copy", "copy GB/s (f32 / f16)",
              "round trip ms (f32 / f16)"]
    note = (f"{H100}, OpenCL 3.0 CUDA; the 12 modes × metrics per storage (ranges), medians of 3, {b.date}, "
            f"{src(b.rel)}.\n\n")
    return note + table(header, rows, ["---"] + ["--:"] * 6)


def volume_h100(root):
    b = Bench(root, "gpu-h100-2026-11-26-bands/volume-gpu.json")
    cases = [(2, 1, "half resolution, noise as an image (texture unit)", "≤ 1 ms"),
             (1, 1, "full resolution, noise as an image", "≤ 4 ms"),
             (2, 0, "half resolution, noise as a buffer (manual trilinear)", "≤ 1 ms"),
             (1, 0, "full resolution, noise as a buffer", "≤ 4 ms")]
    rows = []
    for div, img, name, target in cases:
        t = [b.get("BM_VolumeDevice", integrator=i, divisor=div, noise_image=img, width=1920)["real_time"] for i in (0, 1)]
        limit = float(target.split()[1])
        rows.append([name, f"{t[0]:.2f} ms", f"{t[1]:.2f} ms", target + (": met" if max(t) <= limit else ": missed")])
    note = (f"1920×1080, the demo's 4 volumes, 64 steps, noise on, device time of march + composite; {H100}, "
            f"medians of 3, {b.date}, {src(b.rel)}.\n\n")
    return note + table(["1920×1080", "stylized", "physical", "target"], rows, ["---", "--:", "--:", "---"])


def _report_rows(rows, integrator, steps, resolution, scene):
    up = "depth-aware"
    return [r for r in rows if r["integrator"] == integrator and r["steps"] == str(steps) and
            r["resolution"] == resolution and r["upsampling"] == up and r["noise"] == "buffer" and
            r["storage"] == "rgba32f" and r["scene"] == scene]


def volume_report_table(root):
    rows = volume_report(root)
    out = []
    for integ in ("stylized", "physical"):
        for steps in (8, 32, 64, 256):
            for res in ("full", "half", "quarter"):
                by = {s: _report_rows(rows, integ, steps, res, s)[0] for s in ("demo", "inside", "dense", "thin")}
                d = by["demo"]
                total = sum(float(r["time_ms"]) for r in by.values())
                nonfinite = sum(int(r["nonfinite"]) for r in by.values())
                out.append([integ, str(steps), res, f"{float(d['time_ms']):.1f}", g3(d["max_abs_err"]),
                            g3(d["p999_abs_err"]), f"{float(d['pct_8bit_off']):.1f}", g3(by["inside"]["max_abs_err"]),
                            g3(by["dense"]["max_abs_err"]), g3(by["thin"]["max_abs_err"]), f"{total:.1f}",
                            str(nonfinite)])
    header = ["integrator", "steps", "resolution", "demo ms", "demo max", "demo p99.9", "demo % 8-bit off",
              "inside max", "dense max", "thin max", "all 4 scenes ms", "NaN/Inf"]
    note = ("160×90, RGBA32F, noise buffer, depth-aware below full resolution; 2-core EPYC VM, PoCL 3.1, "
            "2026-11-24, [`volume-report-2core/volume-report.csv`]"
            "(../bench/results/volume-report-2core/volume-report.csv) (all 966 rows).\n\n")
    return note + table(header, out, ["---", "--:", "---"] + ["--:"] * 9)


def volume_stiff(root):
    rows = volume_report(root)
    steps = (8, 16, 32, 64, 128, 256)
    out = []
    for integ, name in (("physical", "physical (exact segment weight)"), ("riemann", "Riemann sum (I += T·σs·L·Δ)")):
        out.append([name] + [g3(_report_rows(rows, integ, s, "full", "dense")[0]["max_abs_err"]) for s in steps])
    note = "Dense scene, full resolution, RGBA32F, max color error; the same run.\n\n"
    return note + table(["steps"] + [str(s) for s in steps], out, ["---"] + ["--:"] * len(steps))


def budget_picks(rows, integrator, budget):
    """The volumetric budget's rule on the report's rows: the fastest (steps, resolution, upsampling,
    noise) of this integrator in RGBA32F whose worst max error over the four scenes is <= budget."""
    variants = {}
    for r in rows:
        if r["integrator"] != integrator or r["storage"] != "rgba32f":
            continue
        key = (int(r["steps"]), r["resolution"], r["upsampling"], r["noise"])
        v = variants.setdefault(key, [0.0, 0.0, 0])
        v[0] = max(v[0], float(r["max_abs_err"]))
        v[1] += float(r["time_ms"])
        v[2] += 1
    variants = {k: v for k, v in variants.items() if v[2] == 4}
    ok = [(v[1], k, v[0]) for k, v in variants.items() if v[0] <= budget]
    if ok:
        return min(ok), None
    best = min((v[0], k) for k, v in variants.items())
    return None, best


def _variant_name(key):
    steps, res, up, noise = key
    s = f"{steps} steps, {res}"
    if res != "full" and up == "bilinear":
        s += ", bilinear"
    if noise == "image":
        s += ", noise image"
    return s


def volume_budget(root):
    rows = volume_report(root)
    out = []
    for e in (0.6, 0.3, 0.1, 0.05, 0.01):
        row = [f"{e:g}"]
        for integ in ("stylized", "physical"):
            pick, best = budget_picks(rows, integ, e)
            if pick:
                row.append(f"{_variant_name(pick[1])} ({pick[0]:.1f} ms over the scenes)")
            else:
                steps, res, up, noise = best[1]
                row.append(f"none: exit 1, \"... the best achievable worst color error is {g3(best[0])} "
                           f"(s{steps} {res} {noise})\"")
        out.append(row)
    note = "The fastest variant meeting a budget, by the budget's rule on the same run (ms: summed over the four scenes):\n\n"
    return note + table(["--max-error", "stylized", "physical"], out, ["--:", "---", "---"])


SHAFTS_CSV = "volume-report-shafts-2core/volume-report.csv"
LAMPS_CSV = "volume-report-lamps-2core/volume-report.csv"


def _marched_scene_table(root, csv_name, scene, date, steps_list):
    """One marched-fog scene of `fogcl report --volumetric` (physical rows): steps x resolution."""
    with open(root / RESULTS / csv_name, newline="") as f:
        rows = list(csv.DictReader(f))
    out = []
    for steps in steps_list:
        for res in ("full", "half", "quarter"):
            r = _report_rows(rows, "physical", steps, res, scene)[0]
            out.append([str(steps), res, f"{float(r['time_ms']):.1f}", g3(r["max_abs_err"]), g3(r["p999_abs_err"]),
                        f"{float(r['pct_8bit_off']):.1f}", r["nonfinite"]])
    note = (f"The `{scene}` scene, physical, 160×90, RGBA32F, noise buffer, depth-aware below full resolution; "
            f"2-core EPYC VM, PoCL 3.1, {date}, {src(csv_name)} (all {len(rows)} rows).\n\n")
    header = ["steps", "resolution", "ms", "max", "p99.9", "% 8-bit off", "NaN/Inf"]
    return note + table(header, out, ["--:", "---"] + ["--:"] * 5)


def volume_shafts(root):
    return _marched_scene_table(root, SHAFTS_CSV, "shafts", "2026-11-29", (8, 16, 32, 64, 128, 256))


def volume_lamps(root):
    return _marched_scene_table(root, LAMPS_CSV, "lamps", "2026-11-29", (8, 16, 32, 64, 128, 256))


def readme_speed(root):
    d2 = suite = Bench(root, "epyc-2core-readme-2026-11-29/fog.json")
    lights = Bench(root, "lights-lanes-2026-11-29/epyc-2core-median3.json")
    lights_gpu = Bench(root, "lights-lanes-2026-11-29/h200.json")
    gpu = Bench(root, "gpu-h100-2026-11-26-readme-b/fog-gpu.json")
    march = Bench(root, "volume-local-2core/lanes-one-run.json")
    comp = Bench(root, "volume-composite-own-2026-11-24/fresh.json")
    vgpu = Bench(root, "gpu-h100-2026-11-26-readme-b/volume-gpu.json")
    key = dict(w=1920, h=1080, mode=2, dist=0, f16=0)
    dev = d2.get("BM_OpenCLDevice", nt=2, **key)
    call = d2.get("BM_OpenCLHostCall", **key)
    hal = d2.get("BM_Halide", **key)
    omp = suite.get("BM_OpenMPSimd", **key)
    omp_cl = suite.get("BM_OpenCLDevice", nt=2, **key)
    g = gpu.get("BM_OpenCLDevice", w=3840, h=2160, mode=2, dist=0, f16=0, nt=2)
    gcopy = gpu.get("BM_DeviceCopy", w=3840, h=2160, f16=0)
    ml = march.get("BM_VolumeDevice", integrator=0, divisor=2, noise_image=0, width=1920)
    mo = march.get("BM_VolumeOpenMP", integrator=0, width=1920)
    ck = comp.get("BM_VolumeCompositeKernel", f16=1, bilinear=0)
    vg = vgpu.get("BM_VolumeDevice", integrator=0, divisor=2, noise_image=1, width=1920)
    lkey = dict(volumes=0, rgb=0, lights=4)
    lh = lights.get("BM_VolumeHeight", path=0, **lkey)
    lh_omp = lights.get("BM_VolumeHeight", path=3, **lkey)
    lh_scalar = lights.get("BM_VolumeHeight", path=2, **lkey)
    lh_gpu = lights_gpu.get("BM_VolumeHeight", path=0, **lkey)
    rcall = gpu.get("BM_OpenCLHostCall", **key)
    rbus = gpu.get("BM_PinnedTransfer", w=1920, h=1080, f16=0, host=1)
    _, sfps, _ = sequence_fps(root, "local-2core-2026-11-24/runs-baseline.json")
    _, xfps, _ = sequence_fps(root, "device-16core-2026-11-24/t16.json")
    gseq_rel = "gpu-h100-2026-11-25-round-trip/sequence-4k-48-frames.json"
    gmeta, gfps, _ = sequence_fps(root, gseq_rel)
    g16 = (gfps[("4k-half-zip", "fogcl", 16)], gfps[("4k-half-zip", "peer", 16)])
    s2 = (sfps[("1080p-float-zip", "fogcl", 2)], sfps[("1080p-float-zip", "peer", 2)])
    x16 = (xfps[("4k-half-zip", "fogcl", 16)], xfps[("4k-half-zip", "peer", 16)])
    f = lambda v: f"{v:.2f} ms"
    rows = [
        ["deferred fog, 1080p exp2 RGBA32F, device time", "2-core EPYC", f(dev["real_time"]),
         f"2-thread memcpy of the frame's bytes, same iterations, {f(dev['memcpy2_ms'])}",
         f"{dev['memcpy2_ms'] / dev['real_time']:.2f}× faster",
         d2.date, src(d2.rel)],
        ["the same, whole host call (`FogPass::apply`)", "2-core EPYC", f(call["real_time"]),
         f"Halide 14, whole `realize()`, {f(hal['real_time'])}", f"{hal['real_time'] / call['real_time']:.2f}× faster",
         d2.date, src(d2.rel)],
        ["the same, device time", "2-core EPYC", f(omp_cl["real_time"]),
         f"OpenMP + SIMD C++ (`-O3 -march=native`), {f(omp['real_time'])}",
         f"{omp['real_time'] / omp_cl['real_time']:.1f}× faster", suite.date, src(suite.rel)],
        ["deferred fog, 4K exp2 RGBA32F, device time", "H100", f"{g['real_time']:.3f} ms",
         f"`clEnqueueCopyBuffer` of the frame, {gcopy['real_time']:.3f} ms", f"{g['bw_vs_copy']:.2f}× its bandwidth",
         gpu.date, src(gpu.rel)],
        ["fog volumes, march, 1080p half, 64 steps, stylized", "2-core EPYC",
         f"{ml['steps_x_pixels_per_s'] / 1e6:.0f} M steps·px/s",
         f"OpenMP + SIMD C++ march, {mo['steps_x_pixels_per_s'] / 1e6:.1f} M",
         f"{ml['steps_x_pixels_per_s'] / mo['steps_x_pixels_per_s']:.1f}× faster", march.date, src(march.rel)],
        ["marched height fog with 4 point lights, 1080p half, 64 steps", "2-core EPYC",
         f"{lh['real_time']:.0f} ms", f"the scalar path (1 thread), {lh_scalar['real_time']:.0f} ms; target ≥ 15×",
         f"{lh_scalar['real_time'] / lh['real_time']:.1f}× faster", lights.date, src(lights.rel)],
        ["the same", "2-core EPYC", f"{lh['real_time']:.0f} ms",
         f"OpenMP + SIMD C++, same formulas, {lh_omp['real_time']:.0f} ms",
         f"{lh_omp['real_time'] / lh['real_time']:.1f}× faster", lights.date, src(lights.rel)],
        ["the same", "H200", f"{lh_gpu['real_time']:.2f} ms", "target ≤ 1 ms",
         "met" if lh_gpu["real_time"] <= 1.0 else "missed", lights_gpu.date, src(lights_gpu.rel)],
        ["fog volumes, upsample + composite, 1080p half, RGBA16F depth-aware", "2-core EPYC", f(ck["composite_ms"]),
         f"2-thread copy of the frame's color and depth, {f(ck['memcpy2_ms'])}",
         f"{ck['composite_vs_memcpy2']:.2f}× its time",
         comp.date, src(comp.rel)],
        ["fog volumes, 1080p half, 64 steps, noise image (the GPU default), stylized", "H100", f(vg["real_time"]),
         f"target ≤ 1 ms", "met", vgpu.date, src(vgpu.rel)],
        ["deferred fog, 1080p exp2 RGBA32F, whole host call from ordinary host images", "H100 (16-core Xeon host)",
         f(rcall["real_time"]), f"the pinned transfer of its bytes (`BM_PinnedTransfer`), {f(rbus['real_time'])}",
         f"{rcall['real_time'] / rbus['real_time']:.2f}× its time (target ≤ 1.5×)", gpu.date, src(gpu.rel)],
        ["`fogcl apply` sequence, 1080p float ZIP, 2 threads", "2-core EPYC", f"{s2[0]:.2f} frames/s",
         f"OpenEXR alone (read + write), {s2[1]:.2f} frames/s", f"{s2[0] / s2[1]:.2f}×", "2026-11-24",
         src("local-2core-2026-11-24/runs-baseline.json")],
        ["`fogcl apply` sequence, 4K half ZIP, 16 threads", "H100 host's 16-core Xeon", f"{x16[0]:.2f} frames/s",
         f"OpenEXR alone, {x16[1]:.2f} frames/s", f"{x16[0] / x16[1]:.2f}×", "2026-11-24",
         src("device-16core-2026-11-24/t16.json")],
        ["`fogcl apply --device gpu` sequence, 4K half ZIP, 48 frames, 16 threads", "H100 (16-core Xeon host)",
         f"{g16[0]:.2f} frames/s", f"OpenEXR alone, {g16[1]:.2f} frames/s", f"{g16[0] / g16[1]:.2f}×",
         gmeta["time"][:10], src(gseq_rel)],
    ]
    # The 2-vCPU Xeon (480 MiB L3), default settings (PoCL's threads floating); its ceiling is the
    # fastest of four copies of the row's bytes (ceiling_ms).
    xe = Bench(root, "xeon-2core-readme-2026-11-26e/fog.json")
    xdev = xe.get("BM_OpenCLDevice", nt=2, **key)
    xcall = xe.get("BM_OpenCLHostCall", **key)
    xhal = xe.get("BM_Halide", **key)
    xomp = xe.get("BM_OpenMPSimd", **key)
    xeon = "2-vCPU Xeon, 480 MiB L3"
    rows[3:3] = [
        ["deferred fog, 1080p exp2 RGBA32F, device time", xeon, f(xdev["real_time"]),
         f"fastest 2-thread copy of the frame's bytes (memcpy, store loops, Halide), {f(xdev['ceiling_ms'])}",
         f"{xdev['vs_copy']:.2f}× faster", xe.date, src(xe.rel)],
        ["the same, whole host call", xeon, f(xcall["real_time"]),
         f"Halide 14, bands of 4 rows, {f(xhal['real_time'])}", f"{xhal['real_time'] / xcall['real_time']:.2f}×",
         xe.date, src(xe.rel)],
        ["the same, device time", xeon, f(xdev["real_time"]),
         f"OpenMP + SIMD C++, {f(xomp['real_time'])}", f"{xomp['real_time'] / xdev['real_time']:.1f}× faster",
         xe.date, src(xe.rel)],
    ]
    # Height fog (docs/DESIGN.md §6) on the same machine and run: bench modes 3 (a valley fog: grey,
    # falloff) and 4 (a haze: per-channel, the sky fogged, a sun lobe).
    hkey = dict(w=1920, h=1080, dist=0, f16=0)
    for mode, what in ((3, "height fog, 1080p valley (grey, falloff) RGBA32F, device time"),
                       (4, "height fog, 1080p haze (per-channel, sky fogged, sun lobe) RGBA32F, device time")):
        hdev = xe.get("BM_OpenCLDevice", nt=2, mode=mode, **hkey)
        homp = xe.get("BM_OpenMPSimd", mode=mode, **hkey)
        rows.insert(6 + 2 * (mode - 3), [
            what, xeon, f(hdev["real_time"]),
            f"fastest 2-thread copy of the frame's bytes, {f(hdev['ceiling_ms'])}",
            f"{hdev['vs_copy']:.2f}× its time (target ≥ 0.8×)", xe.date, src(xe.rel)])
        rows.insert(7 + 2 * (mode - 3), [
            "the same, device time", xeon, f(hdev["real_time"]), f"OpenMP + SIMD C++, same formulas, {f(homp['real_time'])}",
            f"{homp['real_time'] / hdev['real_time']:.1f}× faster", xe.date, src(xe.rel)])
    header = ["what", "machine", "fogcl", "peer (or target)", "fogcl against it", "date", "result file"]
    return table(header, rows, ["---"] * 7).replace("](../bench/", "](bench/")


def readme_accuracy(root):
    d2 = Bench(root, "local-2core-streaming/hostcall-halide-device-final.json")
    suite = Bench(root, "local-2core-streaming/fog.json")
    gpu = Bench(root, "gpu-h100/fog-gpu.json")
    vgpu = Bench(root, "gpu-h100/volume-gpu.json")
    rep = volume_report(root)

    def worst(b, family, f16, **extra):
        return max(b.get(family, w=w, h=h, mode=m, dist=d, f16=f16, **extra)["max_err"]
                   for w, h, _ in FRAMES for m, d, _ in FOGS)

    rows = []
    for f16, name in ((0, "RGBA32F"), (1, "RGBA16F")):
        rows.append([f"deferred fog, linear / exp / exp2 × depth / distance at 1080p and 4K, {name}", "2-core EPYC",
                     g3(worst(d2, "BM_OpenCLDevice", f16, nt=2)),
                     f"Halide 14 (same formulas): {g3(worst(d2, 'BM_Halide', f16))}; OpenMP C++: "
                     f"{g3(worst(suite, 'BM_OpenMPSimd', f16))}", d2.date, src(d2.rel)])
    for f16, name in ((0, "RGBA32F"), (1, "RGBA16F")):
        rows.append([f"deferred fog, the same rows, {name}", "H100", g3(worst(gpu, "BM_OpenCLDevice", f16, nt=0)),
                     "PoCL on the 2-core EPYC, row above", gpu.date, src(gpu.rel)])
    demo = [r for r in rep if r["scene"] == "demo" and r["resolution"] == "full" and r["steps"] == "256"
            and r["noise"] == "buffer" and r["storage"] == "rgba32f"]
    for r in demo:
        rows.append([f"fog volumes, demo scene, {r['integrator']}, 256 steps, full resolution (160×90)", "2-core EPYC",
                     g3(r["max_abs_err"]), "the scalar march in double at 4096 steps (the truth, not a peer)",
                     "2026-11-24", src("volume-report-2core/volume-report.csv")])
    for img, name in ((0, "buffer"), (1, "image (texture unit)")):
        e = max(vgpu.get("BM_VolumeDevice", integrator=i, divisor=1, noise_image=img, width=480)["max_err"]
                for i in (0, 1))
        rows.append([f"fog volumes, 64 steps, full resolution, noise as {name} (480×270)", "H100", g3(e),
                     "the scalar march in double, same steps", vgpu.date, src(vgpu.rel)])
    header = ["what (max color error against the float64 path)", "machine", "fogcl", "peer or reference", "date",
              "result file"]
    return table(header, rows, ["---", "---", "--:", "---", "---", "---"]).replace("](../bench/", "](bench/")


RENDERERS = {
    "deferred-2core": deferred_2core,
    "startup-2core": startup_2core,
    "composite-2core": composite_2core,
    "sequence-16core": sequence_16core,
    "sequence-2core": sequence_2core,
    "deferred-h100": deferred_h100,
    "volume-h100": volume_h100,
    "volume-report": volume_report_table,
    "volume-stiff": volume_stiff,
    "volume-budget": volume_budget,
    "volume-shafts": volume_shafts,
    "volume-lamps": volume_lamps,
    "readme-speed": readme_speed,
    "readme-accuracy": readme_accuracy,
}


# ---------------------------------------------------------------------------------------------


def documents(root):
    return [root / "README.md"] + sorted((root / "docs").glob("*.md"))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true", help="change nothing; exit 1 if a committed table is stale")
    ap.add_argument("--root", default=Path(__file__).resolve().parent.parent, type=Path, help="repository root")
    args = ap.parse_args()
    root = args.root
    rendered, used, failures = {}, set(), []
    for doc in documents(root):
        text = doc.read_text()
        names = OPEN_MARKER.findall(text)
        blocks = {m.group(1) for m in MARKER.finditer(text)}
        for name in names:
            if name not in blocks:
                failures.append(f"{doc.relative_to(root)}: <!-- table:{name} --> has no <!-- /table:{name} -->")
            if name not in RENDERERS:
                failures.append(f"{doc.relative_to(root)}: <!-- table:{name} --> names no renderer "
                                f"(known: {', '.join(sorted(RENDERERS))})")

        def replace(m):
            name = m.group(1)
            if name not in RENDERERS:
                return m.group(0)
            used.add(name)
            if name not in rendered:
                rendered[name] = RENDERERS[name](root)
            return f"<!-- table:{name} -->\n{rendered[name]}<!-- /table:{name} -->"

        new = MARKER.sub(replace, text)
        if new != text:
            rel = str(doc.relative_to(root))
            if args.check:
                diff = difflib.unified_diff(text.splitlines(True), new.splitlines(True), rel, rel + " (rendered)")
                failures.append(f"{rel}: a generated table differs from bench/results/ "
                                f"(run scripts/render_tables.py):\n" + "".join(diff))
            else:
                doc.write_text(new)
                print(f"rendered {rel}")
    for name in sorted(set(RENDERERS) - used):
        failures.append(f"table '{name}' appears in no document")
    for f in failures:
        print(f"render_tables: {f}", file=sys.stderr)
    if not failures:
        print(f"render_tables: {len(used)} tables {'match' if args.check else 'rendered'} "
              f"bench/results/ ({', '.join(sorted(used))})")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
