"""fogcl.read_exr / fogcl.write_exr read and write EXR files as `fogcl apply` does."""

import os
import subprocess

import numpy as np
import pytest

import fogcl
from frames import bits, random_frame

COMPRESSIONS = ["none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab"]
LOSSLESS = {"none", "rle", "zips", "zip", "piz"}


@pytest.mark.parametrize("compression", COMPRESSIONS)
@pytest.mark.parametrize("pixel_type", ["float", "half"])
def test_write_then_read_gives_the_pixels_back(tmp_path, compression, pixel_type):
    rng = np.random.default_rng([COMPRESSIONS.index(compression), pixel_type == "half"])
    dtype = np.float16 if pixel_type == "half" else np.float32
    color, depth = random_frame(rng, int(rng.integers(1, 40)), int(rng.integers(1, 40)), dtype)
    path, dpath = str(tmp_path / "c.exr"), str(tmp_path / "d.exr")
    fogcl.write_exr(path, color, pixel_type=pixel_type, compression=compression)
    fogcl.write_exr_depth(dpath, depth)
    frame = fogcl.read_exr(path, depth=dpath, pixel_type=pixel_type)
    assert frame.compression == compression
    assert frame.color.dtype == dtype and frame.color.shape == color.shape
    assert frame.display_window == (0, 0, color.shape[1] - 1, color.shape[0] - 1)
    err = float(np.max(np.abs(frame.color.astype(np.float64) - color.astype(np.float64))))
    print(f"{pixel_type} {compression} {color.shape}: worst |read - written| = {err}")
    if compression in LOSSLESS or (compression == "pxr24" and pixel_type == "half"):
        assert np.array_equal(bits(frame.color), bits(color))
    assert np.array_equal(frame.depth, depth)


def test_source_keeps_the_files_other_channels_as_the_cli_output(cli, tmp_path):
    """write_exr(source=frame) writes what `fogcl apply --out` writes: the same file, byte for byte
    after the fog, given the same fogged pixels."""
    rng = np.random.default_rng(21)
    color, depth = random_frame(rng, 17, 23)
    c, d = str(tmp_path / "c.exr"), str(tmp_path / "d.exr")
    fogcl.write_exr(c, color, compression="piz")
    fogcl.write_exr_depth(d, depth)
    # The CLI's output has the input's parts and attributes; read it back as a source.
    flags = ["--near", "0.3", "--far", "100", "--fov", "50", "--mode", "exp", "--density", "0.05"]
    subprocess.run([cli, "apply", "--color", c, "--depth", d, "--out", str(tmp_path / "cli.exr")] + flags, check=True)
    frame = fogcl.read_exr(c, depth=d)
    fogged = fogcl.apply(frame.color, frame.depth, camera=frame.camera, near=0.3, far=100, fov=50, mode="exp",
                         density=0.05)
    fogcl.write_exr(str(tmp_path / "py.exr"), fogged, source=frame)
    a, b = (tmp_path / "cli.exr").read_bytes(), (tmp_path / "py.exr").read_bytes()
    print("cli output", len(a), "bytes, module output", len(b), "bytes")
    assert a == b


def test_a_failed_write_leaves_nothing_and_says_why(tmp_path):
    color, _ = random_frame(np.random.default_rng(22), 4, 4)
    with pytest.raises(OSError) as e:
        fogcl.write_exr(str(tmp_path / "missing-folder" / "o.exr"), color)
    print(e.value)
    assert "missing-folder" in str(e.value)
    assert os.listdir(tmp_path) == []
    # An existing file is replaced whole or not at all: a bad compression leaves it as it was.
    target = tmp_path / "o.exr"
    target.write_bytes(b"old")
    with pytest.raises(ValueError) as e:
        fogcl.write_exr(str(target), color, compression="jpeg")
    print(e.value)
    assert target.read_bytes() == b"old" and sorted(os.listdir(tmp_path)) == ["o.exr"]


def test_read_errors_name_the_file(tmp_path):
    bad = tmp_path / "bad.exr"
    bad.write_bytes(b"not an exr")
    for path, kwargs, error in [(str(bad), {}, OSError), (str(tmp_path / "none.exr"), {}, OSError),
                                (str(bad), {"depth_kind": "far"}, ValueError)]:
        with pytest.raises(error) as e:
            fogcl.read_exr(path, **kwargs)
        print(e.value)
        assert path in str(e.value) or "--depth-kind" in str(e.value)
