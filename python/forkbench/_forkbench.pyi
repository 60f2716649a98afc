"""Typed stubs of forkbench's Rust extension (see the functions' docstrings)."""

from __future__ import annotations

import os
from typing import Any, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str
OBSERVATION_FIELDS: list[str]

Outcome = dict[str, Any]
"""A judged trial: the CLI's `trial --json` record (a batch's also has `trial`, `replan`)."""

class ScenarioError(ValueError):
    """A scenario, world or option that cannot be used."""

    file: str
    field: Optional[str]
    reason: str

class BatchError(RuntimeError):
    """A batch that could not run or be read."""

class RecordingError(OSError):
    """A recording that could not be written."""

class Scenario:
    """A loaded and checked scenario."""

    @staticmethod
    def load(path: Union[str, os.PathLike[str]]) -> Scenario: ...
    @staticmethod
    def embedded(name: str) -> Scenario: ...
    def with_pallet_sensing(self, kind: str) -> Scenario: ...
    def with_localizer(self, kind: str) -> Scenario: ...
    @property
    def name(self) -> str: ...
    @property
    def file(self) -> str: ...
    @property
    def cases(self) -> list[str]: ...
    @property
    def planner(self) -> str: ...
    @property
    def tracker(self) -> str: ...
    @property
    def seed(self) -> int: ...
    @property
    def timeout_s(self) -> float: ...
    @property
    def command_limits(self) -> tuple[float, float]:
        """(max speed m/s, max steering rad)."""
    @property
    def has_mission(self) -> bool: ...

def default_scenarios() -> list[Scenario]: ...
def run_trial(
    scenario: Scenario,
    case: Optional[str] = None,
    *,
    seed: Optional[int] = None,
    planner: Optional[str] = None,
    tracker: Optional[str] = None,
    noise: bool = True,
    pallet_noise_scale: Optional[float] = None,
    replan: Optional[bool] = None,
    mcap: Optional[Union[str, os.PathLike[str]]] = None,
) -> Outcome: ...
def run_batch(
    scenarios: Optional[Sequence[Scenario]] = None,
    *,
    trials: int = 20,
    seed: int = 1,
    planners: Optional[Sequence[str]] = None,
    trackers: Optional[Sequence[str]] = None,
    modes: Optional[str] = None,
    pallet_noise_scale: Optional[float] = None,
    jobs: Optional[int] = None,
    out: Optional[Union[str, os.PathLike[str]]] = None,
) -> list[Outcome]: ...

Reward = tuple[float, float, float, float]
Step = tuple[npt.NDArray[np.float32], float, bool, bool, dict[str, Any]]

class PickEnv:
    def __init__(
        self,
        scenario: Scenario,
        *,
        case: Optional[str] = None,
        planner: Optional[str] = None,
        tracker: Optional[str] = None,
        noise: bool = True,
        replan: Optional[bool] = None,
        ticks_per_step: int = 1,
        path_points: int = 0,
        path_spacing_m: float = 0.5,
        reward: Reward = (10.0, 10.0, 0.1, 1.0),
    ) -> None: ...
    @property
    def observation_size(self) -> int: ...
    def reset(
        self, seed: int, case: Optional[str] = None
    ) -> tuple[npt.NDArray[np.float32], dict[str, Any]]: ...
    def step(self, speed_mps: float, steer_rad: float) -> Step: ...
    def expert_step(self) -> Step: ...

class PickVecEnv:
    def __init__(
        self,
        scenario: Scenario,
        num_envs: int,
        *,
        case: Optional[str] = None,
        planner: Optional[str] = None,
        tracker: Optional[str] = None,
        noise: bool = True,
        replan: Optional[bool] = None,
        ticks_per_step: int = 1,
        path_points: int = 0,
        path_spacing_m: float = 0.5,
        reward: Reward = (10.0, 10.0, 0.1, 1.0),
        threads: Optional[int] = None,
    ) -> None: ...
    @property
    def num_envs(self) -> int: ...
    @property
    def observation_size(self) -> int: ...
    def reset(self, seed: int) -> tuple[npt.NDArray[np.float32], list[dict[str, Any]]]: ...
    def step(
        self, actions: npt.NDArray[np.float64]
    ) -> tuple[
        npt.NDArray[np.float32],
        npt.NDArray[np.float64],
        npt.NDArray[np.bool_],
        npt.NDArray[np.bool_],
        list[Optional[dict[str, Any]]],
    ]: ...
