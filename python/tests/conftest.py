"""Shared fixtures: the `specvar` command line, to compare the package with it."""

import json
import os
import pathlib
import subprocess

import pytest

REPOSITORY = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def cli():
    """A function running the `specvar` binary of this repository (built if absent)."""
    binary = os.environ.get("SPECVAR_BIN")
    if not binary:
        # Cargo's target directory, wherever CARGO_TARGET_DIR or a config puts it.
        metadata = subprocess.run(["cargo", "metadata", "--format-version", "1", "--no-deps"],
                                  cwd=REPOSITORY, check=True, capture_output=True, text=True)
        binary = str(pathlib.Path(json.loads(metadata.stdout)["target_directory"]) / "release" / "specvar")
    if not os.path.exists(binary):
        subprocess.run(["cargo", "build", "--release", "--bin", "specvar"], cwd=REPOSITORY, check=True)

    def run(*args, check=True):
        done = subprocess.run([binary, *args], capture_output=True, text=True)
        if check and done.returncode != 0:
            raise AssertionError(done.stderr)
        return done

    return run
