"""The module's own facts: it imports from the build tree and is the library it was built with."""

import re
import subprocess

import fogcl


def test_version_is_the_cli_version(cli):
    version = fogcl.version()
    assert re.fullmatch(r"\d+\.\d+\.\d+", version), version
    out = subprocess.run([cli, "--version"], capture_output=True, text=True, check=True).stdout
    print("module", version, "| cli:", out.splitlines()[0])
    assert version in out.splitlines()[0]
