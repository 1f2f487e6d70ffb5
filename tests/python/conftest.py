# Shared fixtures of the Python tests: the module under test (from PYTHONPATH, set by ctest to
# the build's python/ directory), the command-line program and the repository's data.
import os
import pathlib
import subprocess

import pytest


@pytest.fixture(scope="session")
def source_dir():
    return pathlib.Path(os.environ.get("BUCKLE_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("BUCKLE_CLI")
    if not path or not os.access(path, os.X_OK):
        pytest.fail("BUCKLE_CLI must name the built buckle program (ctest sets it)")
    return path


@pytest.fixture(scope="session")
def run_cli(cli):
    """Runs `buckle ARGS...`; returns the CompletedProcess (text mode)."""

    def run(*args, **kwargs):
        return subprocess.run([cli, *map(str, args)], capture_output=True, text=True, timeout=300, **kwargs)

    return run
