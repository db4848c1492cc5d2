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
