"""Gymnasium environments of a forkbench pick trial: ``forkbench/PalletPick-v0``.

An episode is one pick trial of a scenario case: the truck starts where the case puts it
(after a mission's legs, when the scenario has a mission), with the first localiser fix,
pallet estimate and plan made. Each step is one 10 ms control tick (or
``ticks_per_step`` of them): the agent's command, a rapier2d physics step, the judging,
the next tick's sensing.

Observation (float32; the first 13 fields are ``forkbench.OBSERVATION_FIELDS``): what the
truck's controller knows, never the truth: the localiser's fork-root pose (x, y,
heading), the pallet estimate (face pose), the goal (fork root at the target depth in the
estimate) in the truck's frame, measured speed and steering angle, time left, whether
this tick brought a localiser fix; then, with ``path_points=K``, K (x, y) points of the
planned path ahead in the truck's frame, ``path_spacing_m`` apart.

Action (float32): speed (m/s, forward positive) and equivalent steering angle (rad,
positive left), bounded by the truck's limits. Options:

- ``normalize_actions=True``: the action space is [-1, 1]² and maps linearly onto the
  bounds (the truck's limits, or the residual's), as Stable-Baselines3 recommends;
- ``action_mode="residual"``: the action is a correction added to the scenario's
  tracker's command (speed, steering), within ``residual_limits`` (default 0.3 m/s and
  0.3 rad); the sum is clamped to the truck's limits. Episodes then end as the tracker's
  trial does (the tracker reports the goal reached and the truck stands, or the time
  limit), so a zero action is exactly the tracker's own trial.

Rendering: ``render_mode="rgb_array"`` returns a top-down image (height × width × 3,
uint8; ``render_size=(width, height)``, default 320 × 320) of the racks, the plan (blue),
the true pallet (brown) and its estimate (red outline), the truck (yellow) with its forks
and the last scan returns (magenta); ``"human"`` shows it in a matplotlib window where a
display exists. ``metadata["render_fps"]`` is the simulated rate: 100 / ``ticks_per_step``.

Episode end: terminated when the truck stands with the forks at the required depth, or
as soon as a criterion fails for good (a rack or wall touched, fork contact force,
pallet moved or turned, entry outside the lateral or heading limit); truncated at the
scenario's time limit. ``info["outcome"]`` is then the trial's judged outcome, the same
record a batch writes, with ``info["success"]`` and ``info["failure"]``.

Default reward: the decrease, per step, of the true fork root's distance to the true goal
plus 1 m per radian of heading error; minus 0.1 per simulated second; plus 10 when the
trial is judged a success, minus 10 when judged a failure before the time limit (0 at
the time limit). ``reward=(success, failure, time_per_s, heading_m_per_rad)`` changes the
weights.

Whole cycles: ``episode="cycle"`` makes an episode the scenario's whole handling cycle,
every tick of it the agent's: the mission's legs, a staging drive, the pick, and each
phase the scenario lists after it (lift, reverse out, carry, place, return). The
observation gains a field after the 13 fixed ones, ``forkbench.STAGE_FIELD``: 0 on a
mission leg, 1 staging, 2 the pick, 2 + k the k-th phase after the pick. The agent's
action acts on every stage (``"residual"`` corrects each stage's own controller: the
legs' path follower, the pick's tracker, a phase's commands). The episode is terminated
at the cycle's verdict (a failed phase ends it) and truncated when a drive's time limit
ends it (the pick's, a leg's or a phase's). Its reward, per part:

- legs and staging: minus ``time_per_s`` per simulated second;
- the pick: as above, the potential's decrease and the time;
- leaving the pick or a phase for the next (the cycle only goes on past a success):
  plus ``phase_reward`` (default 2.0) for each part passed, and for the last part at a
  successful end; the phases after the pick: minus ``time_per_s`` per second;
- the end: plus ``success`` for a successful cycle, minus ``failure`` for a failed one
  (0 at a time limit).

``info["outcome"]`` is then the cycle's outcome, equal to `run_trial`'s for the same
seed when every step is `expert_step`. ``phase_reward`` with ``episode="pick"`` is
refused.
"""

from __future__ import annotations

import os
import threading
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import gymnasium
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

if TYPE_CHECKING:
    from typing_extensions import Unpack

    from ._forkbench import RunOptions

from . import _forkbench
from ._forkbench import Scenario

ENV_ID = "forkbench/PalletPick-v0"
DEFAULT_SCENARIO = "field-test"
Reward = tuple[float, float, float, float]


def _scenario(scenario: Scenario | str | os.PathLike[str]) -> Scenario:
    from . import load

    return load(scenario)


def _reward(reward: Sequence[float]) -> Reward:
    """The reward weights as the four floats the core takes."""
    r = [float(x) for x in reward]
    if len(r) != 4:
        raise ValueError(
            f"reward {reward!r}: expected (success, failure, time_per_s, heading_m_per_rad)"
        )
    return (r[0], r[1], r[2], r[3])


RENDER_MODES = ["rgb_array", "human"]


def _render_modes() -> list[str]:
    """The modes this process can show: ``human`` only where a display exists."""
    shown = bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    return RENDER_MODES if shown else ["rgb_array"]


ACTION_MODES = ("command", "residual")


class _Exclusive:
    """One thread at a time in an environment's core: a second thread's call is refused
    with a message saying why, not pyo3's bare "Already borrowed"."""

    def __init__(self) -> None:
        self._lock = threading.Lock()

    def __enter__(self) -> None:
        if not self._lock.acquire(blocking=False):
            raise RuntimeError(
                "this environment is being stepped or reset by another thread; an environment "
                "is used by one thread at a time (give each thread its own, or step many "
                "with PalletPickVectorEnv)"
            )

    def __exit__(self, *_: object) -> None:
        self._lock.release()


class _Actions:
    """How an agent's action becomes the command the core takes: its bounds, whether it
    is normalised to [-1, 1], and whether it corrects the tracker's command."""

    def __init__(
        self,
        scn: Scenario,
        mode: str,
        normalize: bool,
        residual_limits: Sequence[float],
    ) -> None:
        if mode not in ACTION_MODES:
            raise ValueError(f"action_mode {mode!r}: one of {', '.join(ACTION_MODES)}")
        speed, steer = scn.command_limits
        if mode == "residual":
            lim = [float(x) for x in residual_limits]
            # A correction beyond twice the truck's limit cannot act: the sum is clamped.
            top = (2 * speed, 2 * steer)
            if len(lim) != 2 or not all(0.0 < x <= t for x, t in zip(lim, top)):
                raise ValueError(
                    f"residual_limits {residual_limits!r}: two bounds, speed in (0, {top[0]:g}] "
                    f"m/s and steering in (0, {top[1]:g}] rad (twice the truck's limits)"
                )
            speed, steer = lim[0], lim[1]
        self.residual = mode == "residual"
        self.normalize = normalize
        self.bounds = np.array([speed, steer], dtype=np.float64)

    def space(self) -> spaces.Box:
        hi = np.ones(2) if self.normalize else self.bounds
        return spaces.Box(-hi.astype(np.float32), hi.astype(np.float32), dtype=np.float32)

    def command(self, action: Any) -> np.ndarray:
        """(…, 2) actions as (speed, steering) commands or corrections, float64."""
        a = np.asarray(action, dtype=np.float64)
        if self.normalize:
            a = np.clip(a, -1.0, 1.0) * self.bounds
        return a


# Every observation field is finite and far inside this (map coordinates in metres,
# unwrapped headings in radians, seconds); a finite bound keeps the checkers quiet.
OBS_BOUND = 1e6


def _spaces(size: int, actions: _Actions) -> tuple[spaces.Box, spaces.Box]:
    obs = spaces.Box(-OBS_BOUND, OBS_BOUND, shape=(size,), dtype=np.float32)
    return obs, actions.space()


def _render_size(size: Sequence[int]) -> tuple[int, int]:
    w, h = (int(x) for x in size)
    return (w, h)


class PalletPickEnv(gymnasium.Env):
    """One forkbench pick trial per episode (see the module's documentation).

    ``scenario``: a `Scenario`, an embedded scenario's name or a scenario file;
    ``case``: a fixed case (default: each episode draws one); ``planner``, ``tracker``,
    ``noise``, ``replan``: as for `run_trial` (the tracker drives `expert_step` and the
    residual mode). Further keywords are the run's options (``forkbench.RUN_OPTIONS``:
    noise scales, sensing models, missing reflectors, the truck's actuators), as for
    `run_trial`.
    """

    # Gymnasium declares metadata per instance; a class attribute is its convention.
    metadata = {"render_modes": RENDER_MODES, "render_fps": 100}  # noqa: RUF012

    def __init__(
        self,
        scenario: Scenario | str | os.PathLike[str] = DEFAULT_SCENARIO,
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
        render_mode: str | None = None,
        render_size: Sequence[int] = (320, 320),
        normalize_actions: bool = False,
        action_mode: str = "command",
        residual_limits: Sequence[float] = (0.3, 0.3),
        episode: str = "pick",
        phase_reward: float | None = None,
        **options: Unpack[RunOptions],
    ) -> None:
        modes = _render_modes()
        if render_mode is not None and render_mode not in modes:
            raise ValueError(
                f"render_mode {render_mode!r}: None or one of {modes}"
                + ("" if render_mode not in RENDER_MODES else " (no display for 'human')")
            )
        self.render_mode = render_mode
        self.scenario = _scenario(scenario)
        self._case = case
        self._actions = _Actions(self.scenario, action_mode, normalize_actions, residual_limits)
        self._window: Any = None
        self._busy = _Exclusive()
        self._core = _forkbench.PickEnv(
            self.scenario,
            case=case,
            planner=planner,
            tracker=tracker,
            noise=noise,
            replan=replan,
            ticks_per_step=ticks_per_step,
            path_points=path_points,
            path_spacing_m=path_spacing_m,
            reward=_reward(reward),
            render_size=None if render_mode is None else _render_size(render_size),
            episode=episode,
            phase_reward=phase_reward,
            **options,
        )
        # After the core has checked ticks_per_step (at least 1).
        self.metadata = {"render_modes": modes, "render_fps": 100 / ticks_per_step}
        self.observation_space, self.action_space = _spaces(
            self._core.observation_size, self._actions
        )
        if render_mode == "human":
            self._window = _HumanWindow()

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Starts an episode; ``options={"case": name}`` chooses its case."""
        super().reset(seed=seed)
        case = (options or {}).get("case") or self._case
        if case is None:
            cases = self.scenario.cases
            case = cases[int(self.np_random.integers(len(cases)))]
        trial_seed = int(self.np_random.integers(0, 2**63 - 1))
        with self._busy:
            self._ended = False
            return self._core.reset(trial_seed, case)

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        self._refuse_after_end()
        a = self._actions.command(action).reshape(2)
        step = self._core.residual_step if self._actions.residual else self._core.step
        with self._busy:
            out = self._mark_end(step(float(a[0]), float(a[1])))
        if self._window is not None:
            self.render()
        return out

    def render(self) -> np.ndarray | None:
        """The episode now as an RGB image (``rgb_array``), or shown in a window
        (``human``); None without a render mode."""
        if self.render_mode is None:
            return None
        with self._busy:
            frame = self._core.render()
        if self._window is not None and frame is not None:
            self._window.show(frame)
            return None
        return frame

    def close(self) -> None:
        if self._window is not None:
            self._window.close()
            self._window = None

    def expert_step(self) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """One step under the scenario's own tracker (a reference to compare against)."""
        self._refuse_after_end()
        with self._busy:
            return self._mark_end(self._core.expert_step())

    def _refuse_after_end(self) -> None:
        # A step after the end would repeat the terminal reward: Gymnasium's contract is
        # that the caller resets first.
        if getattr(self, "_ended", False):
            raise RuntimeError("the episode has ended (terminated or truncated); call reset()")

    def _mark_end(
        self, out: tuple[np.ndarray, float, bool, bool, dict[str, Any]]
    ) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        self._ended = bool(out[2] or out[3])
        return out


class _HumanWindow:
    """A matplotlib window the frames are shown in (``render_mode="human"``)."""

    def __init__(self) -> None:
        try:
            import matplotlib.pyplot as plt
        except ImportError as e:
            raise RuntimeError("render_mode='human' needs matplotlib") from e
        self._plt = plt
        self._image: Any = None

    def show(self, frame: np.ndarray) -> None:
        if self._image is None:
            self._plt.ion()
            self._image = self._plt.imshow(frame)
            self._plt.axis("off")
        else:
            self._image.set_data(frame)
        self._plt.pause(0.001)

    def close(self) -> None:
        self._plt.close()


class PalletPickVectorEnv(VectorEnv):
    """``num_envs`` pick environments stepped in parallel in Rust on ``threads`` threads
    (default: all cores), with next-step autoreset: the step after an episode ends
    starts the next one and ignores that environment's action. Environment i draws its
    episodes' cases and trial seeds from a stream seeded by ``reset(seed)`` and i, so
    results do not depend on the thread count."""

    # Gymnasium declares metadata per instance; a class attribute is its convention.
    metadata = {"render_modes": [], "autoreset_mode": AutoresetMode.NEXT_STEP}  # noqa: RUF012

    def __init__(
        self,
        num_envs: int = 8,
        scenario: Scenario | str | os.PathLike[str] = DEFAULT_SCENARIO,
        *,
        threads: int | None = None,
        case: str | None = None,
        planner: str | None = None,
        tracker: str | None = None,
        noise: bool = True,
        replan: bool | None = None,
        ticks_per_step: int = 1,
        path_points: int = 0,
        path_spacing_m: float = 0.5,
        reward: Reward = (10.0, 10.0, 0.1, 1.0),
        normalize_actions: bool = False,
        action_mode: str = "command",
        residual_limits: Sequence[float] = (0.3, 0.3),
        episode: str = "pick",
        phase_reward: float | None = None,
        **options: Unpack[RunOptions],
    ) -> None:
        self.scenario = _scenario(scenario)
        self._actions = _Actions(self.scenario, action_mode, normalize_actions, residual_limits)
        self._busy = _Exclusive()
        self._core = _forkbench.PickVecEnv(
            self.scenario,
            num_envs,
            case=case,
            planner=planner,
            tracker=tracker,
            noise=noise,
            replan=replan,
            ticks_per_step=ticks_per_step,
            path_points=path_points,
            path_spacing_m=path_spacing_m,
            reward=_reward(reward),
            threads=threads,
            episode=episode,
            phase_reward=phase_reward,
            **options,
        )
        self.num_envs = num_envs
        self.single_observation_space, self.single_action_space = _spaces(
            self._core.observation_size, self._actions
        )
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)

    def reset(
        self,
        *,
        seed: int | Sequence[int] | None = None,
        options: dict[str, Any] | None = None,
    ) -> tuple[np.ndarray, dict[str, Any]]:
        if seed is None:
            seed = int(np.random.SeedSequence().generate_state(1, np.uint64)[0])
        elif not isinstance(seed, int):
            seed = int(seed[0])
        self._np_random_seed = seed
        with self._busy:
            obs, infos = self._core.reset(seed)
        return obs, self._batch_infos(list(enumerate(infos)))

    def step(
        self, actions: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        a = self._actions.command(actions).reshape(self.num_envs, 2)
        with self._busy:
            obs, rewards, terminated, truncated, ended = self._core.step(a, self._actions.residual)
        return obs, rewards, terminated, truncated, self._batch_infos(ended) if ended else {}

    @property
    def stepping_s(self) -> float:
        """Seconds spent stepping in Rust since the last reset (the rest of a step's time
        is the Python side's)."""
        return self._core.stepping_s

    def _batch_infos(self, infos: Sequence[tuple[int, dict[str, Any]]]) -> dict[str, Any]:
        """Per-environment dicts as Gymnasium's vector info: a key's values in an array,
        ``_key`` marking the environments that have it."""
        out: dict[str, Any] = {}
        for i, info in infos:
            for key, value in info.items():
                if key not in out:
                    out[key] = np.full(self.num_envs, None, dtype=object)
                    out["_" + key] = np.zeros(self.num_envs, dtype=bool)
                out[key][i] = value
                out["_" + key][i] = True
        return out


gymnasium.register(
    id=ENV_ID,
    entry_point="forkbench.gym:PalletPickEnv",
    vector_entry_point="forkbench.gym:PalletPickVectorEnv",
)
