"""`forkbench.report` and `forkbench.replay` are the CLI's `report` and `replay`: the same page byte for byte, the same re-run and verdict."""

from __future__ import annotations

import json

import pytest
from conftest import read_jsonl, without_clock

import forkbench


@pytest.fixture(scope="module")
def batch_dir(cli, tmp_path_factory):
    """A small batch the CLI ran, in both replanning modes, with a baseline of itself."""
    out = tmp_path_factory.mktemp("report") / "batch"
    cli(
        "batch",
        "scenarios/field-test.toml",
        "--modes",
        "both",
        "--trials",
        "3",
        "--seed",
        "11",
        "--record",
        "none",
        "--out",
        str(out),
    )
    cli("baseline", str(out), "--out", str(out.parent / "baseline.json"))
    return out


def test_the_report_is_the_clis_byte_for_byte(cli, batch_dir):
    for baseline in [None, batch_dir.parent / "baseline.json"]:
        want = batch_dir.parent / "cli.html"
        args = ["report", str(batch_dir), "--out", str(want)]
        if baseline:
            args += ["--baseline", str(baseline)]
        cli(*args)
        got = forkbench.report(batch_dir, baseline=baseline, out=batch_dir.parent / "py.html")
        assert got.read_bytes() == want.read_bytes()
        assert b"Failures by first failed criterion" in got.read_bytes()
    assert forkbench.report(batch_dir) == batch_dir / "report.html"


def test_a_report_of_no_batch_raises(tmp_path):
    with pytest.raises(forkbench.BatchError, match="summary|trials|manifest"):
        forkbench.report(tmp_path)


def test_replay_reruns_a_line_as_the_cli_does(cli, batch_dir, tmp_path):
    records = batch_dir / "trials.jsonl"
    line = 2
    want = read_jsonl(records)[line - 1]
    got = forkbench.replay(records, line, mcap=tmp_path / "py.mcap")
    assert got["identical"] is True
    recorded = {k: v for k, v in want.items() if k in got["outcome"]}
    assert without_clock(got["outcome"]) == without_clock(recorded)
    printed = cli("replay", str(records), "--line", str(line), "--mcap", str(tmp_path / "cli.mcap"))
    assert "identical to the recorded outcome" in printed
    assert f"seed {want['seed']}" in printed
    # The same messages; only the outcome's wall-clock time differs, inside a compressed
    # chunk, so the files match in framing and nearly in size, not byte for byte.
    py_mcap, cli_mcap = (tmp_path / "py.mcap").read_bytes(), (tmp_path / "cli.mcap").read_bytes()
    magic = b"\x89MCAP0\r\n"
    assert py_mcap.startswith(magic) and py_mcap.endswith(magic)
    assert abs(len(py_mcap) - len(cli_mcap)) < 64, (len(py_mcap), len(cli_mcap))


def test_replay_takes_a_record_and_notices_one_it_cannot_reproduce(batch_dir):
    record = read_jsonl(batch_dir / "trials.jsonl")[0]
    assert forkbench.replay(record)["identical"] is True
    record["insertion_depth_m"] = 123.0
    assert forkbench.replay(json.loads(json.dumps(record)))["identical"] is False
    with pytest.raises(forkbench.BatchError, match="line 0"):
        forkbench.replay(batch_dir / "trials.jsonl", 0)
    with pytest.raises(forkbench.BatchError, match="not a trial record"):
        forkbench.replay({"scenario": "field-test"})
