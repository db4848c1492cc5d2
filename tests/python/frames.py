"""Random frames and the CLI run that the module's results are compared with."""

import subprocess

import numpy as np

import fogcl


def random_frame(rng, height, width, dtype=np.float32, sky=0.1, reversed_z=False):
    """Linear RGBA in [0, 4) (alpha in [0, 1]) and raw depth in [0, 1), with a share `sky` of
    background pixels (raw depth 1, or 0 reversed)."""
    color = rng.uniform(0.0, 4.0, (height, width, 4)).astype(dtype)
    color[..., 3] = rng.uniform(0.0, 1.0, (height, width)).astype(dtype)
    depth = rng.uniform(0.0, 0.999, (height, width)).astype(np.float32)
    depth[rng.uniform(size=(height, width)) < sky] = 0.0 if reversed_z else 1.0
    return color, depth


def flags(options):
    """fogcl.apply's keywords as `fogcl apply` flags (the documented mapping)."""
    args = []
    for key, value in options.items():
        flag = "--" + key.replace("_", "-")
        if value is True:
            args.append(flag)
        elif value is False or value is None:
            continue
        elif isinstance(value, (tuple, list)):
            args += [flag, ",".join(repr(v) for v in value)]
        else:
            args += [flag, str(value)]
    return args


def run_cli(cli, tmp_path, color, depth, options, extra=()):
    """Writes the frame to EXR, fogs it with the CLI and returns (returncode, stderr, fogged color
    or None)."""
    half = color.dtype == np.float16
    c, d, o = tmp_path / "color.exr", tmp_path / "depth.exr", tmp_path / "out.exr"
    fogcl.write_exr(str(c), color, pixel_type="half" if half else "float")
    fogcl.write_exr_depth(str(d), depth)
    args = [cli, "apply", "--color", str(c), "--depth", str(d), "--out", str(o)]
    if half:
        args += ["--pixel-type", "half"]
    r = subprocess.run(args + flags(options) + list(extra), capture_output=True, text=True)
    if r.returncode != 0:
        return r.returncode, r.stderr, None
    return 0, r.stderr, fogcl.read_exr(str(o), depth=str(d), pixel_type="half" if half else "float").color


def bits(a):
    return a.view(np.uint32 if a.dtype == np.float32 else np.uint16)


def worst(a, b):
    return float(np.nanmax(np.abs(a.astype(np.float64) - b.astype(np.float64)))) if a.size else 0.0
