"""Shared fixtures: the repository root and the CLI binary the Python results are compared with."""

from __future__ import annotations

import json
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def cli_binary() -> pathlib.Path:
    """The forkbench CLI: $FORKBENCH_BIN, else the release build in the cargo target dir."""
    if "FORKBENCH_BIN" in os.environ:
        return pathlib.Path(os.environ["FORKBENCH_BIN"])
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    return target / "release" / "forkbench"


@pytest.fixture(scope="session")
def cli():
    """Runs the CLI from the repository root; returns its stdout (exit 0 or 3 expected)."""
    binary = cli_binary()
    if not binary.exists():
        pytest.fail(f"{binary}: no forkbench CLI (build it or set FORKBENCH_BIN)")

    def run(*args: str) -> str:
        done = subprocess.run(
            [str(binary), *args], cwd=ROOT, capture_output=True, text=True, check=False
        )
        assert done.returncode in (0, 3), (done.returncode, done.stderr)
        return done.stdout

    return run


def without_clock(record: dict) -> dict:
    """A record without what a re-run cannot reproduce: the times measured on the clock."""
    record = dict(record)
    record.pop("wall_time_ms", None)
    record["legs"] = [
        {k: v for k, v in leg.items() if k != "planning_time_s"} for leg in record.get("legs", [])
    ]
    return record


def read_jsonl(path: pathlib.Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
