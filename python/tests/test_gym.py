"""The Gymnasium environments: Gymnasium's own checker, determinism under a seed, the expert equal to a batch trial, episode ends judged by the bench, and the vector form independent of its thread count."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from conftest import ROOT, without_clock
from gymnasium.utils.env_checker import check_env

import forkbench
from forkbench.gym import PalletPickEnv, PalletPickVectorEnv


@pytest.mark.filterwarnings("ignore::UserWarning")
@pytest.mark.parametrize("kwargs", [{}, {"path_points": 6, "ticks_per_step": 5}])
def test_gymnasiums_checker_passes(kwargs):
    env = gym.make("forkbench/PalletPick-v0", **kwargs)
    check_env(env.unwrapped, skip_render_check=True)
    assert env.observation_space.shape == (13 + 2 * kwargs.get("path_points", 0),)


def rollout(env, seed, steps=400):
    obs, _ = env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    seen = [obs]
    for _ in range(steps):
        obs, reward, term, trunc, _info = env.step(rng.uniform(-1, 1, 2) * [0.8, 1.0])
        seen.append(np.append(obs, [reward, term, trunc]))
        if term or trunc:
            break
    return np.concatenate(seen)


def test_same_seed_same_episode():
    a, b = PalletPickEnv(), PalletPickEnv()
    assert np.array_equal(rollout(a, 11), rollout(b, 11))
    assert not np.array_equal(rollout(a, 11), rollout(a, 12))


def test_the_expert_reproduces_the_batch_trial_at_the_episode_seed():
    scn = forkbench.load("bspline-table2")
    env = PalletPickEnv(scn)
    for seed in range(3):
        _, info = env.reset(seed=seed)
        total, steps = 0.0, 0
        while True:
            _, reward, term, trunc, end = env.expert_step()
            total, steps = total + reward, steps + 1
            if term or trunc:
                break
        want = forkbench.run_trial(scn, info["case"], seed=info["seed"])
        assert without_clock(end["outcome"]) == without_clock(want)
        assert end["success"] == want["success"] and end["failure"] == want["failure"]
        # One step per control tick (the truck's 0.02 s period by default), after the
        # truck stood for its first fix and estimate (0.08 s by default); a pick that
        # first drove to a staging pose (a leg, which runs on its own) took fewer.
        tick_s = scn.control_period_s
        assert term
        if not want.get("legs"):
            assert steps >= round((want["sim_time_s"] - 0.1) / tick_s)


def test_episodes_end_as_the_bench_judges():
    env = PalletPickEnv()
    env.reset(seed=1)
    steps = 0
    while True:  # standing still: truncated at the scenario's time limit
        _, _reward, term, trunc, info = env.step([0.0, 0.0])
        steps += 1
        if term or trunc:
            break
    assert trunc and not term and info["failure"] == "timeout"
    assert steps == round(env.scenario.timeout_s / env.scenario.control_period_s)
    # After the end a step raises instead of repeating the terminal reward.
    with pytest.raises(RuntimeError, match="reset"):
        env.step([0.0, 0.0])
    env.reset(seed=2)
    with pytest.raises(ValueError, match="finite"):
        env.step([float("nan"), 0.0])


def vector_rollout(threads, steps=300):
    env = PalletPickVectorEnv(6, "field-test", threads=threads, ticks_per_step=10)
    obs, _ = env.reset(seed=5)
    rng = np.random.default_rng(0)
    out, ended = [obs], 0
    for _ in range(steps):
        actions = rng.uniform(-1, 1, (6, 2)) * [0.8, 1.0] + [0.5, 0.0]
        obs, rewards, term, trunc, info = env.step(actions)
        out += [obs, rewards[:, None], term[:, None], trunc[:, None]]
        ended += int(info.get("_outcome", np.zeros(6, bool)).sum())
    return np.concatenate([np.asarray(x, dtype=np.float64).ravel() for x in out]), ended


def test_the_vector_env_is_independent_of_its_thread_count_and_autoresets():
    one, ended = vector_rollout(1)
    two, ended2 = vector_rollout(2)
    assert np.array_equal(one, two) and ended == ended2
    assert ended > 0, "no episode ended in 300 × 0.1 s of random driving"


def test_make_vec_uses_the_rust_vector():
    env = gym.make_vec(
        "forkbench/PalletPick-v0", num_envs=3, vectorization_mode="vector_entry_point"
    )
    obs, _ = env.reset(seed=0)
    assert obs.shape == (3, 13) and obs.dtype == np.float32
    obs, rewards, term, _trunc, _ = env.step(env.action_space.sample())
    assert rewards.shape == (3,) and term.dtype == np.bool_


def test_an_episode_that_ends_before_driving_terminates_on_its_first_step(tmp_path):
    # With one look from the start (`when_not_seen = "fail"`), spiral-table2's sensing finds
    # no pallet from some start poses: the trial ends at reset.
    once = tmp_path / "spiral-once.toml"
    text = (ROOT / "scenarios/spiral-table2.toml").read_text()
    once.write_text(text + '\n[pick]\nwhen_not_seen = "fail"\n')
    env = PalletPickEnv(forkbench.load(once))
    for seed in range(200):
        _, info = env.reset(seed=seed)
        if "outcome" in info:
            break
    else:
        pytest.fail("no episode ended before driving in 200 seeds")
    assert info["failure"] == "pallet_not_found"
    _, reward, term, trunc, end = env.step([0.5, 0.0])
    assert term and not trunc and reward == -10.0 and end["failure"] == "pallet_not_found"
    vec = PalletPickVectorEnv(8, forkbench.load(once), ticks_per_step=50)
    vec.reset(seed=3)
    ended = 0
    for _ in range(60):  # every reported outcome comes with its episode's last step
        _, _, term, trunc, info = vec.step(np.tile([0.6, 0.0], (8, 1)))
        mask = info.get("_outcome", np.zeros(8, bool))
        assert np.array_equal(mask, term | trunc), (mask, term, trunc)
        ended += int(mask.sum())
    assert ended > 8


def test_a_staged_episode_starts_at_the_staging_pose():
    # Staged (the default), the same geometries start the episode 3 m before the face.
    env = PalletPickEnv("spiral-table2", case="14", noise=False)
    _, info = env.reset(seed=1)
    assert "outcome" not in info, info


def test_a_vector_environment_is_capped_by_memory():
    with pytest.raises(ValueError, match="GiB"):
        PalletPickVectorEnv(1_000_000)
    with pytest.raises(ValueError, match="at least 1"):
        PalletPickVectorEnv(0)


def test_misuse_is_refused_with_a_reason() -> None:
    with pytest.raises(ValueError, match="ticks_per_step"):
        PalletPickEnv(ticks_per_step=0)
    vec = PalletPickVectorEnv(2)
    with pytest.raises(RuntimeError, match="step before reset"):
        vec.step(vec.action_space.sample())
    vec.reset(seed=1)
    vec.step(vec.action_space.sample())


def test_one_environment_is_stepped_by_one_thread_at_a_time() -> None:
    import threading

    env = PalletPickEnv()
    env.reset(seed=3)
    errors: list[str] = []

    def drive() -> None:
        for _ in range(300):
            try:
                _, _, term, trunc, _ = env.step(np.array([0.5, 0.0], dtype=np.float32))
            except RuntimeError as e:
                errors.append(str(e))
                return
            if term or trunc:
                return

    threads = [threading.Thread(target=drive) for _ in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert all("Already borrowed" not in e for e in errors), errors
    assert all("one thread at a time" in e or "has ended" in e for e in errors), errors
