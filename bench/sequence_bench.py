#!/usr/bin/python3
"""`fogcl apply` on frame sequences against its ceiling, OpenEXR alone (bench/exr_peer.cpp).

Generates demo-scene sequences (bench/make_sequence.cpp) once, then for each thread count and
case runs the peer and fogcl one after the other (their order alternating between repetitions,
so that a noisy machine hurts both alike) and takes the median wall time of each. The output is
the input's pixel type (half in -> --pixel-type half) and compression. With --baseline, the
fogcl binary of before the pipeline (one thread, float output) runs on --baseline-cases too.

  bench/sequence_bench.py --bin build --out out/sequence [--threads 1,2,16] [--reps 3]
                          [--cases 1080p-float-zip,...] [--baseline OLD_FOGCL] [--device cpu|gpu|scalar]
                          [--frames N]  (every case with N frames: a long shot amortises the start-up)
                          [--fogcl-args "..."]  (more fogcl apply arguments, e.g. "--host-transfer direct")
                          [--pin]   (runs with N threads on N cores: taskset -c 0-(N-1))
                          [--first-core K]  (with --pin: cores K..K+N-1; a VM's core 0 also
                                             serves its interrupts)

Writes OUT/runs.json (every run) and OUT/table.md (medians, frames/s and ratios).
"""
import argparse
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

CASES = {  # name: (width, height, frames, pixel type, compression)
    "1080p-float-zip": (1920, 1080, 24, "float", "zip"),
    "1080p-float-piz": (1920, 1080, 24, "float", "piz"),
    "1080p-half-zip": (1920, 1080, 24, "half", "zip"),
    "1080p-half-piz": (1920, 1080, 24, "half", "piz"),
    "4k-float-zip": (3840, 2160, 12, "float", "zip"),
    "4k-float-piz": (3840, 2160, 12, "float", "piz"),
    "4k-half-zip": (3840, 2160, 12, "half", "zip"),
    "4k-half-piz": (3840, 2160, 12, "half", "piz"),
}
FOG = ["--near", "0.3", "--far", "1000", "--fov", "60", "--mode", "exp2", "--density", "0.02"]


def find(bin_dir, name):
    for p in (Path(bin_dir) / name, Path(bin_dir) / "bench" / name, Path(bin_dir) / "src" / name):
        if p.exists():
            return str(p)
    sys.exit(f"sequence_bench: no {name} under {bin_dir}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default="build")
    ap.add_argument("--out", default="out/sequence")
    ap.add_argument("--data", default=None, help="where the sequences are generated (default OUT/data)")
    ap.add_argument("--threads", default="1,2," + str(len(os.sched_getaffinity(0))))
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--baseline", default=None)
    ap.add_argument("--baseline-cases", default="1080p-float-zip")
    ap.add_argument("--device", default="cpu")
    ap.add_argument("--frames", type=int, default=0, help="frames of every case (default: the case's own)")
    ap.add_argument("--fogcl-args", default="", help="more arguments of fogcl apply (e.g. --host-transfer direct)")
    ap.add_argument("--pin", action="store_true")
    ap.add_argument("--first-core", type=int, default=0)
    ap.add_argument("--scratch", default=None, help="where outputs are written (default OUT/scratch)")
    a = ap.parse_args()
    fogcl, peer, make = (find(a.bin, n) for n in ("fogcl", "fogcl_exr_peer", "fogcl_make_sequence"))
    out = Path(a.out)
    data = Path(a.data) if a.data else out / "data"
    scratch = Path(a.scratch) if a.scratch else out / "scratch"
    out.mkdir(parents=True, exist_ok=True)
    cases = a.cases.split(",")
    threads = [int(t) for t in a.threads.split(",")]

    # Generate what is missing, several sequences at once.
    jobs = []
    def case(c):
        w, h, n, ptype, comp = CASES[c]
        return (w, h, a.frames, ptype, comp, data / f"{c}-{a.frames}") if a.frames else (w, h, n, ptype, comp, data / c)

    for c in cases:
        w, h, n, ptype, comp, d = case(c)
        if not (d / f"depth.{n:04d}.exr").exists():
            d.mkdir(parents=True, exist_ok=True)
            jobs.append(subprocess.Popen([make, str(d), str(w), str(h), str(n), ptype, comp]))
        if len(jobs) >= 4:
            [j.wait() for j in jobs]
            jobs = []
    if any(j.wait() != 0 for j in jobs):
        sys.exit("sequence_bench: generating a sequence failed")

    def timed(cmd, t):
        shutil.rmtree(scratch, ignore_errors=True)
        scratch.mkdir(parents=True)
        if a.pin:
            cmd = ["taskset", "-c", f"{a.first_core}-{a.first_core + t - 1}"] + cmd
        start = time.perf_counter()
        r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        seconds = time.perf_counter() - start
        if r.returncode != 0:
            sys.exit(f"sequence_bench: {' '.join(cmd)} failed:\n{r.stderr}")
        return seconds

    runs = []
    for rep in range(a.reps):
        for t in threads:
            for c in cases:
                w, h, n, ptype, comp, d = case(c)
                tools = {
                    "peer": [peer, f"{d}/color.%04d.exr", f"{d}/depth.%04d.exr", f"{scratch}/p.%04d.exr", "1", str(n),
                             str(t), ptype, "input"],
                    "fogcl": [fogcl, "apply", "--color", f"{d}/color.####.exr", "--depth", f"{d}/depth.####.exr",
                              "--out", f"{scratch}/f.####.exr", *FOG, "--threads", str(t), "--device", a.device,
                              "--pixel-type", ptype, *a.fogcl_args.split()],
                }
                if a.baseline and c in a.baseline_cases.split(",") and t == threads[0]:  # one thread whatever t is
                    tools["before"] = [a.baseline, "apply", "--color", f"{d}/color.####.exr", "--depth",
                                       f"{d}/depth.####.exr", "--out", f"{scratch}/b.####.exr", *FOG,
                                       "--device", a.device]
                order = list(tools) if rep % 2 == 0 else list(reversed(tools))
                for tool in order:
                    s = timed(tools[tool], t)
                    runs.append({"case": c, "tool": tool, "threads": t, "rep": rep, "seconds": s, "frames": n})
                    print(f"rep {rep} {c:16s} {t:2d} threads {tool:6s} {s:7.2f} s  {n / s:6.2f} frames/s", flush=True)
                    save(out, a, runs)  # after every run: a run cut short still leaves its results
    shutil.rmtree(scratch, ignore_errors=True)
    print(table(save(out, a, runs), runs))


def save(out, a, runs):
    meta = {"machine": platform.node(), "cores": len(os.sched_getaffinity(0)), "device": a.device,
            "pinned": a.pin, "first_core": a.first_core, "reps": a.reps, "time": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())}
    (out / "runs.json").write_text(json.dumps({"meta": meta, "runs": runs}, indent=1))
    (out / "table.md").write_text(table(meta, runs))
    return meta


def fps(runs, case, tool, t=None):
    s = [r["seconds"] for r in runs if r["case"] == case and r["tool"] == tool and (t is None or r["threads"] == t)]
    return None if not s else next(r["frames"] for r in runs if r["case"] == case) / statistics.median(s)


def table(meta, runs):
    threads = sorted({r["threads"] for r in runs})
    cases = list(dict.fromkeys(r["case"] for r in runs))
    lines = [f"{meta['cores']} cores ({meta['machine']}), fog on {meta['device']}, median of {meta['reps']}"
             f"{', N threads pinned to N cores' if meta['pinned'] else ''}, {meta['time']}", "",
             "| case | threads | OpenEXR alone (frames/s) | fogcl apply (frames/s) | ratio | before (frames/s) | fogcl / before |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for c in cases:
        before = fps(runs, c, "before")
        for t in threads:
            p, f = fps(runs, c, "peer", t), fps(runs, c, "fogcl", t)
            if p is None or f is None:
                continue
            b = f"{before:.2f}" if before else ""
            bx = f"{f / before:.2f}x" if before else ""
            lines.append(f"| {c} | {t} | {p:.2f} | {f:.2f} | {f / p:.2f} | {b} | {bx} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
