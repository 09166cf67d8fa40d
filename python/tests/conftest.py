"""Shared fixtures: the CLI binary the Python results are checked against."""

import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]


def cli_path() -> pathlib.Path:
    """The `penumbra` binary: $PENUMBRA_BIN, else the release build of this checkout."""
    if os.environ.get("PENUMBRA_BIN"):
        return pathlib.Path(os.environ["PENUMBRA_BIN"])
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    return target / "release" / "penumbra"


@pytest.fixture(scope="session")
def cli():
    """Run the CLI; fails (not skips) when it has not been built: these tests compare with it."""
    exe = cli_path()
    if not exe.exists():
        pytest.fail(f"{exe} not found: build it with `cargo build --release` (or set PENUMBRA_BIN)")

    def run(*args, **kw):
        return subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True, check=True, **kw)

    return run
