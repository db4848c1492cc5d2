"""fogcl.apply's keywords are `fogcl apply`'s flags: a bad or contradictory set raises ValueError
with the CLI's own message, and nothing escapes as a crash."""

import subprocess

import numpy as np
import pytest

import fogcl
from frames import flags, random_frame

BASE = {"near": 0.3, "far": 1000, "fov": 60, "mode": "exp2", "density": 0.025}

# Each breaks one rule (or is malformed): the CLI refuses it with exit 1 or 2 and one line.
BAD = [
    {"bogus": 3},
    {"mode": "EXP"},
    {"mode": "fog"},
    {"near": -1},
    {"near": "x"},
    {"far": 0.1},
    {"far": None},
    {"fov": 180},
    {"fov": 60, "ortho_size": 5},
    {"density": -0.1},
    {"fog_color": (1, 2)},
    {"fog_color": (1e9, 0, 0)},
    {"mode": "linear", "start": 10, "end": 1},
    {"precision": "fast", "max_error": 0.01},
    {"device": "scalar", "host_transfer": "staged"},
    {"depth_kind": "linear"},
    {"ortho_size": 4, "fov": None, "infinite_far": True},
    {"depth_kind": "distance", "ortho_size": 4, "fov": None},
    {"mode": "exp", "extinction": 0.1},
    {"volumes": "/nonexistent/volumes.json", "eye": (0, 0, 0), "forward": (0, 0, 1), "up": (0, 1, 0)},
    {"device": "no-such-device-name"},
]


@pytest.mark.parametrize("bad", BAD, ids=[",".join(b) for b in BAD])
def test_bad_options_raise_the_cli_message(cli, tmp_path, bad):
    options = {**BASE, **bad}
    color, depth = random_frame(np.random.default_rng(0), 4, 6)
    c, d = str(tmp_path / "c.exr"), str(tmp_path / "d.exr")
    fogcl.write_exr(c, color)
    fogcl.write_exr_depth(d, depth)
    r = subprocess.run([cli, "apply", "--color", c, "--depth", d, "--out", str(tmp_path / "o.exr")] + flags(options),
                       capture_output=True, text=True)
    assert r.returncode in (1, 2) and r.stderr.count("\n") == 1, r.stderr
    cli_message = r.stderr.strip().removeprefix("fogcl: error: ").removesuffix(" (see --help)")
    with pytest.raises(ValueError) as e:
        fogcl.apply(color, depth, **options)
    print(f"{bad}: {e.value}")
    # The file name the CLI puts first is the frame's own name in the module.
    assert str(e.value).replace("fogcl.apply: ", "") == cli_message.replace(c + ": ", "")


@pytest.mark.parametrize("key", ["color", "out", "png", "layer", "depth_channel", "rgba_only", "pixel_type",
                                 "compression", "frames", "keep_going", "threads", "verbose"])
def test_file_flags_are_refused_with_the_way_to_do_it(key):
    color, depth = random_frame(np.random.default_rng(1), 2, 2)
    options = {**BASE, key: "x"}
    with pytest.raises((ValueError, TypeError)) as e:
        fogcl.apply(color, depth, **options) if key != "out" else fogcl.apply(color, depth, out="x", **BASE)
    print(e.value)
    assert key + "=" in str(e.value) or "out=" in str(e.value)


@pytest.mark.parametrize("case", ["shape", "dtype", "depth_dtype", "size", "channels_apart", "read_only_out",
                                  "out_shape", "out_not_array", "overlap"])
def test_bad_arrays_raise_value_error_naming_the_rule(case):
    rng = np.random.default_rng(2)
    color, depth = random_frame(rng, 8, 12)
    kwargs = {}
    if case == "shape":
        color = color[..., :3]
    elif case == "dtype":
        color = color.astype(np.float64)
    elif case == "depth_dtype":
        depth = depth.astype(np.float16)
    elif case == "size":
        depth = depth[:7]
    elif case == "channels_apart":
        color = np.moveaxis(np.ascontiguousarray(np.moveaxis(color, 2, 0)), 0, 2)
    elif case == "read_only_out":
        out = np.zeros_like(color)
        out.flags.writeable = False
        kwargs["out"] = out
    elif case == "out_shape":
        kwargs["out"] = np.zeros((8, 11, 4), np.float32)
    elif case == "out_not_array":
        kwargs["out"] = [1, 2]
    elif case == "overlap":
        big = np.zeros((8, 13, 4), np.float32)
        big[:, :12] = color
        color, kwargs["out"] = big[:, :12], big[:, 1:]
    before = color.copy()
    with pytest.raises(ValueError) as e:
        fogcl.apply(color, depth, **kwargs, **BASE)
    print(f"{case}: {e.value}")
    assert np.array_equal(before, color, equal_nan=True)  # nothing written
