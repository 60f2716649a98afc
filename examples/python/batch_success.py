# %% [markdown]
# # Success per case, from Python
# A notebook-style script (cells in the `# %%` format that Jupyter, VS Code and jupytext
# open as a notebook): run a batch of the embedded default scenarios, both replanning
# modes, with the CLI's seeds, into a pandas DataFrame, then look at success per case.
#
#     python examples/python/batch_success.py [--trials 20] [--plot success.png]

# %%
import argparse
import time

import forkbench

ap = argparse.ArgumentParser()
ap.add_argument("--trials", type=int, default=20)
ap.add_argument("--plot", help="draw success per case to this PNG (needs matplotlib)")
args, _ = ap.parse_known_args()

# %% The README's main job (the embedded scenarios, both modes), as records in job order.
t0 = time.perf_counter()
records = forkbench.run_batch(trials=args.trials, seed=1)
print(f"{len(records)} trials in {time.perf_counter() - t0:.1f} s")

# %% One row per trial; columns as the outcome names them (SI units).
df = forkbench.to_dataframe(records)
df["mode"] = df["replan"].map({True: "replan", False: "plan once"})
print(
    df[
        ["scenario", "case", "planner", "mode", "seed", "success", "failure", "lateral_error_m"]
    ].head()
)

# %% Success per scenario, planner and mode: what `batch` prints.
table = df.pivot_table(
    index=["scenario", "planner"], columns="mode", values="success", aggfunc="mean"
)
print((100 * table).round(1).to_string())

# %% Success per case, and what the failures were.
per_case = df.groupby(["scenario", "case"])["success"].agg(["mean", "count"])
print(per_case.sort_values("mean").head(10).to_string())
print(df.loc[~df["success"], "failure"].value_counts().to_string())

# %% A plot of success per case, one panel per scenario.
if args.plot:
    import matplotlib.pyplot as plt

    scenarios = list(dict.fromkeys(df["scenario"]))  # in the batch's order
    fig, axes = plt.subplots(len(scenarios), 1, figsize=(9, 2.2 * len(scenarios)), squeeze=False)
    for ax, name in zip(axes[:, 0], scenarios):
        rows = df[df["scenario"] == name]
        cases = list(dict.fromkeys(rows["case"]))  # the scenario file's order
        rates = rows.groupby(["case", "mode"])["success"].mean().unstack().loc[cases]
        rates.plot.bar(ax=ax, ylim=(0, 1), width=0.8, legend=False)
        if ax is axes[0, 0]:
            ax.legend(title="mode", bbox_to_anchor=(1.0, 1.0), loc="upper left", fontsize=8)
        ax.set_title(name, fontsize=9)
        ax.set_xlabel("")
        ax.set_ylabel("success")
        ax.tick_params(axis="x", labelsize=7, rotation=0)
    fig.tight_layout()
    fig.savefig(args.plot, dpi=100)
    print(f"wrote {args.plot}")
