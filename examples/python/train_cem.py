"""Trains a docking controller against forkbench/PalletPick-v0 with the cross-entropy
method: a linear policy from the goal and the planned path ahead in the truck's frame (and
the measured speed and steering) to the speed and steering commands, its population evaluated in parallel by the
Rust vector environment. Prints, per iteration, the population's mean return, the elite's
and the success rate; compares with a random policy and the bench's own pure-pursuit
tracker on the same episodes. numpy and Gymnasium only; matplotlib (optional) draws the
curve.

    python examples/python/train_cem.py [--iterations 30] [--population 48] [--plot curve.png]
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from forkbench.gym import PalletPickEnv, PalletPickVectorEnv

PATH_POINTS = 4  # the planned path ahead, every 0.5 m, in the truck's frame
# goal dx, dy, dheading (truck frame), speed, steering, and the path points' lateral offsets
FEATURES = [6, 7, 8, 9, 10] + [13 + 2 * k + 1 for k in range(PATH_POINTS)]
TICKS_PER_STEP = 10  # 0.1 s per decision
MAX_STEPS = 1200  # the field test's 120 s limit


def act(params: np.ndarray, obs: np.ndarray, limits: np.ndarray) -> np.ndarray:
    """Per environment: tanh of a linear map of the features (plus a bias) to the limits."""
    x = np.concatenate([obs[:, FEATURES], np.ones((len(obs), 1))], axis=1)
    return np.tanh(np.einsum("nof,nf->no", params, x)) * limits


def evaluate(params: np.ndarray, seed: int) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Each parameter set's return, success and failure over its first episode (one
    environment each)."""
    env = PalletPickVectorEnv(
        len(params), "field-test", ticks_per_step=TICKS_PER_STEP, path_points=PATH_POINTS
    )
    limits = np.array(env.scenario.command_limits)
    obs, _ = env.reset(seed=seed)
    returns, success = np.zeros(len(params)), np.zeros(len(params), bool)
    failures = ["running"] * len(params)
    live = np.ones(len(params), bool)
    for _ in range(MAX_STEPS):
        obs, reward, term, trunc, info = env.step(act(params, obs, limits))
        returns += np.where(live, reward, 0.0)
        for i in np.flatnonzero(live & (term | trunc)):
            success[i] = bool(info["success"][i])
            failures[i] = info["failure"][i] or "success"
        live &= ~(term | trunc)
        if not live.any():
            break
    return returns, success, failures


def compare(policies: dict[str, np.ndarray], seeds: range) -> dict[str, dict[str, float]]:
    """Policies and the bench's pure-pursuit tracker on the same episodes (the same trial
    seeds, so the same noise draws): mean return and success rate."""
    env = PalletPickEnv("field-test", ticks_per_step=TICKS_PER_STEP, path_points=PATH_POINTS)
    limits = np.array(env.scenario.command_limits)
    out: dict[str, dict[str, list[float]]] = {}
    sampler = np.random.default_rng(0)
    for name in ["pure pursuit (the bench's tracker)", *policies, "uniform random actions"]:
        runs = out.setdefault(name, {"return": [], "success": []})
        for seed in seeds:
            obs, _ = env.reset(seed=seed)
            total = 0.0
            while True:
                if name in policies:
                    obs, r, term, trunc, info = env.step(
                        act(policies[name][None], obs[None], limits)[0]
                    )
                elif name.startswith("uniform"):
                    obs, r, term, trunc, info = env.step(sampler.uniform(-limits, limits))
                else:
                    obs, r, term, trunc, info = env.expert_step()
                total += r
                if term or trunc:
                    break
            runs["return"].append(total)
            runs["success"].append(float(info["success"]))
    return {k: {m: float(np.mean(v)) for m, v in runs.items()} for k, runs in out.items()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--iterations", type=int, default=30)
    ap.add_argument("--population", type=int, default=48)
    ap.add_argument("--elite", type=int, default=8)
    ap.add_argument("--compare-episodes", type=int, default=64)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--min-std", type=float, default=0.1)
    ap.add_argument("--json", help="write the curve here")
    ap.add_argument("--plot", help="draw the curve to this PNG (needs matplotlib)")
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)
    shape = (2, len(FEATURES) + 1)
    mean, std = np.zeros(shape), np.ones(shape)
    curve = []
    t0 = time.perf_counter()
    for it in range(a.iterations):
        params = mean + std * rng.normal(size=(a.population, *shape))
        returns, _, _ = evaluate(params, seed=a.seed * 1000 + it)
        elite = params[np.argsort(returns)[-a.elite :]]
        # A floor on the spread keeps the search from settling on its first plateau.
        mean, std = elite.mean(axis=0), np.maximum(elite.std(axis=0), a.min_std)
        test_returns, test_success, failures = evaluate(
            np.repeat(mean[None], 32, axis=0), seed=10**6 + it
        )
        row = {
            "iteration": it,
            "population_return": float(returns.mean()),
            "elite_return": float(np.sort(returns)[-a.elite :].mean()),
            "mean_policy_return": float(test_returns.mean()),
            "mean_policy_success": float(test_success.mean()),
            "mean_policy_ends": {f: failures.count(f) for f in sorted(set(failures))},
            "elapsed_s": time.perf_counter() - t0,
            "policy": mean.tolist(),
        }
        curve.append(row)
        print(
            f"iter {it:2d}  population {row['population_return']:7.2f}  elite {row['elite_return']:7.2f}  "
            f"mean policy {row['mean_policy_return']:7.2f} (success {row['mean_policy_success']:.0%}; "
            f"{', '.join(f'{k} {v}' for k, v in row['mean_policy_ends'].items())})  "
            f"{row['elapsed_s']:.0f} s",
            flush=True,
        )
    best = max(curve, key=lambda r: r["mean_policy_return"])
    ref = compare(
        {
            "CEM policy (best iteration's mean)": np.array(best["policy"]),
            "random policy (initial distribution)": rng.normal(size=shape),
        },
        range(2000, 2000 + a.compare_episodes),
    )
    print(f"on {a.compare_episodes} further episodes, the same for each:")
    for name, r in ref.items():
        print(f"  {name:40} return {r['return']:7.2f}  success {r['success']:.0%}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"curve": curve, "comparison": ref}, f, indent=1)
    if a.plot:
        import matplotlib.pyplot as plt

        iters = [r["iteration"] for r in curve]
        plt.figure(figsize=(7, 4))
        plt.plot(
            iters,
            [r["mean_policy_return"] for r in curve],
            "o-",
            label="CEM mean policy (32 episodes)",
        )
        plt.plot(iters, [r["population_return"] for r in curve], ".-", label="CEM population")
        styles = {"pure": (":", "green"), "random": ("--", "grey"), "uniform": ("-.", "red")}
        for name, r in ref.items():
            key = name.split()[0]
            if key in styles:
                plt.axhline(r["return"], ls=styles[key][0], color=styles[key][1], label=name)
        plt.xlabel("iteration")
        plt.ylabel("return per episode")
        plt.title("forkbench/PalletPick-v0, field test: cross-entropy method")
        plt.legend()
        plt.tight_layout()
        plt.savefig(a.plot, dpi=110)


if __name__ == "__main__":
    main()
