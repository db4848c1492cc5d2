"""Shared fixtures of the fogcl module's tests: the module from the build tree (PYTHONPATH, set by
ctest), the CLI binary (FOGCL_CLI) that its results are compared with, and the writer of EXR files
with a renderer's camera attributes (FOGCL_WRITE_CAMERA_EXR, tests/write_camera_exr.cpp)."""

import os
import shutil

import pytest

import fogcl  # noqa: F401  (a missing module fails here, with Python's message)


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("FOGCL_CLI") or shutil.which("fogcl")
    if not path:
        pytest.fail("FOGCL_CLI names no fogcl binary (ctest sets it)")
    return path


@pytest.fixture(scope="session")
def write_camera_exr():
    path = os.environ.get("FOGCL_WRITE_CAMERA_EXR")
    if not path and os.environ.get("FOGCL_BUILD_DIR"):
        path = os.path.join(os.environ["FOGCL_BUILD_DIR"], "tests", "fogcl_write_camera_exr")
    if not path or not os.access(path, os.X_OK):
        pytest.fail("FOGCL_WRITE_CAMERA_EXR names no fogcl_write_camera_exr binary (ctest sets it)")
    return path
