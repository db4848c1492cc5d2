#!/usr/bin/python3
"""Fogs a numpy frame: a synthetic ground plane under a sky, fogged with exp2 fog as
`fogcl apply --near 0.3 --far 1000 --fov 60 --mode exp2 --density 0.025` would, written to EXR.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/fog_frame.py fogged.exr
"""

import sys

import numpy as np

import fogcl

near, far, fov = 0.3, 1000.0, 60.0
height, width = 360, 640

# The frame in page-aligned memory (fogcl.empty): a CPU device reads and writes it in place.
color = fogcl.empty((height, width, 4), np.float32)
depth = fogcl.empty((height, width), np.float32)
color[...] = (0.2, 0.4, 0.1, 1.0)  # grass
# Eye depth of a ground plane 1.7 units below the camera, the sky above the horizon.
rows = np.arange(height, dtype=np.float32)[:, None]
below = (rows + 0.5 - height / 2) / (height / 2) * np.tan(np.radians(fov / 2))
with np.errstate(divide="ignore"):
    eye = np.where(below > 0, 1.7 / below, np.inf)
depth[...] = np.broadcast_to(eye, (height, width))
color[np.isinf(depth)] = (0.5, 0.7, 1.0, 1.0)  # sky

stats = {}
fogged = fogcl.apply(color, depth, out=fogcl.empty(color.shape, color.dtype), stats=stats, near=near, far=far,
                     fov=fov, mode="exp2", density=0.025, depth_kind="eye", fog_color=(0.62, 0.68, 0.76))
print(f"device: {stats['device']}")
if "zero_copy_frames" in stats:
    print(f"frames fogged in the arrays' memory: {stats['zero_copy_frames']}, copied: {stats['copied_frames']}")
print(f"ground at the bottom row: {color[-1, 0, :3]} -> {fogged[-1, 0, :3]}; "
      f"near the horizon: {color[height // 2 + 2, 0, :3]} -> {fogged[height // 2 + 2, 0, :3]}")
if len(sys.argv) > 1:
    fogcl.write_exr(sys.argv[1], fogged, compression="zip")
    print(f"wrote {sys.argv[1]}")
