"""Typed stubs of forkbench's Rust extension (see the functions' docstrings)."""

import os
import pathlib
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt
from typing_extensions import TypeAlias, TypedDict, Unpack

__version__: str
OBSERVATION_FIELDS: list[str]
RUN_OPTIONS: list[str]
STAGE_FIELD: str
ENV_DEFAULTS: dict[str, object]

class RunOptions(TypedDict, total=False):
    """A run's options, each a keyword of `run_trial`, `run_batch`, `estimate`,
    `falsify` and the environments (the names are `RUN_OPTIONS`, the CLI's flags)."""

    pallet_noise_scale: float | None
    localization_noise_scale: float | None
    odometry_noise_scale: float | None
    localizer: str | None
    pallet_sensing: str | None
    missing_reflectors: Sequence[str] | None
    truck_preset: str | None
    truck: Mapping[str, float | str] | None
    """Truck settings by dotted path (`steering.dead_time_s`, `wheelbase_m`), numbers but
    for `layout`, a name: `counterbalance`, `pallet_stacker`, `reach_truck`."""

Outcome: TypeAlias = dict[str, Any]
"""A judged trial: the CLI's `trial --json` record (a batch's also has `trial`, `replan`)."""

class ScenarioError(ValueError):
    """A scenario, world or option that cannot be used."""

    file: str
    field: str | None
    reason: str

class BatchError(RuntimeError):
    """A batch that could not run or be read."""

class RecordingError(OSError):
    """A recording that could not be written."""

class Scenario:
    """A loaded and checked scenario."""

    @staticmethod
    def load(path: str | os.PathLike[str]) -> Scenario: ...
    @staticmethod
    def embedded(name: str) -> Scenario: ...
    def with_pallet_sensing(self, kind: str) -> Scenario: ...
    def with_localizer(self, kind: str) -> Scenario: ...
    def with_components(self, path: str | os.PathLike[str]) -> Scenario: ...
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
    def control_period_s(self) -> float:
        """How long one control tick (an environment's step) lasts, s."""
    @property
    def has_mission(self) -> bool: ...

def default_scenarios() -> list[Scenario]: ...
def run_trial(
    scenario: Scenario,
    case: str | None = None,
    *,
    seed: int | None = None,
    planner: str | None = None,
    tracker: str | None = None,
    noise: bool = True,
    replan: bool | None = None,
    mcap: str | os.PathLike[str] | None = None,
    force: bool = False,
    **options: Unpack[RunOptions],
) -> Outcome: ...
def run_batch(
    scenarios: Sequence[Scenario] | None = None,
    *,
    trials: int = 20,
    seed: int = 1,
    planners: Sequence[str] | None = None,
    trackers: Sequence[str] | None = None,
    modes: str | None = None,
    jobs: int | None = None,
    out: str | os.PathLike[str] | None = None,
    force_new: bool = False,
    **options: Unpack[RunOptions],
) -> list[Outcome]: ...
def estimate(
    scenario: Scenario,
    case: str | None = None,
    *,
    event: str = "failure",
    method: str = "ce",
    budget: int = 2000,
    seed: int = 1,
    jobs: int | None = None,
    planner: str | None = None,
    tracker: str | None = None,
    level_fraction: float | None = None,
    per_level: int | None = None,
    **options: Unpack[RunOptions],
) -> dict[str, Any]: ...
def falsify(
    scenario: Scenario,
    case: str | None = None,
    *,
    event: str = "failure",
    budget: int = 2000,
    seed: int = 1,
    monte_carlo: bool = False,
    jobs: int | None = None,
    planner: str | None = None,
    tracker: str | None = None,
    **options: Unpack[RunOptions],
) -> dict[str, Any]: ...
def report(
    dir: str | os.PathLike[str],
    *,
    baseline: str | os.PathLike[str] | None = None,
    out: str | os.PathLike[str] | None = None,
) -> pathlib.Path: ...
def replay(
    record: str | os.PathLike[str] | Outcome,
    line: int = 1,
    *,
    scenario: Scenario | None = None,
    mcap: str | os.PathLike[str] | None = None,
    force: bool = False,
) -> dict[str, Any]: ...

Reward: TypeAlias = tuple[float, float, float, float]
Step: TypeAlias = tuple[npt.NDArray[np.float32], float, bool, bool, dict[str, Any]]

class PickEnv:
    def __init__(
        self,
        scenario: Scenario,
        *,
        case: str | None = None,
        planner: str | None = None,
        tracker: str | None = None,
        noise: bool = True,
        replan: bool | None = None,
        ticks_per_step: int = 1,
        path_points: int = 0,
        path_spacing_m: float = 0.5,
        reward: Reward = (10.0, 10.0, 0.1, 1.0),
        render_size: tuple[int, int] | None = None,
        episode: str = "pick",
        phase_reward: float | None = None,
        **options: Unpack[RunOptions],
    ) -> None: ...
    @property
    def observation_size(self) -> int: ...
    def reset(
        self, seed: int, case: str | None = None
    ) -> tuple[npt.NDArray[np.float32], dict[str, Any]]: ...
    def step(self, speed_mps: float, steer_rad: float) -> Step: ...
    def residual_step(self, speed_mps: float, steer_rad: float) -> Step: ...
    def expert_step(self) -> Step: ...
    def render(self) -> npt.NDArray[np.uint8] | None: ...

class PickVecEnv:
    def __init__(
        self,
        scenario: Scenario,
        num_envs: int,
        *,
        case: str | None = None,
        planner: str | None = None,
        tracker: str | None = None,
        noise: bool = True,
        replan: bool | None = None,
        ticks_per_step: int = 1,
        path_points: int = 0,
        path_spacing_m: float = 0.5,
        reward: Reward = (10.0, 10.0, 0.1, 1.0),
        threads: int | None = None,
        episode: str = "pick",
        phase_reward: float | None = None,
        **options: Unpack[RunOptions],
    ) -> None: ...
    @property
    def num_envs(self) -> int: ...
    @property
    def observation_size(self) -> int: ...
    def reset(self, seed: int) -> tuple[npt.NDArray[np.float32], list[dict[str, Any]]]: ...
    def step(
        self, actions: npt.NDArray[np.float64], residual: bool = False
    ) -> tuple[
        npt.NDArray[np.float32],
        npt.NDArray[np.float64],
        npt.NDArray[np.bool_],
        npt.NDArray[np.bool_],
        list[tuple[int, dict[str, Any]]],
    ]: ...
    @property
    def stepping_s(self) -> float: ...
