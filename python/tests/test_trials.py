"""Trials and batches from Python equal the CLI's at the same seeds; outcomes become a DataFrame; bad input raises exceptions naming file, field and reason."""

from __future__ import annotations

import json
import os

import pytest
from conftest import ROOT, read_jsonl, without_clock

import forkbench


def test_a_trial_equals_the_clis_at_the_same_seed(cli):
    for scenario, case, seed in [("field-test", None, 3), ("bspline-table2", "18", 4)]:
        args = ["trial", f"scenarios/{scenario}.toml", "--seed", str(seed), "--json"]
        if case:
            args += ["--case", case]
        want = json.loads(cli(*args))
        got = forkbench.run_trial(forkbench.load(scenario), case, seed=seed)
        assert without_clock(got) == without_clock(want)


def test_a_batch_equals_the_clis_and_becomes_a_dataframe(cli, tmp_path):
    out = tmp_path / "cli"
    cli(
        "batch",
        "scenarios/field-test.toml",
        "scenarios/rack-pick.toml",
        "--trials",
        "3",
        "--seed",
        "7",
        "--out",
        str(out),
    )
    want = sorted(
        read_jsonl(out / "trials.jsonl"), key=lambda r: (r["scenario"], r["case"], r["trial"])
    )
    scenarios = [
        forkbench.load(ROOT / "scenarios/field-test.toml"),
        forkbench.load(ROOT / "scenarios/rack-pick.toml"),
    ]
    for jobs in (1, 2):
        got = forkbench.run_batch(scenarios, trials=3, seed=7, jobs=jobs)
        got = sorted(got, key=lambda r: (r["scenario"], r["case"], r["trial"]))
        assert [without_clock(r) for r in got] == [without_clock(r) for r in want]
    # The CLI's batch directory, written from Python, holds the same trials.
    written = forkbench.run_batch(scenarios, trials=3, seed=7, out=tmp_path / "py")
    assert len(written) == len(want) == len(read_jsonl(tmp_path / "py" / "trials.jsonl"))
    assert (tmp_path / "py" / "summary.json").exists()
    # Other settings do not resume it; `force_new` starts it over, as the CLI's --force-new.
    with pytest.raises(forkbench.BatchError, match="force_new=True"):
        forkbench.run_batch(scenarios, trials=3, seed=8, out=tmp_path / "py")
    again = forkbench.run_batch(scenarios, trials=3, seed=8, out=tmp_path / "py", force_new=True)
    assert len(again) == len(read_jsonl(tmp_path / "py" / "trials.jsonl")) == len(want)
    assert {r["seed"] for r in again}.isdisjoint({r["seed"] for r in written})
    with pytest.raises(forkbench.BatchError, match="force_new"):
        forkbench.run_batch(scenarios, trials=1, force_new=True)
    df = forkbench.to_dataframe(got)
    assert len(df) == len(want)
    assert {"scenario", "case", "seed", "success", "failure", "lateral_error_m"} <= set(df.columns)
    assert df.groupby("scenario")["success"].mean().between(0, 1).all()


def test_the_external_python_tracker_runs_in_a_batch_beside_pure_pursuit():
    scn = forkbench.load(ROOT / "examples/trackers/stanley-field-test.toml")
    records = forkbench.run_batch([scn], trials=4, trackers=["stanley", "pure_pursuit"])
    by = {t: [r for r in records if r["tracker"] == t] for t in ("stanley", "pure_pursuit")}
    assert len(by["stanley"]) == len(by["pure_pursuit"]) == 4
    assert [r["seed"] for r in by["stanley"]] == [r["seed"] for r in by["pure_pursuit"]]
    assert all(r["failure"] != "error" for r in records), [r["failure_detail"] for r in records]


def test_a_trial_records_to_mcap(tmp_path):
    path = tmp_path / "field.mcap"
    out = forkbench.run_trial(forkbench.load("field-test"), seed=1, noise=False, mcap=path)
    data = path.read_bytes()
    assert out["success"] and data[:8] == b"\x89MCAP0\r\n" and len(data) > 10_000
    # An existing recording is replaced only when asked, as the CLI's --force.
    with pytest.raises(forkbench.RecordingError, match="exists"):
        forkbench.run_trial(forkbench.load("field-test"), seed=1, noise=False, mcap=path)
    forkbench.run_trial(forkbench.load("field-test"), seed=1, noise=False, mcap=path, force=True)
    # A FIFO (opening it to write would wait for a reader) is refused at once, even forced.
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    with pytest.raises(forkbench.RecordingError, match="not a regular file"):
        forkbench.run_trial(forkbench.load("field-test"), seed=1, mcap=fifo, force=True)
    # Records are capped by the memory they would take, refused before any trial runs.
    with pytest.raises(forkbench.BatchError, match="GiB in Python"):
        forkbench.run_batch([forkbench.load("warehouse-cycle")], trials=200_000)
    with pytest.raises(forkbench.BatchError, match="jobs 0"):
        forkbench.run_batch([forkbench.load("field-test")], trials=1, jobs=0)
    with pytest.raises(forkbench.BatchError, match="out"):
        forkbench.run_batch([forkbench.load("field-test")], trials=1, out="")


def test_bad_input_names_file_field_and_reason(tmp_path):
    bad = tmp_path / "bad.toml"
    text = (ROOT / "scenarios/field-test.toml").read_text()
    bad.write_text(
        text.replace("[tolerances]", "[tolerances]\nlateral_m = -1.0", 1)
        if "[tolerances]" in text
        else text + "\n[tolerances]\nlateral_m = -1.0\n"
    )
    with pytest.raises(forkbench.ScenarioError) as e:
        forkbench.Scenario.load(bad)
    assert e.value.file.endswith("bad.toml") and "lateral_m" in e.value.field, (
        e.value.file,
        e.value.field,
    )
    assert e.value.reason
    with pytest.raises(forkbench.ScenarioError) as e:
        forkbench.Scenario.embedded("no-such-scenario")
    assert e.value.field == "name" and "field-test" in e.value.reason
    with pytest.raises(forkbench.ScenarioError) as e:
        forkbench.run_trial(forkbench.load("bspline-table2"), "no-such-case")
    assert e.value.field == "case"
    with pytest.raises(forkbench.ScenarioError) as e:
        forkbench.run_trial(forkbench.load("field-test"), planner="no-such-planner")
    assert e.value.field == "planner"
    with pytest.raises(forkbench.BatchError, match="modes"):
        forkbench.run_batch([forkbench.load("field-test")], trials=1, modes="sometimes")
    with pytest.raises(forkbench.BatchError, match="trials"):
        forkbench.run_batch([forkbench.load("field-test")], trials=0)
    with pytest.raises(forkbench.BatchError, match="more than 2 GiB"):
        forkbench.run_batch([forkbench.load("field-test")], trials=10**12)
    with pytest.raises(ValueError, match="path_points"):
        forkbench.PickEnv(forkbench.load("field-test"), path_points=10**9)


def test_python_validates_options_as_the_cli_does(cli):
    scn = forkbench.load("field-test")
    with pytest.raises(forkbench.ScenarioError) as e:
        forkbench.run_trial(scn, pallet_noise_scale=-1)
    assert e.value.field == "pallet_noise_scale" and "from 0 to" in e.value.reason
    with pytest.raises(forkbench.ScenarioError) as e:
        forkbench.run_trial(scn, noise=False, localization_noise_scale=2)
    assert e.value.field == "localization_noise_scale"
    # The same trial with every override, from Python and from the CLI.
    want = json.loads(
        cli(
            "trial",
            "field-test",
            "--seed",
            "5",
            "--json",
            "--pallet-noise-scale",
            "2",
            "--localizer",
            "gaussian",
            "--odometry-noise-scale",
            "0.5",
        )
    )
    got = forkbench.run_trial(
        scn, seed=5, pallet_noise_scale=2, localizer="gaussian", odometry_noise_scale=0.5
    )
    assert without_clock(got) == without_clock(want)


def test_a_runs_truck_is_its_actuators_timing_and_geometry():
    scn = forkbench.load("field-test")

    def run(**truck: object) -> dict:
        return without_clock(forkbench.run_trial(scn, seed=1, noise=False, **truck))  # type: ignore[arg-type]

    default = run()
    # The default truck is the realistic one; the first (ideal) one and a lag each act.
    assert run(truck_preset="realistic") == default
    assert run(truck_preset="ideal")["lateral_error_m"] != default["lateral_error_m"]
    assert run(truck={"steering.dead_time_s": 0.3})["lateral_error_m"] != default["lateral_error_m"]
    # The geometry is a run's to set too (a truck file holds the whole truck); it acts, and
    # a value out of range is refused naming the key.
    assert run(truck={"wheelbase_m": 2.0})["lateral_error_m"] != default["lateral_error_m"]
    with pytest.raises(forkbench.ScenarioError, match="wheelbase_m"):
        run(truck={"wheelbase_m": -1.0})
    # The layout by its name, as a truck file gives it.
    assert run(truck={"layout": "counterbalance"}) == default
    with pytest.raises(TypeError, match="unknown layout"):
        run(truck={"layout": "sideways"})


def test_a_tracker_from_a_components_file_runs_on_any_scenario(tmp_path):
    import shutil

    shutil.copy(ROOT / "examples/trackers/stanley.py", tmp_path / "stanley.py")
    (tmp_path / "components.toml").write_text(
        '[[tracker]]\nname = "stan"\nkind = "external"\ncommand = ["python3", "stanley.py"]\n'
    )
    scn = forkbench.load("field-test").with_components(tmp_path / "components.toml")
    out = forkbench.run_trial(scn, seed=1, tracker="stan")
    assert out["tracker"] == "stan"
    with pytest.raises(forkbench.ScenarioError, match="components file"):
        forkbench.run_trial(forkbench.load("field-test"), seed=1, tracker="stan")
