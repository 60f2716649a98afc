"""A run's options are defined once, in Rust: every entry point that runs trials takes each
of them as a keyword, refuses any other by name, and the stub declares them."""

from __future__ import annotations

import ast
import pathlib

import pytest

import forkbench
from forkbench import _forkbench
from forkbench.gym import PalletPickEnv

STUB = pathlib.Path(_forkbench.__file__).with_name("_forkbench.pyi")
if not STUB.exists():
    STUB = pathlib.Path(__file__).resolve().parents[1] / "forkbench" / "_forkbench.pyi"

TAKES_OPTIONS = ["run_trial", "run_batch", "estimate", "falsify", "PickEnv", "PickVecEnv"]


def _stub() -> ast.Module:
    return ast.parse(STUB.read_text())


def test_the_stub_declares_every_option_and_every_entry_point_takes_them():
    tree = _stub()
    options = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "RunOptions")
    declared = [s.target.id for s in options.body if isinstance(s, ast.AnnAssign)]
    assert declared == list(forkbench.RUN_OPTIONS)
    found = []
    for node in tree.body:
        if isinstance(node, ast.ClassDef) and node.name in TAKES_OPTIONS:
            fn = next(f for f in node.body if isinstance(f, ast.FunctionDef))
            assert fn.name == "__init__", node.name
        elif isinstance(node, ast.FunctionDef) and node.name in TAKES_OPTIONS:
            fn = node
        else:
            continue
        kw = fn.args.kwarg
        assert kw is not None and kw.arg == "options", node.name
        assert kw.annotation is not None
        assert ast.unparse(kw.annotation) == "Unpack[RunOptions]", node.name
        found.append(node.name)
    assert sorted(found) == sorted(TAKES_OPTIONS)


def test_an_unknown_keyword_is_refused_naming_the_options():
    scn = forkbench.load("field-test")
    calls = [
        lambda: forkbench.run_trial(scn, pallet_noise=2.0),
        lambda: forkbench.run_batch([scn], trials=1, pallet_noise=2.0),
        lambda: forkbench.estimate(scn, pallet_noise=2.0),
        lambda: forkbench.falsify(scn, pallet_noise=2.0),
        lambda: _forkbench.PickEnv(scn, pallet_noise=2.0),
        lambda: _forkbench.PickVecEnv(scn, 1, pallet_noise=2.0),
    ]
    for call in calls:
        with pytest.raises(TypeError, match="pallet_noise") as e:
            call()
        assert "localization_noise_scale" in str(e.value)


def test_a_value_of_the_wrong_type_names_its_option():
    scn = forkbench.load("field-test")
    with pytest.raises(TypeError, match="localizer"):
        forkbench.run_trial(scn, localizer=3)


def test_every_option_reaches_a_batch_and_an_environment():
    """Python's batch once lacked the sensing options; now each reaches the records."""
    scn = forkbench.load("rack-pick")
    options = {
        "pallet_noise_scale": 0.5,
        "localization_noise_scale": 0.5,
        "odometry_noise_scale": 0.5,
        "pallet_sensing": "gaussian",
        "localizer": "nav350",
        "missing_reflectors": ["back-wall-left"],
        "truck_preset": "realistic",
        "truck": {"steering.dead_time_s": 0.05},
    }
    assert sorted(options) == sorted(forkbench.RUN_OPTIONS)
    (record,) = forkbench.run_batch([scn], trials=1, modes="scenario", jobs=1, **options)
    assert {k: record[k] for k in options} == options
    env = PalletPickEnv(scn, **options)
    env.reset(seed=1)
    env.close()
    with pytest.raises(forkbench.ScenarioError, match="pallet_noise"):
        PalletPickEnv(scn, pallet_noise_scale=1000.0)
