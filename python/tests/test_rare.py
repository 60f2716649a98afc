"""Rare events from Python: estimate and falsify equal the CLI's at the same seed, every trial comes back with its point, and bad arguments raise naming them."""

from __future__ import annotations

import json

import pytest
from conftest import ROOT

import forkbench

TAILS = str(ROOT / "examples" / "rare" / "field-test-tails.toml")


def test_an_estimate_equals_the_clis_and_carries_its_trials(cli, tmp_path):
    scn = forkbench.load(TAILS)
    got = forkbench.estimate(scn, method="mc", budget=60, seed=3, jobs=1)
    want = json.loads(
        cli(
            "estimate",
            TAILS,
            "--method",
            "mc",
            "--budget",
            "60",
            "--seed",
            "3",
            "--out",
            str(tmp_path / "mc"),
            "--json",
        )
    )
    assert got["p"] == want["p"] and got["ci"] == pytest.approx(want["ci"])
    assert got["trials"] == 60 and len(got["records"]) == 60
    first = got["records"][0]
    assert len(first["z"]) == 4 and set(first["uncertain"]) >= {
        "pallet.y_m",
        "steering_time_constant_s",
    }
    ce = forkbench.estimate(scn, budget=200, seed=3, jobs=1)
    assert ce["method"] == "ce" and ce["adapting"] <= 100 and ce["trials"] == 200
    sub = forkbench.estimate(scn, method="subset", budget=200, seed=3, jobs=1)
    assert sub["method"] == "subset" and 50 <= sub["trials"] <= 200
    assert sub["levels"][0]["points"] == 50 and sub["stages"] == []
    set_ = forkbench.estimate(
        scn, method="subset", budget=200, seed=3, jobs=1, level_fraction=0.2, per_level=40
    )
    assert set_["levels"][0]["points"] == 40
    with pytest.raises(ValueError, match="subset simulation"):
        forkbench.estimate(scn, method="ce", budget=200, per_level=40)
    with pytest.raises(forkbench.BatchError, match="subset.level_fraction"):
        forkbench.estimate(scn, method="subset", budget=200, level_fraction=0.9)


def test_a_search_returns_its_points_and_refuses_bad_arguments():
    scn = forkbench.load(TAILS)
    f = forkbench.falsify(scn, budget=60, seed=2, jobs=1)
    # Eight of the budget are kept to refine a failure; without one they go unspent.
    assert 52 <= f["trials"] == len(f["records"]) <= 60
    assert f["least_robust"] is not None
    with pytest.raises(ValueError, match="method"):
        forkbench.estimate(scn, method="splitting", budget=60)
    with pytest.raises(ValueError, match="event"):
        forkbench.falsify(scn, event="nonsense", budget=60)
    with pytest.raises(forkbench.BatchError, match="budget"):
        forkbench.estimate(scn, budget=10)
    with pytest.raises(forkbench.BatchError, match="no \\[\\[uncertain\\]\\]"):
        forkbench.estimate(forkbench.load("field-test"), budget=60)
