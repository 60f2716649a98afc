"""forkbench from Python: scenarios, pick trials and batches (as dicts and pandas
DataFrames), and the Gymnasium environment ``forkbench/PalletPick-v0``.

The trials are the CLI's: the same seeds give the same outcomes, judged by the same
criteria. Units are SI (m, rad, s) throughout.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from typing import Any

from ._forkbench import (
    OBSERVATION_FIELDS,
    RUN_OPTIONS,
    STAGE_FIELD,
    BatchError,
    PickEnv,
    PickVecEnv,
    RecordingError,
    Scenario,
    ScenarioError,
    __version__,
    default_scenarios,
    estimate,
    falsify,
    replay,
    report,
    run_batch,
    run_trial,
)

__all__ = [
    "OBSERVATION_FIELDS",
    "RUN_OPTIONS",
    "STAGE_FIELD",
    "BatchError",
    "PickEnv",
    "PickVecEnv",
    "RecordingError",
    "Scenario",
    "ScenarioError",
    "__version__",
    "default_scenarios",
    "estimate",
    "falsify",
    "load",
    "replay",
    "report",
    "run_batch",
    "run_trial",
    "to_dataframe",
]


def load(scenario: Scenario | str | os.PathLike[str]) -> Scenario:
    """A scenario from a `Scenario`, an embedded default's name, or a file path."""
    if isinstance(scenario, Scenario):
        return scenario
    text = os.fspath(scenario)
    if os.path.exists(text) or text.endswith(".toml"):
        return Scenario.load(text)
    return Scenario.embedded(text)


def _flat(record: dict[str, Any]) -> dict[str, Any]:
    """One trial as one row: nested legs become counts, lists become `; `-joined text."""
    row: dict[str, Any] = {}
    for key, value in record.items():
        if key == "legs":
            row["legs"] = len(value)
            row["legs_failed"] = sum(1 for leg in value if not leg.get("success", True))
        elif isinstance(value, list):
            row[key] = "; ".join(str(v) for v in value)
        elif isinstance(value, dict):
            for k, v in value.items():
                row[f"{key}.{k}"] = v
        else:
            row[key] = value
    return row


def to_dataframe(records: Iterable[dict[str, Any]]) -> Any:
    """Trial outcomes (from `run_trial` or `run_batch`) as a pandas DataFrame, one row per
    trial, columns in SI units as the outcome names them. Needs pandas."""
    import pandas as pd

    return pd.DataFrame([_flat(r) for r in records])


try:  # The environment registers itself when Gymnasium is installed.
    from . import gym as _gym  # noqa: F401
except ImportError:  # pragma: no cover - gymnasium is optional
    pass
