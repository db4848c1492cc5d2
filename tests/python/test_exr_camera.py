"""An EXR with the camera a renderer writes into its header (OpenEXR's worldToCamera and
worldToNDC, as Blender and Arnold write them; the file made by the project's C++ fixtures,
tests/write_camera_exr.cpp): fogcl.read_exr gives that camera, and fogcl.apply(camera=it) gives
what `fogcl apply` writes for the file, bit for bit, with the fov, aspect and pose taken from it."""

import json
import subprocess

import numpy as np
import pytest

import fogcl
from frames import bits, flags, worst


def camera_file(tool, path, width, height, fov, seed):
    """Writes the file; returns the worldToCamera matrix it holds (row vectors: p_cam = p_world M)."""
    out = subprocess.run([tool, str(path), str(width), str(height), repr(fov), str(seed)], capture_output=True,
                         text=True, check=True).stdout
    return np.array([float(v) for v in out.split()]).reshape(4, 4)


CASES = [  # (mode, options): the deferred fog, and the volumes whose pose only the file gives
    ("exp2", {"mode": "exp2", "density": 0.02}),
    ("linear", {"mode": "linear", "start": 2.0, "end": 150.0, "distance": True}),
    # Full resolution: the fixture's depth is noise, nearly every 2x2 block has a pixel in front of
    # the volumes, and the low-resolution march would see none of them.
    ("volumes", {"steps": 24, "integrator": "physical", "volume_resolution": "full"}),
]


@pytest.mark.parametrize("case", range(len(CASES)), ids=[c[0] for c in CASES])
def test_read_exr_camera_and_apply_are_the_clis(cli, write_camera_exr, tmp_path, case):
    rng = np.random.default_rng([41, case])
    name, options = CASES[case]
    width, height = int(rng.integers(6, 48)), int(rng.integers(6, 48))
    fov = round(float(rng.uniform(20, 110)), 3)
    path = tmp_path / "camera.exr"
    w2c = camera_file(write_camera_exr, path, width, height, fov, case + 1)
    frame = fogcl.read_exr(str(path), depth_kind="eye")
    cam = frame.camera
    print(f"{name}: {width}x{height}, fov {fov}: read {cam!r}")
    assert cam.present and cam.pose_present, (cam.note, cam.pose_note)
    # The matrices are float32: the fov and aspect back to float32's precision.
    assert abs(cam.fov_y_deg - fov) <= 1e-4 * fov and abs(cam.aspect - width / height) <= 1e-6 * width / height
    # The pose: camera space (+x right, +y up, +z forward) in the file's world, and the eye its origin.
    rot, t = w2c[:3, :3], w2c[3, :3]
    eye, right, up, forward = (np.array(v) for v in (cam.eye, cam.right, cam.up, cam.forward))
    pose_err = max(np.abs(eye @ rot + t).max(), np.abs(right - rot[:, 0]).max(), np.abs(up - rot[:, 1]).max(),
                   np.abs(forward - rot[:, 2]).max())
    print(f"  pose: eye {cam.eye}, forward {cam.forward}; worst |pose - worldToCamera's| = {pose_err:.3g}")
    assert pose_err <= 1e-5

    options = {"near": 0.3, "far": 1000.0, "depth_kind": "eye", **options}
    if name == "volumes":  # two spheres ahead of the file's camera, placed from its matrix
        ahead = [list(map(float, eye + d * forward + s * right)) for d, s in ((6.0, 0.0), (12.0, 2.0))]
        volumes = tmp_path / "volumes.json"
        volumes.write_text(json.dumps({"volumes": [
            {"medium": "homogeneous", "center": ahead[0], "radius": 2.5, "density": 0.4},
            {"medium": "homogeneous", "center": ahead[1], "radius": 3.0, "density": 0.2}]}))
        options["volumes"] = str(volumes)
    out = tmp_path / "cli.exr"
    r = subprocess.run([cli, "apply", "--color", str(path), "--out", str(out), "--verbose"] + flags(options),
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "(from worldToNDC)" in r.stdout + r.stderr  # no --fov: the file's camera
    expected = fogcl.read_exr(str(out), depth_kind="eye")
    got = fogcl.apply(frame.color, frame.depth, camera=cam, **options)
    print(f"  worst |module - cli| = {worst(got, expected.color)}, fogged pixels "
          f"{int(np.sum(np.any(got != frame.color, axis=-1)))} of {width * height}")
    assert np.array_equal(bits(got), bits(expected.color))
    assert not np.array_equal(got, frame.color)
    # Written with the file as the source: the CLI's file, camera attributes included.
    fogcl.write_exr(str(tmp_path / "py.exr"), got, source=frame)
    assert (tmp_path / "py.exr").read_bytes() == out.read_bytes()
    again = fogcl.read_exr(str(tmp_path / "py.exr"), depth_kind="eye").camera
    assert (again.fov_y_deg, again.aspect, again.eye, again.forward) == (cam.fov_y_deg, cam.aspect, cam.eye, cam.forward)

    # Without the camera, fogcl.apply asks for the fov as the CLI does for a file without one.
    with pytest.raises(ValueError) as e:
        fogcl.apply(frame.color, frame.depth, **options)
    print("  without camera=:", e.value)
    assert "--fov" in str(e.value)
