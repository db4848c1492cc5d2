"""fogcl: deferred and volumetric fog on OpenCL devices and in C++ (docs/python.md).

apply(color, depth, **options) fogs a numpy frame as `fogcl apply` does with the same options;
read_exr / write_exr read and write renderer EXR files as the command does; report() measures
error against run time for every precision variant (`fogcl report`), report(volumetric=True) for
every variant of the volumetric pass (`fogcl report --volumetric`).
"""

import numpy as _np

from ._fogcl import Camera, ExrFrame, apply, read_exr, version, write_exr, write_exr_depth  # noqa: F401
from ._fogcl import _frames_in_flight, _release_devices, _report_rows, _volume_report_rows  # noqa: F401
from ._fogcl import empty  # noqa: F401

__all__ = ["apply", "read_exr", "write_exr", "write_exr_depth", "report", "empty", "version", "Camera", "ExrFrame", "REPORT_DTYPE",
           "VOLUME_REPORT_DTYPE"]

# One row of report(): the columns of `fogcl report`'s report.csv (docs/python.md, "Report").
REPORT_DTYPE = _np.dtype([
    ("scene", "U40"), ("variant", "U24"), ("scalar", "?"), ("precision", "U8"), ("storage", "U8"),
    ("time_ms", "f8"), ("max_abs_err_factor", "f8"), ("max_abs_err_color", "f8"), ("p999_abs_err_color", "f8"),
    ("max_ulp", "f8"), ("pct_8bit_off", "f8"), ("nonfinite", "u8"), ("eye_depth_rel_err", "f8"),
])


# One row of report(volumetric=True): the columns of `fogcl report --volumetric`'s volume-report.csv.
VOLUME_REPORT_DTYPE = _np.dtype([
    ("scene", "U16"), ("variant", "U64"), ("integrator", "U12"), ("steps", "i4"), ("resolution", "U8"),
    ("upsampling", "U12"), ("noise", "U8"), ("storage", "U8"), ("time_ms", "f8"), ("max_abs_err", "f8"),
    ("p999_abs_err", "f8"), ("pct_8bit_off", "f8"), ("nonfinite", "u8"),
])


def _list_text(flag, value):
    """A list keyword as its flag's text ("16,32"), which the flag's own rules then check."""
    if value is None:
        return None
    if isinstance(value, (str, int)) and not isinstance(value, bool):
        return str(value)
    try:
        return ",".join(str(v) for v in value)
    except TypeError:
        raise ValueError(f"{flag} must be a list such as [16, 32] or the text '16,32' (got {value!r})") from None


def report(width=None, height=None, runs=None, device="", volumetric=False, steps=None, scenes=None,
           integrators=None):
    """Error against run time, as `fogcl report --width --height --runs --device` measures it.

    Returns a numpy structured array of REPORT_DTYPE, one row per (scene, variant), scene-major;
    its .dtype.metadata holds the device and driver it ran on. Defaults: 640 x 360, 9 runs.

    volumetric=True: `fogcl report --volumetric`'s rows instead, as VOLUME_REPORT_DTYPE (defaults
    160 x 90, 5 runs), .dtype.metadata as volume-report.json's header; steps (e.g. [16, 32]),
    scenes (of demo, dense, thin, inside, shafts, lamps) and integrators (stylized, physical) keep
    only those, as the flags of the same names do.
    """
    if not volumetric:
        for name, value in (("steps", steps), ("scenes", scenes), ("integrators", integrators)):
            if value is not None:
                raise ValueError(f"{name}= (--{name}) selects volumetric variants; it needs volumetric=True")
        dev, driver, rows = _report_rows(int(640 if width is None else width), int(360 if height is None else height),
                                         int(9 if runs is None else runs), str(device))
        dtype = _np.dtype(REPORT_DTYPE, metadata={"device": dev, "driver": driver})
        return _np.array(rows, dtype=dtype)
    meta, rows = _volume_report_rows(int(160 if width is None else width), int(90 if height is None else height),
                                     int(5 if runs is None else runs), str(device), _list_text("--steps", steps),
                                     _list_text("--scenes", scenes), _list_text("--integrators", integrators))
    return _np.array(rows, dtype=_np.dtype(VOLUME_REPORT_DTYPE, metadata=meta))


# The passes on a PyOpenCL context, queue and buffers (docs/python.md, "On your PyOpenCL context").
from ._fogcl import FogPass, VolumePass  # noqa: E402,F401

__all__ += ["FogPass", "VolumePass"]
