"""Steps per second of forkbench's Gymnasium environments (single, and vectorised in Rust)
against pure-Python environments of similar size: a kinematic forklift with the same
observation and action spaces, and Gymnasium's Pendulum-v1. Random actions; each
measurement repeated (interleaved) and the median printed.

    python python/bench/gym_speed.py [--steps 20000] [--repeats 3] [--json]
"""

from __future__ import annotations

import argparse
import functools
import json
import math
import statistics
import time
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from forkbench.gym import PalletPickEnv, PalletPickVectorEnv


class KinematicForkliftEnv(gym.Env):
    """A pure-Python forklift of the same size: rear-steered bicycle kinematics at 10 ms,
    13 observations, 2 actions, a goal in front of a pallet, ends on arrival, on leaving
    a 30 m field or at 120 s. No physics, sensing or judging."""

    def __init__(self) -> None:
        self.observation_space = spaces.Box(-np.inf, np.inf, (13,), np.float32)
        self.action_space = spaces.Box(
            np.array([-0.8, -1.05], np.float32), np.array([0.8, 1.05], np.float32), dtype=np.float32
        )
        self.dt, self.wheelbase = 0.01, 1.6

    def _obs(self) -> np.ndarray:
        x, y, h = self.pose
        gx, gy, gh = self.goal
        dx, dy = gx - x, gy - y
        c, s = math.cos(h), math.sin(h)
        return np.array(
            [
                x,
                y,
                h,
                gx,
                gy,
                gh,
                c * dx + s * dy,
                -s * dx + c * dy,
                gh - h,
                self.v,
                self.steer,
                120.0 - self.t,
                1.0,
            ],
            np.float32,
        )

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.pose = [0.5, 6.6, 1.53 + self.np_random.normal(0, 0.02)]
        self.goal = (2.25, 13.07, 1.79)
        self.v = self.steer = self.t = 0.0
        return self._obs(), {}

    def step(self, action):
        v, steer = float(action[0]), float(action[1])
        x, y, h = self.pose
        self.v, self.steer = v, steer
        # Rear-wheel steering: the heading turns against the steering angle's sign.
        self.pose = [
            x + v * math.cos(h) * self.dt,
            y + v * math.sin(h) * self.dt,
            h + v * math.tan(steer) / self.wheelbase * self.dt,
        ]
        self.t += self.dt
        d = math.hypot(self.goal[0] - self.pose[0], self.goal[1] - self.pose[1])
        terminated = d < 0.05 or abs(self.pose[0]) > 30 or abs(self.pose[1]) > 30
        return self._obs(), -d * self.dt, terminated, self.t >= 120.0, {}


def single(env: gym.Env, steps: int) -> float:
    """Environment steps per second with random actions, resets included."""
    env.reset(seed=0)
    actions = [env.action_space.sample() for _ in range(1000)]
    t0 = time.perf_counter()
    for i in range(steps):
        _, _, term, trunc, _ = env.step(actions[i % 1000])
        if term or trunc:
            env.reset()
    return steps / (time.perf_counter() - t0)


def vectorised(env, steps: int) -> float:
    """Environment steps per second (all environments together) with random actions."""
    env.reset(seed=0)
    n = env.num_envs
    actions = [env.action_space.sample() for _ in range(100)]
    iters = max(1, steps // n)
    t0 = time.perf_counter()
    for i in range(iters):
        env.step(actions[i % 100])
    return iters * n / (time.perf_counter() - t0)


RUST_SIDE: dict[tuple[int, int], list[float]] = {}


def vectorised_rust(num_envs: int, threads: int, steps: int) -> float:
    """As `vectorised`; also keeps the same steps' rate counting only the time spent
    stepping in Rust (what the Python side's overhead is measured against)."""
    env = PalletPickVectorEnv(num_envs, threads=threads)
    rate = vectorised(env, steps)
    RUST_SIDE.setdefault((num_envs, threads), []).append(
        max(1, steps // num_envs) * num_envs / env.stepping_s
    )
    return rate


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--steps", type=int, default=20000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    cases = {
        "forkbench PalletPickEnv (raw)": lambda: single(PalletPickEnv(), a.steps),
        "forkbench gym.make (checker wrappers)": lambda: single(
            gym.make("forkbench/PalletPick-v0"), a.steps
        ),
        "pure-Python kinematic forklift": lambda: single(KinematicForkliftEnv(), a.steps),
        "Gymnasium Pendulum-v1 (raw)": lambda: single(gym.make("Pendulum-v1").unwrapped, a.steps),
    }
    for n in (16, 64, 256):
        for threads in (2, 1):
            label = f"{threads} thread{'s' if threads > 1 else ''}"
            cases[f"forkbench PalletPickVectorEnv × {n}, {label}"] = functools.partial(
                vectorised_rust, n, threads, a.steps * 5
            )
    cases["pure-Python forklift, SyncVectorEnv × 16"] = lambda: vectorised(
        gym.vector.SyncVectorEnv([KinematicForkliftEnv for _ in range(16)]), a.steps
    )
    runs: dict[str, list[float]] = {k: [] for k in cases}
    for _ in range(a.repeats):  # interleaved: every case once per round
        for name, run in cases.items():
            runs[name].append(run())

    def row(v: list[float], stepped: float | None = None) -> dict[str, Any]:
        r: dict[str, Any] = {
            "steps_per_s_median": statistics.median(v),
            "runs": v,
            "us_per_step": 1e6 / statistics.median(v),
        }
        if stepped is not None:
            r["python_stepped_fraction"] = stepped / statistics.median(v)
        return r

    result = {k: row(v) for k, v in runs.items()}
    for (n, threads), v in RUST_SIDE.items():
        label = f"{threads} thread{'s' if threads > 1 else ''}"
        stepped = statistics.median(runs[f"forkbench PalletPickVectorEnv × {n}, {label}"])
        result[f"  Rust-side rate of the same steps, × {n}, {label}"] = row(v, stepped)
    if a.json:
        print(json.dumps(result, indent=1))
        return
    print(f"{'environment':52} {'steps/s (median)':>17} {'µs/step':>9}")
    for k, r in result.items():
        frac = r.get("python_stepped_fraction")
        note = f"  (stepped from Python: {frac:.0%})" if frac else ""
        print(f"{k:52} {r['steps_per_s_median']:17,.0f} {r['us_per_step']:9.2f}{note}")


if __name__ == "__main__":
    main()
