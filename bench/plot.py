#!/usr/bin/python3
"""Reads bench/run.sh's Google Benchmark JSON and writes throughput.png plus a Markdown table
(table.md): throughput per path per resolution, with the 2-thread copy ceiling drawn (the fastest
of glibc memcpy, an ordinary-store loop, a streaming-store loop and a Halide copy: vs_copy)."""
import json
import re
import sys
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/bench")
runs = json.loads((out / "fog.json").read_text())["benchmarks"]
pocl1 = json.loads((out / "pocl1.json").read_text())["benchmarks"] if (out / "pocl1.json").exists() else []

MODES = {"0": "linear", "1": "exp", "2": "exp2", "3": "height (valley)", "4": "height (haze, sun)"}
PATHS = {
    "BM_Scalar": "scalar C++ (1 thread)",
    "BM_OpenMPSimd": "OpenMP+SIMD C++ (2 threads)",
    "BM_OpenMPSimdFastMath": "OpenMP+SIMD -ffast-math (2 threads)",
    "BM_Halide": "Halide 14 JIT (2 threads)",
    "BM_OpenCLDevice": "OpenCL PoCL, device time",
    "BM_OpenCLHostCall": "OpenCL PoCL, host call",
}


def medians(benchmarks):
    """name -> (args dict, median run)"""
    found = {}
    for b in benchmarks:
        if b.get("aggregate_name", "median") != "median" or b.get("error_occurred"):
            continue
        name = b["run_name"] if "run_name" in b else b["name"]
        parts = name.split("/")
        args = dict(p.split(":", 1) for p in parts[1:] if ":" in p)
        found[name] = (parts[0], args, b)
    return found


def gbps(b):
    return b["bytes_per_second"] / 1e9


def ms(b):
    return b["real_time"] * {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b["time_unit"]]


rows = medians(runs)
# The cache-resident rows (512x256) get their own table below, not a place in the plot.
cache_rows = {k: v for k, v in rows.items() if v[0] == "BM_OpenCLDeviceCacheResident"}
rows = {k: v for k, v in rows.items() if v[0] != "BM_OpenCLDeviceCacheResident"}
resolutions = sorted({(int(a["w"]), int(a["h"])) for _, (n, a, _) in rows.items()
                      if "w" in a and "mode" in a and n not in ("BM_HostCallParts", "BM_ModeAB")},
                     key=lambda r: r[0] * r[1])
memcpy = {(int(a["w"]), int(a["h"]), int(a["threads"])): b for _, (n, a, b) in rows.items() if n == "BM_Memcpy"}
# The copy ceiling per frame and thread count: the fastest of the copy ways (older results: memcpy).
COPIES = {"BM_Memcpy": "memcpy", "BM_CopyLoop": "loop", "BM_CopyStream": "stream", "BM_CopyHalide": "Halide"}
ceiling = {}
for _, (n, a, b) in rows.items():
    key = (int(a.get("w", 0)), int(a.get("h", 0)), int(a.get("threads", 0)))
    if n in COPIES and (key not in ceiling or ms(b) < ms(ceiling[key][1])):
        ceiling[key] = (COPIES[n], b)


def vs_copy(b):
    """The row's ratio to the copy ceiling of the same iterations (older results: to memcpy)."""
    return b["vs_copy"] if "vs_copy" in b else b["vs_memcpy2"]


def ceiling_ms(b):
    way = {0: "memcpy", 1: "loop", 2: "stream", 3: "Halide"}.get(int(b.get("ceiling_way", 0)), "?")
    return f"{b['ceiling_ms']:.2f} ({way})" if "ceiling_ms" in b else f"{b['memcpy2_ms']:.2f} (memcpy)"

# Plot: one panel per (metric, storage); bars grouped by resolution, exp2 mode shown (the costliest).
fig, axes = plt.subplots(2, 2, figsize=(14, 9), sharey=True)
for ax, (dist, f16) in zip(axes.flat, [("0", "0"), ("1", "0"), ("0", "1"), ("1", "1")]):
    width = 0.8 / len(PATHS)
    for i, (bench, label) in enumerate(PATHS.items()):
        ys = []
        for (w, h) in resolutions:
            key = [b for _, (n, a, b) in rows.items()
                   if n == bench and a.get("w") == str(w) and a.get("h") == str(h) and a.get("mode") == "2"
                   and a.get("dist") == dist and a.get("f16") == f16 and a.get("nt", "2") == "2"]
            ys.append(gbps(key[0]) if key else 0)
        ax.bar([r + i * width for r in range(len(resolutions))], ys, width, label=label)
    for r, (w, h) in enumerate(resolutions):
        if (w, h, 2) in ceiling:
            way, b = ceiling[(w, h, 2)]
            ax.hlines(gbps(b), r - 0.1, r + 0.9, colors="k", linestyles="--",
                      label="fastest copy, 2 threads (ceiling)" if r == 0 else None)
    ax.set_xticks([r + 0.4 for r in range(len(resolutions))], [f"{w}x{h}" for w, h in resolutions])
    ax.set_title(f"exp2 fog, {'distance' if dist == '1' else 'depth'}-based, {'RGBA16F' if f16 == '1' else 'RGBA32F'}")
    ax.set_ylabel("GB/s moved (color in + out, depth in)")
    ax.set_yscale("log")
handles, labels = axes.flat[0].get_legend_handles_labels()
fig.legend(handles, labels, fontsize=9, loc="lower center", ncol=4)  # below the panels: no bar hidden
fig.suptitle("fogcl throughput per path (higher is better); dashed: the fastest 2-thread copy of the same bytes")
fig.tight_layout(rect=(0, 0.07, 1, 1))
fig.savefig(out / "throughput.png", dpi=110)

# Table: per resolution / mode / metric / storage: ms and ratio to the copy ceiling for each path.
# The Halide peer's own error sits next to its time; host call / device (the call over its own
# kernel, same iterations) and host call / Halide are the ratios of the host-call targets.
lines = ["| frame | fog | storage | copy ceiling 2T ms (interleaved, way) | scalar ms | OpenMP ms | OpenMP fast-math ms | Halide ms | "
         "OpenCL device ms | OpenCL device, ordinary stores ms | OpenCL device, streaming stores ms | OpenCL host call ms | host call / device | "
         "Halide / device | Halide / host call | OpenCL vs copy | host call vs copy | Halide vs copy | OpenCL vs scalar | "
         "max err (OpenCL) | max err (Halide) |",
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
by_case = defaultdict(dict)
for _, (n, a, b) in rows.items():
    if "mode" in a and n not in ("BM_HostCallParts", "BM_ModeAB"):
        # nt=0 / nt=1: the same device run with ordinary / non-temporal stores forced (the default,
        # nt=2, picks by frame size), each its own column.
        name = n + {"0": "-plain", "1": "-nt"}.get(a.get("nt"), "")
        by_case[(int(a["w"]), int(a["h"]), a["mode"], a["dist"], a["f16"])][name] = b
for (w, h, mode, dist, f16), paths in sorted(by_case.items(), key=lambda kv: (kv[0][0] * kv[0][1], kv[0][2:])):
    def t(name):
        return f"{ms(paths[name]):.2f}" if name in paths else "-"
    cl = paths.get("BM_OpenCLDevice")
    sc = paths.get("BM_Scalar")
    ratio = f"{vs_copy(cl):.2f}" if cl else "-"
    speedup = f"{ms(sc) / ms(cl):.1f}x" if cl and sc else "-"
    err = f"{cl['max_err']:.1e}" if cl else "-"
    hc = paths.get("BM_OpenCLHostCall")
    hl = paths.get("BM_Halide")
    # The host call over its own kernel in the same iterations (call_vs_kernel); older results
    # without it fall back to the two benchmarks' ratio.
    hc_dev = (f"{hc['call_vs_kernel']:.2f}" if hc and hc.get("call_vs_kernel") else
              f"{ms(hc) / ms(cl):.2f}" if hc and cl else "-")
    # Halide over fogcl: >= 1 where fogcl is at or ahead of the Halide peer.
    hl_cl = f"{ms(hl) / ms(cl):.2f}" if hl and cl else "-"
    hl_hc = f"{ms(hl) / ms(hc):.2f}" if hc and hl else "-"
    hc_m2 = f"{vs_copy(hc):.2f}" if hc else "-"
    hl_m2 = f"{vs_copy(hl):.2f}" if hl else "-"
    hl_err = f"{hl['max_err']:.1e}" if hl else "-"
    # The ceiling the ratio used: the fastest 2-thread copy measured interleaved with the OpenCL rows.
    m2 = ceiling_ms(cl) if cl and ("ceiling_ms" in cl or "memcpy2_ms" in cl) else "-"
    lines.append(f"| {w}x{h} | {MODES[mode]} {'distance' if dist == '1' else 'depth'} | {'f16' if f16 == '1' else 'f32'} | "
                 f"{m2} | {t('BM_Scalar')} | {t('BM_OpenMPSimd')} | {t('BM_OpenMPSimdFastMath')} | {t('BM_Halide')} | "
                 f"{t('BM_OpenCLDevice')} | {t('BM_OpenCLDevice-plain')} | {t('BM_OpenCLDevice-nt')} | {t('BM_OpenCLHostCall')} | {hc_dev} | {hl_cl} | {hl_hc} | "
                 f"{ratio} | {hc_m2} | {hl_m2} | {speedup} | {err} | {hl_err} |")

extra = []
for _, (n, a, b) in rows.items():
    if n in ("BM_ProgramBuild", "BM_FirstDispatch", "BM_DispatchOverhead", "BM_OpticalDepth"):
        label = n + ("" if not a else " " + " ".join(f"{k}={v}" for k, v in a.items() if k not in ("iterations", "manual_time")))
        extra.append(f"| {label} | {ms(b):.3f} ms |")
for name in ("start-cold", "start-warm"):
    p = out / f"{name}.json"
    if p.exists():
        for b in json.loads(p.read_text())["benchmarks"]:
            extra.append(f"| process start to first 1080p frame ({name.split('-')[1]} PoCL cache) | {ms(b):.1f} ms |")
p1 = medians(pocl1)
for _, (n, a, b) in p1.items():
    if n == "BM_OpenCLDevice" and a.get("w") == "1920" and a.get("f16") == "0" and a.get("nt") == "2":
        two = [x for _, (m, aa, x) in rows.items() if m == n and aa == a]
        if two:
            extra.append(f"| PoCL 1 vs 2 threads, 1080p {MODES[a['mode']]} {'distance' if a['dist'] == '1' else 'depth'} | "
                         f"{ms(b):.2f} ms vs {ms(two[0]):.2f} ms ({ms(b) / ms(two[0]):.2f}x) |")
# Cache-resident frame: compute cost per block of 16 pixels, PoCL with 2 threads (it runs a grid this
# small on one) and with 1; the same frame's memcpy with 1 thread for scale.
cache = ["| 512x256 (in cache) | storage | OpenCL device µs | ns per 16 px | ns per 16 px, POCL_MAX_PTHREAD_COUNT=1 |",
         "|---|---|---|---|---|"]
cache_1t = {k: v for k, v in p1.items() if v[0] == "BM_OpenCLDeviceCacheResident"}
for name, (n, a, b) in sorted(cache_rows.items(), key=lambda kv: (kv[1][1]["f16"], kv[1][1]["mode"], kv[1][1]["dist"])):
    one = cache_1t.get(name)
    cache.append(f"| {MODES[a['mode']]} {'distance' if a['dist'] == '1' else 'depth'} | {'f16' if a['f16'] == '1' else 'f32'} | "
                 f"{ms(b) * 1e3:.1f} | {b['ns_per_16px']:.2f} | {one[2]['ns_per_16px']:.2f} |" if one else
                 f"{ms(b) * 1e3:.1f} | {b['ns_per_16px']:.2f} | - |")
for (w, h, t), b in sorted(memcpy.items()):
    if (w, h) == (512, 256):
        cache.append(f"| memcpy of the RGBA32F frame's bytes, {t} thread{'s' if t > 1 else ''} | | {ms(b) * 1e3:.1f} | "
                     f"{ms(b) * 1e6 * 16 / (w * h):.2f} | |")
# The copy ceiling's ways per frame (BM_Memcpy, BM_CopyLoop, BM_CopyStream, BM_CopyHalide), the
# pass's bytes against the LLC the OS reports (frame_vs_llc), the fastest marked.
copies = ["| frame | pass bytes / LLC | threads | " + " | ".join(f"{v} ms" for v in COPIES.values()) + " | ceiling |",
          "|---|---|---|" + "---|" * len(COPIES) + "---|"]
for (w, h, t) in sorted(ceiling, key=lambda k: (k[0] * k[1], k[2])):
    cells = []
    for n in COPIES:
        b = rows.get(f"{n}/w:{w}/h:{h}/threads:{t}/min_time:0.200/manual_time", (None, None, None))[2]
        cells.append(f"{ms(b):.3f}" if b else "-")
    way, b = ceiling[(w, h, t)]
    llc = f"{b['frame_vs_llc']:.3f}" if "frame_vs_llc" in b else "-"
    copies.append(f"| {w}x{h} | {llc} | {t} | " + " | ".join(cells) + f" | {way} {ms(b):.3f} ms |")
cache += [""] + copies
# Where the host call's time goes (BM_HostCallParts: apply's steps before buffer caching, timed apart).
# way: 0 before (separate wait, map, unmap, finish), 4 apply before, 7 apply now; see fog_bench.cpp.
parts = ["| host call parts, µs | storage | way | create buffers | checks | writes | enqueue | wait | device | "
         "queued -> start | unmap + finish (map too for way 0) | release | call ms | call / device |",
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
for name, (n, a, b) in sorted(((k, v) for k, v in rows.items() if v[0] == "BM_HostCallParts"),
                              key=lambda kv: (int(kv[1][1]["w"]), kv[1][1]["mode"], kv[1][1]["f16"],
                                              int(kv[1][1].get("way", "0")))):
    parts.append(f"| {a['w']}x{a['h']} {MODES[a['mode']]} {'distance' if a['dist'] == '1' else 'depth'} | "
                 f"{'f16' if a['f16'] == '1' else 'f32'} | {a.get('way', '0')} | " +
                 " | ".join(f"{b[k]:.0f}" for k in ("create_us", "check_us", "sync_us", "enqueue_us", "wait_us",
                                                    "device_us", "launch_us", "readback_us", "release_us")) +
                 f" | {ms(b):.3f} | {b['parts_vs_device']:.2f} |")
# Linear against exp and exp2 under the same conditions (BM_ModeAB) and the kernel's block classes.
modes_ab = ["| frame | metric | storage | linear ms | exp ms | exp2 ms | linear / exp2 | blocks copy / fog / mix / "
            "per-lane: linear | exp2 |", "|---|---|---|---|---|---|---|---|---|"]
for name, (n, a, b) in sorted(((k, v) for k, v in rows.items() if v[0] == "BM_ModeAB"),
                              key=lambda kv: (int(kv[1][1]["w"]), kv[1][1]["dist"], kv[1][1]["f16"])):
    share = lambda p: " / ".join(f"{100 * b[p + k]:.1f}" for k in ("copy", "fog", "mix", "lanes"))
    modes_ab.append(f"| {a['w']}x{a['h']} | {'distance' if a['dist'] == '1' else 'depth'} | "
                    f"{'f16' if a['f16'] == '1' else 'f32'} | {b['linear_ms']:.2f} | {b['exp_ms']:.2f} | "
                    f"{b['exp2_ms']:.2f} | {b['linear_vs_exp2']:.2f} | {share('lin_')} % | {share('exp2_')} % |")
parts += [""] + modes_ab
(out / "table.md").write_text("\n".join(lines) + "\n\n" + "\n".join(cache) + "\n\n" + "\n".join(parts) +
                              "\n\n| start-up and overhead | median |\n|---|---|\n" + "\n".join(extra) + "\n")
print((out / "table.md").read_text())
