"""Shared fixtures: the repository's folders and the command line binary
the Python package is checked against (`FLICKER_BIN`, default
`target/release/flicker`, which `cargo test --release` builds)."""

import json
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
MODELS = ROOT / "models"


def binary() -> Path:
    path = Path(os.environ.get("FLICKER_BIN", ROOT / "target" / "release" / "flicker"))
    if not path.exists():
        raise RuntimeError(f"{path}: build the command line first (cargo build --release)")
    return path


@pytest.fixture
def cli(tmp_path):
    """Run the command line; returns (completed process, output folder)."""

    def call(*args):
        out = tmp_path / "cli"
        done = subprocess.run(
            [str(binary()), *[str(a) for a in args]],
            capture_output=True,
            text=True,
            cwd=tmp_path,
        )
        return done, out

    return call


def read_log(path: Path):
    """The events of a JSON Lines log, as dicts."""
    return [json.loads(line) for line in path.read_text().splitlines() if line]
