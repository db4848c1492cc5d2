#!/usr/bin/env python3
"""Summarises a gpu-run.sh results folder as Markdown on stdout: the test suite's totals,
failures and skips, then the benchmarks against their targets (docs/gpu.md). A line starting with
"FAILED" marks a failed test or a missed target (gpu-run.sh exits non-zero on one)."""
import glob
import json
import os
import re
import sys
import xml.etree.ElementTree as ET

results = sys.argv[1] if len(sys.argv) > 1 else "."
out = []


def p(line=""):
    out.append(line)


def load(name):
    path = os.path.join(results, name)
    if not os.path.exists(path):
        return []
    with open(path) as f:
        text = f.read()
    try:
        data = json.loads(text)
    except json.JSONDecodeError:
        return []
    rows = []
    for b in data.get("benchmarks", []):
        if b.get("run_type") == "aggregate" and b.get("aggregate_name") != "median":
            continue
        b = dict(b)
        b["base"] = b.get("run_name", b["name"])
        rows.append(b)
    return rows


def ms(b):
    scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b.get("time_unit", "ns")]
    return b["real_time"] * scale


def args(name):
    return dict(re.findall(r"(\w+):(\d+)", name))


# fog_bench.cpp's mode argument.
MODES = {"0": "linear", "1": "exp", "2": "exp2", "3": "height valley", "4": "height haze"}


with open(os.path.join(results, "machine.txt")) if os.path.exists(os.path.join(results, "machine.txt")) else open(os.devnull) as f:
    p("# fogcl on the GPU machine")
    p()
    for line in f:
        p("- " + line.rstrip())
    p()

# ---- tests -----------------------------------------------------------------------------------
xmls = sorted(glob.glob(os.path.join(results, "tests-*.xml")))
logs = sorted(glob.glob(os.path.join(results, "tests-*.log")))
if logs:
    passed, failed, skipped = 0, [], []
    for x in xmls:
        for case in ET.parse(x).getroot().iter("testcase"):
            name = f'{case.get("classname")}.{case.get("name")}'
            failure = case.find("failure")
            skip = case.find("skipped")
            if failure is not None:
                failed.append((name, (failure.get("message") or "").splitlines()[0:3]))
            elif skip is not None or case.get("result") == "skipped":
                msg = (skip.get("message") if skip is not None else "") or ""
                skipped.append((name, msg.strip().splitlines()[-1] if msg.strip() else ""))
            else:
                passed += 1
    p("## Test suite (FOGCL_DEVICE=gpu)")
    p()
    p(f"{passed} passed, {len(failed)} failed, {len(skipped)} skipped ({len(xmls)} of {len(logs)} shards wrote XML)")
    p()
    if len(xmls) < len(logs):
        p(f"FAILED: {len(logs) - len(xmls)} shards ended without their XML (crash or timeout: see tests-N.log)")
    for name, msg in failed:
        p(f"FAILED: {name}: {' / '.join(m.strip() for m in msg)}")
    if skipped:
        p()
        p("Skipped, by reason:")
        reasons = {}
        for name, msg in skipped:
            reasons.setdefault(msg, []).append(name)
        for msg, names in sorted(reasons.items(), key=lambda kv: -len(kv[1])):
            example = names[0] if len(names) == 1 else f"{len(names)} tests, e.g. {names[0]}"
            p(f"- {msg} ({example})")
    p()

# ---- deferred pass ---------------------------------------------------------------------------
fog = load("fog-gpu.json")
if fog:
    copies = {}
    for b in fog:
        if b["base"].startswith("BM_DeviceCopy/"):
            a = args(b["base"])
            copies[(a["w"], a["f16"])] = b
    host = {}
    for b in fog:
        if b["base"].startswith("BM_OpenCLHostCall/"):
            a = args(b["base"])
            host[(a["w"], a["mode"], a["dist"], a["f16"])] = b
    p("## Deferred pass on the GPU (median of 3)")
    p()
    p("Device-resident: device buffers, kernel time from profiling events. Copy: clEnqueueCopyBuffer of")
    p("color and depth (read + written bytes). bw_vs_copy = pass bandwidth / copy bandwidth, the copy")
    p("interleaved with the pass's iterations. Round trip: the convenience call (upload + kernel + download).")
    p()
    p("| frame | mode | metric | color | device ms | GB/s | copy GB/s | bw_vs_copy | round trip ms | max err |")
    p("|---|---|---|---|---:|---:|---:|---:|---:|---:|")
    worst = {}
    for b in fog:
        if not b["base"].startswith("BM_OpenCLDevice/"):
            continue
        a = args(b["base"])
        copy = copies.get((a["w"], a["f16"]))
        rt = host.get((a["w"], a["mode"], a["dist"], a["f16"]))
        fmt = "f16" if a["f16"] == "1" else "f32"
        ratio = b.get("bw_vs_copy", float("nan"))
        if a["w"] == "3840":  # Unity's modes against 0.8 of the copy, height fog against 0.9
            group = "height fog" if MODES[a["mode"]].startswith("height") else "linear, exp, exp2"
            worst[(group, fmt)] = min(worst.get((group, fmt), 9e9), ratio)
        p(f'| {a["w"]}x{a["h"]} | {MODES[a["mode"]]} | {"distance" if a["dist"] == "1" else "depth"} | {fmt} '
          f'| {ms(b):.4f} | {b["bytes_per_second"] / 1e9:.0f} '
          f'| {copy["bytes_per_second"] / 1e9 if copy else float("nan"):.0f} | {ratio:.2f} '
          f'| {ms(rt) if rt else float("nan"):.2f} | {b.get("max_err", float("nan")):.2g} |')
    p()
    for (group, fmt), r in sorted(worst.items()):
        target = 0.9 if group == "height fog" else 0.8
        verdict = "met" if r >= target else "FAILED"
        line = f"4K device-resident {group} {fmt}: worst bw_vs_copy {r:.2f} (target >= {target}): {verdict}"
        p(line if verdict == "met" else "FAILED: " + line)
    for b in fog:
        if re.match(r"BM_(DispatchOverhead|FirstDispatch|ProgramBuild)", b["base"]):
            p(f'- {b["base"].split("/min_time")[0].split("/manual_time")[0]}: {ms(b):.3f} ms')
    p()

# ---- volumetric pass -------------------------------------------------------------------------
vol = load("volume-gpu.json")
if vol:
    integ = {"0": "stylized", "1": "physical"}
    p("## Volumetric pass on the GPU (demo scene, 4 volumes, 64 steps, noise on; median of 3)")
    p()
    p("| frame | integrator | resolution | noise | march ms | composite ms | device ms | steps·px/s | round trip ms | max err (480x270) |")
    p("|---|---|---|---|---:|---:|---:|---:|---:|---:|")
    errs = {}
    host = {}
    for b in vol:
        a = args(b["base"])
        if b["base"].startswith("BM_VolumeDevice/") and a["width"] == "480":
            errs[(a["integrator"], a["divisor"], a["noise_image"])] = b.get("max_err", float("nan"))
        if b["base"].startswith("BM_VolumeHostCall/"):
            if a.get("f16", "0") == "0":
                host[(a["integrator"], a["divisor"], a["noise_image"], a["width"])] = b
    for b in vol:
        if not b["base"].startswith("BM_VolumeDevice/"):
            continue
        a = args(b["base"])
        res = {"1": "full", "2": "half", "4": "quarter"}[a["divisor"]]
        key = (a["integrator"], a["divisor"], a["noise_image"])
        rt = host.get(key + (a["width"],))
        p(f'| {a["width"]}x{int(a["width"]) * 9 // 16} | {integ[a["integrator"]]} | {res} '
          f'| {"image" if a["noise_image"] == "1" else "buffer"} | {b["march_ms"]:.3f} | {b["composite_ms"]:.3f} '
          f'| {ms(b):.3f} | {b["steps_x_pixels_per_s"]:.3g} | {ms(rt) if rt else float("nan"):.2f} '
          f'| {errs.get(key, float("nan")):.2g} |')
    p()
    for b in vol:
        a = args(b["base"])
        if b["base"].startswith("BM_VolumeDevice/") and a["width"] == "1920":
            limit = 4.0 if a["divisor"] == "1" else 1.0
            res = "full" if a["divisor"] == "1" else "half"
            noise = "image" if a["noise_image"] == "1" else "buffer"
            ok = ms(b) <= limit
            line = f'1080p {integ[a["integrator"]]} {res}, noise {noise}: {ms(b):.3f} ms (target <= {limit:g} ms): {"met" if ok else "missed"}'
            p("- " + line)
        if b["base"].startswith("BM_VolumeNothingVisible"):
            p(f'- nothing visible: {ms(b) * 1e3:.1f} µs, {b.get("dispatches", 0):.0f} dispatches')
    p()
scalar = load("volume-scalar.json")
for b in scalar:
    a = args(b["base"])
    p(f'- scalar float march, 480x270 half, {"stylized" if a["integrator"] == "0" else "physical"}, one thread: '
      f'{ms(b):.1f} ms, {b["steps_x_pixels_per_s"]:.3g} steps·px/s')
if scalar:
    p()

# ---- a GPU renderer's frame where it lies ----------------------------------------------------
inter = load("interop-gpu.json")
if inter:
    p("## A CUDA producer's frame fogged in its memory (exp2, in place; median of 200)")
    p()
    p("| frame | storage | signal to signal ms | deferred pass ms | beyond the pass µs | target: pass + 50 µs |")
    p("|---|---|---:|---:|---:|---|")
    for b in inter:
        if not b["base"].startswith("BM_ExternalSignalToSignal/"):
            continue
        a = args(b["base"])
        if "error_message" in b or "pass_ms" not in b:
            p(f'| {a.get("w")}x{a.get("h")} | | skipped: {b.get("error_message", "no figures")} | | | |')
            continue
        over = b["over_pass_us"]
        verdict = "met" if over <= 50 else "FAILED"
        p(f'| {a["w"]}x{a["h"]} | {"f16" if a["f16"] == "1" else "f32"} | {b["median_ms"]:.4f} | {b["pass_ms"]:.4f} '
          f'| {over:.1f} | {verdict} |')
    p()
    parts = {"0": "CUDA signals and waits alone", "1": "+ OpenCL waits and signals", "2": "+ acquire, release",
             "3": "+ the deferred pass (ExternalFrame::enqueue)", "4": "no semaphores: the host waits both ways",
             "5": "OpenCL signals alone", "6": "part 1 on a queue without profiling",
             "7": "OpenCL waits, then writes a counter CUDA waits for (no OpenCL signal)"}
    for b in inter:
        if b["base"].startswith("BM_ExternalHandOverParts/") and "error_message" not in b:
            part = args(b["base"])["part"]
            p(f'- hand-over part {part}, {parts.get(part, "?")} (1080p f16): {ms(b) * 1e3:.1f} µs')
    p()
    vulkan = [b for b in inter if b["base"].startswith("BM_VulkanSignalToSignal/")]
    if vulkan:
        p("## A Vulkan producer's frame fogged in its memory (exp2 or the fog volumes, in place; Vulkan timestamps, median of 200)")
        p()
        whats = {"0": "ExternalFrame::enqueue", "1": "OpenCL waits and signals only", "2": "no OpenCL: Vulkan's round trip"}
        orders = {"0": "fogcl enqueued first", "1": "fogcl enqueued after Vulkan's signal ran"}
        p("| frame | storage | fogcl's side | order | signal to signal ms | pass ms | beyond the pass µs |"
          " target: deferred pass + 50 µs, volumes 1.1x the pass |")
        p("|---|---|---|---|---:|---:|---:|---|")
        for b in vulkan:
            a = args(b["base"])
            if "error_message" in b or "pass_ms" not in b:
                p(f'| {a.get("w")}x{a.get("h")} | | | | skipped: {b.get("error_message", "no figures")} | | | |')
                continue
            over = b["over_pass_us"]
            volumes = a.get("vol") == "1"
            # The volumes' pass_ms may include the host's enqueue (interop_vulkan_bench.cpp): their
            # ratio is a lower bound, which can fail the target but not meet it.
            if a["what"] != "0" or a["order"] != "0":
                verdict = "(a part)"
            elif volumes:
                verdict = (f'FAILED ({b["ratio"]:.2f}x)' if b["ratio"] > 1.1 else
                           f'undecided (>= {b["ratio"]:.2f}x: the pass time may include the host\'s enqueue)')
            else:
                verdict = "met" if over <= 50 else "FAILED"
            side = whats.get(a["what"], "?") + (", fog volumes" if volumes else ", deferred")
            p(f'| {a["w"]}x{a["h"]} | {"f16" if a["f16"] == "1" else "f32"} | {side} '
              f'| {orders.get(a["order"], "?")} | {b["median_ms"]:.4f} | {b["pass_ms"]:.4f} | {over:.1f} | {verdict} |')
        p()
    for b in inter:
        if b["base"].startswith("BM_VulkanReadyAlreadySignalled/") and "error_message" not in b:
            what = "OpenCL waits, then a marker" if args(b["base"])["wait"] == "1" else "a marker alone"
            p(f'- a "ready" Vulkan has already signalled, host clock to the marker\'s event: {what}: '
              f'{ms(b) * 1e3:.1f} µs')
    p()
    for b in inter:
        a = args(b["base"])
        whole = a.get("what", "0") == "0" and a.get("order", "0") == "0"
        producer = "Vulkan" if b["base"].startswith("BM_Vulkan") else "CUDA"
        if a.get("vol") == "1":
            if "ratio" in b and b["ratio"] > 1.1 and whole:
                p(f'FAILED: {producer} volumes {a["w"]}x{a["h"]} f16={a["f16"]}: the hand-over is {b["ratio"]:.2f}x '
                  f'the pass (target <= 1.1)')
        elif "over_pass_us" in b and b["over_pass_us"] > 50 and whole:
            p(f'FAILED: {producer} {a["w"]}x{a["h"]} f16={a["f16"]}: the hand-over costs {b["over_pass_us"]:.1f} µs '
              f'beyond the pass (target <= 50)')
    p()

# ---- host round trips against the bus ----------------------------------------------------------
# Each convenience call's round trip (BM_OpenCLHostCall in fog-gpu.json, BM_VolumeHostCall in
# volume-gpu.json) against BM_PinnedTransfer of the same bytes from the deferred run (color and
# depth up, color down: the three buffers both passes' apply moves), matched by frame size and
# storage. BM_VolumeHostCall names its width only (height = width * 9 / 16) and its storage (f16).
# ratio = round trip ms / pinned transfer ms; above 1.5 a line starts with FAILED.
transfers = {}
for b in fog:
    if b["base"].startswith("BM_PinnedTransfer/"):
        a = args(b["base"])
        transfers[(a["w"], a["h"], a["f16"], a["host"])] = b
if transfers:
    trips = []
    for b in fog:
        a = args(b["base"])
        if b["base"].startswith("BM_OpenCLHostCall/") and a["w"] in ("1920", "3840"):
            what = f'deferred {MODES.get(a["mode"], a["mode"])}{" distance" if a["dist"] == "1" else ""}'
            trips.append((what, a["w"], a["h"], a["f16"], b))
        if b["base"].startswith("BM_OpenCLHostCallPinned/"):
            what = f'deferred {MODES.get(a["mode"], a["mode"])}, pinned images'
            trips.append((what, a["w"], a["h"], a["f16"], b))
    for b in vol:
        a = args(b["base"])
        if b["base"].startswith("BM_VolumeHostCall/"):
            res = {"1": "full", "2": "half", "4": "quarter"}.get(a["divisor"], a["divisor"])
            what = (f'volume {"physical" if a["integrator"] == "1" else "stylized"} {res}, '
                    f'noise {"image" if a["noise_image"] == "1" else "buffer"}')
            trips.append((what, a["width"], str(int(a["width"]) * 9 // 16), a.get("f16", "0"), b))
    p("## Host round trip vs the pinned transfer of its bytes (median of 3)")
    p()
    p("Round trip: the convenience call, host images in and out. Pinned / pageable: BM_PinnedTransfer,")
    p("color and depth written to device buffers then color read back, from CL_MEM_ALLOC_HOST_PTR memory")
    p("mapped once / from ordinary memory, in the deferred pass's run. ratio = round trip / pinned (target <= 1.5).")
    p()
    p("| call | frame | color | round trip ms | pinned ms | pinned GB/s | pageable ms | pageable GB/s | ratio |")
    p("|---|---|---|---:|---:|---:|---:|---:|---:|")
    nan = float("nan")
    verdicts = []
    for what, w, h, f16, b in trips:
        pinned, pageable = transfers.get((w, h, f16, "1")), transfers.get((w, h, f16, "0"))
        fmt = "f16" if f16 == "1" else "f32"
        ratio = ms(b) / ms(pinned) if pinned else nan
        p(f'| {what} | {w}x{h} | {fmt} | {ms(b):.2f} | {ms(pinned) if pinned else nan:.2f} '
          f'| {pinned["GBps"] if pinned else nan:.1f} | {ms(pageable) if pageable else nan:.2f} '
          f'| {pageable["GBps"] if pageable else nan:.1f} | {ratio:.2f} |')
        if ratio > 1.5:
            verdicts.append(f"FAILED: round trip {what} {w}x{h} {fmt}: {ms(b):.2f} ms, {ratio:.2f}x the pinned "
                            f"transfer of its bytes ({ms(pinned):.2f} ms; target <= 1.5x)")
        elif not pinned:
            verdicts.append(f"- round trip {what} {w}x{h} {fmt}: no pinned transfer of its frame in fog-gpu.json")
    p()
    met = len(trips) - len(verdicts)
    p(f"- {met} of {len(trips)} round trips within 1.5x the pinned transfer of their bytes")
    for v in verdicts:
        p(v)
    p()

# ---- PoCL scaling ----------------------------------------------------------------------------
pocl = sorted(glob.glob(os.path.join(results, "volume-pocl-*.json")), key=lambda s: int(re.findall(r"(\d+)\.json", s)[0]))
if pocl:
    p("## PoCL on the machine's cores: the volumetric march, 1080p half, noise buffer (median of 3)")
    p()
    p("| threads | stylized march ms | speed-up | physical march ms | speed-up |")
    p("|---:|---:|---:|---:|---:|")
    base = {}
    for path in pocl:
        t = re.findall(r"(\d+)\.json", path)[0]
        cells = {}
        for b in load(os.path.basename(path)):
            if "march_ms" in b:
                cells[args(b["base"])["integrator"]] = b["march_ms"]
        for i in cells:
            base.setdefault(i, cells[i])
        row = [t]
        for i in ("0", "1"):
            if i in cells:
                row += [f"{cells[i]:.1f}", f"{base[i] / cells[i]:.1f}x"]
            else:
                row += ["", ""]
        p("| " + " | ".join(row) + " |")
    p()

print("\n".join(out))
