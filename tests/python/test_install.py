"""`cmake --install` puts the package where Debian's python3 looks under the prefix
(lib/python3.X/dist-packages), and it imports and fogs from there, finding libfogcl in the
prefix's library folder."""

import os
import subprocess
import sys

import pytest


def test_installed_package_imports_and_fogs(tmp_path):
    build = os.environ.get("FOGCL_BUILD_DIR")
    if not build:
        pytest.skip("FOGCL_BUILD_DIR names no build folder (ctest sets it)")
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", build, "--prefix", str(prefix)], check=True, capture_output=True)
    site = prefix / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}" / "dist-packages"
    script = ("import fogcl, numpy as np; print(fogcl.__file__); "
              "c = np.ones((3, 5, 4), np.float32); d = np.full((3, 5), 0.5, np.float32); "
              "print(float(fogcl.apply(c, d, near=0.3, far=100, fov=60, mode='exp', density=0.1)[0, 0, 0]))")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "LD_LIBRARY_PATH")}
    r = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                       env={**env, "PYTHONPATH": str(site)}, cwd=tmp_path)
    print(r.stdout, r.stderr)
    assert r.returncode == 0
    assert r.stdout.splitlines()[0].startswith(str(site))
    assert 0.0 < float(r.stdout.splitlines()[1]) < 1.0
