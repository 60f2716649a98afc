#!/usr/bin/env python3
"""forkbench's PRM and RRT-Connect against OMPL's C++ library on the same grid, start and goal.

    python3 tools/ompl_compare.py [--runs N] [--forkbench PATH] [--json FILE]

OMPL is Debian's `libompl-dev` (1.5.2), driven by `tools/ompl_bench.cpp`, which this script
builds with g++ (installing `libompl-dev g++` with apt-get when they are missing and it
runs as root). The map is the warehouse world rasterised at 5 cm with the obstacles grown
by Luo's 0.815 m (`forkbench map --inflate-m`), written as a ROS map; both libraries plan
on that file: forkbench with `plan … --map MAP.yaml --inflate-m 0`, OMPL in a 2-D real
vector space whose validity checker reads the same cells, motions checked every half cell
(forkbench walks every cell). The leg is `reproduce prm`'s: the charging station (3, 3) to
the aisle before row 2b, bay 3.

Times are the planners' own, map loaded before, every run of a planner in one process (warm
caches on both sides): forkbench's sampling, connection and search (`plan --runs`); OMPL's
`solve` to its first exact solution (setup done before). Lengths: the first
solution, then after each library's simplification (OMPL: `SimpleSetup::simplifySolution`;
forkbench: vertex shortcuts then seeded random shortcuts, `nav::simplify`). Every run has
its own seed (forkbench) or its place in one seeded stream (OMPL).
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
START, GOAL = (3.0, 3.0), (30.75, 10.25)
INFLATE_M = 0.815
OMPL_INCLUDE = "/usr/include/ompl-1.5"


def ensure_ompl():
    """The C++ toolchain and OMPL's headers, installed with apt-get when missing."""
    if shutil.which("g++") and os.path.isdir(OMPL_INCLUDE):
        return
    if os.geteuid() != 0:
        sys.exit("needs g++ and libompl-dev (apt-get install g++ libompl-dev)")
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    subprocess.run(["apt-get", "update", "-qq"], check=True, env=env)
    subprocess.run(["apt-get", "install", "-y", "-q", "g++", "libompl-dev"], check=True,
                   env=env, stdout=subprocess.DEVNULL)


def build_bench(out_dir, name="ompl_bench"):
    """tools/NAME.cpp built with g++ against OMPL into OUT_DIR/NAME."""
    exe = os.path.join(out_dir, name)
    src = os.path.join(ROOT, "tools", name + ".cpp")
    subprocess.run(["g++", "-O2", "-std=c++17", src, f"-I{OMPL_INCLUDE}", "-I/usr/include/eigen3",
                    "-lompl", "-o", exe], check=True)
    return exe


def forkbench_runs(exe, yaml_path, planner, runs, extra):
    """`runs` plans in one process (seeds 0, 1, …), as OMPL's runs share one process."""
    cmd = [exe, "plan", planner, "--map", yaml_path, "--inflate-m", "0", "--connect-m", "10",
           "--seed", "0", "--runs", str(runs), "--json", "--start", "%g,%g,0" % START,
           "--goal", "%g,%g,0" % GOAL] + extra
    out = []
    done = subprocess.run(cmd, capture_output=True, text=True)
    # Exit 3 says some run found no path (its line has success false); others are errors.
    if done.returncode not in (0, 3):
        raise SystemExit(f"{' '.join(cmd)}: exit {done.returncode}: {done.stderr.strip()}")
    for line in done.stdout.splitlines():
        v = json.loads(line)
        t = v["timing_s"]
        simple = v.get("simplified") or {}
        out.append({"success": v["success"], "time_s": t["sampling"] + t["connection"] + t["search"],
                    "length_m": v["length_m"], "simplified_length_m": simple.get("length_m"),
                    "simplify_s": simple.get("time_s")})
    return out


def ompl_runs(bench, yaml_path, planner, runs, timeout_s):
    cmd = [bench, yaml_path, planner, str(runs), "1", *(str(v) for v in START + GOAL), str(timeout_s), "1.0"]
    lines = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout.splitlines()
    out = [json.loads(line) for line in lines]
    for r in out:
        if not r["success"]:
            r["length_m"] = r["simplified_length_m"] = None
    return out


def pct(values, q):
    v = sorted(values)
    return v[min(len(v) - 1, int(q * len(v)))] if v else float("nan")


def row(library, planner, runs):
    ok = [r for r in runs if r["success"]]
    med = lambda k: statistics.median(r[k] for r in ok) if ok else float("nan")
    p90 = lambda k: pct([r[k] for r in ok], 0.9)
    times = [r["time_s"] for r in runs]
    return {"library": library, "planner": planner, "success": len(ok), "runs": len(runs),
            "time_median_ms": 1e3 * statistics.median(times), "time_p90_ms": 1e3 * pct(times, 0.9),
            "length_median_m": med("length_m"), "length_p90_m": p90("length_m"),
            "simplified_median_m": med("simplified_length_m"), "simplified_p90_m": p90("simplified_length_m"),
            "simplify_median_ms": 1e3 * med("simplify_s")}


def table(rows, runs):
    lines = [f"warehouse map, 5 cm cells inflated by {INFLATE_M} m; {START} → {GOAL}; {runs} seeds each\n",
             "| library | planner | success | time to first solution, median / p90 | length median / p90 "
             "| simplified length median / p90 (time) | OMPL time / forkbench |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        ratio = f"{r['ratio']:.1f}×" if "ratio" in r else ""
        lines.append(
            f"| {r['library']} | {r['planner']} | {r['success']}/{r['runs']} | "
            f"{r['time_median_ms']:.3f} / {r['time_p90_ms']:.3f} ms | "
            f"{r['length_median_m']:.2f} / {r['length_p90_m']:.2f} m | "
            f"{r['simplified_median_m']:.2f} / {r['simplified_p90_m']:.2f} m ({r['simplify_median_ms']:.2f} ms) | {ratio} |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=100)
    ap.add_argument("--timeout-s", type=float, default=10.0)
    ap.add_argument("--json", help="also write the rows to FILE")
    ap.add_argument("--check", action="store_true",
                    help="exit 1 unless forkbench succeeds as often as OMPL with each planner")
    ap.add_argument("--forkbench", default=os.path.join(
        os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target")), "release", "forkbench"))
    a = ap.parse_args()
    ensure_ompl()
    tmp = tempfile.mkdtemp(prefix="ompl-compare-")
    bench = build_bench(tmp)
    subprocess.run([a.forkbench, "map", os.path.join(ROOT, "worlds", "warehouse.toml"),
                    "--margin-m", "0", "--inflate-m", str(INFLATE_M), "--out", tmp],
                   check=True, capture_output=True)
    yaml_path = os.path.join(tmp, "warehouse.yaml")
    om_prm = row("OMPL", "prm", ompl_runs(bench, yaml_path, "prm", a.runs, a.timeout_s))
    om_rrt = row("OMPL", "rrt-connect", ompl_runs(bench, yaml_path, "rrt-connect", a.runs, a.timeout_s))
    fb_first = row("forkbench", "prm --first-solution",
                   forkbench_runs(a.forkbench, yaml_path, "prm", a.runs, ["--first-solution"]))
    fb_500 = row("forkbench", "prm (500 nodes, the paper's)",
                 forkbench_runs(a.forkbench, yaml_path, "prm", a.runs, ["--nodes", "500"]))
    fb_rrt = row("forkbench", "rrt-connect", forkbench_runs(a.forkbench, yaml_path, "rrt-connect", a.runs, []))
    for fb, om in [(fb_first, om_prm), (fb_500, om_prm), (fb_rrt, om_rrt)]:
        fb["ratio"] = om["time_median_ms"] / fb["time_median_ms"]
    rows = [om_prm, fb_first, fb_500, om_rrt, fb_rrt]
    print(table(rows, a.runs))
    if a.json:
        json.dump(rows, open(a.json, "w"), indent=1)
    short = [f"{fb['planner']}: {fb['success']} < {om['success']}"
             for fb, om in [(fb_first, om_prm), (fb_500, om_prm), (fb_rrt, om_rrt)] if fb["success"] < om["success"]]
    if a.check and short:
        sys.exit("forkbench succeeds less often than OMPL: " + "; ".join(short))


if __name__ == "__main__":
    main()
