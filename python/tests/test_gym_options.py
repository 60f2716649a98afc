"""The environment's options for standard RL libraries: normalised actions that pass the checkers without warnings, the residual mode whose zero action is the tracker's own trial, and frames that Gymnasium's video recorder writes."""

from __future__ import annotations

import warnings

import gymnasium as gym
import numpy as np
import pytest
from conftest import without_clock
from gymnasium.utils.env_checker import check_env

import forkbench
from forkbench.gym import PalletPickEnv, PalletPickVectorEnv


@pytest.mark.parametrize("mode", ["command", "residual"])
def test_the_normalised_options_pass_gymnasiums_checker_without_warnings(mode):
    env = gym.make(
        "forkbench/PalletPick-v0",
        normalize_actions=True,
        action_mode=mode,
        render_mode="rgb_array",
        disable_env_checker=True,
    ).unwrapped
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env)
    assert env.action_space.low.tolist() == [-1, -1] and env.action_space.high.tolist() == [1, 1]


@pytest.mark.parametrize("mode", ["command", "residual"])
def test_the_normalised_options_pass_stable_baselines3s_checker_without_warnings(mode):
    sb3_checker = pytest.importorskip("stable_baselines3.common.env_checker")
    env = PalletPickEnv(normalize_actions=True, action_mode=mode, render_mode="rgb_array")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sb3_checker.check_env(env, warn=True)


def test_normalised_actions_map_onto_the_bounds():
    env = PalletPickEnv(normalize_actions=True)
    speed, steer = env.scenario.command_limits
    assert env._actions.command([1.0, -1.0]).tolist() == [speed, -steer]
    assert env._actions.command([2.0, 0.5]).tolist() == [speed, 0.5 * steer]
    res = PalletPickEnv(normalize_actions=True, action_mode="residual", residual_limits=(0.2, 0.1))
    assert res._actions.command([-1.0, 1.0]).tolist() == [-0.2, 0.1]
    with pytest.raises(ValueError, match="action_mode"):
        PalletPickEnv(action_mode="torque")
    with pytest.raises(ValueError, match="residual_limits"):
        PalletPickEnv(action_mode="residual", residual_limits=(0.0, 0.1))
    with pytest.raises(ValueError, match="twice the truck's limits"):
        PalletPickEnv(action_mode="residual", residual_limits=(5.0, 0.1))
    with pytest.raises(ValueError, match="render_size"):
        PalletPickEnv(render_mode="rgb_array", render_size=(4, 4))


@pytest.mark.parametrize("scenario", ["field-test", "bspline-table2"])
def test_a_zero_residual_is_the_trackers_own_trial(scenario):
    scn = forkbench.load(scenario)
    env = PalletPickEnv(scn, action_mode="residual", normalize_actions=True)
    for seed in range(3):
        _, info = env.reset(seed=seed)
        steps = 0
        while True:
            _, _, term, trunc, end = env.step(np.zeros(2, dtype=np.float32))
            steps += 1
            if term or trunc:
                break
        want = forkbench.run_trial(scn, info["case"], seed=info["seed"])
        assert without_clock(end["outcome"]) == without_clock(want)


def test_a_residual_changes_the_trial():
    env = PalletPickEnv(action_mode="residual", ticks_per_step=10)

    def drive(correction):
        env.reset(seed=1)
        for _ in range(30):
            obs, _, _, _, _ = env.step(correction)
        return obs

    zero, turned = drive([0.0, 0.0]), drive([0.0, -0.3])
    # The tracker steers back against it, but the heading differs.
    assert abs(zero[2] - turned[2]) > 1e-3, "a steering correction left the heading as it was"


def test_frames_show_the_episode_and_record_video_writes_it(tmp_path):
    pytest.importorskip("moviepy")
    env = PalletPickEnv(
        render_mode="rgb_array", render_size=(200, 160), ticks_per_step=10, action_mode="residual"
    )
    assert env.metadata["render_fps"] == 10 and "rgb_array" in env.metadata["render_modes"]
    env.reset(seed=0)
    frame = env.render()
    assert frame is not None and frame.shape == (160, 200, 3) and frame.dtype == np.uint8
    # The truck (yellow) and the pallet (brown) are in the picture.
    yellow = (frame[..., 0] > 200) & (frame[..., 1] > 150) & (frame[..., 2] < 100)
    brown = (abs(frame[..., 0].astype(int) - 150) < 20) & (
        abs(frame[..., 1].astype(int) - 100) < 20
    )
    assert (
        yellow.sum() > 20 and brown.sum() + ((frame[..., 0] > 200) & (frame[..., 1] < 80)).sum() > 5
    )
    env.close()
    video = gym.wrappers.RecordVideo(
        PalletPickEnv(render_mode="rgb_array", ticks_per_step=10, action_mode="residual"),
        str(tmp_path / "videos"),
        episode_trigger=lambda _: True,
        disable_logger=True,
    )
    video.reset(seed=0)
    for _ in range(300):
        _, _, term, trunc, _ = video.step(np.zeros(2))
        if term or trunc:
            break
    video.close()
    files = list((tmp_path / "videos").glob("*.mp4"))
    assert files and files[0].stat().st_size > 1000, files


def test_without_a_render_mode_render_is_none():
    env = PalletPickEnv()
    env.reset(seed=0)
    assert env.render() is None
    with pytest.raises(ValueError, match="render_mode"):
        PalletPickEnv(render_mode="ascii")


def test_the_vector_env_takes_normalised_residual_actions():
    env = PalletPickVectorEnv(4, normalize_actions=True, action_mode="residual", ticks_per_step=10)
    assert env.single_action_space.high.tolist() == [1, 1]
    obs, _ = env.reset(seed=2)
    for _ in range(5):
        obs, rewards, _, _, _ = env.step(np.zeros((4, 2)))
    assert obs.shape == (4, 13) and np.isfinite(rewards).all()
