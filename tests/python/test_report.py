"""fogcl.report returns `fogcl report`'s rows: the same scenes and variants as its report.csv,
each measured (errors >= 0, finite times)."""

import csv
import subprocess

import numpy as np

import fogcl


def test_report_rows_are_the_clis(cli, tmp_path):
    rows = fogcl.report(width=16, height=8, runs=7)
    assert rows.dtype.names == fogcl.REPORT_DTYPE.names
    print("device:", rows.dtype.metadata["device"], "|", len(rows), "rows; worst color error",
          float(rows["max_abs_err_color"].max()))
    subprocess.run([cli, "report", "--width", "16", "--height", "8", "--runs", "7", "--out", str(tmp_path)],
                   capture_output=True, text=True)  # report.csv is written before the plot
    with open(tmp_path / "report.csv", newline="") as f:
        expected = [(r["scene"], r["variant"]) for r in csv.DictReader(f)]
    assert [(r["scene"], r["variant"]) for r in rows] == expected
    for name in ("max_abs_err_factor", "max_abs_err_color", "p999_abs_err_color", "max_ulp", "pct_8bit_off"):
        assert np.all(rows[name] >= 0) and np.all(np.isfinite(rows[name])), name
    assert np.all(rows["time_ms"] > 0)
    assert np.all(rows["nonfinite"] == 0)
    assert set(rows["variant"][rows["scalar"]]) <= {"scalar-rgba32f"}


def test_report_options_follow_the_clis_rules():
    import pytest
    for kwargs, message in [({"runs": 3}, "--runs must be >= 7"), ({"width": 0}, "--width must be in [1, 16384]"),
                            ({"device": "CPU"}, "keywords are lowercase")]:
        with pytest.raises(ValueError) as e:
            fogcl.report(**kwargs)
        print(e.value)
        assert message in str(e.value)


VOLUME_KEYS = ("scene", "variant", "integrator", "steps", "resolution", "upsampling", "noise", "storage")


def test_volumetric_report_rows_are_the_clis(cli, tmp_path):
    """report(volumetric=True) measures `fogcl report --volumetric`'s variants with the same
    options; at full resolution, 64 steps are much closer to the reference than 4."""
    options = {"width": 16, "height": 8, "runs": 3, "scenes": ["demo", "shafts"], "steps": [4, 64]}
    rows = fogcl.report(volumetric=True, **options)
    assert rows.dtype.names == fogcl.VOLUME_REPORT_DTYPE.names
    meta = rows.dtype.metadata
    assert (meta["width"], meta["height"], meta["runs"], meta["reference_steps"]) == (16, 8, 3, 4096)
    print("device:", meta["device"], "|", len(rows), "rows; worst color error", float(rows["max_abs_err"].max()))
    subprocess.run([cli, "report", "--volumetric", "--width", "16", "--height", "8", "--runs", "3", "--scenes",
                    "demo,shafts", "--steps", "4,64", "--out", str(tmp_path)], capture_output=True, text=True)
    with open(tmp_path / "volume-report.csv", newline="") as f:
        expected = [tuple(r[k] for k in VOLUME_KEYS) for r in csv.DictReader(f)]
    assert [tuple(str(r[k]) for k in VOLUME_KEYS) for r in rows] == expected
    assert set(rows["scene"]) == {"demo", "shafts"} and set(rows["steps"]) == {4, 64}
    assert set(rows["integrator"][rows["scene"] == "shafts"]) == {"physical"}  # the marched fog's only
    assert {"stylized", "physical"} <= set(rows["integrator"][rows["scene"] == "demo"])
    for name in ("max_abs_err", "p999_abs_err", "pct_8bit_off"):
        assert np.all(rows[name] >= 0) and np.all(np.isfinite(rows[name])), name
    assert np.all(rows["p999_abs_err"] <= rows["max_abs_err"])
    assert np.all(rows["time_ms"] > 0) and np.all(rows["nonfinite"] == 0)

    # Error against steps: each full-resolution variant at 4 and at 64 steps (lower resolutions are
    # dominated by the upsampling's error on this tiny frame).
    full = rows[rows["resolution"] == "full"]
    worst_gain = np.inf
    for few in full[full["steps"] == 4]:
        same = ((full["scene"] == few["scene"]) & (full["integrator"] == few["integrator"]) &
                (full["noise"] == few["noise"]) & (full["storage"] == few["storage"]) & (full["steps"] == 64))
        (many,) = full[same]
        print(f"  {few['scene']} {few['integrator']} {few['noise']} {few['storage']}: max error "
              f"{few['max_abs_err']:.3g} at 4 steps, {many['max_abs_err']:.3g} at 64")
        worst_gain = min(worst_gain, few["max_abs_err"] / max(many["max_abs_err"], 1e-12))
    print("smallest ratio of the max error at 4 steps to that at 64:", worst_gain)
    assert worst_gain > 4


def test_volumetric_report_options_follow_the_clis_rules():
    import pytest
    for kwargs, message in [({"runs": 2}, "--runs must be >= 3 with --volumetric"),
                            ({"steps": [0]}, "--steps"), ({"steps": [16, 5000]}, "--steps"),
                            ({"scenes": ["demo", "fog"]}, "--scenes"), ({"integrators": "riemann"}, "--integrators"),
                            ({"height": 0}, "--height must be in [1, 16384]"),
                            ({"device": "scalar"}, "the scalar path"), ({"steps": 16.5}, "--steps"),
                            ({"scenes": 3}, "--scenes")]:
        with pytest.raises(ValueError) as e:
            fogcl.report(volumetric=True, **kwargs)
        print(e.value)
        assert message in str(e.value)
    with pytest.raises(ValueError) as e:
        fogcl.report(steps=[16])
    print(e.value)
    assert "needs volumetric=True" in str(e.value)
