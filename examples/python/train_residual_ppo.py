"""Residual reinforcement learning on forkbench/PalletPick-v0 with Stable-Baselines3's
PPO: the agent's action is a bounded correction to the scenario's pure-pursuit command
(``action_mode="residual"``, ``normalize_actions=True``), so learning starts from the
bench's own tracker. Trains, draws the learning curve (success on fixed evaluation
episodes against training steps), and compares the trained policy with pure pursuit on
the same evaluation episodes, paired (the same trial seeds, so the same noise draws).

    pip install "./python[gym]" stable-baselines3 matplotlib
    python examples/python/train_residual_ppo.py [--steps 200000] [--eval 200] \
        [--plot curve.png] [--json result.json]
"""

from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np

from forkbench.gym import PalletPickEnv

SCENARIO = "field-test"
RESIDUAL_LIMITS = (0.3, 0.3)  # m/s, rad: the largest correction
TICKS_PER_STEP = 10  # 0.1 s per decision
PATH_POINTS = 4


def make_env() -> PalletPickEnv:
    return PalletPickEnv(
        SCENARIO,
        action_mode="residual",
        normalize_actions=True,
        residual_limits=RESIDUAL_LIMITS,
        ticks_per_step=TICKS_PER_STEP,
        path_points=PATH_POINTS,
    )


EVAL_SEED0 = 1_000_000  # evaluation episodes never seen in training


def episode(env: PalletPickEnv, seed: int, policy) -> tuple[bool, str, float]:
    """One evaluation episode: success, failure, return."""
    obs, _ = env.reset(seed=seed)
    total = 0.0
    while True:
        obs, reward, term, trunc, info = env.step(policy(obs))
        total += reward
        if term or trunc:
            return bool(info["success"]), info["failure"] or "success", total


def evaluate(policy, seeds: range) -> list[tuple[bool, str, float]]:
    env = make_env()
    return [episode(env, s, policy) for s in seeds]


def mcnemar_p(b: int, c: int) -> float:
    """Exact two-sided McNemar p for b and c discordant pairs."""
    n = b + c
    if n == 0:
        return 1.0
    tail = sum(math.comb(n, k) for k in range(min(b, c) + 1)) / 2**n
    return min(1.0, 2 * tail)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=200_000)
    ap.add_argument("--envs", type=int, default=8)
    ap.add_argument("--eval", type=int, default=200, help="evaluation episodes at the end")
    ap.add_argument("--curve-eval", type=int, default=50, help="episodes per curve point")
    ap.add_argument("--curve-every", type=int, default=25_000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--log-std-init", type=float, default=-1.0)
    ap.add_argument("--learning-rate", type=float, default=3e-4)
    ap.add_argument("--plot")
    ap.add_argument("--json")
    a = ap.parse_args()

    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.env_util import make_vec_env

    torch.set_num_threads(2)
    venv = make_vec_env(make_env, n_envs=a.envs, seed=a.seed)
    # Residual RL starts at the tracker: SB3 initialises the action head near zero, and a
    # small initial spread keeps early exploration close to pure pursuit.
    model = PPO(
        "MlpPolicy",
        venv,
        seed=a.seed,
        verbose=0,
        device="cpu",
        n_steps=512,
        batch_size=256,
        learning_rate=a.learning_rate,
        policy_kwargs={"log_std_init": a.log_std_init},
    )
    curve_seeds = range(EVAL_SEED0, EVAL_SEED0 + a.curve_eval)

    def trained(obs):
        return model.predict(obs, deterministic=True)[0]

    curve: list[tuple[int, float, float]] = []

    def point(steps: int) -> None:
        """Success and mean return of the deterministic policy on the curve's episodes."""
        runs = evaluate(trained, curve_seeds)
        curve.append(
            (steps, float(np.mean([r[0] for r in runs])), float(np.mean([r[2] for r in runs])))
        )
        print(
            f"{steps:>8} steps: success {curve[-1][1]:.0%}, return {curve[-1][2]:.2f}", flush=True
        )

    class Curve(BaseCallback):
        # Evaluated between updates (at the end of a rollout), so each point is a policy
        # that was trained, not one half-way through collecting.
        def _on_step(self) -> bool:
            return True

        def _on_rollout_start(self) -> None:
            if self.num_timesteps // a.curve_every > len(curve) - 1:
                point(self.num_timesteps)

    point(0)
    t0 = time.perf_counter()
    model.learn(total_timesteps=a.steps, callback=Curve())
    train_s = time.perf_counter() - t0
    point(model.num_timesteps)

    seeds = range(EVAL_SEED0, EVAL_SEED0 + a.eval)
    rl = evaluate(trained, seeds)
    pp = evaluate(lambda obs: np.zeros(2, dtype=np.float32), seeds)
    both = sum(r[0] and p[0] for r, p in zip(rl, pp))
    only_rl = sum(r[0] and not p[0] for r, p in zip(rl, pp))
    only_pp = sum(p[0] and not r[0] for r, p in zip(rl, pp))
    result = {
        "scenario": SCENARIO,
        "env": {
            "action_mode": "residual",
            "normalize_actions": True,
            "residual_limits": list(RESIDUAL_LIMITS),
            "ticks_per_step": TICKS_PER_STEP,
            "path_points": PATH_POINTS,
        },
        "training_steps": model.num_timesteps,
        "training_s": round(train_s, 1),
        "episodes": a.eval,
        "residual_ppo_successes": sum(r[0] for r in rl),
        "pure_pursuit_successes": sum(p[0] for p in pp),
        "both": both,
        "only_residual_ppo": only_rl,
        "only_pure_pursuit": only_pp,
        "mcnemar_p": round(mcnemar_p(only_rl, only_pp), 4),
        "residual_ppo_mean_return": round(float(np.mean([r[2] for r in rl])), 2),
        "pure_pursuit_mean_return": round(float(np.mean([p[2] for p in pp])), 2),
        "curve": curve,
    }
    print(json.dumps({k: v for k, v in result.items() if k != "curve"}, indent=1))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(result, f, indent=1)
    if a.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, (ax, ax2) = plt.subplots(1, 2, figsize=(10, 4))
        xs, ys, rs = zip(*curve)
        pp = evaluate(lambda o: np.zeros(2, dtype=np.float32), curve_seeds)
        ax.plot(xs, [100 * y for y in ys], marker="o", label="residual PPO (deterministic)")
        ax.axhline(100 * np.mean([p[0] for p in pp]), color="grey", ls="--", label="pure pursuit")
        ax.set_ylabel(f"success on {a.curve_eval} evaluation episodes (%)")
        ax.set_ylim(0, 100)
        ax2.plot(xs, rs, marker="o", label="residual PPO (deterministic)")
        ax2.axhline(np.mean([p[2] for p in pp]), color="grey", ls="--", label="pure pursuit")
        ax2.set_ylabel("mean return on the same episodes")
        for x in (ax, ax2):
            x.set_xlabel("training steps (0.1 s decisions)")
            x.legend(loc="lower right")
        fig.suptitle(f"Residual PPO on {SCENARIO}, {a.envs} environments")
        fig.tight_layout()
        fig.savefig(a.plot, dpi=110)
        print(f"wrote {a.plot}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
