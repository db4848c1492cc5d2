"""The examples under examples/python run and do what they say: fog_sequence.py writes the frames
`fogcl apply` writes for the same shot, byte for byte."""

import os
import pathlib
import subprocess
import sys

import numpy as np

import fogcl
from frames import random_frame

EXAMPLES = pathlib.Path(__file__).resolve().parents[2] / "examples" / "python"


def run_example(name, args=(), env=None):
    return subprocess.run([sys.executable, str(EXAMPLES / name), *args], capture_output=True, text=True,
                          env={**os.environ, **(env or {})})


def test_fog_frame(tmp_path):
    r = run_example("fog_frame.py", [str(tmp_path / "fogged.exr")])
    print(r.stdout, r.stderr)
    assert r.returncode == 0
    color = fogcl.read_exr(str(tmp_path / "fogged.exr"), depth_channel="A").color  # written without depth
    assert np.all(np.isfinite(color))
    assert np.any(np.abs(color[-1, 0, :3] - (0.2, 0.4, 0.1)) > 1e-3)  # the ground is fogged


def test_fog_sequence_writes_the_clis_frames(cli, tmp_path):
    rng = np.random.default_rng(31)
    (tmp_path / "render").mkdir()
    for frame in range(7, 13):
        color, depth = random_frame(rng, 20, 30)
        fogcl.write_exr(str(tmp_path / "render" / f"shot.{frame:04d}.exr"), color, compression="piz")
        fogcl.write_exr_depth(str(tmp_path / "render" / f"depth.{frame:04d}.exr"), depth)
    shot = {"FIRST": "7", "LAST": "12", "COLOR": str(tmp_path / "render/shot.####.exr"),
            "DEPTH": str(tmp_path / "render/depth.####.exr"), "OUT": str(tmp_path / "py/shot.####.exr"),
            "NEAR": "0.3", "FAR": "1000", "MODE": "exp2", "DENSITY": "0.02", "FOG_COLOR": "0.6,0.7,0.8",
            "FOGCL_ARGS": "--fov 40 --distance", "THREADS": "3"}
    r = run_example("fog_sequence.py", env=shot)
    print(r.stdout, r.stderr)
    assert r.returncode == 0, r.stderr
    (tmp_path / "cli").mkdir()
    subprocess.run([cli, "apply", "--color", shot["COLOR"], "--depth", shot["DEPTH"], "--out",
                    str(tmp_path / "cli/shot.####.exr"), "--near", "0.3", "--far", "1000", "--mode", "exp2",
                    "--density", "0.02", "--fog-color", "0.6,0.7,0.8", "--fov", "40", "--distance"],
                   check=True, capture_output=True)
    for frame in range(7, 13):
        a = (tmp_path / f"py/shot.{frame:04d}.exr").read_bytes()
        b = (tmp_path / f"cli/shot.{frame:04d}.exr").read_bytes()
        assert a == b, frame
    # A chunk of a Slurm array: task 1 of chunks of 4 is frames 11-12.
    r = run_example("fog_sequence.py", env={**shot, "CHUNK": "4", "SLURM_ARRAY_TASK_ID": "1",
                                             "OUT": str(tmp_path / "chunk/shot.####.exr")})
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in (tmp_path / "chunk").iterdir()) == ["shot.0011.exr", "shot.0012.exr"]
    # A broken frame fails alone, named; the others are written.
    (tmp_path / "render/shot.0009.exr").write_bytes(b"broken")
    r = run_example("fog_sequence.py", env={**shot, "OUT": str(tmp_path / "bad/shot.####.exr")})
    print(r.stderr)
    assert r.returncode == 1
    assert "frame 9 failed" in r.stderr and "shot.0009.exr" in r.stderr
    assert sorted(p.name for p in (tmp_path / "bad").iterdir()) == [f"shot.{f:04d}.exr" for f in (7, 8, 10, 11, 12)]
