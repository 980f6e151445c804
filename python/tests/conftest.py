"""Shared fixtures: the `specvar` command line, to compare the package with it."""

import os
import pathlib
import subprocess

import pytest

REPOSITORY = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def cli():
    """A function running the `specvar` binary of this repository (built if absent)."""
    binary = os.environ.get("SPECVAR_BIN") or str(REPOSITORY / "target" / "release" / "specvar")
    if not os.path.exists(binary):
        subprocess.run(["cargo", "build", "--release", "--bin", "specvar"], cwd=REPOSITORY, check=True)

    def run(*args, check=True):
        done = subprocess.run([binary, *args], capture_output=True, text=True)
        if check and done.returncode != 0:
            raise AssertionError(done.stderr)
        return done

    return run
