#!/usr/bin/python3
"""Fogs a shot's frames with fogcl's Python module, several frames at once on threads: the
Python version of examples/slurm_fog_shot.sh, described by the same environment variables, and
like it one Slurm array task per chunk of CHUNK frames (without SLURM_ARRAY_TASK_ID: every frame).

    FIRST, LAST    the shot's first and last frame numbers                               (required)
    COLOR          the renderer's frames, e.g. 'render/shot.####.exr' (or %04d)          (required)
    OUT            where the fogged frames go, e.g. 'fogged/shot.####.exr'; its folder is created
    NEAR, MODE     camera near plane [world units]; fog mode exp, exp2, linear, height or off
    FAR            camera far plane (required unless FOGCL_ARGS has --infinite-far)
    CHUNK          frames per array task (default 50)
    DEPTH          depth frames (default: the color file's depth channel)
    DEPTH_CHANNEL, DEPTH_KIND, DENSITY, FOG_COLOR, START, END, PIXEL_TYPE, COMPRESSION, DEVICE
                   as in examples/slurm_fog_shot.sh
    FOGCL_ARGS     further `fogcl apply` flags, e.g. '--fov 40 --reversed-z'
    THREADS        frames in flight at once (default: SLURM_CPUS_PER_TASK, else the cores this
                   process may use)

Each frame is read, fogged and written on a worker thread; fogcl releases the GIL while it reads,
fogs and writes, so the frames overlap. A frame that fails is reported and the others go on; the
exit status is then 1. Outputs appear complete or not at all, as the CLI's.

    FIRST=1 LAST=48 COLOR='render/shot.####.exr' OUT='fogged/shot.####.exr' NEAR=0.1 FAR=2000 \\
      MODE=exp2 DENSITY=0.004 PYTHONPATH=build/python /usr/bin/python3 examples/python/fog_sequence.py
"""

import os
import re
import shlex
import sys
from concurrent.futures import ThreadPoolExecutor

import fogcl


def need(name):
    value = os.environ.get(name, "")
    if not value:
        sys.exit(f"fog_sequence: error: set {name} (see the header of {sys.argv[0]})")
    return value


def frame_path(pattern, frame):
    """'shot.####.exr' or 'shot.%04d.exr' -> 'shot.0042.exr'."""
    hashes = re.search(r"#+", pattern)
    if hashes:
        return pattern[:hashes.start()] + str(frame).zfill(len(hashes.group())) + pattern[hashes.end():]
    return re.sub(r"%0(\d+)d", lambda m: str(frame).zfill(int(m.group(1))), pattern, count=1)


def flag_options(args):
    """'--fov 40 --reversed-z' -> {'fov': '40', 'reversed_z': True}."""
    words, options, i = shlex.split(args), {}, 0
    while i < len(words):
        key = words[i].removeprefix("--").replace("-", "_")
        if i + 1 < len(words) and not words[i + 1].startswith("--"):
            options[key], i = words[i + 1], i + 2
        else:
            options[key], i = True, i + 1
    return options


def main():
    first, last = int(need("FIRST")), int(need("LAST"))
    color, out = need("COLOR"), need("OUT")
    chunk = int(os.environ.get("CHUNK", "50"))
    task = os.environ.get("SLURM_ARRAY_TASK_ID")
    if task is not None:  # this task's chunk
        first = first + int(task) * chunk
        last = min(first + chunk - 1, last)
        if first > last:
            print(f"fog_sequence: task {task}: no frames (the shot ends at {last})")
            return 0
    options = {"near": need("NEAR"), "mode": need("MODE")}
    for name, key in [("FAR", "far"), ("DEPTH_KIND", "depth_kind"), ("DENSITY", "density"),
                      ("FOG_COLOR", "fog_color"), ("START", "start"), ("END", "end"), ("DEVICE", "device")]:
        if os.environ.get(name):
            options[key] = os.environ[name]
    options.update(flag_options(os.environ.get("FOGCL_ARGS", "")))
    reading = {"depth_kind": options.get("depth_kind", "raw"), "reversed_z": bool(options.get("reversed_z")),
               "infinite_far": bool(options.get("infinite_far")), "pixel_type": os.environ.get("PIXEL_TYPE", "float")}
    if os.environ.get("DEPTH_CHANNEL"):
        reading["depth_channel"] = os.environ["DEPTH_CHANNEL"]
    writing = {"pixel_type": reading["pixel_type"], "compression": os.environ.get("COMPRESSION") or None}
    depth = os.environ.get("DEPTH", "")
    threads = int(os.environ.get("THREADS") or os.environ.get("SLURM_CPUS_PER_TASK") or len(os.sched_getaffinity(0)))
    os.makedirs(os.path.dirname(out) or ".", exist_ok=True)

    def fog(frame):
        source = fogcl.read_exr(frame_path(color, frame), depth=frame_path(depth, frame) if depth else "", **reading)
        fogged = fogcl.apply(source.color, source.depth, out=source.color, camera=source.camera, **options)
        fogcl.write_exr(frame_path(out, frame), fogged, source=source, **writing)

    frames = range(first, last + 1)
    print(f"fog_sequence: frames {first}-{last}, {threads} thread(s)")
    failed = 0
    with ThreadPoolExecutor(max_workers=threads) as pool:
        for frame, done in zip(frames, [pool.submit(fog, f) for f in frames]):
            try:
                done.result()
            except (ValueError, OSError, RuntimeError, MemoryError) as e:
                failed += 1
                print(f"fog_sequence: frame {frame} failed: {e}", file=sys.stderr)
    if failed:
        print(f"fog_sequence: error: {failed} of {len(frames)} frames failed", file=sys.stderr)
        return 1
    print(f"fog_sequence: wrote {len(frames)} frames to {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
