"""Whole-cycle episodes: every stage's tick is the agent's, the outcome equals run_trial's,
the stage field walks the cycle, and each part passed earns the phase reward."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest
from conftest import ROOT, without_clock

import forkbench
from forkbench import _forkbench
from forkbench.gym import PalletPickEnv

CYCLE = ROOT / "scenarios" / "rack-pick-cycle.toml"


def expert_episode(env: _forkbench.PickEnv, seed: int) -> tuple[list[float], list[float], dict]:
    """The stage after each expert step, the step rewards, and the last info."""
    obs, info = env.reset(seed, "default")
    stages, rewards = [float(obs[len(forkbench.OBSERVATION_FIELDS)])], []
    for _ in range(200_000):
        obs, reward, terminated, truncated, info = env.expert_step()
        stages.append(float(obs[len(forkbench.OBSERVATION_FIELDS)]))
        rewards.append(reward)
        if terminated or truncated:
            return stages, rewards, info
    pytest.fail("no end")


def test_a_cycle_episode_under_the_expert_equals_run_trial_and_rewards_each_part() -> None:
    scn = forkbench.load(CYCLE)
    env = _forkbench.PickEnv(
        scn, case="default", reward=(0.0, 0.0, 0.0, 0.0), episode="cycle", phase_reward=1.0
    )
    assert env.observation_size == len(forkbench.OBSERVATION_FIELDS) + 1
    stages, rewards, info = expert_episode(env, 7)
    want = forkbench.run_trial(scn, "default", seed=7)
    assert without_clock(info["outcome"]) == without_clock(want)
    assert [p["name"] for p in want["phases"]] == ["pick", "lift", "reverse_out"]
    assert want["success"]
    # The stage field walks pick (2), lift (3), reverse out (4), never back.
    assert stages[0] == 2.0 and stages[-1] == 4.0
    assert sorted(set(stages)) == [2.0, 3.0, 4.0]
    assert all(b >= a for a, b in zip(stages, stages[1:]))
    # With every other weight 0, the steps after the pick earn exactly one per part passed.
    after_pick = [r for s, r in zip(stages[1:], rewards) if s > 2.0]
    assert sum(after_pick) == pytest.approx(3.0)


def test_a_pick_episode_of_the_cycle_scenario_stops_at_the_pick() -> None:
    scn = forkbench.load(CYCLE)
    env = _forkbench.PickEnv(scn, case="default")
    assert env.observation_size == len(forkbench.OBSERVATION_FIELDS)
    env.reset(7, "default")
    for _ in range(200_000):
        *_, terminated, truncated, info = env.expert_step()
        if terminated or truncated:
            break
    assert info["outcome"].get("phases", []) == []
    assert "cycle" not in info["outcome"]


def test_cycle_options_are_checked() -> None:
    scn = forkbench.load(CYCLE)
    with pytest.raises(ValueError, match="episode"):
        _forkbench.PickEnv(scn, episode="shift")
    with pytest.raises(ValueError, match="phase_reward"):
        _forkbench.PickEnv(scn, phase_reward=1.0)
    with pytest.raises(ValueError, match="phase_reward"):
        _forkbench.PickEnv(scn, episode="cycle", phase_reward=float("nan"))


def test_the_gymnasium_cycle_env_passes_the_checker_and_vectorises() -> None:
    env = PalletPickEnv(
        CYCLE,
        case="default",
        episode="cycle",
        ticks_per_step=20,
        normalize_actions=True,
        action_mode="residual",
    )
    from gymnasium.utils.env_checker import check_env

    check_env(env, skip_render_check=True)
    obs, _ = env.reset(seed=1)
    total = 0.0
    for _ in range(5_000):
        obs, reward, terminated, truncated, info = env.step(np.zeros(2, dtype=np.float32))
        total += reward
        if terminated or truncated:
            break
    assert terminated and info["success"], info.get("outcome", {}).get("failure_detail")
    vec = gymnasium.make_vec(
        "forkbench/PalletPick-v0",
        num_envs=2,
        vectorization_mode="vector_entry_point",
        scenario=CYCLE,
        case="default",
        episode="cycle",
        ticks_per_step=20,
    )
    obs, _ = vec.reset(seed=2)
    assert obs.shape == (2, len(forkbench.OBSERVATION_FIELDS) + 1)
    assert set(obs[:, len(forkbench.OBSERVATION_FIELDS)]) == {2.0}
    vec.close()
