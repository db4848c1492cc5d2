"""Shared fixtures of the fogcl module's tests: the module from the build tree (PYTHONPATH, set by
ctest) and the CLI binary (FOGCL_CLI) that its results are compared with."""

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
