"""fogcl: deferred and volumetric fog on OpenCL devices and in C++ (docs/python.md).

apply(color, depth, **options) fogs a numpy frame as `fogcl apply` does with the same options;
read_exr / write_exr read and write renderer EXR files as the command does; report() measures
error against run time for every precision variant (`fogcl report`).
"""

import numpy as _np

from ._fogcl import Camera, ExrFrame, apply, read_exr, version, write_exr, write_exr_depth  # noqa: F401
from ._fogcl import _frames_in_flight, _release_devices, _report_rows  # noqa: F401
from ._fogcl import empty  # noqa: F401

__all__ = ["apply", "read_exr", "write_exr", "write_exr_depth", "report", "empty", "version", "Camera", "ExrFrame", "REPORT_DTYPE"]

# One row of report(): the columns of `fogcl report`'s report.csv (docs/python.md, "Report").
REPORT_DTYPE = _np.dtype([
    ("scene", "U40"), ("variant", "U24"), ("scalar", "?"), ("precision", "U8"), ("storage", "U8"),
    ("time_ms", "f8"), ("max_abs_err_factor", "f8"), ("max_abs_err_color", "f8"), ("p999_abs_err_color", "f8"),
    ("max_ulp", "f8"), ("pct_8bit_off", "f8"), ("nonfinite", "u8"), ("eye_depth_rel_err", "f8"),
])


def report(width=640, height=360, runs=9, device=""):
    """Error against run time, as `fogcl report --width --height --runs --device` measures it.

    Returns a numpy structured array of REPORT_DTYPE, one row per (scene, variant), scene-major;
    its .dtype.metadata holds the device and driver it ran on.
    """
    dev, driver, rows = _report_rows(int(width), int(height), int(runs), str(device))
    dtype = _np.dtype(REPORT_DTYPE, metadata={"device": dev, "driver": driver})
    return _np.array(rows, dtype=dtype)


# The passes on a PyOpenCL context, queue and buffers (docs/python.md, "On your PyOpenCL context").
from ._fogcl import FogPass, VolumePass  # noqa: E402,F401

__all__ += ["FogPass", "VolumePass"]
